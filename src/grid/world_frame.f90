!> The map from the grid's own frame, in which the solver works, to the world frame in which results
!> are written. Today the grid is axis-aligned with the world and the map is the identity; a grid
!> rotated against the world changes these procedures only (positions rotate and translate; vectors
!> and tensors rotate). Results always have 3 components: z = 0 in 2-D (plane strain in x-y).
module world_frame
   use kinds, only: rp
   use tensor_layout, only: to_matrix
   implicit none
   private

   public :: grid_to_world, grid_to_world_vectors, grid_to_world_tensors

contains

   !> World positions world(3, n) of the grid-frame positions x(dim, n) [m].
   pure subroutine grid_to_world(x, world)
      real(rp), intent(in) :: x(:, :)
      real(rp), intent(out) :: world(:, :)
      world(:, 1:size(x, 2)) = 0.0_rp
      world(1:size(x, 1), 1:size(x, 2)) = x
   end subroutine grid_to_world

   !> World components world(3, n) of the grid-frame vectors v(dim, n) (velocities).
   pure subroutine grid_to_world_vectors(v, world)
      real(rp), intent(in) :: v(:, :)
      real(rp), intent(out) :: world(:, :)
      world(:, 1:size(v, 2)) = 0.0_rp
      world(1:size(v, 1), 1:size(v, 2)) = v
   end subroutine grid_to_world_vectors

   !> World components of symmetric tensors s(n_components(dim), n) in the layout of tensor_layout, as
   !> full 3x3 matrices stored row by row: world(9, n) = (xx, xy, xz, yx, yy, yz, zx, zy, zz).
   pure subroutine grid_to_world_tensors(s, dim, world)
      real(rp), intent(in) :: s(:, :)
      integer, intent(in) :: dim
      real(rp), intent(out) :: world(:, :)
      integer :: p
      do p = 1, size(s, 2)
         world(:, p) = reshape(to_matrix(s(:, p), dim), [9])    ! symmetric: column order = row order
      end do
   end subroutine grid_to_world_tensors
end module world_frame
