!> The 3-D kernels' stencil cache (src/transfer/grid_transfer.F90, stencil_cache_t): P2G keeps each
!> particle's base node and position in cells, the re-map and G2P of the same step read them instead of
!> locating the particle again. With and without the cache every transfer must give the same bits; a cache
!> that no longer matches the particles must not be read (forgotten, or of another particle count), and a
!> stale one that is read must show (so the cached path is the one these comparisons run).
module test_stencil_cache
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm
   use assertions, only: assertTrue, assertEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use grid_transfer, only: particles_to_grid, update_velocity_and_remap, grid_to_particles
   use stencil_cache, only: stencil_cache_t, forget_stencils
   use test_scenes, only: water_scene, add_body
   implicit none
   private

   public :: test_cached_transfers_bitwise_linear, test_cached_transfers_bitwise_bspline2, &
             test_cached_transfers_bitwise_apic, test_unmatched_cache_not_read

contains

   !> A 3-D water block on 0.1 m cells, 2 x 2 x 2 particles per cell, with varied velocities and stresses
   !> (every sum of the transfers non-trivial), and nodal velocities and increments to read back.
   subroutine make_solver(comm, shape, transfer, solver)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), intent(in) :: shape, transfer
      type(solver_t), intent(inout) :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      real(rp) :: s
      integer :: p, k, i
      scene = water_scene(3, 0.1_rp, [1.0_rp, 0.8_rp, 0.6_rp], 2.0e6_rp, 9.81_rp)
      call add_body(scene, 1, [0.13_rp, 0.05_rp, 0.1_rp], [0.83_rp, 0.55_rp, 0.4_rp], 2, .false., 0.0_rp)
      scene%grid%shape_function = shape
      scene%run%transfer = transfer
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do p = 1, solver%particles%count
         s = real(solver%particles%id(p), rp)
         solver%particles%x(:, p) = solver%particles%x(:, p) + 0.01_rp * [(sin(2.1_rp * s + k), k = 1, 3)]
         solver%particles%v(:, p) = [(sin(1.3_rp * s + k), k = 1, 3)]
         solver%particles%sbar(:, p) = [(1.0e3_rp * cos(0.7_rp * s * k + k), k = 1, solver%particles%n_sigma)]
         if (solver%particles%n_affine > 0) solver%particles%affine(:, p) = [(cos(0.3_rp * s + k), k = 1, 9)]
      end do
      do i = 1, solver%grid%node_count
         s = real(i, rp)
         solver%grid%velocity(:, i) = [(sin(0.9_rp * s + k), k = 1, 3)]
         solver%grid%velocity_increment(:, i) = [(0.1_rp * cos(1.7_rp * s + k), k = 1, 3)]
      end do
   end subroutine make_solver

   subroutine test_cached_transfers_bitwise_linear(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_bitwise(comm, 'linear', 'flip')
   end subroutine test_cached_transfers_bitwise_linear

   subroutine test_cached_transfers_bitwise_bspline2(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_bitwise(comm, 'bspline2', 'flip')
   end subroutine test_cached_transfers_bitwise_bspline2

   subroutine test_cached_transfers_bitwise_apic(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_bitwise(comm, 'linear', 'apic')
   end subroutine test_cached_transfers_bitwise_apic

   !> P2G, the re-map (MUSL) and G2P (USL's velocity sums, MUSL's strain velocities, positions) run on two
   !> copies of the same particles, one with the cache and one without: every result equal bit for bit.
   subroutine check_bitwise(comm, shape, transfer)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), intent(in) :: shape, transfer
      type(solver_t) :: solver
      type(stencil_cache_t) :: cache
      real(rp), allocatable :: x0(:, :), v0(:, :), affine0(:, :), accumulated(:, :), momentum(:, :, :), &
                               x(:, :, :), v(:, :, :), d(:, :, :), w(:, :, :), affine(:, :, :)
      integer :: run, n
      logical :: apic
      call make_solver(comm, shape, transfer, solver)
      n = solver%particles%count
      apic = solver%particles%n_affine > 0
      x0 = solver%particles%x(:, 1:n)
      v0 = solver%particles%v(:, 1:n)
      if (apic) affine0 = solver%particles%affine(:, 1:n)
      allocate (momentum(3, solver%grid%node_count, 2), x(3, n, 2), v(3, n, 2), d(solver%particles%n_sigma, n, 2), &
                w(3, n, 2), affine(solver%particles%n_affine, n, 2))
      do run = 1, 2          ! 1: without the cache, 2: with it
         solver%particles%x(:, 1:n) = x0
         solver%particles%v(:, 1:n) = v0
         if (apic) solver%particles%affine(:, 1:n) = affine0
         if (run == 1) then
            call particles_to_grid(solver%grid, solver%particles, solver%gravity)
            accumulated = solver%grid%accumulated
            call update_velocity_and_remap(solver%grid, solver%particles, 0.95_rp, momentum(:, :, run))
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 0.5_rp, update_velocity=.true., &
                                   compute_strain=.true., update_position=.true., strain_rate=d(:, :, run), &
                                   spin=w(:, :, run), strain_velocity=momentum(:, :, run))
         else
            call particles_to_grid(solver%grid, solver%particles, solver%gravity, stencils=cache)
            call assertEqual(n, cache%count, 'P2G keeps the stencils of all particles')
            call assertTrue(all(accumulated == solver%grid%accumulated), 'P2G: the same bits with the cache')
            call update_velocity_and_remap(solver%grid, solver%particles, 0.95_rp, momentum(:, :, run), &
                                           stencils=cache)
            ! two slices, as the solver's G2P runs material by material
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 0.5_rp, update_velocity=.true., &
                                   compute_strain=.true., update_position=.true., strain_rate=d(:, 1:n / 2, run), &
                                   spin=w(:, 1:n / 2, run), strain_velocity=momentum(:, :, run), first=1, last=n / 2, &
                                   stencils=cache)
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 0.5_rp, update_velocity=.true., &
                                   compute_strain=.true., update_position=.true., strain_rate=d(:, n / 2 + 1:n, run), &
                                   spin=w(:, n / 2 + 1:n, run), strain_velocity=momentum(:, :, run), first=n / 2 + 1, &
                                   last=n, stencils=cache)
         end if
         x(:, :, run) = solver%particles%x(:, 1:n)
         v(:, :, run) = solver%particles%v(:, 1:n)
         if (apic) affine(:, :, run) = solver%particles%affine(:, 1:n)
      end do
      call assertTrue(all(momentum(:, :, 1) == momentum(:, :, 2)), 'the re-map: the same bits with the cache')
      call assertTrue(all(v(:, :, 1) == v(:, :, 2)), 'the velocities: the same bits with the cache')
      call assertTrue(all(affine(:, :, 1) == affine(:, :, 2)), 'C_p: the same bits with the cache')
      call assertTrue(all(d(:, :, 1) == d(:, :, 2)), 'the rates of deformation: the same bits with the cache')
      call assertTrue(all(w(:, :, 1) == w(:, :, 2)), 'the spins: the same bits with the cache')
      call assertTrue(all(x(:, :, 1) == x(:, :, 2)), 'the new positions: the same bits with the cache')
      call assertTrue(any(x(:, :, 1) /= x0), 'the particles moved')
      call solver%free()
   end subroutine check_bitwise

   !> Particles moved after P2G: a forgotten cache, or one of another particle count, is not read (G2P
   !> locates the moved particles itself, as without a cache); a stale cache that were read would give
   !> other strain rates, which shows that the comparison can fail.
   subroutine test_unmatched_cache_not_read(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: solver
      type(stencil_cache_t) :: cache
      real(rp), allocatable :: x0(:, :), d(:, :, :), w(:, :)
      integer :: n, case
      call make_solver(comm, 'linear', 'flip', solver)
      n = solver%particles%count
      allocate (d(solver%particles%n_sigma, n, 4), w(3, n))
      call particles_to_grid(solver%grid, solver%particles, solver%gravity, stencils=cache)
      ! every particle a third of a cell further along x: other stencils
      solver%particles%x(1, 1:n) = solver%particles%x(1, 1:n) + solver%grid%h / 3.0_rp
      x0 = solver%particles%x(:, 1:n)
      do case = 1, 4
         solver%particles%x(:, 1:n) = x0
         select case (case)
         case (1)    ! no cache: the reference
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 1.0_rp, update_velocity=.false., &
                                   compute_strain=.true., update_position=.false., strain_rate=d(:, :, case), spin=w)
         case (2)    ! stale, read (what the solver must never do: it forgets the cache when particles move)
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 1.0_rp, update_velocity=.false., &
                                   compute_strain=.true., update_position=.false., strain_rate=d(:, :, case), spin=w, &
                                   stencils=cache)
         case (3)    ! another particle count
            solver%particles%count = n - 1
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 1.0_rp, update_velocity=.false., &
                                   compute_strain=.true., update_position=.false., strain_rate=d(:, 1:n - 1, case), &
                                   spin=w, stencils=cache)
            solver%particles%count = n
            d(:, n, case) = d(:, n, 1)
         case (4)    ! forgotten
            call forget_stencils(cache)
            call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 0.95_rp, 1.0_rp, update_velocity=.false., &
                                   compute_strain=.true., update_position=.false., strain_rate=d(:, :, case), spin=w, &
                                   stencils=cache)
         end select
      end do
      call assertTrue(any(d(:, :, 2) /= d(:, :, 1)), 'a stale cache, read, gives other strain rates')
      call assertTrue(all(d(:, :, 3) == d(:, :, 1)), 'a cache of another particle count is not read')
      call assertTrue(all(d(:, :, 4) == d(:, :, 1)), 'a forgotten cache is not read')
      call assertEqual(-1, cache%count, 'forgotten: it holds no stencils')
      call solver%free()
   end subroutine test_unmatched_cache_not_read
end module test_stencil_cache
