!> APIC's transfers (src/transfer/grid_transfer_kernels.inc, docs/theory.md "APIC"): an affine velocity
!> field survives P2G and G2P exactly; each transfer keeps the angular momentum
!> sum m_p (x_p x v_p + eps : (C_p D_p)^T) exactly. On 1, 2 and 4 ranks (ghost-node sums).
module test_affine_transfer
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_MAX
   use assertions, only: assertTrue, assertEqual, assertLessThanOrEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use background_grid, only: row_mass
   use grid_transfer, only: particles_to_grid, grid_to_particles
   use node_halo, only: sum_shared_nodes
   use test_scenes, only: water_scene, add_body
   use apic_measures, only: particle_angular_momentum
   implicit none
   private

   public :: test_affine_field_round_trip_2d, test_affine_field_round_trip_3d, test_p2g_keeps_angular_momentum_2d, &
             test_p2g_keeps_angular_momentum_3d

contains

   !> A water block (no gravity) on 0.1 m cells, 3 x 3 particles per cell, with APIC.
   subroutine make_solver(comm, dim, solver)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(solver_t), intent(inout) :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      scene = water_scene(dim, 0.1_rp, [1.0_rp, 0.8_rp, 0.6_rp], 2.0e6_rp, 0.0_rp)
      call add_body(scene, 1, [0.13_rp, 0.05_rp, 0.1_rp], [0.83_rp, 0.55_rp, 0.4_rp], 3, .false., 0.0_rp)
      scene%run%transfer = 'apic'
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      call assertEqual(dim * dim, solver%particles%n_affine, 'the particles carry B_p')
   end subroutine make_solver

   subroutine test_affine_field_round_trip_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_affine_round_trip(comm, 2)
   end subroutine test_affine_field_round_trip_2d

   subroutine test_affine_field_round_trip_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_affine_round_trip(comm, 3)
   end subroutine test_affine_field_round_trip_3d

   !> v(x) = v0 + A x on the particles with C_p = A: P2G gives every node with mass exactly v(x_i); G2P from
   !> the nodal field v(x_i) gives back v_p = v(x_p), C_p = A and d_p = sym A.
   subroutine check_affine_round_trip(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      real(rp), parameter :: a3(3, 3) = reshape([0.3_rp, 0.7_rp, -0.2_rp, -1.1_rp, 0.2_rp, 0.4_rp, 0.5_rp, -0.6_rp, &
                                                 0.1_rp], [3, 3]), v3(3) = [0.5_rp, -0.25_rp, 0.75_rp]
      type(solver_t) :: solver
      real(rp) :: a(dim, dim), v0(dim), x(dim), m, worst(2)
      real(rp), allocatable :: d(:, :), w(:, :)
      integer :: p, i, mom
      a = a3(1:dim, 1:dim)
      v0 = v3(1:dim)
      call make_solver(comm, dim, solver)
      do p = 1, solver%particles%count
         solver%particles%v(:, p) = v0 + matmul(a, solver%particles%x(:, p))
         solver%particles%affine(:, p) = reshape(a, [dim * dim])
      end do
      call particles_to_grid(solver%grid, solver%particles, solver%gravity)
      call sum_shared_nodes(solver%domain, solver%grid, solver%grid%accumulated)
      mom = solver%grid%row_momentum
      worst = 0.0_rp
      do i = 1, solver%grid%node_count
         x = solver%grid%origin(1:dim) + solver%grid%node_indices(i) * solver%grid%h
         m = solver%grid%accumulated(row_mass, i)
         if (m > 1.0e-9_rp) worst(1) = max(worst(1), maxval(abs(solver%grid%accumulated(mom:mom + dim - 1, i) / m - &
                                                                 (v0 + matmul(a, x)))))
         solver%grid%velocity(:, i) = v0 + matmul(a, x)
         solver%grid%velocity_increment(:, i) = 0.0_rp
      end do
      allocate (d(solver%particles%n_sigma, solver%particles%count), w(0, solver%particles%count))
      call grid_to_particles(solver%grid, solver%particles, 0.0_rp, 0.95_rp, 1.0_rp, update_velocity=.true., &
                             compute_strain=.true., update_position=.false., strain_rate=d, spin=w)
      do p = 1, solver%particles%count
         worst(2) = max(worst(2), maxval(abs(solver%particles%v(:, p) - (v0 + matmul(a, solver%particles%x(:, p))))))
         call assertEqual(reshape(a, [dim * dim]), solver%particles%affine(:, p), 1.0e-12_rp, 'G2P: C_p = A')
         call assertEqual(a(1, 1), d(1, p), 1.0e-13_rp, 'G2P: d_xx = A_xx')
      end do
      call MPI_Allreduce(MPI_IN_PLACE, worst, 2, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertEqual(0.0_rp, worst(1), 1.0e-13_rp, 'P2G: nodal velocity = v(x_i) at every node with mass')
      call assertEqual(0.0_rp, worst(2), 1.0e-13_rp, 'G2P: v_p = v(x_p)')
      call solver%free()
   end subroutine check_affine_round_trip

   subroutine test_p2g_keeps_angular_momentum_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_p2g_angular_momentum(comm, 2)
   end subroutine test_p2g_keeps_angular_momentum_2d

   subroutine test_p2g_keeps_angular_momentum_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_p2g_angular_momentum(comm, 3)
   end subroutine test_p2g_keeps_angular_momentum_3d

   !> Arbitrary (non-affine) v_p and C_p: sum_i x_i x P_i over the nodes after P2G equals the particles'
   !> sum m_p (x_p x v_p + eps : (C_p D_p)^T) ([J15] sec. 5.3), and P2G's linear momentum sum m_p v_p. Then
   !> G2P from these nodal velocities (v_i = P_i / m_i) gives the particles the same angular momentum back.
   subroutine check_p2g_angular_momentum(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(solver_t) :: solver
      real(rp) :: l_particles(3), node_sums(6), x(3), pm(3), s, l_back(3)
      integer :: p, i, k, mom
      call make_solver(comm, dim, solver)
      do p = 1, solver%particles%count
         s = real(solver%particles%id(p), rp)
         solver%particles%v(:, p) = [(sin(1.3_rp * s + k), k = 1, dim)]
         solver%particles%affine(:, p) = [(2.0_rp * cos(0.7_rp * s * k + k), k = 1, dim * dim)]
      end do
      l_particles = particle_angular_momentum(solver%particles, solver%grid, comm)
      call particles_to_grid(solver%grid, solver%particles, solver%gravity)
      call sum_shared_nodes(solver%domain, solver%grid, solver%grid%accumulated)
      mom = solver%grid%row_momentum
      node_sums = 0.0_rp
      do i = 1, solver%grid%node_count
         if (.not. solver%grid%owns_node(solver%grid%node_indices(i))) cycle
         x = 0.0_rp
         pm = 0.0_rp
         x(1:dim) = solver%grid%origin(1:dim) + solver%grid%node_indices(i) * solver%grid%h
         pm(1:dim) = solver%grid%accumulated(mom:mom + dim - 1, i)
         node_sums(1:3) = node_sums(1:3) + [x(2) * pm(3) - x(3) * pm(2), x(3) * pm(1) - x(1) * pm(3), &
                                            x(1) * pm(2) - x(2) * pm(1)]
         node_sums(4:6) = node_sums(4:6) + pm
      end do
      call MPI_Allreduce(MPI_IN_PLACE, node_sums, 6, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call assertLessThanOrEqual(1.0e-3_rp, maxval(abs(l_particles)), 'a non-trivial angular momentum')
      call assertEqual(l_particles, node_sums(1:3), 1.0e-13_rp * maxval(abs(l_particles)), &
                       'grid angular momentum = particles'' (with eps : B^T)')
      pm = 0.0_rp
      do p = 1, solver%particles%count
         pm(1:dim) = pm(1:dim) + solver%particles%mass(p) * solver%particles%v(:, p)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, pm, 3, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call assertEqual(pm, node_sums(4:6), 1.0e-13_rp * maxval(abs(pm)), 'linear momentum (the affine part adds none)')
      ! G2P at the same positions (no move): v_p = sum N v_i, C_p = sum v_i (x) grad N give L back
      do i = 1, solver%grid%node_count
         solver%grid%velocity(:, i) = 0.0_rp
         if (solver%grid%accumulated(row_mass, i) > 0.0_rp) solver%grid%velocity(:, i) = &
            solver%grid%accumulated(mom:mom + dim - 1, i) / solver%grid%accumulated(row_mass, i)
         solver%grid%velocity_increment(:, i) = 0.0_rp
      end do
      call grid_to_particles(solver%grid, solver%particles, 0.0_rp, 0.95_rp, 1.0_rp, update_velocity=.true., &
                             compute_strain=.false., update_position=.false., strain_rate=solver%particles%strain_rate, &
                             spin=solver%particles%spin)
      l_back = particle_angular_momentum(solver%particles, solver%grid, comm)
      call assertEqual(l_particles, l_back, 1.0e-12_rp * maxval(abs(l_particles)), 'G2P gives the angular momentum back')
      call solver%free()
   end subroutine check_p2g_angular_momentum
end module test_affine_transfer
