!> Shape functions: partition of unity, gradients summing to zero, exact reproduction of linear fields.
module test_shape_functions
   use kinds, only: rp
   use assertions, only: assertEqual
   use shape_functions, only: n_corners, corner_offset, shape_values_and_gradients
   implicit none
   private

   public :: test_partition_of_unity, test_gradient_sum, test_linear_reproduction

   real(rp), parameter :: h = 0.25_rp

contains

   !> A reproducible set of points in the unit cell, including its corners and faces.
   function sample_points(dim) result(xi)
      integer, intent(in) :: dim
      real(rp), allocatable :: xi(:, :)
      integer :: i, k
      allocate (xi(dim, 40))
      do i = 1, size(xi, 2)
         do k = 1, dim
            xi(k, i) = modulo(0.6180339887_rp * i * (k + 1) + 0.1_rp * k, 1.0_rp)
         end do
      end do
      xi(:, 1) = 0.0_rp
      xi(:, 2) = 1.0_rp
      xi(1, 3) = 0.0_rp
   end function sample_points

   subroutine test_partition_of_unity()
      integer :: dim, i
      real(rp), allocatable :: xi(:, :)
      real(rp) :: n(8), g(3, 8)
      do dim = 2, 3
         xi = sample_points(dim)
         do i = 1, size(xi, 2)
            call shape_values_and_gradients(dim, xi(:, i), 1.0_rp / h, n(1:2**dim), g(1:dim, 1:2**dim))
            call assertEqual(1.0_rp, sum(n(1:2**dim)), 1.0e-14_rp, 'sum of N_a')
            call assertEqual(0.0_rp, min(0.0_rp, minval(n(1:2**dim))), 0.0_rp, 'N_a >= 0')
         end do
      end do
   end subroutine test_partition_of_unity

   subroutine test_gradient_sum()
      integer :: dim, i, k
      real(rp), allocatable :: xi(:, :)
      real(rp) :: n(8), g(3, 8)
      do dim = 2, 3
         xi = sample_points(dim)
         do i = 1, size(xi, 2)
            call shape_values_and_gradients(dim, xi(:, i), 1.0_rp / h, n(1:2**dim), g(1:dim, 1:2**dim))
            do k = 1, dim
               call assertEqual(0.0_rp, sum(g(k, 1:2**dim)), 1.0e-12_rp, 'sum of dN_a/dx_k')
            end do
         end do
      end do
   end subroutine test_gradient_sum

   !> sum N_a x_a = x and sum x_a (x) grad N_a = I: a linear velocity field gives its exact gradient.
   subroutine test_linear_reproduction()
      integer :: dim, i, a, k, l
      real(rp), allocatable :: xi(:, :)
      real(rp) :: n(8), g(3, 8), x_node(3), x_interp(3), jac(3, 3)
      do dim = 2, 3
         xi = sample_points(dim)
         do i = 1, size(xi, 2)
            call shape_values_and_gradients(dim, xi(:, i), 1.0_rp / h, n(1:2**dim), g(1:dim, 1:2**dim))
            x_interp = 0.0_rp
            jac = 0.0_rp
            do a = 1, n_corners(dim)
               do k = 1, dim
                  x_node(k) = h * corner_offset(a, k)
               end do
               x_interp(1:dim) = x_interp(1:dim) + n(a) * x_node(1:dim)
               do l = 1, dim
                  jac(1:dim, l) = jac(1:dim, l) + x_node(1:dim) * g(l, a)
               end do
            end do
            call assertEqual(h * xi(:, i), x_interp(1:dim), 1.0e-14_rp, 'sum N_a x_a = x')
            do k = 1, dim
               do l = 1, dim
                  call assertEqual(merge(1.0_rp, 0.0_rp, k == l), jac(k, l), 1.0e-13_rp, 'sum x_a grad N_a = I')
               end do
            end do
         end do
      end do
   end subroutine test_linear_reproduction
end module test_shape_functions
