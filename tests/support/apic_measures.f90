!> Angular momentum of the particles as APIC defines it, for the tests of the affine transfer.
module apic_measures
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use shape_functions, only: shape_values_and_gradients, shape_bspline2
   use grid_transfer, only: node_offsets
   implicit none
   private

   public :: particle_angular_momentum, particle_d

contains

   !> L = sum_p m_p x_p x v_p + m_p eps : (C_p D_p)^T over all ranks, about the grid frame's origin, with
   !> D_p at the particle's position ([J15] sec. 5.3: B_p = C_p D_p; the part m_p eps : B_p^T is what the
   !> affine velocity puts on the grid's nodes). Without affine matrices the first sum alone. 2-D:
   !> (0, 0, L_z). Collective.
   function particle_angular_momentum(particles, grid, comm) result(l)
      type(particle_set_t), intent(in) :: particles
      type(grid_t), intent(in) :: grid
      type(MPI_Comm), intent(in) :: comm
      real(rp) :: l(3), x(3), v(3), b(3, 3)
      integer :: p, d
      d = particles%dim
      l = 0.0_rp
      do p = 1, particles%count
         x = 0.0_rp
         v = 0.0_rp
         x(1:d) = particles%x(:, p)
         v(1:d) = particles%v(:, p)
         l = l + particles%mass(p) * [x(2) * v(3) - x(3) * v(2), x(3) * v(1) - x(1) * v(3), x(1) * v(2) - x(2) * v(1)]
         if (particles%n_affine == 0) cycle
         b = 0.0_rp
         b(1:d, 1:d) = matmul(reshape(particles%affine(:, p), [d, d]), particle_d(grid, particles%x(:, p)))
         l = l + particles%mass(p) * [b(3, 2) - b(2, 3), b(1, 3) - b(3, 1), b(2, 1) - b(1, 2)]
      end do
      call MPI_Allreduce(MPI_IN_PLACE, l, 3, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
   end function particle_angular_momentum

   !> D_p = sum_a N_a (x_a - x_p)(x_a - x_p)^T of a particle at x (its cell located as the kernels do); with
   !> quadratic B-splines h^2/4 I at any x ([J15] sec. 5.4).
   function particle_d(grid, x) result(dp)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      real(rp) :: dp(grid%dim, grid%dim), xi(grid%dim), n(2**grid%dim), g(grid%dim, 2**grid%dim)
      real(rp) :: d(grid%dim, 2**grid%dim)
      integer :: k, a
      if (grid%shape == shape_bspline2) then
         dp = 0.0_rp
         do k = 1, grid%dim
            dp(k, k) = 0.25_rp * grid%h**2
         end do
         return
      end if
      do k = 1, grid%dim
         xi(k) = (x(k) - grid%origin(k)) * grid%inv_h
         xi(k) = xi(k) - real(min(floor(xi(k)), grid%global_cells(k) - 1), rp)
      end do
      call shape_values_and_gradients(grid%dim, xi, grid%inv_h, n, g)
      call node_offsets(grid%dim, xi, grid%h, d)
      dp = 0.0_rp
      do a = 1, 2**grid%dim
         do k = 1, grid%dim
            dp(:, k) = dp(:, k) + n(a) * d(:, a) * d(k, a)
         end do
      end do
   end function particle_d
end module apic_measures
