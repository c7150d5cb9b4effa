!> Shape functions: partition of unity, gradients summing to zero, exact reproduction of linear fields;
!> the same patch conditions for the quadratic B-spline stencil at random positions of a grid.
module test_shape_functions
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use shape_functions, only: n_corners, corner_offset, shape_values_and_gradients, shape_linear, shape_bspline2, &
                              stencil_nodes, stencil_offset, stencil_base, stencil_values
   implicit none
   private

   public :: test_partition_of_unity, test_gradient_sum, test_linear_reproduction, test_bspline2_patch, &
             test_bspline2_support

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

   !> A zero (dim, nodes) array for the gradients, passed whole so that the shape functions get it without a
   !> copy (a section of a larger array was copied at every call: a Debug build's run-time warning).
   pure function gradient_array(dim, nodes) result(g)
      integer, intent(in) :: dim, nodes
      real(rp), allocatable :: g(:, :)
      allocate (g(dim, nodes), source=0.0_rp)
   end function gradient_array

   subroutine test_partition_of_unity()
      integer :: dim, i
      real(rp), allocatable :: xi(:, :)
      real(rp) :: n(8)
      real(rp), allocatable :: g(:, :)  ! (dim, corners)
      do dim = 2, 3
         xi = sample_points(dim)
         g = gradient_array(dim, 2**dim)
         do i = 1, size(xi, 2)
            call shape_values_and_gradients(dim, xi(:, i), 1.0_rp / h, n(1:2**dim), g)
            call assertEqual(1.0_rp, sum(n(1:2**dim)), 1.0e-14_rp, 'sum of N_a')
            call assertEqual(0.0_rp, min(0.0_rp, minval(n(1:2**dim))), 0.0_rp, 'N_a >= 0')
         end do
      end do
   end subroutine test_partition_of_unity

   subroutine test_gradient_sum()
      integer :: dim, i, k
      real(rp), allocatable :: xi(:, :)
      real(rp) :: n(8)
      real(rp), allocatable :: g(:, :)  ! (dim, corners)
      do dim = 2, 3
         xi = sample_points(dim)
         g = gradient_array(dim, 2**dim)
         do i = 1, size(xi, 2)
            call shape_values_and_gradients(dim, xi(:, i), 1.0_rp / h, n(1:2**dim), g)
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
      real(rp) :: n(8), x_node(3), x_interp(3), jac(3, 3)
      real(rp), allocatable :: g(:, :)  ! (dim, corners)
      do dim = 2, 3
         xi = sample_points(dim)
         g = gradient_array(dim, 2**dim)
         do i = 1, size(xi, 2)
            call shape_values_and_gradients(dim, xi(:, i), 1.0_rp / h, n(1:2**dim), g)
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

   !> Quadratic B-splines at random positions of a grid of 7 cells per axis (origin -0.3), 2-D and 3-D, for
   !> both stencils through the generic entry points: sum N = 1, N >= 0, sum N x_i = x_p, sum grad N = 0 and
   !> sum x_i (x) grad N = I to round-off; the stencil stays inside the nodes -1 .. cells + 1.
   subroutine test_bspline2_patch()
      integer, parameter :: cells = 7, samples = 200
      real(rp), parameter :: origin = -0.3_rp
      integer :: dim, i, a, k, l, kind, base(3), nodes
      real(rp) :: s(3), xi(3), x_p(3), x_node(3), x_interp(3), grad_sum(3), jac(3, 3), n(27), r(3)
      real(rp), allocatable :: g(:, :)  ! (dim, nodes)
      do kind = shape_linear, shape_bspline2
         do dim = 2, 3
            nodes = stencil_nodes(kind, dim)
            g = gradient_array(dim, nodes)
            do i = 1, samples
               call random_number(r)
               ! in the grid, with the two upper faces of the whole grid among the samples
               s(1:dim) = r(1:dim) * cells
               if (i == 1) s(1:dim) = real(cells, rp)
               if (i == 2) s(1:dim) = 0.0_rp
               if (i == 3) s(1:dim) = 0.5_rp
               x_p(1:dim) = origin + s(1:dim) * h
               do k = 1, dim
                  base(k) = stencil_base(kind, s(k), cells)
                  xi(k) = s(k) - base(k)
               end do
               call stencil_values(kind, dim, xi(1:dim), 1.0_rp / h, n(1:nodes), g)
               call assertEqual(1.0_rp, sum(n(1:nodes)), 1.0e-14_rp, 'sum of N_a')
               call assertTrue(minval(n(1:nodes)) >= 0.0_rp, 'N_a >= 0')
               call assertTrue(all(base(1:dim) >= merge(-1, 0, kind == shape_bspline2)) .and. &
                               all(base(1:dim) + merge(2, 1, kind == shape_bspline2) <= &
                                   cells + merge(1, 0, kind == shape_bspline2)), 'stencil inside the nodes')
               x_interp = 0.0_rp
               grad_sum = 0.0_rp
               jac = 0.0_rp
               do a = 1, nodes
                  do k = 1, dim
                     x_node(k) = origin + (base(k) + stencil_offset(kind, a, k)) * h
                  end do
                  x_interp(1:dim) = x_interp(1:dim) + n(a) * x_node(1:dim)
                  grad_sum(1:dim) = grad_sum(1:dim) + g(1:dim, a)
                  do l = 1, dim
                     jac(1:dim, l) = jac(1:dim, l) + x_node(1:dim) * g(l, a)
                  end do
               end do
               call assertEqual(x_p(1:dim), x_interp(1:dim), 1.0e-14_rp, 'sum N_a x_a = x_p')
               call assertEqual(0.0_rp, grad_sum(1:dim), 1.0e-12_rp, 'sum grad N_a = 0')
               do k = 1, dim
                  do l = 1, dim
                     call assertEqual(merge(1.0_rp, 0.0_rp, k == l), jac(k, l), 1.0e-13_rp, 'sum x_a grad N_a = I')
                  end do
               end do
            end do
         end do
      end do
   end subroutine test_bspline2_patch

   !> The 1-D quadratic B-spline of [SKB08] at known points: a particle on a node gives 1/8, 3/4, 1/8;
   !> halfway between two nodes 1/2, 1/2, 0 (the stencil centred on the lower one); the value is C1 across
   !> the switch of the nearest node (the values of a node agree from both sides).
   subroutine test_bspline2_support()
      real(rp) :: n(9), g(2, 9), below(9), gb(2, 9)
      integer :: base
      call stencil_values(shape_bspline2, 2, [1.0_rp, 1.0_rp], 1.0_rp / h, n, g)
      call assertEqual([0.125_rp, 0.75_rp, 0.125_rp] * 0.75_rp, n(4:6), 1.0e-15_rp, 'on a node: 1/8, 3/4, 1/8')
      call assertEqual([-0.5_rp, 0.0_rp, 0.5_rp] / h * 0.75_rp, g(1, 4:6), 1.0e-14_rp, 'on a node: slopes -1/2, 0, 1/2')
      base = stencil_base(shape_bspline2, 3.5_rp, 10)
      call assertEqual(3, base, 'halfway: the stencil starts below the upper node')
      call stencil_values(shape_bspline2, 2, [0.5_rp, 1.0_rp], 1.0_rp / h, n, g)
      call assertEqual([0.5_rp, 0.5_rp, 0.0_rp] * 0.75_rp, n(4:6), 1.0e-15_rp, 'halfway: 1/2, 1/2, 0')
      ! the same point seen from the stencil one node lower (xi = 1.5): the weights shift by one node
      call stencil_values(shape_bspline2, 2, [1.5_rp, 1.0_rp], 1.0_rp / h, below, gb)
      call assertEqual(n(4:5), below(5:6), 1.0e-15_rp, 'continuous across the switch of the nearest node')
      call assertEqual(g(1, 4:5), gb(1, 5:6), 1.0e-13_rp, 'C1 across the switch of the nearest node')
   end subroutine test_bspline2_support
end module test_shape_functions
