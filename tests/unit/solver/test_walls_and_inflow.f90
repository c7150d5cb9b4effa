!> Walls in any orientation, the rotated grid frame and fluid inflow (issue 5), on 1, 2 and 4 ranks:
!>  - `&wall` groups on the sides of the box constrain the same nodes as `&box_walls` and give the same
!>    run bit for bit (an aligned grid reproduces the box walls exactly);
!>  - a tank at rest on a grid turned by 90 degrees is the same tank as on the aligned grid, to round-off;
!>  - an inlet creates rho0 v0 H of mass per unit time exactly (one layer every Dp / v0), with ids that
!>    do not depend on the number of ranks, and no particle ends behind a wall.
module test_walls_and_inflow
   use kinds, only: rp, i8, name_len
   use time_table, only: time_table_t
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_Allgather, MPI_Allgatherv, MPI_IN_PLACE, MPI_INTEGER, &
                      MPI_INTEGER8, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_MIN, MPI_Comm_size
   use assertions, only: assertTrue, assertEqual, assertRelativelyEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, wall_spec_t, inlet_spec_t, wall_none
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use test_scenes, only: water_scene, add_body, tank_with_inlet
   use input_text, only: int_text, real_text
   implicit none
   private

   public :: test_wall_groups_equal_box_walls, test_quarter_turn_grid_is_the_same_tank, &
             test_inflow_mass_flux_and_ids, test_no_particle_behind_a_wall, test_hydrograph_inflow

