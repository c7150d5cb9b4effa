!> Unit tests of src/boundaries/wall_pressure_taps.f90 (issue 50): the weights by which a wall-pressure
!> gauge reads a patch of a wall from the nodal impulses of its constraint. For a uniform pressure p the
!> nodal loads are p times the hat integrals over the wetted surface; the gauge must then read p exactly,
!> for any patch (inside, at the wall's end, wider than a cell, narrower), in 2-D and 3-D; patches tiling
!> a wall must share each node's load out completely; a node of another face is no tap; and the
!> constraint must add exactly sum w dp . n / |patch| to the gauge's column.
module test_wall_pressure_taps
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use wall_pressure_taps, only: wall_sensor_t, pressure_taps_t, patch_weight
   use wall_conditions, only: slip_condition_t
   use planar_wall, only: planar_wall_t
   use constraint_list, only: constraint_list_t
   implicit none
   private

   public :: test_uniform_pressure_read_exactly_2d, test_uniform_pressure_read_exactly_3d, &
             test_tiling_patches_share_every_load, test_other_faces_are_no_taps, test_constraint_fills_the_column

   real(rp), parameter :: h = 0.01_rp
   integer, parameter :: nodes = 21               !< a wall from y = 0 to 20 h, wetted all along

contains

   !> The integral of node j's hat (half-width h about y_j = j h) over the wetted 0 .. 20 h.
   pure real(rp) function wetted_hat(j)
      integer, intent(in) :: j
      wetted_hat = h
      if (j == 0 .or. j == nodes - 1) wetted_hat = 0.5_rp * h
   end function wetted_hat

   !> A sensor on the wall x = 0 (normal +x) of the 2-D wall above, centre y, half-size r.
   pure function sensor_2d(y, r) result(sensor)
      real(rp), intent(in) :: y, r
      type(wall_sensor_t) :: sensor
      sensor%slot = 1
      sensor%point = [0.0_rp, y, 0.0_rp]
      sensor%normal = [1.0_rp, 0.0_rp, 0.0_rp]
      sensor%radius = r
      sensor%wet_lo(2) = 0.0_rp
      sensor%wet_hi(2) = (nodes - 1) * h
   end function sensor_2d

   !> The reading sum_j w_j J_j / |patch| for the loads J_j = p integral of N_j.
   real(rp) function reading_2d(sensor, p) result(reading)
      type(wall_sensor_t), intent(in) :: sensor
      real(rp), intent(in) :: p
      real(rp) :: weight, area
      integer :: j
      reading = 0.0_rp
      do j = 0, nodes - 1
         call patch_weight(sensor, 2, h, [0.0_rp, j * h], weight, area)
         reading = reading + weight * p * wetted_hat(j) / area
      end do
   end function reading_2d

   !> Patches in the middle, off the nodes, wider and narrower than a cell, and cut by the wall's end (a
   !> gauge 3 mm above a floor with 1 cm cells): each reads the uniform 2500 Pa to round-off.
   subroutine test_uniform_pressure_read_exactly_2d()
      real(rp), parameter :: p = 2500.0_rp
      call assertEqual(p, reading_2d(sensor_2d(10.0_rp * h, 0.5_rp * h), p), 1.0e-9_rp, 'on a node, one cell')
      call assertEqual(p, reading_2d(sensor_2d(7.37_rp * h, 0.21_rp * h), p), 1.0e-9_rp, 'between nodes, narrow')
      call assertEqual(p, reading_2d(sensor_2d(12.5_rp * h, 3.2_rp * h), p), 1.0e-9_rp, 'wide')
      call assertEqual(p, reading_2d(sensor_2d(0.3_rp * h, 0.5_rp * h), p), 1.0e-9_rp, 'cut by the wall end')
      call assertEqual(p, reading_2d(sensor_2d(0.0_rp, 0.21_rp * h), p), 1.0e-9_rp, 'centred on the end')
      call assertEqual(p, reading_2d(sensor_2d(19.9_rp * h, 2.0_rp * h), p), 1.0e-9_rp, 'cut by the upper end')
   end subroutine test_uniform_pressure_read_exactly_2d

   !> A face z = 0 (normal +z) wetted over 0 .. 20 h in x and 0 .. 10 h in y; a square patch at a corner
   !> of that region and one inside read the uniform pressure exactly.
   subroutine test_uniform_pressure_read_exactly_3d()
      real(rp), parameter :: p = 1234.5_rp
      type(wall_sensor_t) :: sensor
      real(rp) :: weight, area, reading, load
      integer :: i, j, k
      do k = 1, 2
         sensor%slot = 1
         sensor%normal = [0.0_rp, 0.0_rp, 1.0_rp]
         sensor%wet_lo(1:2) = [0.0_rp, 0.0_rp]
         sensor%wet_hi(1:2) = [20.0_rp * h, 10.0_rp * h]
         if (k == 1) then
            sensor%point = [0.4_rp * h, 9.7_rp * h, 0.0_rp]
            sensor%radius = 0.6_rp * h
         else
            sensor%point = [11.2_rp * h, 4.9_rp * h, 0.0_rp]
            sensor%radius = 1.7_rp * h
         end if
         reading = 0.0_rp
         do j = 0, 10
            do i = 0, 20
               call patch_weight(sensor, 3, h, [i * h, j * h, 0.0_rp], weight, area)
               load = p * merge(0.5_rp, 1.0_rp, i == 0 .or. i == 20) * merge(0.5_rp, 1.0_rp, j == 0 .or. j == 10) * h * h
               reading = reading + weight * load / area
            end do
         end do
         call assertEqual(p, reading, 1.0e-9_rp, merge('patch at a corner', 'patch inside     ', k == 1))
      end do
   end subroutine test_uniform_pressure_read_exactly_3d

   !> Seven patches of unequal size tiling the wall 0 .. 20 h: every node's weights add up to 1, so the
   !> patches' loads add up to the wall's (impulse-exact panels).
   subroutine test_tiling_patches_share_every_load()
      real(rp), parameter :: edges(8) = [0.0_rp, 1.3_rp, 2.0_rp, 5.5_rp, 9.0_rp, 9.4_rp, 15.0_rp, 20.0_rp] * h
      real(rp) :: total(0:nodes - 1), weight, area
      integer :: j, s
      total = 0.0_rp
      do s = 1, 7
         do j = 0, nodes - 1
            call patch_weight(sensor_2d(0.5_rp * (edges(s) + edges(s + 1)), 0.5_rp * (edges(s + 1) - edges(s))), &
                              2, h, [0.0_rp, j * h], weight, area)
            call assertEqual(edges(s + 1) - edges(s), area, 1.0e-15_rp, 'patch length')
            total(j) = total(j) + weight
         end do
      end do
      call assertEqual([(1.0_rp, j = 0, nodes - 1)], total, 1.0e-12_rp, 'each node shared out completely')
   end subroutine test_tiling_patches_share_every_load

   !> Taps of a box corner: nodes on the sensor's face are taps, a node whose normal is the other face's
   !> (at 90 degrees) or that lies off the sensor's plane is not.
   subroutine test_other_faces_are_no_taps()
      type(pressure_taps_t) :: taps
      real(rp) :: feet(2, 3), normals(2, 3)
      taps%sensors = [sensor_2d(5.0_rp * h, 0.5_rp * h)]
      feet(:, 1) = [0.0_rp, 5.0_rp * h]
      normals(:, 1) = [1.0_rp, 0.0_rp]
      feet(:, 2) = [0.0_rp, 5.0_rp * h]
      normals(:, 2) = [0.0_rp, 1.0_rp]             ! the top face's normal
      feet(:, 3) = [2.0_rp * h, 5.0_rp * h]         ! another plane
      normals(:, 3) = [1.0_rp, 0.0_rp]
      call taps%place(2, h, feet, normals)
      call assertEqual(1, size(taps%slot), 'one tap')
      call assertTrue(taps%first(1) == 1 .and. taps%first(2) == 2 .and. taps%first(3) == 2 .and. taps%first(4) == 2, &
                      'the tap is node 1''s')
      call assertEqual([0.75_rp / h, 0.0_rp], taps%vector(:, 1), 1.0e-9_rp, 'weight 3/4 of the hat over the patch h')
   end subroutine test_other_faces_are_no_taps

   !> A wall x = 0 with a sensor tap on its one node: the constraint's impulse m (v^c - v*) goes to the
   !> wall's column, and dp . vector to the sensor's column after the walls'.
   subroutine test_constraint_fills_the_column()
      type(constraint_list_t) :: walls
      type(planar_wall_t) :: wall
      real(rp) :: v(2, 1), impulse(6, 2), feet(2, 1), normals(2, 1)
      wall%normal(1:2) = [1.0_rp, 0.0_rp]
      wall%normals = reshape([1.0_rp, 0.0_rp], [2, 1])
      call wall%set_condition(slip_condition_t())
      wall%nodes = [1]
      wall%counted = [.true.]
      allocate (wall%arm(3, 1))
      wall%arm = 0.0_rp
      wall%taps%sensors = [sensor_2d(5.0_rp * h, 0.5_rp * h)]
      feet(:, 1) = [0.0_rp, 5.0_rp * h]
      normals(:, 1) = [1.0_rp, 0.0_rp]
      call wall%taps%place(2, h, feet, normals)
      call walls%append(wall, 0)
      v(:, 1) = [-2.0_rp, 1.0_rp]
      impulse = 0.0_rp
      call walls%constrain(2, v, [3.0_rp], impulse)
      call assertEqual([6.0_rp, 0.0_rp], impulse(1:2, 1), 1.0e-14_rp, 'the wall: m (v^c - v*) = 3 x 2')
      call assertEqual(6.0_rp * 0.75_rp / h, impulse(1, 2), 1.0e-9_rp, 'the sensor: dp . n x 3/4 / h')
   end subroutine test_constraint_fills_the_column
end module test_wall_pressure_taps
