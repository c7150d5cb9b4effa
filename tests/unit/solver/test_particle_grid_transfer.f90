!> Particle-to-grid transfer with ghost-node sums: mass and momentum are conserved, internal forces
!> sum to zero, on any number of ranks.
module test_particle_grid_transfer
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use assertions, only: assertTrue, assertRelativelyEqual, assertEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use background_grid, only: row_mass
   use grid_transfer, only: particles_to_grid, grid_to_particles
   use node_halo, only: sum_shared_nodes
   use test_scenes, only: water_scene, add_body
   implicit none
   private

   public :: test_p2g_conserves_mass_and_momentum_2d, test_p2g_conserves_mass_and_momentum_3d, &
             test_g2p_reproduces_linear_velocity

contains

   subroutine test_p2g_conserves_mass_and_momentum_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_conservation(comm, 2)
   end subroutine test_p2g_conserves_mass_and_momentum_2d

   subroutine test_p2g_conserves_mass_and_momentum_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_conservation(comm, 3)
   end subroutine test_p2g_conserves_mass_and_momentum_3d

   !> A water block with a non-uniform velocity and a non-uniform stress.
   subroutine make_solver(comm, dim, solver)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(solver_t), intent(inout) :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      integer :: p
      scene = water_scene(dim, 0.1_rp, [1.0_rp, 0.8_rp, 0.6_rp], 2.0e6_rp, 9.81_rp)
      call add_body(scene, 1, [0.13_rp, 0.05_rp, 0.1_rp], [0.83_rp, 0.55_rp, 0.4_rp], 3, .true., 0.5_rp)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do p = 1, solver%particles%count
         associate (x => solver%particles%x(:, p))
            solver%particles%v(:, p) = 0.5_rp + x(1) - 2.0_rp * x(2)**2
            solver%particles%sbar(:, p) = solver%particles%sbar(:, p) * (1.0_rp + x(1))
         end associate
      end do
   end subroutine make_solver

   subroutine check_conservation(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(solver_t) :: solver
      real(rp) :: particle_sums(7), node_sums(7)
      integer :: p, i, k, g(3), rest
      logical :: counted

      call make_solver(comm, dim, solver)
      particle_sums = 0.0_rp
      do p = 1, solver%particles%count
         particle_sums(1) = particle_sums(1) + solver%particles%mass(p)
         particle_sums(2:1 + dim) = particle_sums(2:1 + dim) + solver%particles%mass(p) * solver%particles%v(:, p)
         particle_sums(2 + dim:1 + 2 * dim) = particle_sums(2 + dim:1 + 2 * dim) + solver%particles%mass(p) * &
                                              solver%gravity(1:dim)
      end do
      call particles_to_grid(solver%grid, solver%particles, solver%gravity)
      call sum_shared_nodes(solver%domain, solver%grid, solver%grid%accumulated)
      ! after the ghost-node sum a shared node holds the full value on every rank: count it once, on
      ! the rank whose cells start at it (or at the upper boundary of the active region)
      node_sums = 0.0_rp
      do i = 1, solver%grid%node_count
         rest = i - 1
         do k = 1, dim
            g(k) = solver%grid%node_lo(k) + mod(rest, solver%grid%n_nodes(k))
            rest = rest / solver%grid%n_nodes(k)
         end do
         counted = .true.
         do k = 1, dim
            if (g(k) > solver%grid%cell_hi(k) .and. &
                g(k) < solver%domain%cuts(solver%domain%dims(k), k)) counted = .false.
         end do
         if (counted) node_sums(1:1 + 2 * dim) = node_sums(1:1 + 2 * dim) + solver%grid%accumulated(:, i)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, particle_sums, 7, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call MPI_Allreduce(MPI_IN_PLACE, node_sums, 7, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call assertRelativelyEqual(particle_sums(1), node_sums(row_mass), 1.0e-13_rp, 'mass')
      do k = 1, dim
         call assertRelativelyEqual(particle_sums(1 + k), node_sums(1 + k), 1.0e-12_rp, 'momentum')
         ! internal forces cancel (sum_a grad N_a = 0): the total force is the weight
         call assertEqual(particle_sums(1 + dim + k), node_sums(1 + dim + k), &
                          1.0e-10_rp * abs(particle_sums(1)) * 10.0_rp, 'total force = weight')
      end do
      call solver%free()
   end subroutine check_conservation

   !> Nodal velocities of a linear field v = A x + b: G2P gives v_p and L_p = A exactly.
   subroutine test_g2p_reproduces_linear_velocity(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: solver
      real(rp), parameter :: a(2, 2) = reshape([0.1_rp, -0.3_rp, 0.2_rp, 0.05_rp], [2, 2]), b(2) = [1.0_rp, -2.0_rp]
      real(rp) :: x(2)
      real(rp), allocatable :: d(:, :), w(:, :)
      integer :: i, p, rest, g(2)
      call make_solver(comm, 2, solver)
      ! water without a scheme: the set holds neither rate nor spin (the step keeps them in a block buffer);
      ! G2P writes them where it is told
      call assertEqual(0, solver%particles%n_spin, 'a water scene holds no spin')
      call assertEqual(0, solver%particles%n_rate, 'nor a rate of deformation')
      allocate (d(4, solver%particles%count), w(1, solver%particles%count))
      do i = 1, solver%grid%node_count
         rest = i - 1
         g(1) = solver%grid%node_lo(1) + mod(rest, solver%grid%n_nodes(1))
         g(2) = solver%grid%node_lo(2) + rest / solver%grid%n_nodes(1)
         x = solver%grid%origin(1:2) + g * solver%grid%h
         solver%grid%velocity(:, i) = matmul(a, x) + b
         solver%grid%velocity_increment(:, i) = 0.0_rp
      end do
      call grid_to_particles(solver%grid, solver%particles, 0.0_rp, 0.0_rp, 1.0_rp, .true., .true., .false., &
                             strain_rate=d, spin=w)
      do p = 1, solver%particles%count
         call assertEqual(matmul(a, solver%particles%x(:, p)) + b, solver%particles%v(:, p), 1.0e-13_rp, 'PIC v_p')
         call assertEqual([a(1, 1), a(2, 2), 0.0_rp, 0.5_rp * (a(1, 2) + a(2, 1))], d(:, p), 1.0e-13_rp, &
                          'd_p of a linear field')
         call assertEqual(0.5_rp * (a(1, 2) - a(2, 1)), w(1, p), 1.0e-13_rp, 'w_p')
      end do
      call solver%free()
   end subroutine test_g2p_reproduces_linear_velocity
end module test_particle_grid_transfer
