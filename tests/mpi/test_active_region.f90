!> The active region (docs/theory.md section 6.2): grid work and memory cover only the cells near the
!> particles, so a scene gives the same particle states in a domain padded with empty space, the box
!> follows particles that travel far, and none is lost on the way.
module test_active_region
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_size, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM, &
                      MPI_MAX, MPI_INTEGER
   use assertions, only: assertTrue, assertEqual, assertLessThanOrEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, wall_spec_t, wall_none
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use input_text, only: real_text, int_text
   use test_scenes, only: water_scene, add_body, tank_with_inlet, corner_column
   use active_region, only: slack_cells
   use time_loop_steps, only: start_run, step_run
   implicit none
   private

   public :: test_padded_column_is_identical, test_padded_filling_tank_is_identical, test_travelling_block_is_followed, &
             test_travelling_block_3d_is_followed

   !> Cells of empty space added on every side of the padded scenes.
   integer, parameter :: padding = 40

contains

   !> A 0.5 m x 0.5 m water column collapsing in the corner of a 2 m x 1 m tank, 300 steps, with each
   !> scheme (FOAL1 reads two cell layers around every occupied cell, NB works on nodes) and with the
   !> volume correction by shifting (which measures the room the walls leave at each node): the same
   !> particle states in the tank padded by 40 cells of empty space on every side (the tank's walls
   !> then &wall groups). On 1 rank the runs differ only by the rounding of x - origin.
   subroutine test_padded_column_is_identical(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=5), parameter :: schemes(4) = [character(len=5) :: 'none', 'C0', 'NB', 'FOAL1']
      type(scene_t) :: scene
      integer :: i
      do i = 1, size(schemes)
         scene = corner_column([2.0_rp, 1.0_rp], 0.5_rp, schemes(i))
         call compare_with_padded(comm, scene, 300, 'collapsing column, '//trim(schemes(i)))
      end do
      scene = corner_column([2.0_rp, 1.0_rp], 0.5_rp, 'none')
      scene%materials(1)%volume_correction = 'shifting'
      call compare_with_padded(comm, scene, 300, 'collapsing column, shifting')
   end subroutine test_padded_column_is_identical

   !> The 3 m x 2 m tank filled through an opening at the foot of its left wall (the inlet must lie in
   !> the active region before any particle exists), 300 steps at a fixed step.
   subroutine test_padded_filling_tank_is_identical(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = tank_with_inlet(0.6_rp, 1.0_rp, 1.0_rp)
      scene%inlets(1)%hydrostatic = .true.
      scene%run%fixed_dt = 4.0e-4_rp
      call compare_with_padded(comm, scene, 300, 'filling tank')
   end subroutine test_padded_filling_tank_is_identical

   !> A free 0.5 m x 0.5 m block of water (no gravity, no walls reached) crossing an 8 m x 8 m domain
   !> diagonally at (6, -4) m/s for 0.5 s, with FOAL1: the active region is laid out anew many times,
   !> no particle is lost, the block moves rigidly (a uniform velocity field is reproduced exactly up to
   !> round-off), and the region stays a small part of the grid.
   subroutine test_travelling_block_is_followed(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = water_scene(2, 0.05_rp, [8.0_rp, 8.0_rp, 0.0_rp], 2.0e6_rp, 0.0_rp)
      call add_body(scene, 1, [1.0_rp, 6.0_rp, 0.0_rp], [1.5_rp, 6.5_rp, 0.0_rp], 2, .false., 0.0_rp)
      scene%bodies(1)%velocity = [6.0_rp, -4.0_rp, 0.0_rp]
      scene%materials(1)%stabilization = 'FOAL1'
      call check_travelling_block(comm, scene, 0.5_rp, 10, 0.05_rp)
   end subroutine test_travelling_block_is_followed

   !> The same in 3-D: a 0.4 m cube crossing a 4 m cube at (4, 3, -2) m/s for 0.5 s, standard MPM.
   subroutine test_travelling_block_3d_is_followed(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = water_scene(3, 0.1_rp, [4.0_rp, 4.0_rp, 4.0_rp], 2.0e6_rp, 0.0_rp)
      call add_body(scene, 1, [0.5_rp, 0.5_rp, 2.5_rp], [0.9_rp, 0.9_rp, 2.9_rp], 2, .false., 0.0_rp)
      scene%bodies(1)%velocity = [4.0_rp, 3.0_rp, -2.0_rp]
      ! the bound counts the guard of a step at CFL 0.5 (at CFL 1.30 the guard is one cell wider: 0.107 of
      ! the grid)
      scene%run%cfl = 0.5_rp
      call check_travelling_block(comm, scene, 0.5_rp, 3, 0.1_rp)
   end subroutine test_travelling_block_3d_is_followed

   !> Run `scene` until `end_time` as the time loop does (balance checks included); the block must be
   !> laid out anew at least `min_relayouts` times, lose nothing, move by v t rigidly, and the active
   !> region must never exceed `max_fraction` of the grid's cells.
   subroutine check_travelling_block(comm, scene, end_time, min_relayouts, max_fraction)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      real(rp), intent(in) :: end_time, max_fraction
      integer, intent(in) :: min_relayouts
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: before, after
      real(rp) :: centre_before(3), centre_after(3), size_before(3), size_after(3), largest_fraction, velocity(3)
      integer :: dim, lo(3), hi(3)

      dim = scene%grid%dim
      call start_run(solver, scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      before = solver%diagnostics()
      call block_shape(comm, solver, centre_before, size_before)
      largest_fraction = 0.0_rp
      do while (solver%time < end_time)
         call step_run(solver, status)
         call solver%domain%region(lo, hi)
         largest_fraction = max(largest_fraction, real(product(hi(1:dim) - lo(1:dim) + 1), rp) / &
                                product(real(solver%domain%global_cells(1:dim), rp)))
      end do
      call assertTrue(status%ok, 'balance: '//trim(status%message))
      after = solver%diagnostics()
      call block_shape(comm, solver, centre_after, size_after)
      velocity = scene%bodies(1)%velocity

      call assertEqual(before%particles, after%particles, 'no particle lost')
      call assertEqual(0_i8, after%lost_particles, 'none counted as lost')
      call assertTrue(solver%relayouts >= min_relayouts, 'the region followed the block: '// &
                      int_text(solver%relayouts)//' layouts, at least '//int_text(min_relayouts))
      call assertLessThanOrEqual(largest_fraction, max_fraction, 'largest active region / grid')
      call assertLessThanOrEqual(maxval(abs(centre_after(1:dim) - centre_before(1:dim) - velocity(1:dim) * solver%time)), &
                                 1.0e-9_rp, 'the block moved by v t')
      call assertLessThanOrEqual(maxval(abs(size_after(1:dim) - size_before(1:dim))), 1.0e-9_rp, 'rigidly')
      call solver%free()
   end subroutine check_travelling_block

   !> Mass centre and extent (max - min along each axis) of all particles of all ranks (grid frame).
   subroutine block_shape(comm, solver, centre, extent)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t), intent(in) :: solver
      real(rp), intent(out) :: centre(3), extent(3)
      real(rp) :: sums(4), high(3), low(3)
      integer :: p, dim, n
      dim = solver%grid%dim
      n = solver%particles%count
      sums = 0.0_rp
      high = 0.0_rp
      low = 0.0_rp
      high(1:dim) = -huge(1.0_rp)
      low(1:dim) = -huge(1.0_rp)
      do p = 1, n
         sums(1:dim) = sums(1:dim) + solver%particles%mass(p) * solver%particles%x(:, p)
         sums(4) = sums(4) + solver%particles%mass(p)
         high(1:dim) = max(high(1:dim), solver%particles%x(:, p))
         low(1:dim) = max(low(1:dim), -solver%particles%x(:, p))
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call MPI_Allreduce(MPI_IN_PLACE, high, 3, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(MPI_IN_PLACE, low, 3, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      centre = sums(1:3) / sums(4)
      extent = high + low
   end subroutine block_shape

   !> Run `scene` and the same scene padded with empty space for n_steps steps (balance checks as in the
   !> time loop) and compare every particle's state by id: positions, velocities, stresses and densities
   !> agree to 1e-12 relative to the largest value of each.
   subroutine compare_with_padded(comm, scene, n_steps, label)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: n_steps
      character(len=*), intent(in) :: label
      real(rp), allocatable :: tight(:, :), wide(:, :)
      real(rp) :: scale, difference
      integer :: dim, row, lo(3), hi(3), region_cells(2), tight_extent(3)
      integer(i8) :: lost(2)
      character(len=*), parameter :: names(4) = [character(len=8) :: 'position', 'velocity', 'stress', 'density']
      integer :: first(4), last(4), f

      dim = scene%grid%dim
      call run_and_gather(comm, scene, n_steps, tight, lost(1), lo, hi)
      region_cells(1) = product(hi(1:dim) - lo(1:dim) + 1)
      tight_extent = hi - lo + 1
      call run_and_gather(comm, padded(scene, padding), n_steps, wide, lost(2), lo, hi)
      region_cells(2) = product(hi(1:dim) - lo(1:dim) + 1)

      call assertEqual(size(tight, 2), size(wide, 2), 'particles ('//label//')')
      call assertTrue(size(tight, 2) > 0, 'the scene has particles ('//label//')')
      call assertEqual(0_i8, lost(1), 'none lost ('//label//')')
      call assertEqual(0_i8, lost(2), 'none lost, padded ('//label//')')
      ! the padded grid has (n + 80)^2 cells; the region at most a margin more than the tight scene's
      ! on each side where the tight one ends at the grid (the margin is at most 3 + slack_cells cells here)
      call assertLessThanOrEqual(region_cells(2), product(tight_extent(1:dim) + 2 * (3 + slack_cells)), &
                                 'padded active region ('//label//')')
      if (size(tight, 2) /= size(wide, 2)) return
      first = [1, 1 + dim, 1 + 2 * dim, size(tight, 1)]
      last = [dim, 2 * dim, size(tight, 1) - 1, size(tight, 1)]
      do f = 1, size(names)
         scale = maxval(abs(tight(first(f):last(f), :)))
         difference = 0.0_rp
         do row = first(f), last(f)
            difference = max(difference, maxval(abs(tight(row, :) - wide(row, :))))
         end do
         call assertLessThanOrEqual(difference, 1.0e-12_rp * max(scale, tiny(1.0_rp)), &
                                    trim(names(f))//' (max '//real_text(scale)//', '//label//')')
      end do
   end subroutine compare_with_padded

   !> n_steps steps of `scene`; every particle's state (x, v, sbar, density; the grid frame is the world's) as
   !> column id + 1 of `states` on every rank (the scenes' ids are 0 .. N - 1), the lost particles and
   !> the last active region.
   subroutine run_and_gather(comm, scene, n_steps, states, lost, lo, hi)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: n_steps
      real(rp), allocatable, intent(out) :: states(:, :)
      integer(i8), intent(out) :: lost
      integer, intent(out) :: lo(3), hi(3)
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: diag
      integer, allocatable :: seen(:)
      integer :: step, p, dim, rows, column

      call start_run(solver, scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do step = 1, n_steps
         call step_run(solver, status)
      end do
      call assertTrue(status%ok, 'balance: '//trim(status%message))
      diag = solver%diagnostics()
      lost = diag%lost_particles
      call solver%domain%region(lo, hi)
      dim = solver%grid%dim
      rows = 2 * dim + solver%particles%n_sigma + 1
      allocate (states(rows, diag%particles), seen(diag%particles))
      states = 0.0_rp
      seen = 0
      associate (particles => solver%particles)
         do p = 1, particles%count
            column = int(particles%id(p)) + 1
            if (column < 1 .or. column > size(seen)) cycle
            seen(column) = seen(column) + 1
            states(1:dim, column) = particles%x(:, p)
            states(dim + 1:2 * dim, column) = particles%v(:, p)
            states(2 * dim + 1:rows - 1, column) = particles%sbar(:, p)
            states(rows, column) = particles%density(p)
         end do
      end associate
      call MPI_Allreduce(MPI_IN_PLACE, states, size(states), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call MPI_Allreduce(MPI_IN_PLACE, seen, size(seen), MPI_INTEGER, MPI_SUM, comm)
      call assertTrue(all(seen == 1), 'every id once')
      call solver%free()
   end subroutine run_and_gather

   !> `scene` in a grid `cells` cells larger on every side: the sides of &box_walls become &wall groups
   !> of the same geometry (the box faces), the rest is unchanged (world coordinates).
   function padded(scene, cells) result(wide)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: cells
      type(scene_t) :: wide
      type(wall_spec_t) :: wall
      real(rp) :: upper(3)
      integer :: k, side, dim
      dim = scene%grid%dim
      wide = scene
      if (.not. allocated(wide%walls)) allocate (wide%walls(0))
      upper = scene%grid%origin + scene%grid%ncells * scene%grid%cell_size
      do k = 1, dim
         do side = 1, 2
            if (scene%grid%wall(side, k) == wall_none) cycle
            wall%condition = scene%grid%wall(side, k)
            wall%normal = 0.0_rp
            wall%normal(k) = merge(1.0_rp, -1.0_rp, side == 1)
            wall%lower = scene%grid%origin
            wall%upper = upper
            wall%point = scene%grid%origin
            if (side == 2) wall%point(k) = upper(k)
            wall%lower(k) = wall%point(k)
            wall%upper(k) = wall%point(k)
            wide%walls = [wide%walls, wall]
         end do
      end do
      wide%grid%wall = wall_none
      wide%grid%origin(1:dim) = scene%grid%origin(1:dim) - cells * scene%grid%cell_size
      wide%grid%ncells(1:dim) = scene%grid%ncells(1:dim) + 2 * cells
      wide%grid%extent(1:dim) = wide%grid%ncells(1:dim) * scene%grid%cell_size
   end function padded
end module test_active_region
