!> The solid shapes a scene places in the world (issue 15): the geometry of a `&structure` and of a
!> `&body`. A shape is plain data of fixed size (the scene travels between ranks as bytes) plus pure
!> functions: its signed distance (signed_distance: negative inside), outward normal, bounding box,
!> exact area or volume, and the check of its parameters. Everything is in the world frame.
!>
!>   2-D: 'box' (a rectangle), 'circle', 'polygon'
!>   3-D: 'box', 'cylinder' (any axis), 'sphere', 'extruded_polygon' (a polygon of the x-y plane
!>        extruded along z over z_range)
!> A box is given by its centre, its edge lengths `size` along its own axes and a `rotation` [degrees]
!> about `rotation_axis` (2-D: about z); a cylinder by its centre, `axis` (any length, made unit),
!> `length` and `radius`. Polygon vertices are listed in order (either sense); the last joins the first,
!> and a last vertex equal to the first is the same polygon written closed.
module shape_geometry
   use kinds, only: rp, name_len
   use signed_distance, only: box_distance, ball_distance, capped_cylinder_distance, polygon_distance, &
                              extruded_polygon_distance
   implicit none
   private

   !> Largest number of polygon vertices a shape holds (fixed: the scene is broadcast as bytes).
   integer, parameter, public :: max_vertices = 100
   !> A vertex slot that holds no vertex.
   real(rp), parameter, public :: no_vertex = huge(1.0_rp)

   character(len=*), parameter, public :: shape_box = 'box', shape_circle = 'circle', shape_polygon = 'polygon', &
                                          shape_cylinder = 'cylinder', shape_sphere = 'sphere', &
                                          shape_extruded_polygon = 'extruded_polygon'
   !> The shape keywords of each dimension, for messages.
   character(len=*), parameter, public :: shapes_2d(*) = [character(len=16) :: shape_box, shape_circle, shape_polygon]
   character(len=*), parameter, public :: shapes_3d(*) = [character(len=16) :: shape_box, shape_cylinder, shape_sphere, &
                                                          shape_extruded_polygon]

   real(rp), parameter :: pi = acos(-1.0_rp)

   type, public :: shape_t
      character(len=name_len) :: kind = shape_box
      real(rp) :: centre(3) = 0.0_rp           !< box, circle, sphere, cylinder: centre [m]
      real(rp) :: size(3) = 0.0_rp             !< box: edge lengths along its own axes [m]
      real(rp) :: rotation = 0.0_rp            !< box: rotation about rotation_axis, counter-clockwise [degrees]
      real(rp) :: rotation_axis(3) = [0.0_rp, 0.0_rp, 1.0_rp]  !< box, 3-D: the axis of `rotation`
      real(rp) :: radius = 0.0_rp              !< circle, sphere, cylinder [m]
      real(rp) :: axis(3) = [0.0_rp, 0.0_rp, 1.0_rp]          !< cylinder: direction of its axis
      real(rp) :: length = 0.0_rp              !< cylinder: length along its axis [m]
      real(rp) :: vertices(2, max_vertices) = no_vertex        !< polygon: (x, y) of each vertex [m]
      real(rp) :: z_range(2) = 0.0_rp          !< extruded polygon: lowest and highest z [m]
   end type shape_t

   public :: box_from_corners, vertex_count, polygon_vertices, shape_distance, shape_normal, shape_bounds, &
             shape_measure, shape_problem, box_axes, polygon_area, translated_shape, box_corners

