!> Shape functions of the regular grid (docs/theory.md section 1.1, algorithms.md section 1.1):
!>  - 'linear': multilinear, 2**dim non-zero nodes per particle, the corners of its cell;
!>  - 'bspline2': quadratic B-splines [SKB08], 3**dim nodes, the stencil centred on the node nearest the
!>    particle.
!>
!> A particle's stencil starts at its base node (along each axis: BASE of the shape's .inc) and node a of
!> the stencil is numbered a = 1 + i + w j + w**2 k with w the stencil width (2 or 3) and i, j, k in
!> 0..w-1 the offsets from the base node along x, y, z. The formulas live in multilinear_shape.inc and
!> bspline2_shape.inc, which the transfer kernels include as well.
module shape_functions
   use kinds, only: rp
   implicit none
   private

   !> Shape function kinds (grid_t%shape), from `&grid shape_function`.
   integer, parameter, public :: shape_linear = 1, shape_bspline2 = 2

   public :: n_corners, corner_offset, shape_2d, shape_3d, shape_values_and_gradients
   public :: bspline2_2d, bspline2_3d, shape_function_kind, stencil_width, stencil_nodes, ghost_node_layers, &
             stencil_offset, stencil_base, stencil_values

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

   !> The kind of a `&grid shape_function` keyword (validated: 'linear' or 'bspline2').
   pure integer function shape_function_kind(name) result(kind)
      character(len=*), intent(in) :: name
      kind = shape_linear
      if (name == 'bspline2') kind = shape_bspline2
   end function shape_function_kind

   !> Nodes per axis a particle touches.
   pure integer function stencil_width(kind)
      integer, intent(in) :: kind
      stencil_width = merge(3, 2, kind == shape_bspline2)
   end function stencil_width

   !> Nodes a particle touches: stencil_width**dim.
   pure integer function stencil_nodes(kind, dim)
      integer, intent(in) :: kind, dim
      stencil_nodes = stencil_width(kind)**dim
   end function stencil_nodes

   !> Node layers a rank needs beyond the corners of its cells on each side: a particle in a cell reaches
   !> one node further than the cell's corners with bspline2.
   pure integer function ghost_node_layers(kind)
      integer, intent(in) :: kind
      ghost_node_layers = stencil_width(kind) - 2
   end function ghost_node_layers

   !> Offset (0 .. width - 1) of stencil node `a` from the base node along axis `k`.
   pure integer function stencil_offset(kind, a, k)
      integer, intent(in) :: kind, a, k
      stencil_offset = mod((a - 1) / stencil_width(kind)**(k - 1), stencil_width(kind))
   end function stencil_offset

   !> Base node (global index along one axis) of the stencil at s = (x - origin) / h on an axis of `cells` cells.
   pure integer function stencil_base(kind, s, cells)
      integer, intent(in) :: kind, cells
      real(rp), intent(in) :: s
      if (kind == shape_bspline2) then
         stencil_base = base_bspline2(s, cells)
      else
         stencil_base = base_linear(s, cells)
      end if
   end function stencil_base

   !> N_a and grad N_a of the stencil, xi the position in cells from its base node.
   pure subroutine stencil_values(kind, dim, xi, inv_h, n, grad)
      integer, intent(in) :: kind, dim
      real(rp), intent(in) :: xi(:), inv_h
      real(rp), intent(out) :: n(:), grad(:, :)
      if (kind == shape_bspline2) then
         if (dim == 2) then
            call bspline2_2d(xi, inv_h, n, grad)
         else
            call bspline2_3d(xi, inv_h, n, grad)
         end if
      else
         call shape_values_and_gradients(dim, xi, inv_h, n, grad)
      end if
   end subroutine stencil_values

   !> Multilinear N_a and grad N_a at fractional position xi in [0, 1]^dim of a cell of edge 1/inv_h.
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
#define BASE base_linear
#include "multilinear_shape.inc"
#undef KERNEL_DIM
#undef SHAPE
#undef BASE
#define KERNEL_DIM 3
#define SHAPE shape_3d
#define BASE base_linear
#include "multilinear_shape.inc"
#undef KERNEL_DIM
#undef SHAPE
#undef BASE
#define KERNEL_DIM 2
#define SHAPE bspline2_2d
#define BASE base_bspline2
#include "bspline2_shape.inc"
#undef KERNEL_DIM
#undef SHAPE
#undef BASE
#define KERNEL_DIM 3
#define SHAPE bspline2_3d
#define BASE base_bspline2
#include "bspline2_shape.inc"
end module shape_functions
