!> The map between the grid's own frame, in which the solver works, and the world frame in which a
!> scene is described and results are written (algorithms.md section 4.2 [R]).
!>
!> The grid may be rotated against the world by theta_g about z, pivoting on a world point x_o (the
!> lower corner of the scene box): x_world = x_o + R(theta_g) (x_grid - x_o). The scene's geometry,
!> gravity and initial velocities are mapped into the grid frame once; results are mapped back.
!> Without rotation the map is the identity, applied as a copy so that it is exact.
!> Results always have 3 components: z = 0 in 2-D (plane strain in x-y).
module world_frame
   use kinds, only: rp
   use tensor_layout, only: to_matrix
   use scene_description, only: grid_spec_t
   implicit none
   private

   real(rp), parameter :: pi = acos(-1.0_rp)

   type, public :: frame_t
      real(rp) :: rotation_degrees = 0.0_rp
      real(rp) :: pivot(3) = 0.0_rp                 !< world point the rotation keeps [m]
      real(rp) :: to_world(3, 3) = reshape([1.0_rp, 0.0_rp, 0.0_rp, 0.0_rp, 1.0_rp, 0.0_rp, 0.0_rp, 0.0_rp, 1.0_rp], &
                                           [3, 3])  !< R(theta_g), grid components -> world components
      logical :: rotated = .false.
   contains
      procedure :: init => frame_init
      procedure :: grid_point => frame_grid_point
      procedure :: grid_vector => frame_grid_vector
      procedure :: world_point => frame_world_point
      procedure :: world_vector => frame_world_vector
      procedure :: to_world_points => frame_to_world_points
      procedure :: to_world_vectors => frame_to_world_vectors
      procedure :: to_world_tensors => frame_to_world_tensors
   end type frame_t

   public :: covering_grid, place_grid