contains

   !> A settling water column in a 2 x 1.5 box with slip sides and floor.
   function column_scene() result(scene)
      type(scene_t) :: scene
      scene = water_scene(2, 0.1_rp, [2.0_rp, 1.5_rp, 0.0_rp], 2.0e6_rp, 10.0_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [0.8_rp, 1.0_rp, 0.0_rp], 2, .false., 0.0_rp)
      scene%grid%wall(2, 2) = wall_none
   end function column_scene

   subroutine test_wall_groups_equal_box_walls(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: box, walls
      type(solver_t) :: a, b
      type(status_t) :: status
      type(diagnostics_t) :: da, db
      integer :: w, step

      box = column_scene()
      walls = box
      walls%grid%wall = wall_none
      allocate (walls%walls(3))
      walls%walls(1) = wall_spec_t(point=[0.0_rp, 0.0_rp, 0.0_rp], normal=[1.0_rp, 0.0_rp, 0.0_rp], &
                                   lower=[0.0_rp, 0.0_rp, 0.0_rp], upper=[0.0_rp, 1.5_rp, 0.0_rp])
      walls%walls(2) = wall_spec_t(point=[2.0_rp, 0.7_rp, 0.0_rp], normal=[-3.0_rp, 0.0_rp, 0.0_rp])   ! unbounded, any length
      walls%walls(3) = wall_spec_t(point=[1.0_rp, 0.0_rp, 0.0_rp], normal=[0.0_rp, 1.0_rp, 0.0_rp], &
                                   lower=[0.0_rp, 0.0_rp, 0.0_rp], upper=[2.0_rp, 0.0_rp, 0.0_rp])
      call a%init(box, comm, status)
      call assertTrue(status%ok, 'box walls: '//trim(status%message))
      call b%init(walls, comm, status)
      call assertTrue(status%ok, 'wall groups: '//trim(status%message))
      call assertEqual(a%constraints%count(), b%constraints%count(), 'number of walls')
      do w = 1, min(a%constraints%count(), b%constraints%count())
         call assertEqual(size(a%constraints%items(w)%item%nodes), size(b%constraints%items(w)%item%nodes), 'nodes of wall')
      end do
      do step = 1, 150
         call a%advance()
         call b%advance()
      end do
      da = a%diagnostics()
      db = b%diagnostics()
      call assertTrue(da%kinetic_energy > 1.0_rp, 'the column moves')
      ! bit for bit: the differences are exactly zero
      call assertTrue(all(abs([da%kinetic_energy - db%kinetic_energy, da%h_eq - db%h_eq, da%max_speed - db%max_speed, &
                               da%time - db%time]) <= 0.0_rp), 'the same run bit for bit')
      call a%free()
      call b%free()
   end subroutine test_wall_groups_equal_box_walls

   !> In 2-D (gravity along -y) and in 3-D (gravity along -z, the grid turned about the vertical).
   subroutine test_quarter_turn_grid_is_the_same_tank(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_quarter_turn(comm, 2)
      call check_quarter_turn(comm, 3)
   end subroutine test_quarter_turn_grid_is_the_same_tank

   subroutine check_quarter_turn(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(scene_t) :: aligned, turned
      type(solver_t) :: a, b
      type(status_t) :: status
      type(diagnostics_t) :: da, db
      integer :: step
      real(rp) :: pressure_a, pressure_b

      real(rp) :: depth
      if (dim == 2) then
         aligned = water_scene(2, 0.2_rp, [1.6_rp, 2.4_rp, 0.0_rp], 2.0e7_rp, 10.0_rp)
         call add_body(aligned, 1, [0.0_rp, 0.0_rp, 0.0_rp], [1.6_rp, 1.2_rp, 0.0_rp], 3, .true., 1.2_rp)
         depth = 1.2_rp
      else
         aligned = water_scene(3, 0.2_rp, [1.6_rp, 1.2_rp, 1.2_rp], 2.0e7_rp, 10.0_rp)
         call add_body(aligned, 1, [0.0_rp, 0.0_rp, 0.0_rp], [1.6_rp, 1.2_rp, 0.6_rp], 2, .true., 0.6_rp)
         depth = 0.6_rp
      end if
      aligned%grid%wall(2, dim) = wall_none
      aligned%materials(1)%stabilization = 'FOAL1'
      turned = aligned
      turned%grid%rotation = 90.0_rp
      call a%init(aligned, comm, status)
      call assertTrue(status%ok, 'aligned: '//trim(status%message))
      call b%init(turned, comm, status)
      call assertTrue(status%ok, 'turned: '//trim(status%message))
      call assertTrue(b%grid%frame%rotated, 'the grid is turned')
      do step = 1, 100
         call a%advance()
         call b%advance()
      end do
      da = a%diagnostics()
      db = b%diagnostics()
      call assertEqual(da%particles, db%particles, 'particles')
      call assertRelativelyEqual(da%h_eq, db%h_eq, 1.0e-12_rp, 'h_eq')
      call assertRelativelyEqual(da%time, db%time, 1.0e-12_rp, 'time after 100 steps')
      pressure_a = bottom_pressure(a)
      pressure_b = bottom_pressure(b)
      call assertRelativelyEqual(pressure_a, pressure_b, 1.0e-9_rp, 'largest pressure')
      ! FOAL1 holds the cell averages: the bottom cells' pressure is rho g (H - h / 2)
      call assertRelativelyEqual(pressure_a, 1000.0_rp * 10.0_rp * (depth - 0.1_rp), 1.0e-3_rp, &
                                 'largest pressure = rho g (H - h/2)')
      call assertTrue(da%kinetic_energy < 1.0e-6_rp * 1000.0_rp * 10.0_rp * depth**3 .and. &
                      db%kinetic_energy < 1.0e-6_rp * 1000.0_rp * 10.0_rp * depth**3, 'both tanks stay at rest')
      call assertEqual(b%wall_corrections, 0, 'no particle crossed a wall of the turned grid')
      call a%free()
      call b%free()
   end subroutine check_quarter_turn

   !> Largest particle pressure on any rank.
   real(rp) function bottom_pressure(solver) result(pressure)
      type(solver_t), intent(in) :: solver
      integer :: p
      pressure = 0.0_rp
      do p = 1, solver%particles%count
         pressure = max(pressure, -solver%particles%density(p) * sum(solver%particles%sbar(1:3, p)) / 3.0_rp)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, pressure, 1, MPI_DOUBLE_PRECISION, MPI_MAX, solver%domain%comm)
   end function bottom_pressure

   !> The scene of the inflow tests: a 3 x 2 box, floor and right wall, left wall above an opening of
   !> 0.5 m at the floor through which water enters at 2 m/s until t = 0.1 s.
   function inflow_scene() result(scene)
      type(scene_t) :: scene
      scene = tank_with_inlet(0.5_rp, 2.0_rp, 0.1_rp)
      scene%run%cfl = 0.3_rp
   end function inflow_scene

   !> In 2-D, and in 3-D through an opening 0.5 m (along y) x 0.4 m (along z).
   subroutine test_inflow_mass_flux_and_ids(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_inflow(comm, 2)
      call check_inflow(comm, 3)
   end subroutine test_inflow_mass_flux_and_ids

   subroutine check_inflow(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: diag
      real(rp), parameter :: rho = 1000.0_rp, speed = 2.0_rp, height = 0.5_rp, spacing = 0.1_rp / 3
      real(rp) :: expected
      integer(i8), allocatable :: ids(:)
      integer(i8) :: before, per_layer
      integer :: layers, step
      real(rp) :: area, front

      if (dim == 2) then
         scene = inflow_scene()
         area = height
         per_layer = 15
      else
         scene = water_scene(3, 0.1_rp, [3.0_rp, 1.0_rp, 1.0_rp], 2.0e6_rp, 10.0_rp)
         allocate (scene%inlets(1))
         scene%inlets(1) = inlet_spec_t(material='water', material_index=1, point=[0.0_rp, 0.0_rp, 0.0_rp], &
                                        direction=[1.0_rp, 0.0_rp, 0.0_rp], height=0.5_rp, width=0.4_rp, &
                                        velocity=2.0_rp, start_time=0.0_rp, end_time=0.1_rp, particles_per_cell=3)
         scene%run%cfl = 0.3_rp
         area = height * 0.4_rp
         per_layer = 15 * 12
      end if
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'init: '//trim(status%message))
      diag = solver%diagnostics()
      call assertEqual(diag%particles, 0_i8, 'no particle before the inlet opens')
      do step = 1, 2000
         before = diag%particles
         call solver%advance()
         diag = solver%diagnostics()
         ! the time step resolves the inflow: at most one layer of 15 particles per step
         call assertTrue(diag%particles - before <= per_layer, 'one layer per step at most')
         ! mass = rho Dp H per layer, one layer each time v0 t passes a multiple of Dp [exact]
         layers = floor(speed * min(solver%time, 0.1_rp) / spacing + 1.0e-9_rp)
         expected = rho * spacing * area * layers
         call assertRelativelyEqual(diag%total_mass, expected, 1.0e-12_rp, 'injected mass = rho Dp H x layers')
         if (solver%time > 0.15_rp) exit
      end do
      ! over the open time, the mean flux is rho v0 H within one layer: 0.2 m of 0.2 m here, exactly 6 layers
      call assertRelativelyEqual(diag%total_mass, rho * speed * area * 0.1_rp, 1.0e-9_rp, 'total = rho v0 H (W) t_open')
      call assertEqual(diag%particles, 6_i8 * per_layer, '6 layers')
      ! ids: first_id (no bodies: 0) + layer * per_layer + index, the same whatever the rank count
      ids = gathered_ids(solver, comm)
      call assertTrue(all(ids == [(int(step, i8), step=0, int(6 * per_layer) - 1)]), 'ids 0 .. N - 1, each once')
      call assertEqual(solver%lost_particles, 0, 'nothing left the grid')
      ! the fluid flows away from the opening: its front has passed the 0.2 m injected by the time it closed
      front = 0.0_rp
      if (solver%particles%count > 0) front = maxval(solver%particles%x(1, 1:solver%particles%count))
      call MPI_Allreduce(MPI_IN_PLACE, front, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertTrue(front > 0.2_rp, 'the stream advances (front at '//real_text(front)//' m)')
      call assertTrue(step > 100, 'the open inlet limited the time step ('//int_text(step)//' steps to 0.15 s)')
      call solver%free()
   end subroutine check_inflow

   !> A hydrograph through the 0.5 m opening: v = 1 -> 3 m/s and H = 0.2 -> 0.5 m linear over the 0.1 s it
   !> is open (height_from_file). Then int v H dt = 0.2 t + 3.5 t^2 + 20 t^3 and L(0.1) = 0.2 m = 6 Dp.
   !> The mass injected is that integral up to less than one layer rho Dp H_max after every step, exactly
   !> it at the end (6 whole layers); ids are unique, within the 6 layers' stride, on any number of ranks.
   subroutine test_hydrograph_inflow(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: diag
      real(rp), parameter :: rho = 1000.0_rp, spacing = 0.1_rp / 3
      real(rp) :: t, expected
      integer(i8), allocatable :: ids(:)
      integer :: step, k

      scene = inflow_scene()
      scene%inlets(1)%velocity = 0.0_rp
      scene%inlets(1)%velocity_file = 'hydrograph.csv'
      scene%inlets(1)%height_from_file = .true.
      allocate (scene%inlet_tables(1))
      scene%inlet_tables(1) = time_table_t(path='hydrograph.csv', checksum='', &
                                           columns=[character(len=name_len) :: 'velocity', 'height'], &
                                           time=[0.0_rp, 0.1_rp], values=reshape([1.0_rp, 0.2_rp, 3.0_rp, 0.5_rp], [2, 2]), &
                                           line=[2, 3])
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'init: '//trim(status%message))
      do step = 1, 2000
         call solver%advance()
         diag = solver%diagnostics()
         t = min(solver%time, 0.1_rp)
         expected = rho * (0.2_rp * t + 3.5_rp * t**2 + 20.0_rp * t**3)
         call assertTrue(diag%total_mass <= expected * (1.0_rp + 1.0e-12_rp) .and. &
                         diag%total_mass >= expected - rho * spacing * 0.5_rp, &
                         'mass '//real_text(diag%total_mass)//' = rho int v H dt = '//real_text(expected)// &
                         ' within one layer at t = '//real_text(solver%time))
         if (solver%time > 0.15_rp) exit
      end do
      call assertRelativelyEqual(rho * 0.075_rp, diag%total_mass, 1.0e-9_rp, 'total = rho int v H dt over the open time')
      ids = gathered_ids(solver, comm)
      call assertTrue(all(ids(2:) > ids(:size(ids) - 1)), 'ids unique')
      call assertTrue(ids(1) >= 0 .and. ids(size(ids)) < 6 * 15, 'ids within the 6 layers of 15 across')
      ! layers across: about H_k / Dp, H_k between 0.2 and 0.5 m
      k = size(ids)
      call assertTrue(k >= 6 * 6 .and. k <= 6 * 15, int_text(k)//' particles in 6 layers of 6 to 15')
      call assertTrue(step > 100, 'the table''s peak speed limited the time step ('//int_text(step)//' steps)')
      call solver%free()
   end subroutine test_hydrograph_inflow

   !> Every rank's particle ids, sorted.
   function gathered_ids(solver, comm) result(ids)
      type(solver_t), intent(in) :: solver
      type(MPI_Comm), intent(in) :: comm
      integer(i8), allocatable :: ids(:)
      integer, allocatable :: counts(:), displacements(:)
      integer :: ranks, r, i, j
      integer(i8) :: swap
      call MPI_Comm_size(comm, ranks)
      allocate (counts(ranks), displacements(ranks))
      call MPI_Allgather(solver%particles%count, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, comm)
      displacements(1) = 0
      do r = 2, ranks
         displacements(r) = displacements(r - 1) + counts(r - 1)
      end do
      allocate (ids(sum(counts)))
      call MPI_Allgatherv(solver%particles%id(1:solver%particles%count), solver%particles%count, MPI_INTEGER8, ids, &
                          counts, displacements, MPI_INTEGER8, comm)
      do i = 2, size(ids)          ! insertion sort: a few hundred ids
         swap = ids(i)
         j = i - 1
         do while (j >= 1)
            if (ids(j) <= swap) exit
            ids(j + 1) = ids(j)
            j = j - 1
         end do
         ids(j + 1) = swap
      end do
   end function gathered_ids

   !> A jet into a tank on a grid turned by 30 degrees: after 0.3 s (the inlet closed at 0.1 s and is
   !> now a wall) no particle is behind the floor, the right wall or the left wall and its closed opening.
   subroutine test_no_particle_behind_a_wall(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: diag
      real(rp) :: x(2), lowest(3)
      integer :: p, step

      scene = inflow_scene()
      scene%grid%rotation = 30.0_rp
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'init: '//trim(status%message))
      do step = 1, 20000
         call solver%advance()
         if (solver%time > 0.3_rp) exit
      end do
      diag = solver%diagnostics()
      call assertEqual(diag%particles, 90_i8, 'all 90 particles there')
      lowest = huge(1.0_rp)           ! smallest signed distance to: floor, right wall, left wall (x = 0)
      do p = 1, solver%particles%count
         x = solver%grid%frame%world_point(solver%particles%x(:, p))
         lowest = min(lowest, [x(2), 3.0_rp - x(1), x(1)])
      end do
      call MPI_Allreduce(MPI_IN_PLACE, lowest, 3, MPI_DOUBLE_PRECISION, MPI_MIN, comm)
      call assertTrue(all(lowest >= -1.0e-12_rp), 'no particle behind a wall')
      call solver%free()
   end subroutine test_no_particle_behind_a_wall
end module test_walls_and_inflow
