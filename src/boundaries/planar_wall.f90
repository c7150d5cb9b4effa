!> A planar wall (`&wall`, a `&box_walls` side, an inlet's feeder and closing walls): the part of a plane
!> (point x_w, normal n_w) inside a world-frame box, its extent; phi(x) = n_w . (x - x_w), one normal for
!> all its nodes (constraint). Its nodes are those with -depth <= phi <= 0 whose foot point x - phi n_w
!> lies in the extent widened by `margin` (h for walls, the cells cut by the wall's ends). On an aligned
!> grid these are exactly the nodes on the wall's grid line.
module planar_wall
   use kinds, only: rp
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use surface_condition, only: surface_condition_t
   use constraint, only: constraint_t, safeguard_pass_t, constraint_depth
   implicit none
   private

   type, extends(constraint_t), public :: planar_wall_t
      real(rp) :: normal(3) = 0.0_rp       !< unit normal pointing into the fluid (grid frame)
      real(rp) :: point(3) = 0.0_rp        !< a point on the wall (grid frame)
      real(rp) :: lower(3) = -huge(1.0_rp) !< extent: world-frame bounding box of the wall
      real(rp) :: upper(3) = huge(1.0_rp)
      real(rp) :: margin = 0.0_rp          !< tolerance of the extent test [m]
      integer :: axis = 0                  !< k if the grid-frame normal is +-e_k, else 0
      !> a moving wall: its point and extent in the scene (world frame)
      real(rp) :: rest_point(3) = 0.0_rp, rest_lower(3) = 0.0_rp, rest_upper(3) = 0.0_rp
   contains
      procedure :: distance => plane_distance
      procedure :: behind => behind_plane
      procedure :: find_nodes => find_plane_nodes
      procedure :: put => put_plane
      procedure :: keep_out => keep_behind_plane
      procedure :: clearly_in_front => plane_clearly_in_front
      procedure :: may_cut_support => plane_may_cut_support
      procedure :: narrow_wet_interval => plane_narrows_interval
      procedure :: narrow_along_line => plane_narrows_line
      procedure :: in_extent
   end type planar_wall_t

   public :: make_planar_wall

contains

   !> A wall of condition `condition` through the world point `point` with the world unit normal `normal`,
   !> its extent lower..upper (world) widened by `margin`, and the local nodes it constrains. Its impulse goes
   !> to entry `load` of loads.csv, its moment about the world point `moment_point` (default `point`).
   function make_planar_wall(grid, point, normal, lower, upper, margin, condition, active_from, active_until, load, &
                             moment_point) result(wall)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: point(3), normal(3), lower(3), upper(3), margin
      class(surface_condition_t), intent(in) :: condition
      real(rp), intent(in), optional :: active_from, active_until
      integer, intent(in), optional :: load
      real(rp), intent(in), optional :: moment_point(3)
      type(planar_wall_t) :: wall
      integer :: dim

      dim = grid%dim
      call wall%set_condition(condition)
      wall%point = 0.0_rp
      wall%normal = 0.0_rp
      wall%point(1:dim) = grid%frame%grid_point(point(1:dim))
      wall%normal(1:dim) = grid%frame%grid_vector(normal(1:dim) / norm2(normal(1:dim)))
      wall%normals = reshape(wall%normal(1:dim), [dim, 1])
      wall%lower = lower
      wall%upper = upper
      wall%margin = margin
      wall%depth = constraint_depth(grid)
      if (present(active_from)) wall%active_from = active_from
      if (present(active_until)) wall%active_until = active_until
      if (present(load)) wall%load = load
      wall%moment_point = wall%point
      if (present(moment_point)) then
         if (all(abs(moment_point(1:dim)) < huge(1.0_rp))) wall%moment_point(1:dim) = grid%frame%grid_point(moment_point(1:dim))
      end if
      ! the axis fast path of the safeguard needs a normal with exactly one non-zero component
      if (count(abs(wall%normal(1:dim)) > 0.0_rp) == 1) wall%axis = maxloc(abs(wall%normal(1:dim)), 1)
      call wall%find_nodes(grid)
   end function make_planar_wall

   !> phi(x) = n_w . (x - x_w); the normal is n_w everywhere.
   real(rp) function plane_distance(self, grid, x, normal) result(distance)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      real(rp), intent(out), optional :: normal(:)
      distance = dot_product(self%normal(1:size(x)), x - self%point(1:size(x)))
      if (present(normal)) normal = self%normal(1:size(x))
   end function plane_distance

   !> True if the grid-frame point x lies on the wall or behind it (within `tolerance` in front), not
   !> farther behind than its depth, with its foot point inside its extent. `widen` [m] deepens the depth
   !> and widens the extent (whether a ball of that radius about x may touch the wall's zone).
   logical function behind_plane(self, grid, x, tolerance, widen) result(behind)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:), tolerance
      real(rp), intent(in), optional :: widen
      real(rp) :: distance, extra
      integer :: d
      d = size(x)
      extra = 0.0_rp
      if (present(widen)) extra = widen
      distance = plane_distance(self, grid, x)
      behind = distance <= tolerance .and. distance >= -(self%depth + extra)
      if (.not. behind) return
      behind = foot_in_extent(self, grid%frame%world_point(x - distance * self%normal(1:d)), self%margin + extra)
   end function behind_plane

   !> True if the foot of the grid-frame point x on the wall lies in its extent.
   logical function in_extent(self, grid, x)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      real(rp) :: foot(size(x))
      foot = grid%frame%world_point(x - plane_distance(self, grid, x) * self%normal(1:size(x)))
      in_extent = foot_in_extent(self, foot, self%margin)
   end function in_extent

   !> The world-frame foot point lies in the wall's extent widened by `margin` [m] on every side.
   pure logical function foot_in_extent(self, foot, margin) result(inside)
      class(planar_wall_t), intent(in) :: self
      real(rp), intent(in) :: foot(:), margin
      integer :: d
      d = size(foot)
      inside = all(foot >= self%lower(1:d) - margin) .and. all(foot <= self%upper(1:d) + margin)
   end function foot_in_extent

   !> Every point within `reach` of x is in front of the plane.
   logical function plane_clearly_in_front(self, grid, x, reach) result(clear)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:), reach
      clear = dot_product(self%normal(1:size(x)), x - self%point(1:size(x))) > reach
   end function plane_clearly_in_front

   !> The node x lies at most `ahead` in front of the plane and at most depth + extra (+ margin) behind it.
   logical function plane_may_cut_support(self, x, ahead, extra, margin) result(may)
      class(planar_wall_t), intent(in) :: self
      real(rp), intent(in) :: x(:), ahead, extra, margin
      real(rp) :: distance
      distance = dot_product(self%normal(1:size(x)), x - self%point(1:size(x)))
      may = distance <= ahead .and. distance >= -(self%depth + extra) - margin
   end function plane_may_cut_support

   !> A wall across grid axis `along`, with the sensor's point on its fluid side and in its extent, bounds
   !> the interval that can be wetted along that axis.
   subroutine plane_narrows_interval(self, grid, along, point, wet_lo, wet_hi)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: along
      real(rp), intent(in) :: point(:)
      real(rp), intent(inout) :: wet_lo, wet_hi
      if (self%axis /= along) return
      if (plane_distance(self, grid, point) < -1.0e-9_rp * grid%h) return
      if (.not. self%in_extent(grid, point)) return
      if (self%normal(along) > 0.0_rp) then
         wet_lo = max(wet_lo, self%point(along))
      else
         wet_hi = min(wet_hi, self%point(along))
      end if
   end subroutine plane_narrows_interval

   !> The line point + s tangent (grid frame) crosses the wall at s* inside its extent: the wettable part of
   !> it is s >= s* where the tangent points into the material (t . n > 0), else s <= s*. A line along the
   !> wall (|t . n| < 1e-6) is not narrowed.
   subroutine plane_narrows_line(self, grid, point, tangent, lo, hi)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: point(:), tangent(:)
      real(rp), intent(inout) :: lo, hi
      real(rp) :: along, crossing
      integer :: d
      d = size(point)
      along = dot_product(tangent(1:d), self%normal(1:d))
      if (abs(along) < 1.0e-6_rp) return
      crossing = dot_product(self%point(1:d) - point(1:d), self%normal(1:d)) / along
      if (.not. self%in_extent(grid, point(1:d) + crossing * tangent(1:d))) return
      if (along > 0.0_rp) then
         lo = max(lo, crossing)
      else
         hi = min(hi, crossing)
      end if
   end subroutine plane_narrows_line

   !> Put the wall at displacement d from its place in the scene (point and extent); an unbounded side stays
   !> unbounded (huge + d rounds to huge).
   subroutine put_plane(self, grid, d)
      class(planar_wall_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: d(3)
      integer :: dim
      dim = grid%dim
      self%point(1:dim) = grid%frame%grid_point(self%rest_point(1:dim) + d(1:dim))
      self%lower(1:dim) = self%rest_lower(1:dim) + d(1:dim)
      self%upper(1:dim) = self%rest_upper(1:dim) + d(1:dim)
   end subroutine put_plane

   !> The nodes of the rank's box the wall constrains, with its loads' bookkeeping and its taps. A moving
   !> wall whose normal is a grid axis scans only the grid lines within its depth (a piston: a few lines of
   !> nodes per step).
   subroutine find_plane_nodes(self, grid)
      class(planar_wall_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer :: lo(3), hi(3), k
      real(rp) :: a, b
      lo = grid%node_lo
      hi = grid%node_hi
      k = self%axis
      if (self%moving .and. k > 0) then
         ! nodes with -depth <= phi <= tolerance lie between these planes (one line more each side)
         a = self%point(k) - self%depth
         b = self%point(k) + self%depth
         lo(k) = max(lo(k), floor((a - grid%origin(k)) / grid%h) - 1)
         hi(k) = min(hi(k), ceiling((b - grid%origin(k)) / grid%h) + 1)
      end if
      call self%scan_nodes(grid, lo, hi, .false.)
   end subroutine find_plane_nodes

   !> The safeguard (algorithms.md section 4.2): a particle behind the wall (inside its extent and depth)
   !> goes back onto it and loses its velocity into it as the condition says; a moving wall's at its place at
   !> the step's end, relative to v_w. The pass is skipped when the particles' bounds say no particle can be
   !> behind a wall normal to a grid axis. Body fields are the structures' business (pass%field unused).
   subroutine keep_behind_plane(self, grid, particles, pass)
      class(planar_wall_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      type(safeguard_pass_t), intent(inout) :: pass
      integer :: p, d
      real(rp) :: distance, vn, dp(particles%dim), before(particles%dim), vw(particles%dim)
      d = particles%dim
      if (self%axis > 0) then
         ! no particle behind it: skip the pass (the usual case; x - x0 is monotonic in x)
         associate (k => self%axis)
            if (self%normal(k) > 0.0_rp .and. pass%lowest(k) - self%point(k) >= 0.0_rp) return
            if (self%normal(k) < 0.0_rp .and. pass%highest(k) - self%point(k) <= 0.0_rp) return
         end associate
         if (.not. self%moving) then
            call keep_behind_axis_plane()
            return
         end if
      end if
      ! any wall; a moving one: a particle behind it gets at least the wall's normal velocity, v - v_w
      ! losing what the condition takes
      vw = self%wall_velocity(1:d)
      associate (n => self%normal(1:d), x0 => self%point(1:d), skip => pass%skip, &
                 corrections => pass%corrections)
         do p = 1, particles%count
            distance = dot_product(particles%x(:, p) - x0, n)
            if (distance >= 0.0_rp) cycle
            if (skip(particles%material(p))) cycle
            if (.not. self%behind(grid, particles%x(:, p), 0.0_rp)) cycle
            particles%x(:, p) = particles%x(:, p) - distance * n
            if (self%moving) then
               before = particles%v(:, p)
               if (dot_product(before - vw, n) < 0.0_rp) then
                  particles%v(:, p) = self%condition%particle_velocity(before, vw, n, .true.)
                  call self%record_particle_impulse(grid, pass, particles%mass(p) * (particles%v(:, p) - before), &
                                                    particles%x(:, p))
               end if
            else
               vn = dot_product(particles%v(:, p), n)
               if (vn < 0.0_rp) then
                  call self%condition%particle_on_plane(particles%v(:, p), n, vn, particles%mass(p), dp)
                  call self%record_particle_impulse(grid, pass, dp, particles%x(:, p))
               end if
            end if
            corrections = corrections + 1
         end do
      end associate

   contains

      !> A fixed wall normal to grid axis k: the same operation without the dot products.
      subroutine keep_behind_axis_plane()
         integer :: k
         real(rp) :: sense, x0
         k = self%axis
         sense = self%normal(k)
         x0 = self%point(k)
         associate (skip => pass%skip, corrections => pass%corrections)
            do p = 1, particles%count
               if (sense * (particles%x(k, p) - x0) >= 0.0_rp) cycle
               if (skip(particles%material(p))) cycle
               if (.not. self%behind(grid, particles%x(:, p), 0.0_rp)) cycle
               particles%x(k, p) = x0
               if (sense * particles%v(k, p) < 0.0_rp) then
                  call self%condition%particle_on_plane(particles%v(:, p), self%normal(1:d), sense * particles%v(k, p), &
                                                        particles%mass(p), dp, axis=k)
                  call self%record_particle_impulse(grid, pass, dp, particles%x(:, p))
               end if
               corrections = corrections + 1
            end do
         end associate
      end subroutine keep_behind_axis_plane
   end subroutine keep_behind_plane
end module planar_wall
