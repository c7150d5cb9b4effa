!> Angular momentum of the particles as APIC defines it, for the tests of the affine transfer.
module apic_measures
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use particle_set, only: particle_set_t
   implicit none
   private

   public :: particle_angular_momentum, affine_spin

contains

   !> L = sum_p m_p x_p x v_p + m_p eps : B_p^T over all ranks, about the grid frame's origin ([J15] sec. 5.3,
   !> [J17] sec. 4: the part m_p eps : B_p^T is the momentum the affine velocity puts on the grid's nodes).
   !> Without affine matrices the first sum alone. 2-D: (0, 0, L_z). Collective.
   function particle_angular_momentum(particles, comm) result(l)
      type(particle_set_t), intent(in) :: particles
      type(MPI_Comm), intent(in) :: comm
      real(rp) :: l(3), x(3), v(3)
      integer :: p, d
      d = particles%dim
      l = 0.0_rp
      do p = 1, particles%count
         x = 0.0_rp
         v = 0.0_rp
         x(1:d) = particles%x(:, p)
         v(1:d) = particles%v(:, p)
         l = l + particles%mass(p) * cross(x, v)
         if (particles%n_affine > 0) l = l + particles%mass(p) * affine_spin(particles%affine(:, p), d)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, l, 3, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
   end function particle_angular_momentum

   !> eps : B^T, (eps : B^T)_k = eps_kab B_ba, of a B stored column-major as b(dim**2).
   pure function affine_spin(b, dim) result(s)
      real(rp), intent(in) :: b(:)
      integer, intent(in) :: dim
      real(rp) :: s(3), m(3, 3)
      m = 0.0_rp
      m(1:dim, 1:dim) = reshape(b, [dim, dim])
      s = [m(3, 2) - m(2, 3), m(1, 3) - m(3, 1), m(2, 1) - m(1, 2)]
   end function affine_spin

   pure function cross(a, b) result(c)
      real(rp), intent(in) :: a(3), b(3)
      real(rp) :: c(3)
      c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
   end function cross
end module apic_measures
