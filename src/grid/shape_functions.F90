!> Multilinear shape functions of the regular grid (algorithms.md section 1.1):
!> bilinear in 2-D, trilinear in 3-D, 2**dim non-zero corner nodes per particle.
!>
!> Corners of a cell are numbered a = 1 + i + 2 j + 4 k with i, j, k in {0, 1} the offsets of the
!> corner from the cell's lower node along x, y, z. The formulas live in multilinear_shape.inc, which
!> the transfer kernels include as well.
module shape_functions
   use kinds, only: rp
   implicit none
   private

   public :: n_corners, corner_offset, shape_2d, shape_3d, shape_values_and_gradients

contains

   !> Number of corner nodes of a cell.
   pure integer function n_corners(dim)
      integer, intent(in) :: dim
      n_corners = 2**dim
   end function n_corners

   !> Offset (0 or 1) of corner `a` from the cell's lower node along axis `k`.
   pure integer function corner_offset(a, k)
      integer, intent(in) :: a, k
      corner_offset = ibits(a - 1, k - 1, 1)
   end function corner_offset

   !> N_a and grad N_a at fractional position xi in [0, 1]^dim of a cell of edge 1/inv_h.
   pure subroutine shape_values_and_gradients(dim, xi, inv_h, n, grad)
      integer, intent(in) :: dim
      real(rp), intent(in) :: xi(:), inv_h
      real(rp), intent(out) :: n(:), grad(:, :)
      if (dim == 2) then
         call shape_2d(xi, inv_h, n, grad)
      else
         call shape_3d(xi, inv_h, n, grad)
      end if
   end subroutine shape_values_and_gradients

#define KERNEL_DIM 2
#define SHAPE shape_2d
#include "multilinear_shape.inc"
#undef KERNEL_DIM
#undef SHAPE
#define KERNEL_DIM 3
#define SHAPE shape_3d
#include "multilinear_shape.inc"
end module shape_functions
