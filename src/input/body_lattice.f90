!> Where the particles of a `&body` sit: its shape, the lattice of its particles, which lattice points
!> it keeps, its bounds, its ids and its particle count (docs/input.md "&body", docs/theory.md
!> section 3.5). Seeding (particle_seeding), bodies.csv (body_motion), the active region and the
!> memory check all ask here, so they agree on every body.
!>
!> - A box that is not rotated keeps its own lattice (as before shapes existed): along axis k
!>   n_k = nint((upper_k - lower_k) / (h / ppc)) points at spacing (upper_k - lower_k) / n_k, centred in
!>   their lattice cells, all kept: its mass is exactly rho0 times its volume.
!> - Every other shape uses the lattice of the scene box: points origin + (i + 1/2) s, s = h / ppc
!>   (on an unrotated grid the centres of the grid's cells cut into ppc per direction), over the lattice
!>   cells that meet the shape's bounding box, and keeps the points inside the shape (signed distance
!>   < 0): a lattice cell counts wholly, with its volume s^dim, if its centre is inside.
!> - A body of a points file has one particle per point of the file.
!> Ids: body offset + lattice index (x fastest; points outside the shape leave their ids unused), or +
!> row index of the file (0-based), so they do not depend on the ranks.
module body_lattice
   use kinds, only: rp, i8
   use scene_description, only: scene_t, body_spec_t, grid_spec_t
   use shape_geometry, only: shape_t, shape_box, shape_distance, shape_bounds, shape_measure
   implicit none
   private

   !> The lattice of one body.
   type, public :: body_lattice_t
      real(rp) :: lower(3) = 0.0_rp     !< world corner of lattice cell (0, 0, 0) [m]
      real(rp) :: spacing(3) = 1.0_rp   !< lattice spacing per axis (1 on unused axes) [m]
      integer :: n(3) = 1               !< lattice points per axis (1 on unused axes)
      logical :: whole = .true.         !< every point belongs to the body (a box that is not rotated)
      type(shape_t) :: shape            !< the body's shape: points are kept where its distance is < 0
   end type body_lattice_t

   !> Largest lattice count_particles walks point by point [R]: above it the count is the shape's
   !> measure over the lattice cell volume (only the memory check asks for such sizes).
   real(rp), parameter, public :: counted_lattice_limit = 2.0_rp**27

   public :: body_shape, has_points_file, box_corners_given, body_lattice_of, lattice_point, lattice_keeps, &
             body_id_count, scene_id_count, body_bounds, count_particles, particle_spacing