contains

   !> The axis-aligned box lower..upper as a shape.
   pure function box_from_corners(lower, upper) result(shape)
      real(rp), intent(in) :: lower(3), upper(3)
      type(shape_t) :: shape
      shape%kind = shape_box
      shape%centre = 0.5_rp * (lower + upper)
      shape%size = upper - lower
   end function box_from_corners

   !> `shape` with the centre and size of the box lower..upper (its first dim components; rotation kept).
   pure function box_corners(shape, lower, upper, dim) result(box)
      type(shape_t), intent(in) :: shape
      real(rp), intent(in) :: lower(3), upper(3)
      integer, intent(in) :: dim
      type(shape_t) :: box, corners
      real(rp) :: lo(3), up(3)
      lo = 0.0_rp
      up = 0.0_rp
      lo(1:dim) = lower(1:dim)
      up(1:dim) = upper(1:dim)
      corners = box_from_corners(lo, up)
      box = shape
      box%centre(1:dim) = corners%centre(1:dim)
      box%size(1:dim) = corners%size(1:dim)
   end function box_corners

   !> Vertices given: the leading slots that hold one (a last vertex equal to the first is dropped).
   pure integer function vertex_count(shape) result(n)
      type(shape_t), intent(in) :: shape
      n = 0
      do while (n < max_vertices)
         if (any(shape%vertices(:, n + 1) >= no_vertex)) exit
         n = n + 1
      end do
      if (n > 1) then
         if (maxval(abs(shape%vertices(:, n) - shape%vertices(:, 1))) <= 0.0_rp) n = n - 1
      end if
   end function vertex_count

   pure function polygon_vertices(shape) result(vertices)
      type(shape_t), intent(in) :: shape
      real(rp), allocatable :: vertices(:, :)
      vertices = shape%vertices(:, 1:vertex_count(shape))
   end function polygon_vertices

   !> Rows: the unit axes of a box in the world (dim x dim): the world axes turned by `rotation` about
   !> `rotation_axis` (Rodrigues' formula; 2-D: about z).
   pure function box_axes(shape, dim) result(axes)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      real(rp) :: axes(dim, dim)
      real(rp) :: r(3, 3), k(3), c, s, angle
      integer :: i
      angle = shape%rotation * pi / 180.0_rp
      c = cos(angle)
      s = sin(angle)
      k = [0.0_rp, 0.0_rp, 1.0_rp]
      if (dim == 3 .and. norm2(shape%rotation_axis) > 0.0_rp) k = shape%rotation_axis / norm2(shape%rotation_axis)
      ! R = c I + s [k]x + (1 - c) k k^T; column j of R is the turned world axis e_j
      r = (1.0_rp - c) * spread(k, 2, 3) * spread(k, 1, 3)
      do i = 1, 3
         r(i, i) = r(i, i) + c
      end do
      r(1, 2) = r(1, 2) - s * k(3)
      r(2, 1) = r(2, 1) + s * k(3)
      r(1, 3) = r(1, 3) + s * k(2)
      r(3, 1) = r(3, 1) - s * k(2)
      r(2, 3) = r(2, 3) - s * k(1)
      r(3, 2) = r(3, 2) + s * k(1)
      axes = transpose(r(1:dim, 1:dim))
   end function box_axes

   !> Signed distance of the world point x (size dim) to the shape: negative inside.
   pure real(rp) function shape_distance(shape, x) result(phi)
      type(shape_t), intent(in) :: shape
      real(rp), intent(in) :: x(:)
      integer :: dim
      dim = size(x)
      select case (shape%kind)
      case (shape_box)
         phi = box_distance(x, shape%centre(1:dim), 0.5_rp * shape%size(1:dim), box_axes(shape, dim))
      case (shape_circle, shape_sphere)
         phi = ball_distance(x, shape%centre(1:dim), shape%radius)
      case (shape_cylinder)
         associate (a => shape%axis / norm2(shape%axis))
            phi = capped_cylinder_distance(x, shape%centre - 0.5_rp * shape%length * a, a, shape%length, shape%radius)
         end associate
      case (shape_polygon)
         phi = polygon_distance(x, polygon_vertices(shape))
      case (shape_extruded_polygon)
         phi = extruded_polygon_distance(x, polygon_vertices(shape), shape%z_range(1), shape%z_range(2))
      case default
         phi = huge(1.0_rp)
      end select
   end function shape_distance

   !> Outward unit normal grad(phi) at x by central differences of the exact distance over `step` [m]
   !> (|grad phi| = 1 off the shape's medial axis; on it, e.g. at a box's diagonal inside, the mean of the
   !> two faces' normals, made unit). Zero if undefined (the centre of a ball).
   pure function shape_normal(shape, x, step) result(normal)
      type(shape_t), intent(in) :: shape
      real(rp), intent(in) :: x(:), step
      real(rp) :: normal(size(x)), e(size(x)), length
      integer :: k
      do k = 1, size(x)
         e = 0.0_rp
         e(k) = step
         normal(k) = shape_distance(shape, x + e) - shape_distance(shape, x - e)
      end do
      length = norm2(normal)
      if (length > 0.0_rp) then
         normal = normal / length
      else
         normal = 0.0_rp
      end if
   end function shape_normal

   !> The shape moved by the world vector d (its first dim components; a moving `&structure`): centre,
   !> every vertex given (a closing copy of the first too) and, in 3-D, z_range.
   pure function translated_shape(shape, d, dim) result(moved)
      type(shape_t), intent(in) :: shape
      real(rp), intent(in) :: d(3)
      integer, intent(in) :: dim
      type(shape_t) :: moved
      integer :: v
      moved = shape
      moved%centre(1:dim) = shape%centre(1:dim) + d(1:dim)
      do v = 1, max_vertices
         if (any(shape%vertices(:, v) >= no_vertex)) exit
         moved%vertices(:, v) = shape%vertices(:, v) + d(1:2)
      end do
      if (dim == 3) moved%z_range = shape%z_range + d(3)
   end function translated_shape

   !> World-frame bounding box of the shape (exact for every kind).
   pure subroutine shape_bounds(shape, dim, lower, upper)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      real(rp), intent(out) :: lower(3), upper(3)
      real(rp) :: reach(3), a(3)
      integer :: n
      lower = 0.0_rp
      upper = 0.0_rp
      select case (shape%kind)
      case (shape_box)
         ! half-extent along world axis k: sum over the box's axes of |component| x half size
         reach = 0.0_rp
         reach(1:dim) = matmul(0.5_rp * shape%size(1:dim), abs(box_axes(shape, dim)))
         lower(1:dim) = shape%centre(1:dim) - reach(1:dim)
         upper(1:dim) = shape%centre(1:dim) + reach(1:dim)
      case (shape_circle, shape_sphere)
         lower(1:dim) = shape%centre(1:dim) - shape%radius
         upper(1:dim) = shape%centre(1:dim) + shape%radius
      case (shape_cylinder)
         a = shape%axis / norm2(shape%axis)
         ! the end discs reach radius sqrt(1 - a_k^2) along world axis k
         reach = 0.5_rp * shape%length * abs(a) + shape%radius * sqrt(max(0.0_rp, 1.0_rp - a**2))
         lower = shape%centre - reach
         upper = shape%centre + reach
      case (shape_polygon, shape_extruded_polygon)
         n = vertex_count(shape)
         if (n == 0) return
         lower(1:2) = minval(shape%vertices(:, 1:n), 2)
         upper(1:2) = maxval(shape%vertices(:, 1:n), 2)
         if (dim == 3) then
            lower(3) = shape%z_range(1)
            upper(3) = shape%z_range(2)
         end if
      end select
   end subroutine shape_bounds

   !> Exact area (2-D) or volume (3-D) of the shape [m^2 or m^3].
   pure real(rp) function shape_measure(shape, dim) result(measure)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      select case (shape%kind)
      case (shape_box)
         measure = product(shape%size(1:dim))
      case (shape_circle)
         measure = pi * shape%radius**2
      case (shape_sphere)
         measure = 4.0_rp / 3.0_rp * pi * shape%radius**3
      case (shape_cylinder)
         measure = pi * shape%radius**2 * shape%length
      case (shape_polygon)
         measure = abs(polygon_area(polygon_vertices(shape)))
      case (shape_extruded_polygon)
         measure = abs(polygon_area(polygon_vertices(shape))) * (shape%z_range(2) - shape%z_range(1))
      case default
         measure = 0.0_rp
      end select
   end function shape_measure

   !> Signed area of a polygon (shoelace formula; positive counter-clockwise).
   pure real(rp) function polygon_area(vertices) result(area)
      real(rp), intent(in) :: vertices(:, :)
      integer :: k, n
      n = size(vertices, 2)
      area = 0.0_rp
      do k = 1, n
         associate (a => vertices(:, k), b => vertices(:, modulo(k, n) + 1))
            area = area + 0.5_rp * (a(1) * b(2) - b(1) * a(2))
         end associate
      end do
   end function polygon_area

   !> What is wrong with the shape's parameters in a `dim`-dimensional scene, as 'variable: reason'
   !> ('' if nothing): the caller prefixes file and group.
   pure function shape_problem(shape, dim) result(problem)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      character(len=:), allocatable :: problem
      integer :: n
      problem = ''
      if (dim == 2 .and. .not. any(shapes_2d == shape%kind)) then
         problem = "shape: '"//trim(shape%kind)//"' is not a 2-D shape (2-D: box, circle, polygon)"
         return
      else if (dim == 3 .and. .not. any(shapes_3d == shape%kind)) then
         problem = "shape: '"//trim(shape%kind)//"' is not a 3-D shape (3-D: box, cylinder, sphere, extruded_polygon)"
         return
      end if
      select case (shape%kind)
      case (shape_box)
         if (any(.not. (shape%size(1:dim) > 0.0_rp))) problem = 'size: every edge length must be > 0'
         if (dim == 3 .and. abs(shape%rotation) > 0.0_rp .and. .not. (norm2(shape%rotation_axis) > 0.0_rp)) &
            problem = 'rotation_axis: must not be zero'
      case (shape_circle, shape_sphere)
         if (.not. (shape%radius > 0.0_rp)) problem = 'radius: must be > 0'
      case (shape_cylinder)
         if (.not. (shape%radius > 0.0_rp)) problem = 'radius: must be > 0'
         if (.not. (shape%length > 0.0_rp)) problem = 'length: must be > 0'
         if (.not. (norm2(shape%axis) > 0.0_rp)) problem = 'axis: must not be zero'
      case (shape_polygon, shape_extruded_polygon)
         n = vertex_count(shape)
         problem = polygon_problem(shape%vertices(:, 1:n))
         if (len(problem) == 0 .and. shape%kind == shape_extruded_polygon .and. &
             .not. (shape%z_range(2) > shape%z_range(1))) problem = 'z_range: the second value must be > the first'
      end select
   end function shape_problem

   !> A polygon must enclose an area and not cross itself: at least 3 vertices, no two edges meeting
   !> except neighbours at their shared vertex, and a non-zero area.
   pure function polygon_problem(vertices) result(problem)
      real(rp), intent(in) :: vertices(:, :)
      character(len=:), allocatable :: problem
      integer :: n, i, j
      character(len=12) :: a, b
      problem = ''
      n = size(vertices, 2)
      if (n < 3) then
         problem = 'vertices: a polygon needs at least 3 vertices (x1, y1, x2, y2, x3, y3, ...); it is closed '// &
                   'from the last vertex back to the first'
         return
      end if
      do i = 1, n
         do j = i + 1, n
            if (j == i + 1 .or. (i == 1 .and. j == n)) then
               ! neighbours share a vertex; they must not fold back onto each other
               if (neighbours_overlap(vertices, i, j)) then
                  write (a, '(i0)') i
                  write (b, '(i0)') j
                  problem = 'vertices: edges '//trim(a)//' and '//trim(b)//' of the polygon fold back onto each other'
                  return
               end if
               cycle
            end if
            if (segments_meet(vertices(:, i), vertices(:, modulo(i, n) + 1), vertices(:, j), vertices(:, modulo(j, n) + 1))) then
               write (a, '(i0)') i
               write (b, '(i0)') j
               problem = 'vertices: the polygon crosses itself (edge '//trim(a)//' meets edge '//trim(b)// &
                         '; edge k runs from vertex k to the next)'
               return
            end if
         end do
      end do
      if (.not. (abs(polygon_area(vertices)) > 0.0_rp)) problem = 'vertices: the polygon encloses no area'
   end function polygon_problem

   !> Edges i and j (neighbours) lie on one line and overlap beyond their shared vertex, or one has no length.
   pure logical function neighbours_overlap(vertices, i, j) result(overlap)
      real(rp), intent(in) :: vertices(:, :)
      integer, intent(in) :: i, j
      real(rp) :: u(2), w(2)
      integer :: n, first, shared, last
      n = size(vertices, 2)
      ! first -> shared -> last along the polygon
      if (j == i + 1) then
         first = i
         shared = j
      else
         first = n
         shared = 1
      end if
      last = modulo(shared, n) + 1
      u = vertices(:, first) - vertices(:, shared)
      w = vertices(:, last) - vertices(:, shared)
      overlap = maxval(abs(u)) <= 0.0_rp .or. maxval(abs(w)) <= 0.0_rp
      if (overlap) return
      overlap = abs(u(1) * w(2) - u(2) * w(1)) <= 1.0e-12_rp * norm2(u) * norm2(w) .and. dot_product(u, w) > 0.0_rp
   end function neighbours_overlap

   !> The closed segments a-b and c-d share a point.
   pure logical function segments_meet(a, b, c, d) result(meet)
      real(rp), intent(in) :: a(2), b(2), c(2), d(2)
      real(rp) :: d1, d2, d3, d4
      d1 = cross(c, d, a)
      d2 = cross(c, d, b)
      d3 = cross(a, b, c)
      d4 = cross(a, b, d)
      if (((d1 > 0.0_rp .and. d2 < 0.0_rp) .or. (d1 < 0.0_rp .and. d2 > 0.0_rp)) .and. &
          ((d3 > 0.0_rp .and. d4 < 0.0_rp) .or. (d3 < 0.0_rp .and. d4 > 0.0_rp))) then
         meet = .true.
         return
      end if
      meet = (abs(d1) <= 0.0_rp .and. on_segment(c, d, a)) .or. (abs(d2) <= 0.0_rp .and. on_segment(c, d, b)) .or. &
             (abs(d3) <= 0.0_rp .and. on_segment(a, b, c)) .or. (abs(d4) <= 0.0_rp .and. on_segment(a, b, d))
   end function segments_meet

   !> (q - p) x (r - p): which side of the line p-q the point r lies on.
   pure real(rp) function cross(p, q, r)
      real(rp), intent(in) :: p(2), q(2), r(2)
      cross = (q(1) - p(1)) * (r(2) - p(2)) - (q(2) - p(2)) * (r(1) - p(1))
   end function cross

   !> r, known to lie on the line p-q, lies within the segment.
   pure logical function on_segment(p, q, r)
      real(rp), intent(in) :: p(2), q(2), r(2)
      on_segment = r(1) >= min(p(1), q(1)) .and. r(1) <= max(p(1), q(1)) .and. &
                   r(2) >= min(p(2), q(2)) .and. r(2) <= max(p(2), q(2))
   end function on_segment
end module shape_geometry
