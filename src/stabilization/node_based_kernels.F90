!> The particle loops of NB (node_based_anti_locking.f90), instantiated per dimension and shape function as
!> the transfer kernels are (grid_transfer.F90): the shape values of `prepare` inline the very SHAPE of
!> multilinear_shape.inc / bspline2_shape.inc, and the nodal scatter and gather run over a compile-time
!> stencil and stress components (4 in 2-D, 6 in 3-D) instead of the runtime-sized loops around
!> shape_functions' generic `stencil_values` they replace (a 2.1 times dearer step than standard MPM).
module node_based_kernels
   use kinds, only: rp
   use background_grid, only: grid_t
   use shape_functions, only: shape_bspline2
   use particle_set, only: particle_set_t
   use stencil_cache, only: stencil_cache_t, holds_stencils
   implicit none
   private

   public :: store_shape_values, scatter_to_nodes, gather_from_nodes, divide_by_mass, clear

contains

   !> The kernel instance of a grid: 1 multilinear 2-D, 2 multilinear 3-D, 3 B-spline 2-D, 4 B-spline 3-D.
   pure integer function instance(grid)
      type(grid_t), intent(in) :: grid
      instance = merge(1, 2, grid%dim == 2)
      if (grid%shape == shape_bspline2) instance = instance + 2
   end function instance

   !> base(q), weight(:, q) = N_a(x_p^n) of particles p = first..last (q = p - first + 1) and, with
   !> `mass`, mass(i) += N_ip m_p.
   subroutine store_shape_values(grid, particles, first, last, base, weight, mass, stencils)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      integer, intent(inout), contiguous :: base(:)
      real(rp), intent(inout), contiguous :: weight(:, :)
      ! assumed size, not a contiguous assumed shape: the caller's row nodal_mass(1, :) is contiguous but not
      ! known to be, and gfortran 12 copies such a section in and out of a contiguous dummy at every call
      real(rp), intent(inout), optional :: mass(*)
      type(stencil_cache_t), intent(in), optional :: stencils
      select case (instance(grid))
      case (1); call store_2d(grid, particles, first, last, base, weight, mass)
      case (2); call store_3d(grid, particles, first, last, base, weight, mass, stencils)
      case (3); call store_b2_2d(grid, particles, first, last, base, weight, mass)
      case default; call store_b2_3d(grid, particles, first, last, base, weight, mass, stencils)
      end select
   end subroutine store_shape_values

   !> nodal(:, i) += sum_q N_iq mass(q) values(:, q) (the stencils stored by store_shape_values).
   subroutine scatter_to_nodes(grid, base, weight, mass, values, nodal)
      type(grid_t), intent(in) :: grid
      integer, intent(in), contiguous :: base(:)
      real(rp), intent(in), contiguous :: weight(:, :), mass(:), values(:, :)
      real(rp), intent(inout), contiguous :: nodal(:, :)
      select case (instance(grid))
      case (1); call scatter_2d(grid, base, weight, mass, values, nodal)
      case (2); call scatter_3d(grid, base, weight, mass, values, nodal)
      case (3); call scatter_b2_2d(grid, base, weight, mass, values, nodal)
      case default; call scatter_b2_3d(grid, base, weight, mass, values, nodal)
      end select
   end subroutine scatter_to_nodes

   !> values(:, q) := sum_i N_iq nodal(:, i).
   subroutine gather_from_nodes(grid, base, weight, nodal, values)
      type(grid_t), intent(in) :: grid
      integer, intent(in), contiguous :: base(:)
      real(rp), intent(in), contiguous :: weight(:, :), nodal(:, :)
      real(rp), intent(inout), contiguous :: values(:, :)
      select case (instance(grid))
      case (1); call gather_2d(grid, base, weight, nodal, values)
      case (2); call gather_3d(grid, base, weight, nodal, values)
      case (3); call gather_b2_2d(grid, base, weight, nodal, values)
      case default; call gather_b2_3d(grid, base, weight, nodal, values)
      end select
   end subroutine gather_from_nodes

   !> nodal(:, i) := nodal(:, i) / mass(i) where mass(i) > 0, i = 1..size(mass).
   subroutine divide_by_mass(grid, mass, nodal)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: mass(:)   !< a row of grid%accumulated may be passed: not contiguous
      real(rp), intent(inout), contiguous :: nodal(:, :)
      select case (instance(grid))
      case (1); call divide_2d(mass, nodal)
      case (2); call divide_3d(mass, nodal)
      case (3); call divide_b2_2d(mass, nodal)
      case default; call divide_b2_3d(mass, nodal)
      end select
   end subroutine divide_by_mass

   !> values(1:n) := 0 as one block (an array section of columns was zeroed column by column, one memset
   !> call per node).
   subroutine clear(n, values)
      integer, intent(in) :: n
      real(rp), intent(out) :: values(n)
      values = 0.0_rp
   end subroutine clear

#define KERNEL_DIM 2
#define N_SIGMA 4
#define WIDTH 2
#define SHAPE shape_2d
#define BASE base_linear
#define STORE store_2d
#define SCATTER scatter_2d
#define GATHER gather_2d
#define DIVIDE divide_2d
#include "../grid/multilinear_shape.inc"
#include "node_based_kernels.inc"

#define KERNEL_DIM 3
#define N_SIGMA 6
#define WIDTH 2
#define SHAPE shape_3d
#define BASE base_linear
#define STORE store_3d
#define SCATTER scatter_3d
#define GATHER gather_3d
#define DIVIDE divide_3d
#include "../grid/multilinear_shape.inc"
#include "node_based_kernels.inc"

#define KERNEL_DIM 2
#define N_SIGMA 4
#define WIDTH 3
#define SHAPE bspline2_2d
#define BASE base_bspline2
#define STORE store_b2_2d
#define SCATTER scatter_b2_2d
#define GATHER gather_b2_2d
#define DIVIDE divide_b2_2d
#include "../grid/bspline2_shape.inc"
#include "node_based_kernels.inc"

#define KERNEL_DIM 3
#define N_SIGMA 6
#define WIDTH 3
#define SHAPE bspline2_3d
#define BASE base_bspline2
#define STORE store_b2_3d
#define SCATTER scatter_b2_3d
#define GATHER gather_b2_3d
#define DIVIDE divide_b2_3d
#include "../grid/bspline2_shape.inc"
#include "node_based_kernels.inc"
end module node_based_kernels