contains

   !> The body reads its particles from a file of points.
   pure logical function has_points_file(body)
      type(body_spec_t), intent(in) :: body
      has_points_file = len_trim(body%points_file) > 0
   end function has_points_file

   !> The scene gives the box by `lower`/`upper` (they differ on some used axis).
   pure logical function box_corners_given(body, dim)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      box_corners_given = any(body%upper(1:dim) > body%lower(1:dim) .or. body%upper(1:dim) < body%lower(1:dim))
   end function box_corners_given

   !> The body's shape in the world frame: `shape` as given, a box given by lower/upper made centre/size.
   pure function body_shape(body, dim) result(shape)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      type(shape_t) :: shape
      shape = body%shape
      if (shape%kind == shape_box .and. box_corners_given(body, dim)) then
         shape%centre = 0.5_rp * (body%lower + body%upper)
         shape%size = body%upper - body%lower
      end if
   end function body_shape

   !> Lattice spacing h / ppc of the body [m].
   pure real(rp) function particle_spacing(body, grid)
      type(body_spec_t), intent(in) :: body
      type(grid_spec_t), intent(in) :: grid
      particle_spacing = grid%cell_size / body%particles_per_cell
   end function particle_spacing

   !> The lattice of a body of a shape (not of a points file). Call on a validated body.
   pure function body_lattice_of(body, grid) result(lattice)
      type(body_spec_t), intent(in) :: body
      type(grid_spec_t), intent(in) :: grid
      type(body_lattice_t) :: lattice
      real(rp) :: lo(3), hi(3), s
      integer :: dim, first(3), last(3)
      dim = grid%dim
      lattice%shape = body_shape(body, dim)
      lattice%whole = lattice%shape%kind == shape_box .and. .not. abs(lattice%shape%rotation) > 0.0_rp
      if (lattice%whole) then
         ! the lattice of the box itself: the same expressions as before shapes, so the same particles
         call body_bounds_of_box(body, dim, lo, hi)
         lattice%n(1:dim) = nint((hi(1:dim) - lo(1:dim)) / (grid%cell_size / body%particles_per_cell))
         lattice%lower = lo
         lattice%spacing(1:dim) = (hi(1:dim) - lo(1:dim)) / lattice%n(1:dim)
      else
         s = particle_spacing(body, grid)
         call shape_bounds(lattice%shape, dim, lo, hi)
         ! the lattice cells of the scene box that meet the bounding box
         first(1:dim) = floor((lo(1:dim) - grid%origin(1:dim)) / s)
         last(1:dim) = max(first(1:dim), ceiling((hi(1:dim) - grid%origin(1:dim)) / s) - 1)
         lattice%n(1:dim) = last(1:dim) - first(1:dim) + 1
         lattice%lower = 0.0_rp
         lattice%lower(1:dim) = grid%origin(1:dim) + first(1:dim) * s
         lattice%spacing(1:dim) = s
      end if
   end function body_lattice_of

   !> World position of lattice point k (0-based, x fastest) [m].
   pure function lattice_point(lattice, k) result(x)
      type(body_lattice_t), intent(in) :: lattice
      integer(i8), intent(in) :: k
      real(rp) :: x(3)
      integer(i8) :: ijk(3)
      ijk(1) = mod(k, int(lattice%n(1), i8))
      ijk(2) = mod(k / lattice%n(1), int(lattice%n(2), i8))
      ijk(3) = k / (int(lattice%n(1), i8) * lattice%n(2))
      x = lattice%lower + (real(ijk, rp) + 0.5_rp) * lattice%spacing
   end function lattice_point

   !> The lattice point x (world, size dim) is a particle of the body.
   pure logical function lattice_keeps(lattice, x)
      type(body_lattice_t), intent(in) :: lattice
      real(rp), intent(in) :: x(:)
      lattice_keeps = lattice%whole
      if (.not. lattice_keeps) lattice_keeps = shape_distance(lattice%shape, x) < 0.0_rp
   end function lattice_keeps

   !> Ids body b of the scene takes: its lattice points, inside or not, or the points of its file.
   pure integer(i8) function body_id_count(scene, b) result(n)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: b
      type(body_lattice_t) :: lattice
      n = 0
      if (has_points_file(scene%bodies(b))) then
         if (allocated(scene%body_points)) then
            if (allocated(scene%body_points(b)%volume)) n = size(scene%body_points(b)%volume, kind=i8)
         end if
      else
         lattice = body_lattice_of(scene%bodies(b), scene%grid)
         n = product(int(lattice%n, i8))
      end if
   end function body_id_count

   !> Ids all bodies of the scene take: the first id free for the inlets' particles.
   pure integer(i8) function scene_id_count(scene) result(n)
      type(scene_t), intent(in) :: scene
      integer :: b
      n = 0
      if (.not. allocated(scene%bodies)) return
      do b = 1, size(scene%bodies)
         n = n + body_id_count(scene, b)
      end do
   end function scene_id_count

   !> World bounding box lo..hi of body b's particles [m].
   pure subroutine body_bounds(scene, b, lo, hi)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: b
      real(rp), intent(out) :: lo(3), hi(3)
      type(body_lattice_t) :: lattice
      integer :: dim
      dim = scene%grid%dim
      lo = 0.0_rp
      hi = 0.0_rp
      if (has_points_file(scene%bodies(b))) then
         if (.not. allocated(scene%body_points)) return
         if (.not. allocated(scene%body_points(b)%position)) return
         if (size(scene%body_points(b)%position, 2) == 0) return
         lo(1:dim) = minval(scene%body_points(b)%position, 2)
         hi(1:dim) = maxval(scene%body_points(b)%position, 2)
      else
         lattice = body_lattice_of(scene%bodies(b), scene%grid)
         if (lattice%whole) then
            lo = lattice%lower
            hi(1:dim) = lattice%lower(1:dim) + lattice%n(1:dim) * lattice%spacing(1:dim)
         else
            call shape_bounds(lattice%shape, dim, lo, hi)
         end if
      end if
   end subroutine body_bounds

   !> Particles body b makes (a real: a bad scene may ask for more than any integer holds), and whether
   !> the count is exact: a lattice of more than counted_lattice_limit points that is not a whole box
   !> gives the shape's measure over the lattice cell volume instead. Call on a validated body.
   subroutine count_particles(scene, b, n, exact)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: b
      real(rp), intent(out) :: n
      logical, intent(out) :: exact
      type(body_lattice_t) :: lattice
      real(rp) :: lo(3), hi(3), s, points
      integer(i8) :: k, kept
      integer :: dim

      dim = scene%grid%dim
      exact = .true.
      associate (body => scene%bodies(b))
         if (has_points_file(body)) then
            n = real(body_id_count(scene, b), rp)
            return
         end if
         s = particle_spacing(body, scene%grid)
         if (body%shape%kind == shape_box .and. .not. abs(body%shape%rotation) > 0.0_rp) then
            ! in reals first: the lattice may not fit default integers
            call body_bounds_of_box(body, dim, lo, hi)
            n = product(anint((hi(1:dim) - lo(1:dim)) / s))
            return
         end if
         call shape_bounds(body_shape(body, dim), dim, lo, hi)
         points = product(aint((hi(1:dim) - lo(1:dim)) / s) + 2.0_rp)
         if (points > counted_lattice_limit) then
            exact = .false.
            n = anint(shape_measure(body_shape(body, dim), dim) / s**dim)
            return
         end if
         lattice = body_lattice_of(body, scene%grid)
         kept = 0
         do k = 0, product(int(lattice%n, i8)) - 1
            if (lattice_keeps(lattice, pack_point(lattice_point(lattice, k), dim))) kept = kept + 1
         end do
         n = real(kept, rp)
      end associate
   end subroutine count_particles

   !> The corners of an unrotated box body, given by lower/upper or by centre/size.
   pure subroutine body_bounds_of_box(body, dim, lo, hi)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      real(rp), intent(out) :: lo(3), hi(3)
      if (box_corners_given(body, dim)) then
         lo = body%lower
         hi = body%upper
      else
         lo = body%shape%centre - 0.5_rp * body%shape%size
         hi = body%shape%centre + 0.5_rp * body%shape%size
      end if
   end subroutine body_bounds_of_box

   pure function pack_point(x, dim) result(y)
      real(rp), intent(in) :: x(3)
      integer, intent(in) :: dim
      real(rp) :: y(dim)
      y = x(1:dim)
   end function pack_point
end module body_lattice