contains

   !> A grid rotated by `degrees` counter-clockwise about z, pivoting on the world point `pivot`.
   pure subroutine frame_init(self, degrees, pivot)
      class(frame_t), intent(inout) :: self
      real(rp), intent(in) :: degrees, pivot(3)
      real(rp) :: angle
      self%rotation_degrees = degrees
      self%pivot = pivot
      self%rotated = abs(degrees) > 0.0_rp
      angle = degrees * pi / 180.0_rp
      self%to_world = 0.0_rp
      self%to_world(1, :) = [cos(angle), -sin(angle), 0.0_rp]
      self%to_world(2, :) = [sin(angle), cos(angle), 0.0_rp]
      self%to_world(3, 3) = 1.0_rp
      if (.not. self%rotated) self%to_world = reshape([1, 0, 0, 0, 1, 0, 0, 0, 1], [3, 3])
   end subroutine frame_init

   !> Grid-frame position of the world point x (both of size dim).
   pure function frame_grid_point(self, x) result(g)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: x(:)
      real(rp) :: g(size(x))
      if (.not. self%rotated) then
         g = x
      else
         g = self%pivot(1:size(x)) + self%grid_vector(x - self%pivot(1:size(x)))
      end if
   end function frame_grid_point

   !> Grid-frame components of the world vector v.
   pure function frame_grid_vector(self, v) result(g)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: v(:)
      real(rp) :: g(size(v))
      integer :: d
      d = size(v)
      if (.not. self%rotated) then
         g = v
      else
         g = matmul(transpose(self%to_world(1:d, 1:d)), v)
      end if
   end function frame_grid_vector

   !> World position of the grid-frame point x.
   pure function frame_world_point(self, x) result(w)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: x(:)
      real(rp) :: w(size(x))
      if (.not. self%rotated) then
         w = x
      else
         w = self%pivot(1:size(x)) + self%world_vector(x - self%pivot(1:size(x)))
      end if
   end function frame_world_point

   !> World components of the grid-frame vector v.
   pure function frame_world_vector(self, v) result(w)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: v(:)
      real(rp) :: w(size(v))
      integer :: d
      d = size(v)
      if (.not. self%rotated) then
         w = v
      else
         w = matmul(self%to_world(1:d, 1:d), v)
      end if
   end function frame_world_vector

   !> World positions world(3, n) of the grid-frame positions x(dim, n) [m].
   pure subroutine frame_to_world_points(self, x, world)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: x(:, :)
      real(rp), intent(out) :: world(:, :)
      integer :: p
      world(:, 1:size(x, 2)) = 0.0_rp
      do p = 1, size(x, 2)
         world(1:size(x, 1), p) = self%world_point(x(:, p))
      end do
   end subroutine frame_to_world_points

   !> World components world(3, n) of the grid-frame vectors v(dim, n) (velocities).
   pure subroutine frame_to_world_vectors(self, v, world)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: v(:, :)
      real(rp), intent(out) :: world(:, :)
      integer :: p
      world(:, 1:size(v, 2)) = 0.0_rp
      do p = 1, size(v, 2)
         world(1:size(v, 1), p) = self%world_vector(v(:, p))
      end do
   end subroutine frame_to_world_vectors

   !> World components of symmetric tensors s(n_components(dim), n) in the layout of tensor_layout, as
   !> full 3x3 matrices stored row by row: world(9, n) = (xx, xy, xz, yx, yy, yz, zx, zy, zz);
   !> sigma_world = R sigma R^T.
   pure subroutine frame_to_world_tensors(self, s, dim, world)
      class(frame_t), intent(in) :: self
      real(rp), intent(in) :: s(:, :)
      integer, intent(in) :: dim
      real(rp), intent(out) :: world(:, :)
      integer :: p
      do p = 1, size(s, 2)
         if (self%rotated) then
            world(:, p) = reshape(matmul(self%to_world, matmul(to_matrix(s(:, p), dim), transpose(self%to_world))), [9])
         else
            world(:, p) = reshape(to_matrix(s(:, p), dim), [9])    ! symmetric: column order = row order
         end if
      end do
   end subroutine frame_to_world_tensors

   !> The frame of `&grid` (rotation about its origin) and the grid covering its scene box: the grid's
   !> lower corner in the grid frame and its cells along the grid's axes.
   pure subroutine place_grid(spec, frame, origin, cells)
      type(grid_spec_t), intent(in) :: spec
      type(frame_t), intent(out) :: frame
      real(rp), intent(out) :: origin(3)
      integer, intent(out) :: cells(3)
      call frame%init(spec%rotation, spec%origin)
      call covering_grid(frame, spec%dim, spec%origin, spec%ncells * spec%cell_size, spec%cell_size, origin, cells)
   end subroutine place_grid

   !> The smallest grid of whole cells h, aligned with the frame's axes and with a node on the pivot, that
   !> covers the world box lower..lower+extent: its grid-frame lower corner `origin` and cell counts.
   !> Without rotation that is the box itself (extent is a whole multiple of h).
   pure subroutine covering_grid(frame, dim, lower, extent, h, origin, cells)
      type(frame_t), intent(in) :: frame
      integer, intent(in) :: dim
      real(rp), intent(in) :: lower(3), extent(3), h
      real(rp), intent(out) :: origin(3)
      integer, intent(out) :: cells(3)
      ! corners closer than this fraction of h to a grid line count as on it (45 degrees: sqrt(2)/2 h sums)
      real(rp), parameter :: snap = 1.0e-9_rp
      real(rp) :: corner(dim), g(dim), g_min(dim), g_max(dim)
      integer :: i, k
      origin = lower
      cells = 1
      if (.not. frame%rotated) then
         cells(1:dim) = nint(extent(1:dim) / h)
         return
      end if
      g_min = huge(1.0_rp)
      g_max = -huge(1.0_rp)
      do i = 0, 2**dim - 1
         do k = 1, dim
            corner(k) = lower(k) + merge(extent(k), 0.0_rp, btest(i, k - 1))
         end do
         g = frame%grid_point(corner) - frame%pivot(1:dim)
         g_min = min(g_min, g)
         g_max = max(g_max, g)
      end do
      do k = 1, dim
         origin(k) = frame%pivot(k) + h * floor(g_min(k) / h + snap)
         cells(k) = max(1, ceiling((frame%pivot(k) + g_max(k) - origin(k)) / h - snap))
      end do
   end subroutine covering_grid
end module world_frame
