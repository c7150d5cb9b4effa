!> Sensors on the boundary constraints: wall-pressure gauges, panels and load cells, read from the impulse
!> the constraints give the material (docs/loads.md, "Wall pressure" and "Panels and load cells";
!> docs/theory.md section 3.2).
!>
!> The constraint changes the momentum of each wall node i by dp_i in a step; for a pressure p on the
!> surface that is the consistent nodal load dp_i . n = dt * integral of p N_i over the wetted surface.
!> A gauge or a panel is a patch of the surface about its point x_s (2-D: a segment; 3-D: a rectangle in
!> the tangent plane of the unit normal n_s into the fluid): for a gauge a square of half-width r, for a
!> panel the box lower .. upper of the scene seen along each tangent. Each node whose foot point (the node
!> moved onto the surface along its normal) lies in the patch's plane with a normal close to n_s is a tap
!> with the weight
!>
!>   w_i = prod_k  integral over (patch cut to the wetted interval) of N_i  /  integral over the wetted
!>                 interval of N_i
!>
!> along each tangent axis k, N_i the hat function of width h about the foot point. The patch reads
!> p = sum_i w_i dp_i . n_s / (|patch| dt) and (panels) the force F = -sum_i w_i dp_i / dt: for a uniform
!> pressure exact, whatever the patch's size and place, and for a linear one exact when the patch's edges
!> lie on nodes, because the nodal loads are the hat integrals over the wetted surface and the weights the
!> part of each in the patch; the weights of patches tiling a face add up to 1 at every node, so their
!> loads add up to the face's. The wetted interval is where the surface can carry fluid along a tangent
!> that is a grid axis: the scene box, cut by the planar walls normal to that axis (a floor below a sensor
!> in a corner); on a surface whose tangents are not grid axes (a turned grid, a curved structure) a
!> gauge's is unbounded, a panel's cut by the planar walls its tangent lines cross, and a panel reads the
!> nodes through a wider hat (turned_reach_cells): the weights are approximate there.
!> A load cell is a box of the scene: every constrained node in it (lower <= x < upper, world frame) is a
!> tap of weight 1, so that load cells tiling a region add up to the load on it.
!>
!> A tap adds, to its sensor's column of the impulse accumulator, w dp to rows 1:dim (panels, load cells)
!> and dp . n_s w / |patch| to row pressure_row (gauges, panels).
module surface_sensors
   use kinds, only: rp
   use world_frame, only: frame_t
   implicit none
   private

   !> Normals within this cosine count as the sensor's face (a box's other faces are at 90 degrees).
   real(rp), parameter :: same_face_cosine = 0.7_rp
   !> A panel on a surface whose tangents are not grid axes (a turned grid) reads each node's load through a
   !> hat of this many cells' half-width about its foot point instead of one: the staircase of nodes such a
   !> wall constrains carries loads that vary from node to node, and a one-cell hat split them at a panel's
   !> edge by the foot point's place (a one-cell panel read +41 % on the tank turned by 30 degrees; with 4
   !> cells -0.4 %; docs/loads.md) [R]. A pressure distribution along such a wall is resolved to about that.
   real(rp), parameter :: turned_reach_cells = 4.0_rp
   !> Consistent weights below this are left out: the patches tiling a face then share every node's load
   !> out to 1e-14 of it.
   real(rp), parameter :: negligible_weight = 1.0e-15_rp
   !> The row of a sensor's impulse column that holds p |patch| dt (rows 1:3 hold the force impulse).
   integer, parameter, public :: pressure_row = 4

   !> Sensor kinds.
   integer, parameter, public :: sensor_gauge = 1      !< a wall-pressure gauge: pressure over a square patch
   integer, parameter, public :: sensor_panel = 2      !< a panel: force and pressure over a rectangle
   integer, parameter, public :: sensor_load_cell = 3  !< a load cell: force on the constrained nodes in a box

   !> One sensor on a constraint: what it sees (grid frame unless said).
   type, public :: surface_sensor_t
      integer :: slot = 0                    !< its index among the scene's sensors (its impulse column)
      integer :: kind = sensor_gauge
      real(rp) :: point(3) = 0.0_rp          !< centre of the patch, on the surface
      real(rp) :: normal(3) = 0.0_rp         !< unit normal into the fluid at the point
      real(rp) :: radius = 0.0_rp            !< gauge: half-size of the patch along each tangent [m]
      real(rp) :: lower(3) = 0.0_rp, upper(3) = 0.0_rp   !< panel, load cell: the box, world frame [m]
      !> along tangent k, the patch's interval in the tangent coordinate (patch_weight) [m]
      real(rp) :: patch_lo(2) = 0.0_rp, patch_hi(2) = 0.0_rp
      !> along grid axis k (a tangent), the interval of the surface that can be wetted
      real(rp) :: wet_lo(3) = -huge(1.0_rp), wet_hi(3) = huge(1.0_rp)
      !> a panel on a surface whose tangents are not grid axes: along tangent k, the wettable interval of the
      !> tangent coordinate (the planar walls its line crosses)
      real(rp) :: tangent_lo(2) = -huge(1.0_rp), tangent_hi(2) = huge(1.0_rp)
      !> a panel on a face whose tangents are grid axes: the consistent weights c_k(j) of the nodes along
      !> each tangent k (consistent_weights), the first of which lies at first_node(k)
      logical :: consistent = .false.
      real(rp) :: first_node(2) = 0.0_rp
      integer :: nodes_along(2) = 0
      real(rp), allocatable :: along_weight(:, :)   !< (node, k)
   contains
      procedure :: set_patch
      procedure :: reads_force
      procedure :: along_value
   end type surface_sensor_t

   !> The consistent weights of a panel along one tangent (set_patch).
   type :: weight_column_t
      real(rp), allocatable :: weights(:)
   end type weight_column_t

   !> The sensors of one constraint and their taps on its current node list.
   type, public :: sensor_taps_t
      type(surface_sensor_t), allocatable :: sensors(:)
      integer, allocatable :: first(:)          !< taps of the wall's node i: first(i) .. first(i + 1) - 1
      integer, allocatable :: slot(:)           !< the sensor slot of tap t
      real(rp), allocatable :: weight(:)        !< w_i of tap t for the force rows (0: a gauge's tap)
      real(rp), allocatable :: vector(:, :)     !< (dim, t): w_i n_s / |patch|, so that dp_i . vector = p dt
      logical :: force_sensors = .false.        !< some sensor reads force (the safeguard's part counts)
   contains
      procedure :: place => taps_place
      procedure :: any => taps_any
      procedure :: add_point_impulse
   end type sensor_taps_t

   public :: tangent_axes, patch_weight, add_tap_impulse

contains

   pure logical function taps_any(self)
      class(sensor_taps_t), intent(in) :: self
      taps_any = .false.
      if (allocated(self%sensors)) taps_any = size(self%sensors) > 0
   end function taps_any

   !> A panel or load cell: force rows; a gauge reads pressure only.
   elemental logical function reads_force(self)
      class(surface_sensor_t), intent(in) :: self
      reads_force = self%kind /= sensor_gauge
   end function reads_force

   !> The patch along each tangent, once point, normal and wetted intervals are set (grid frame) and the
   !> grid's frame is `frame`: a gauge's square c -+ r, a panel's box seen along each tangent (the range of
   !> its corners' coordinates); a panel whose tangents are grid axes also gets its consistent weights on
   !> the nodes origin + j h (`origin`, `h`: the grid's, optional). Load cells have none.
   pure subroutine set_patch(self, dim, frame, origin, h)
      class(surface_sensor_t), intent(inout) :: self
      integer, intent(in) :: dim
      type(frame_t), intent(in) :: frame
      real(rp), intent(in), optional :: origin(:), h
      real(rp) :: tangents(dim, dim - 1), corner(dim), s, c
      type(weight_column_t) :: columns(2)
      logical :: axes
      integer :: k, along, m, j
      if (self%kind == sensor_load_cell) return
      call tangent_axes(self%normal(1:dim), dim, tangents, axes)
      do k = 1, dim - 1
         along = maxloc(abs(tangents(:, k)), 1)
         c = 0.0_rp
         if (axes) c = self%point(along)
         if (self%kind == sensor_gauge) then
            self%patch_lo(k) = c - self%radius
            self%patch_hi(k) = c + self%radius
            cycle
         end if
         self%patch_lo(k) = huge(1.0_rp)
         self%patch_hi(k) = -huge(1.0_rp)
         do m = 0, 2**dim - 1
            do j = 1, dim
               corner(j) = merge(self%upper(j), self%lower(j), btest(m, j - 1))
            end do
            corner = frame%grid_point(corner)
            if (axes) then
               s = corner(along)
            else
               s = dot_product(corner - self%point(1:dim), tangents(:, k))
            end if
            self%patch_lo(k) = min(self%patch_lo(k), s)
            self%patch_hi(k) = max(self%patch_hi(k), s)
         end do
      end do
      if (self%kind /= sensor_panel .or. .not. axes .or. .not. present(origin)) return
      self%consistent = .true.
      do k = 1, dim - 1
         along = maxloc(abs(tangents(:, k)), 1)
         call consistent_weights(self%wet_lo(along), self%wet_hi(along), self%patch_lo(k), self%patch_hi(k), &
                                 origin(along), h, self%first_node(k), columns(k)%weights)
         self%nodes_along(k) = size(columns(k)%weights)
      end do
      if (allocated(self%along_weight)) deallocate (self%along_weight)
      allocate (self%along_weight(maxval(self%nodes_along(1:dim - 1)), 2))
      self%along_weight = 0.0_rp
      do k = 1, dim - 1
         self%along_weight(1:self%nodes_along(k), k) = columns(k)%weights
      end do
   end subroutine set_patch

   !> Along one tangent, the wetted interval lo .. hi, the panel's patch_lo .. patch_hi and the nodes
   !> origin + j h whose hats N_j reach into the wetted interval (the first at `first`): the weights
   !> c = M^-1 b, M_ij = integral over lo .. hi of N_i N_j, b_i = integral over the patch (cut to lo .. hi)
   !> of N_i. For nodal loads f_i = integral of p N_i over the surface, sum c_i f_i is the integral over the
   !> patch of the L2 projection of p onto the hats: exact for any p linear along the face (the lumped
   !> weights of patch_weight are exact for a uniform one, and for a linear one only away from the face's
   !> ends). Patches tiling lo .. hi have weights summing to M^-1 M 1 = 1 at every node [R].
   pure subroutine consistent_weights(lo, hi, patch_lo, patch_hi, origin, h, first, weights)
      real(rp), intent(in) :: lo, hi, patch_lo, patch_hi, origin, h
      real(rp), intent(out) :: first
      real(rp), allocatable, intent(out) :: weights(:)
      real(rp), allocatable :: x(:), diagonal(:), upper(:), lower(:), breaks(:)
      real(rp) :: a, b, m, f(3, 2)
      integer :: j_lo, j_hi, n, i, q, left
      ! every node whose hat overlaps lo .. hi by more than round-off
      j_lo = floor((lo - origin) / h) - 1
      j_hi = ceiling((hi - origin) / h) + 1
      x = [(origin + i * h, i = j_lo, j_hi)]
      x = pack(x, min(hi, x + h) - max(lo, x - h) > 1.0e-9_rp * h)
      n = size(x)
      first = x(1)
      allocate (diagonal(n), upper(n), lower(n), weights(n))
      diagonal = 0.0_rp
      upper = 0.0_rp
      ! M by Simpson's rule between consecutive break points (the nodes inside lo .. hi and its ends): a
      ! product of two hats is quadratic there, so the rule is exact
      breaks = [lo, pack(x, x > lo .and. x < hi), hi]
      do q = 1, size(breaks) - 1
         a = breaks(q)
         b = breaks(q + 1)
         m = 0.5_rp * (a + b)
         left = max(1, min(n - 1, count(x <= m)))
         do i = 1, 2
            f(:, i) = [hat(a, x(left + i - 1), h), hat(m, x(left + i - 1), h), hat(b, x(left + i - 1), h)]
         end do
         if (n == 1) then
            diagonal(1) = diagonal(1) + simpson(f(:, 1), f(:, 1), b - a)
            cycle
         end if
         diagonal(left) = diagonal(left) + simpson(f(:, 1), f(:, 1), b - a)
         diagonal(left + 1) = diagonal(left + 1) + simpson(f(:, 2), f(:, 2), b - a)
         upper(left) = upper(left) + simpson(f(:, 1), f(:, 2), b - a)
      end do
      do i = 1, n
         weights(i) = hat_integral(max(patch_lo, lo), min(patch_hi, hi), x(i), h)
         if (min(patch_hi, hi) <= max(patch_lo, lo)) weights(i) = 0.0_rp
      end do
      ! M c = b, tridiagonal and symmetric positive definite: elimination without pivoting (Thomas)
      lower = eoshift(upper, -1)
      do i = 2, n
         m = lower(i) / diagonal(i - 1)
         diagonal(i) = diagonal(i) - m * upper(i - 1)
         weights(i) = weights(i) - m * weights(i - 1)
      end do
      weights(n) = weights(n) / diagonal(n)
      do i = n - 1, 1, -1
         weights(i) = (weights(i) - upper(i) * weights(i + 1)) / diagonal(i)
      end do
   end subroutine consistent_weights

   !> The consistent weight of a point at tangent coordinate s along tangent k: sum_j c_k(j) N_j(s) (at a
   !> node, its own c_k).
   pure real(rp) function along_value(self, k, s, h) result(value)
      class(surface_sensor_t), intent(in) :: self
      integer, intent(in) :: k
      real(rp), intent(in) :: s, h
      real(rp) :: u, t
      integer :: j
      u = (s - self%first_node(k)) / h
      j = floor(u)
      t = u - j
      value = 0.0_rp
      if (j >= 0 .and. j < self%nodes_along(k)) value = value + (1.0_rp - t) * self%along_weight(j + 1, k)
      if (j + 1 >= 0 .and. j + 1 < self%nodes_along(k)) value = value + t * self%along_weight(j + 2, k)
   end function along_value

   !> integral over a width w of the product of two linear functions given at its start, middle and end
   pure real(rp) function simpson(f, g, w)
      real(rp), intent(in) :: f(3), g(3), w
      simpson = w / 6.0_rp * (f(1) * g(1) + 4.0_rp * f(2) * g(2) + f(3) * g(3))
   end function simpson

   !> The hat of half-width h about x_j at s.
   pure real(rp) function hat(s, x_j, h)
      real(rp), intent(in) :: s, x_j, h
      hat = max(0.0_rp, 1.0_rp - abs(s - x_j) / h)
   end function hat

   !> The taps of the wall's nodes at `points` (dim, node; grid frame), whose foot points `feet` and unit
   !> normals `normals` are given (grid frame), h the cell size, `frame` the grid's.
   pure subroutine taps_place(self, dim, h, points, feet, normals, frame)
      class(sensor_taps_t), intent(inout) :: self
      integer, intent(in) :: dim
      real(rp), intent(in) :: h, points(:, :), feet(:, :), normals(:, :)
      type(frame_t), intent(in) :: frame
      integer :: i, s, n, count
      real(rp) :: weight, area
      integer, allocatable :: slot(:)
      real(rp), allocatable :: vector(:, :), weights(:)
      if (.not. self%any()) return
      self%force_sensors = any(self%sensors%reads_force())
      n = size(feet, 2)
      allocate (slot(n * size(self%sensors)), vector(dim, n * size(self%sensors)), weights(n * size(self%sensors)))
      if (allocated(self%first)) deallocate (self%first)
      allocate (self%first(n + 1))
      count = 0
      do i = 1, n
         self%first(i) = count + 1
         do s = 1, size(self%sensors)
            call sensor_weight(self%sensors(s), dim, h, points(1:dim, i), feet(1:dim, i), normals(1:dim, i), frame, &
                               weight, area)
            if (.not. is_tap(self%sensors(s), weight)) cycle
            count = count + 1
            slot(count) = self%sensors(s)%slot
            weights(count) = merge(weight, 0.0_rp, self%sensors(s)%reads_force())
            vector(:, count) = 0.0_rp
            if (self%sensors(s)%kind /= sensor_load_cell) vector(:, count) = weight / area * self%sensors(s)%normal(1:dim)
         end do
      end do
      self%first(n + 1) = count + 1
      self%slot = slot(1:count)
      self%weight = weights(1:count)
      self%vector = vector(:, 1:count)
   end subroutine taps_place

   !> A node of weight w is a tap of the sensor: w > 0 (lumped weights), or |w| above round-off (the
   !> consistent weights of a panel alternate in sign and decay by 2 - sqrt(3) per node away from it).
   pure logical function is_tap(sensor, weight)
      type(surface_sensor_t), intent(in) :: sensor
      real(rp), intent(in) :: weight
      if (sensor%consistent) then
         is_tap = abs(weight) > negligible_weight
      else
         is_tap = weight > 0.0_rp
      end if
   end function is_tap

   !> The weight of a point (a node at `x` whose foot point is `foot` with normal `normal`, grid frame) in
   !> the sensor, and (gauges, panels) the patch's area cut to the wetted intervals (2-D: its length);
   !> weight 0: not a tap.
   pure subroutine sensor_weight(sensor, dim, h, x, foot, normal, frame, weight, area)
      type(surface_sensor_t), intent(in) :: sensor
      integer, intent(in) :: dim
      real(rp), intent(in) :: h, x(dim), foot(dim), normal(dim)
      type(frame_t), intent(in) :: frame
      real(rp), intent(out) :: weight, area
      real(rp) :: world(dim)
      weight = 0.0_rp
      area = 0.0_rp
      if (sensor%kind == sensor_load_cell) then
         world = frame%world_point(x)
         if (all(world >= sensor%lower(1:dim) .and. world < sensor%upper(1:dim))) weight = 1.0_rp
         return
      end if
      if (dot_product(normal, sensor%normal(1:dim)) < same_face_cosine) return
      if (abs(dot_product(foot - sensor%point(1:dim), sensor%normal(1:dim))) > 0.5_rp * h) return
      call patch_weight(sensor, dim, h, foot, weight, area)
      if (area <= 0.0_rp) weight = 0.0_rp
   end subroutine sensor_weight

   !> The weight of a node whose foot point is `foot` in the sensor's patch, and the patch's area (its
   !> length in 2-D), both cut to the wetted intervals.
   pure subroutine patch_weight(sensor, dim, h, foot, weight, area)
      type(surface_sensor_t), intent(in) :: sensor
      integer, intent(in) :: dim
      real(rp), intent(in) :: h, foot(dim)
      real(rp), intent(out) :: weight, area
      real(rp) :: tangents(dim, dim - 1), s, lo, hi, a, b, whole, reach
      logical :: axes
      integer :: k, along
      call tangent_axes(sensor%normal(1:dim), dim, tangents, axes)
      weight = 1.0_rp
      area = 1.0_rp
      do k = 1, dim - 1
         if (axes) then
            along = maxloc(abs(tangents(:, k)), 1)
            s = foot(along)
            lo = sensor%wet_lo(along)
            hi = sensor%wet_hi(along)
         else
            s = dot_product(foot - sensor%point(1:dim), tangents(:, k))
            lo = sensor%tangent_lo(k)
            hi = sensor%tangent_hi(k)
         end if
         ! a panel's node beyond the wetted interval (behind the wall across it: a quadratic B-spline's
         ! second layer) carries load of the face's end, and counts as a node at the end [R]
         if (sensor%kind == sensor_panel) s = min(max(s, lo), hi)
         ! the patch cut to the wetted interval, and the part of it the node's hat covers
         area = area * max(0.0_rp, min(sensor%patch_hi(k), hi) - max(sensor%patch_lo(k), lo))
         if (sensor%consistent) then
            weight = weight * sensor%along_value(k, s, h)
            cycle
         end if
         reach = h
         if (.not. axes .and. sensor%kind == sensor_panel) reach = turned_reach_cells * h
         lo = max(lo, s - reach)
         hi = min(hi, s + reach)
         a = max(sensor%patch_lo(k), lo)
         b = min(sensor%patch_hi(k), hi)
         whole = hat_integral(lo, hi, s, reach)
         if (b <= a .or. whole <= 0.0_rp) then
            weight = 0.0_rp
         else
            weight = weight * hat_integral(a, b, s, reach) / whole
         end if
      end do
   end subroutine patch_weight

   !> impulse(:, slot) of tap t gains its share of the nodal impulse dp (`impulse` holds the sensors'
   !> columns only).
   pure subroutine add_tap_impulse(taps, t, dp, impulse)
      type(sensor_taps_t), intent(in) :: taps
      integer, intent(in) :: t
      real(rp), intent(in) :: dp(:)
      real(rp), intent(inout) :: impulse(:, :)
      integer :: column, d
      column = taps%slot(t)
      d = size(dp)
      if (taps%weight(t) /= 0.0_rp) impulse(1:d, column) = impulse(1:d, column) + taps%weight(t) * dp
      impulse(pressure_row, column) = impulse(pressure_row, column) + dot_product(dp, taps%vector(:, t))
   end subroutine add_tap_impulse

   !> The particle safeguard's impulse dp on a particle put back onto the surface at `x` (grid frame), with
   !> the surface's normal there: the panels' and load cells' columns of `impulse` (the sensors' columns
   !> only) gain its share, as a node's there would. Gauges read the nodal impulse only (docs/loads.md).
   pure subroutine add_point_impulse(self, dim, h, x, normal, frame, dp, impulse)
      class(sensor_taps_t), intent(in) :: self
      integer, intent(in) :: dim
      real(rp), intent(in) :: h, x(dim), normal(dim), dp(dim)
      type(frame_t), intent(in) :: frame
      real(rp), intent(inout) :: impulse(:, :)
      real(rp) :: weight, area
      integer :: s, column
      if (.not. self%force_sensors) return
      do s = 1, size(self%sensors)
         associate (sensor => self%sensors(s))
            if (.not. sensor%reads_force()) cycle
            call sensor_weight(sensor, dim, h, x, x, normal, frame, weight, area)
            if (.not. is_tap(sensor, weight)) cycle
            column = sensor%slot
            impulse(1:dim, column) = impulse(1:dim, column) + weight * dp
            if (sensor%kind == sensor_panel) impulse(pressure_row, column) = impulse(pressure_row, column) + &
                                                                             weight / area * dot_product(dp, sensor%normal(1:dim))
         end associate
      end do
   end subroutine add_point_impulse

   !> dim - 1 unit tangents of the plane normal to n: the other grid axes when n is a grid axis (`axes`),
   !> else the grid axes least aligned with n, made orthonormal against n (Gram-Schmidt).
   pure subroutine tangent_axes(n, dim, tangents, axes)
      real(rp), intent(in) :: n(:)
      integer, intent(in) :: dim
      real(rp), intent(out) :: tangents(dim, dim - 1)
      logical, intent(out) :: axes
      integer :: normal_axis, k, t, j
      real(rp) :: e(dim)
      normal_axis = maxloc(abs(n(1:dim)), 1)
      axes = abs(abs(n(normal_axis)) - 1.0_rp) <= 1.0e-9_rp
      t = 0
      do k = 1, dim
         if (k == normal_axis) cycle
         t = t + 1
         e = 0.0_rp
         e(k) = 1.0_rp
         if (.not. axes) then
            e = e - dot_product(e, n(1:dim)) * n(1:dim)
            do j = 1, t - 1
               e = e - dot_product(e, tangents(:, j)) * tangents(:, j)
            end do
            e = e / norm2(e)
         end if
         tangents(:, t) = e
      end do
   end subroutine tangent_axes

   !> The integral over a .. b of the hat function of half-width h about s, max(0, 1 - |u - s| / h) [m].
   pure real(rp) function hat_integral(a, b, s, h)
      real(rp), intent(in) :: a, b, s, h
      hat_integral = h * (primitive((b - s) / h) - primitive((a - s) / h))
   end function hat_integral

   !> Antiderivative of the unit hat, 0 below -1 and 1 above 1.
   pure real(rp) function primitive(z)
      real(rp), intent(in) :: z
      if (z <= -1.0_rp) then
         primitive = 0.0_rp
      else if (z <= 0.0_rp) then
         primitive = 0.5_rp * (z + 1.0_rp)**2
      else if (z < 1.0_rp) then
         primitive = 1.0_rp - 0.5_rp * (1.0_rp - z)**2
      else
         primitive = 1.0_rp
      end if
   end function primitive
end module surface_sensors
