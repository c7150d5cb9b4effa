!> Unit tests of src/boundaries/surface_sensors.f90 (issue 50): the weights by which a wall-pressure
!> gauge reads a patch of a wall from the nodal impulses of its constraint. For a uniform pressure p the
!> nodal loads are p times the hat integrals over the wetted surface; the gauge must then read p exactly,
!> for any patch (inside, at the wall's end, wider than a cell, narrower), in 2-D and 3-D; patches tiling
!> a wall must share each node's load out completely; a node of another face is no tap; and the
!> constraint must add exactly sum w dp . n / |patch| to the gauge's column. Panels (issue 52): their
!> consistent weights read a pressure linear along the face exactly, also at the face's ends, and panels
!> tiling a face share every node's load out completely; a load cell takes the nodes in its box; the
!> safeguard's impulse on a particle is shared out as a node's there would be.
module test_surface_sensors
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use surface_sensors, only: surface_sensor_t, sensor_taps_t, patch_weight, pressure_row, add_tap_impulse, &
                              sensor_panel, sensor_load_cell
   use input_text, only: int_text
   use world_frame, only: frame_t
   use wall_conditions, only: slip_condition_t
   use planar_wall, only: planar_wall_t
   use constraint_list, only: constraint_list_t
   implicit none
   private

   public :: test_uniform_pressure_read_exactly_2d, test_uniform_pressure_read_exactly_3d, &
             test_tiling_patches_share_every_load, test_other_faces_are_no_taps, test_constraint_fills_the_column, &
             test_panel_reads_linear_pressure_exactly, test_tiling_panels_share_every_load, &
             test_panel_patch_from_its_box, test_load_cell_takes_the_nodes_in_its_box, &
             test_safeguard_impulse_shared_out

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
      type(surface_sensor_t) :: sensor
      sensor%slot = 1
      sensor%point = [0.0_rp, y, 0.0_rp]
      sensor%normal = [1.0_rp, 0.0_rp, 0.0_rp]
      sensor%radius = r
      call sensor%set_patch(2, frame_t())
      sensor%wet_lo(2) = 0.0_rp
      sensor%wet_hi(2) = (nodes - 1) * h
   end function sensor_2d

   !> The reading sum_j w_j J_j / |patch| for the loads J_j = p integral of N_j.
   real(rp) function reading_2d(sensor, p) result(reading)
      type(surface_sensor_t), intent(in) :: sensor
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
      type(surface_sensor_t) :: sensor
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
         call sensor%set_patch(3, frame_t())
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
      type(sensor_taps_t) :: taps
      real(rp) :: feet(2, 3), normals(2, 3)
      taps%sensors = [sensor_2d(5.0_rp * h, 0.5_rp * h)]
      feet(:, 1) = [0.0_rp, 5.0_rp * h]
      normals(:, 1) = [1.0_rp, 0.0_rp]
      feet(:, 2) = [0.0_rp, 5.0_rp * h]
      normals(:, 2) = [0.0_rp, 1.0_rp]             ! the top face's normal
      feet(:, 3) = [2.0_rp * h, 5.0_rp * h]         ! another plane
      normals(:, 3) = [1.0_rp, 0.0_rp]
      call taps%place(2, h, feet, feet, normals, frame_t())
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
      call wall%taps%place(2, h, feet, feet, normals, frame_t())
      call walls%append(wall, 0)
      v(:, 1) = [-2.0_rp, 1.0_rp]
      impulse = 0.0_rp
      call walls%constrain(2, v, [3.0_rp], impulse)
      call assertEqual([6.0_rp, 0.0_rp], impulse(1:2, 1), 1.0e-14_rp, 'the wall: m (v^c - v*) = 3 x 2')
      call assertEqual(6.0_rp * 0.75_rp / h, impulse(pressure_row, 2), 1.0e-9_rp, 'the sensor: dp . n x 3/4 / h')
   end subroutine test_constraint_fills_the_column

   !> A panel lower .. upper (y) on the wall x = 0 of the 2-D wall above (wetted 0 .. 20 h), with its
   !> consistent weights on the nodes j h.
   function panel_2d(lower, upper) result(sensor)
      real(rp), intent(in) :: lower, upper
      type(surface_sensor_t) :: sensor
      sensor%slot = 1
      sensor%kind = sensor_panel
      sensor%point = [0.0_rp, 0.5_rp * (lower + upper), 0.0_rp]
      sensor%normal = [1.0_rp, 0.0_rp, 0.0_rp]
      sensor%lower = [0.0_rp, lower, 0.0_rp]
      sensor%upper = [0.0_rp, upper, 0.0_rp]
      sensor%wet_lo(2) = 0.0_rp
      sensor%wet_hi(2) = (nodes - 1) * h
      call sensor%set_patch(2, frame_t(), [0.0_rp, 0.0_rp], h)
   end function panel_2d

   !> The nodal loads of the pressure p(y) = p0 - g y over the wetted 0 .. 20 h: J_j = integral of p N_j.
   pure real(rp) function linear_load(j, p0, g)
      integer, intent(in) :: j
      real(rp), intent(in) :: p0, g
      real(rp) :: y
      y = j * h
      if (j == 0) then
         linear_load = h * (p0 / 3.0_rp + (p0 - g * h) / 6.0_rp)
      else if (j == nodes - 1) then
         linear_load = h * ((p0 - g * (y - h)) / 6.0_rp + (p0 - g * y) / 3.0_rp)
      else
         linear_load = h * (p0 - g * y)
      end if
   end function linear_load

   !> A hydrostatic pressure (linear in y) read by panels at the lower end (one cell: the lumped weights
   !> are 1/6 of rho g h off there), inside, off the nodes and at the upper end: each reads the mean of p
   !> over its segment to round-off, and its force is that mean times its length.
   subroutine test_panel_reads_linear_pressure_exactly()
      real(rp), parameter :: p0 = 2000.0_rp, g = 9810.0_rp
      real(rp), parameter :: segments(2, 5) = reshape([0.0_rp, 1.0_rp, 3.0_rp, 8.0_rp, 2.3_rp, 4.9_rp, &
                                                       17.5_rp, 20.0_rp, 0.0_rp, 20.0_rp], [2, 5]) * h
      type(surface_sensor_t) :: panel
      real(rp) :: weight, area, force, exact
      integer :: s, j
      do s = 1, size(segments, 2)
         panel = panel_2d(segments(1, s), segments(2, s))
         force = 0.0_rp
         do j = 0, nodes - 1
            call patch_weight(panel, 2, h, [0.0_rp, j * h], weight, area)
            force = force + weight * linear_load(j, p0, g)
         end do
         exact = p0 - g * 0.5_rp * (segments(1, s) + segments(2, s))
         call assertEqual(segments(2, s) - segments(1, s), area, 1.0e-15_rp, 'panel length')
         call assertEqual(exact, force / area, 1.0e-9_rp * p0, 'mean pressure of a panel '//int_text(s))
      end do
   end subroutine test_panel_reads_linear_pressure_exactly

   !> Six panels of unequal size, edges on and off the nodes, tiling the wall 0 .. 20 h: every node's
   !> weights add up to 1 (to round-off), so the panels' loads add up to the wall's.
   subroutine test_tiling_panels_share_every_load()
      real(rp), parameter :: edges(7) = [0.0_rp, 1.0_rp, 2.7_rp, 5.5_rp, 9.0_rp, 15.0_rp, 20.0_rp] * h
      real(rp) :: total(0:nodes - 1), weight, area
      integer :: j, s
      total = 0.0_rp
      do s = 1, 6
         do j = 0, nodes - 1
            call patch_weight(panel_2d(edges(s), edges(s + 1)), 2, h, [0.0_rp, j * h], weight, area)
            total(j) = total(j) + weight
         end do
      end do
      call assertEqual([(1.0_rp, j = 0, nodes - 1)], total, 1.0e-13_rp, 'each node shared out completely')
   end subroutine test_tiling_panels_share_every_load

   !> A 3-D panel given by its box on a face y = 0.3 (normal -y), the grid turned by 0 and by 30 degrees:
   !> along x and z its patch is the box's extent, and its area their product.
   subroutine test_panel_patch_from_its_box()
      type(surface_sensor_t) :: panel
      type(frame_t) :: frame
      real(rp) :: weight, area
      panel%kind = sensor_panel
      panel%lower = [0.1_rp, 0.3_rp, 0.05_rp]
      panel%upper = [0.25_rp, 0.3_rp, 0.15_rp]
      panel%point = [0.175_rp, 0.3_rp, 0.1_rp]
      panel%normal = [0.0_rp, -1.0_rp, 0.0_rp]
      panel%wet_lo = [0.0_rp, 0.0_rp, 0.0_rp]
      panel%wet_hi = [1.0_rp, 1.0_rp, 1.0_rp]
      call panel%set_patch(3, frame_t(), [0.0_rp, 0.0_rp, 0.0_rp], 0.05_rp)
      call assertEqual([0.1_rp, 0.05_rp], panel%patch_lo, 1.0e-15_rp, 'patch from lower (x, z)')
      call assertEqual([0.25_rp, 0.15_rp], panel%patch_hi, 1.0e-15_rp, 'patch to upper (x, z)')
      call patch_weight(panel, 3, 0.05_rp, panel%point, weight, area)
      call assertEqual(0.015_rp, area, 1.0e-15_rp, 'area 0.15 m x 0.1 m')
      ! the turned grid: the face's normal is not a grid axis; the tangents are the world's x and z
      call frame%init(30.0_rp, [0.0_rp, 0.0_rp, 0.0_rp])
      panel%normal(1:3) = frame%grid_vector([0.0_rp, -1.0_rp, 0.0_rp])
      panel%point(1:3) = frame%grid_point([0.175_rp, 0.3_rp, 0.1_rp])
      call panel%set_patch(3, frame)
      call assertEqual(0.15_rp, panel%patch_hi(1) - panel%patch_lo(1), 1.0e-12_rp, 'turned: extent along x')
      call assertEqual(0.1_rp, panel%patch_hi(2) - panel%patch_lo(2), 1.0e-12_rp, 'turned: extent along z')
   end subroutine test_panel_patch_from_its_box

   !> A load cell 0 <= y < 5 h on the wall's nodes: the nodes 0 .. 4 are taps of weight 1 (the one at 5 h
   !> belongs to the next cell), and they add the full impulse to the cell's force rows.
   subroutine test_load_cell_takes_the_nodes_in_its_box()
      type(sensor_taps_t) :: taps
      type(surface_sensor_t) :: cell
      real(rp) :: feet(2, nodes), normals(2, nodes), impulse(6, 1)
      integer :: j, t
      cell%slot = 1
      cell%kind = sensor_load_cell
      cell%lower = [-h, 0.0_rp, 0.0_rp]
      cell%upper = [h, 5.0_rp * h, 0.0_rp]
      taps%sensors = [cell]
      do j = 1, nodes
         feet(:, j) = [0.0_rp, (j - 1) * h]
         normals(:, j) = [1.0_rp, 0.0_rp]
      end do
      call taps%place(2, h, feet, feet, normals, frame_t())
      call assertEqual(5, size(taps%slot), 'five taps')
      call assertEqual([(1.0_rp, j = 1, 5)], taps%weight, 0.0_rp, 'weight 1')
      impulse = 0.0_rp
      do t = 1, size(taps%slot)
         call add_tap_impulse(taps, t, [2.0_rp, -1.0_rp], impulse)
      end do
      call assertEqual([10.0_rp, -5.0_rp], impulse(1:2, 1), 1.0e-14_rp, 'the cell: five impulses (2, -1)')
      call assertEqual(0.0_rp, impulse(pressure_row, 1), 0.0_rp, 'a load cell reads no pressure')
   end subroutine test_load_cell_takes_the_nodes_in_its_box

   !> A particle put back onto the wall at y = 2.7 h: its impulse goes to the panels tiling the wall as a
   !> node's there would (shares adding up to it), and not to a gauge.
   subroutine test_safeguard_impulse_shared_out()
      type(sensor_taps_t) :: taps
      type(surface_sensor_t) :: gauge
      real(rp) :: impulse(6, 4)
      integer :: s
      taps%sensors = [panel_2d(0.0_rp, 2.0_rp * h), panel_2d(2.0_rp * h, 3.5_rp * h), panel_2d(3.5_rp * h, 20.0_rp * h)]
      gauge = sensor_2d(2.7_rp * h, h)
      gauge%slot = 4
      taps%sensors = [taps%sensors, gauge]
      do s = 1, 3
         taps%sensors(s)%slot = s
      end do
      taps%force_sensors = .true.
      impulse = 0.0_rp
      call taps%add_point_impulse(2, h, [0.0_rp, 2.7_rp * h], [1.0_rp, 0.0_rp], frame_t(), [3.0_rp, 0.5_rp], impulse)
      call assertEqual([3.0_rp, 0.5_rp], sum(impulse(1:2, 1:3), 2), 1.0e-13_rp, 'the panels share it out')
      call assertTrue(impulse(1, 2) > impulse(1, 1) .and. impulse(1, 2) > impulse(1, 3), 'most to the panel it is on')
      call assertEqual([0.0_rp, 0.0_rp, 0.0_rp], impulse(1:3, 4), 0.0_rp, 'nothing to the gauge')
   end subroutine test_safeguard_impulse_shared_out
end module test_surface_sensors
