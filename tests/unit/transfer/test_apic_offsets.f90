!> The identity behind APIC's affine terms on the multilinear grid (docs/theory.md "APIC"): with
!> D_p = sum_a N_a (x_a - x_p)(x_a - x_p)^T and the offsets x_a - x_p of grid_transfer's node_offsets,
!> grad N_a = D_p^-1 (x_a - x_p) N_a, so that the P2G term m_p B_p D_p^-1 (x_a - x_p) N_a is m_p B_p grad N_a.
module test_apic_offsets
   use kinds, only: rp
   use assertions, only: assertEqual, assertRelativelyEqual
   use shape_functions, only: shape_values_and_gradients
   use grid_transfer, only: node_offsets
   implicit none
   private

   public :: test_gradient_is_offset_over_d_2d, test_gradient_is_offset_over_d_3d

contains

   subroutine test_gradient_is_offset_over_d_2d()
      call check_gradient_identity(2)
   end subroutine test_gradient_is_offset_over_d_2d

   subroutine test_gradient_is_offset_over_d_3d()
      call check_gradient_identity(3)
   end subroutine test_gradient_is_offset_over_d_3d

   !> D_p = sum_a N_a (x_a - x_p)(x_a - x_p)^T is diagonal, D_kk = xi_k (1 - xi_k) h^2, and
   !> grad N_a = D_p^-1 (x_a - x_p) N_a for every corner, at positions inside the cell and within 1e-9 of
   !> its faces; on a face D_p is singular while grad N_a stays finite (why the kernels use grad N_a).
   subroutine check_gradient_identity(dim)
      integer, intent(in) :: dim
      real(rp), parameter :: h = 0.37_rp
      real(rp), parameter :: points(3, 6) = reshape([0.5_rp, 0.5_rp, 0.5_rp, 0.13_rp, 0.71_rp, 0.42_rp, &
                                                     0.97_rp, 0.02_rp, 0.61_rp, 1.0e-9_rp, 0.3_rp, 1.0_rp - 1.0e-9_rp, &
                                                     0.25_rp, 0.999_rp, 0.001_rp, 0.66_rp, 0.66_rp, 0.1_rp], [3, 6])
      real(rp) :: xi(dim), n(2**dim), g(dim, 2**dim), d(dim, 2**dim), dp(dim, dim), expected(dim, dim)
      integer :: q, a, k
      do q = 1, size(points, 2)
         xi = points(1:dim, q)
         call shape_values_and_gradients(dim, xi, 1.0_rp / h, n, g)
         call node_offsets(dim, xi, h, d)
         dp = 0.0_rp
         do a = 1, 2**dim
            do k = 1, dim
               dp(:, k) = dp(:, k) + n(a) * d(:, a) * d(k, a)
            end do
         end do
         expected = 0.0_rp
         do k = 1, dim
            expected(k, k) = xi(k) * (1.0_rp - xi(k)) * h**2
         end do
         call assertEqual(expected, dp, 1.0e-15_rp * h**2, 'D_p diagonal with xi (1 - xi) h^2')
         do a = 1, 2**dim
            do k = 1, dim
               call assertRelativelyEqual(g(k, a), d(k, a) * n(a) / dp(k, k), 1.0e-9_rp, &
                                          'grad N_a = D^-1 (x_a - x_p) N_a')
            end do
         end do
      end do
      ! on a grid line (xi_1 = 0) D_11 = 0 but the gradient is finite: +-1/h times the other factors
      xi = 0.5_rp
      xi(1) = 0.0_rp
      call shape_values_and_gradients(dim, xi, 1.0_rp / h, n, g)
      call assertEqual(1.0_rp / h / 2**(dim - 1), g(1, 2), 1.0e-14_rp, 'grad N on a grid line')
   end subroutine check_gradient_identity
end module test_apic_offsets
