!> A structure (`&structure`): the surface of a shape_t (shape_geometry) as a constraint; phi is the shape's
!> exact signed distance and n = grad phi, evaluated once per node when the node list is built. Unlike a
!> wall's, its safeguard acts at any depth: a structure is solid. A moving structure's shape is translated.
module structure_surface
   use kinds, only: rp
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use shape_geometry, only: shape_t, shape_distance, shape_normal, shape_bounds, translated_shape, shape_box
   use surface_condition, only: surface_condition_t, friction_node
   use constraint, only: constraint_t, safeguard_pass_t, add_impulse, constraint_depth, on_surface_tolerance
   implicit none
   private

   !> Step of the central differences of a shape's normal, in cells: far below the curvature of any
   !> resolved surface, far above the round-off of the distance (1e-16 m / 1e-4 h).
   real(rp), parameter :: normal_step_in_cells = 1.0e-4_rp

   type, extends(constraint_t), public :: structure_surface_t
      type(shape_t) :: shape               !< the obstacle, world frame
      type(shape_t) :: rest_shape          !< a moving one: its shape in the scene
      !> grid-frame bounding box of the shape (the safeguard's quick rejection)
      real(rp) :: box_lower(3) = -huge(1.0_rp), box_upper(3) = huge(1.0_rp)
   contains
      procedure :: distance => shape_surface_distance
      procedure :: behind => behind_surface
      procedure :: find_nodes => find_surface_nodes
      procedure :: put => put_shape
      procedure :: keep_out => keep_outside_structure
      procedure :: narrow_own_interval => box_face_interval
   end type structure_surface_t

   public :: make_structure_surface

contains

   !> The surface of the world-frame `shape` with condition `condition`, its impulse to loads.csv entry
   !> `load` with the moment about the world point `moment_point`, and the local nodes it constrains with
   !> the shape's outward normal at each (in the grid frame).
   function make_structure_surface(grid, shape, condition, load, moment_point) result(structure)
      type(grid_t), intent(in) :: grid
      type(shape_t), intent(in) :: shape
      class(surface_condition_t), intent(in) :: condition
      integer, intent(in) :: load
      real(rp), intent(in) :: moment_point(3)
      type(structure_surface_t) :: structure
      integer :: dim
      dim = grid%dim
      call structure%set_condition(condition)
      structure%shape = shape
      structure%load = load
      structure%depth = constraint_depth(grid)
      structure%moment_point = 0.0_rp
      structure%moment_point(1:dim) = grid%frame%grid_point(moment_point(1:dim))
      call set_box(structure, grid)
      call structure%find_nodes(grid)
   end function make_structure_surface

   !> phi: the shape's signed distance; the normal grad phi by central differences.
   real(rp) function shape_surface_distance(self, grid, x, normal) result(distance)
      class(structure_surface_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      real(rp), intent(out), optional :: normal(:)
      distance = shape_distance(self%shape, grid%frame%world_point(x))
      if (present(normal)) &
         normal = grid%frame%grid_vector(shape_normal(self%shape, grid%frame%world_point(x), normal_step_in_cells * grid%h))
   end function shape_surface_distance

   !> On the surface or inside (within `tolerance` outside), not deeper than depth + widen.
   logical function behind_surface(self, grid, x, tolerance, widen) result(behind)
      class(structure_surface_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:), tolerance
      real(rp), intent(in), optional :: widen
      real(rp) :: distance, extra
      extra = 0.0_rp
      if (present(widen)) extra = widen
      distance = shape_surface_distance(self, grid, x)
      behind = distance <= tolerance .and. distance >= -(self%depth + extra)
   end function behind_surface

   !> The shape translated by d from its place in the scene, and its box.
   subroutine put_shape(self, grid, d)
      class(structure_surface_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: d(3)
      self%shape = translated_shape(self%rest_shape, d, grid%dim)
      call set_box(self, grid)
   end subroutine put_shape

   !> The grid-frame box (box_lower, box_upper): that of the corners of its shape's world box.
   subroutine set_box(self, grid)
      type(structure_surface_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer :: dim, k, corner
      real(rp) :: x(3), world(3), lower(3), upper(3)
      dim = grid%dim
      call shape_bounds(self%shape, dim, lower, upper)
      self%box_lower = huge(1.0_rp)
      self%box_upper = -huge(1.0_rp)
      x = 0.0_rp
      world = 0.0_rp
      do corner = 0, 2**dim - 1
         do k = 1, dim
            world(k) = merge(upper(k), lower(k), btest(corner, k - 1))
         end do
         x(1:dim) = grid%frame%grid_point(world(1:dim))
         self%box_lower(1:dim) = min(self%box_lower(1:dim), x(1:dim))
         self%box_upper(1:dim) = max(self%box_upper(1:dim), x(1:dim))
      end do
   end subroutine set_box

   !> The local nodes it constrains (-depth <= phi <= tolerance), with the shape's outward normal at each
   !> (grid frame), its loads' bookkeeping and its taps: only the nodes of its box widened by depth + h.
   subroutine find_surface_nodes(self, grid)
      class(structure_surface_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer :: dim, lo(3), hi(3)
      real(rp) :: reach

      dim = grid%dim
      reach = self%depth + grid%h
      lo = grid%node_lo
      hi = grid%node_hi
      ! the index range of the widened box (scan_nodes decides; this only bounds the scan)
      lo(1:dim) = max(lo(1:dim), floor((self%box_lower(1:dim) - reach - grid%origin(1:dim)) / grid%h) - 1)
      hi(1:dim) = min(hi(1:dim), ceiling((self%box_upper(1:dim) + reach - grid%origin(1:dim)) / grid%h) + 1)
      call self%scan_nodes(grid, lo, hi, .true.)
   end subroutine find_surface_nodes

   !> The safeguard of a structure: a particle with phi < 0 moves to its foot point x - phi n on the
   !> surface (n = grad phi at x) and loses its velocity into the structure as the condition says; of a
   !> moving structure, of its velocity relative to v_w. The pass is skipped when no particle can be in the
   !> structure's box (the particles' bounds).
   !> A particle put on a curved surface lands at phi = 0 only to round-off; counting it inside only below
   !> -on_surface_tolerance h keeps the next step's decision (and its change of velocity) from depending on
   !> that round-off, which differs with the number of ranks. With body fields (pass%field), a particle of
   !> body field f > 0 meets Coulomb friction pass%field_friction(f) if that is >= 0, and its impulse is also
   !> added to pass%field_impulse(:, f).
   subroutine keep_outside_structure(self, grid, particles, pass)
      class(structure_surface_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      type(safeguard_pass_t), intent(inout) :: pass
      integer :: p, d, f
      real(rp) :: world(particles%dim), phi, n(particles%dim), before(particles%dim), step, tolerance
      real(rp) :: dp(particles%dim), relative(particles%dim), vw(particles%dim)
      logical :: coulomb
      d = particles%dim
      if (any(pass%highest(1:d) < self%box_lower(1:d)) .or. any(pass%lowest(1:d) > self%box_upper(1:d))) return
      step = normal_step_in_cells * grid%h
      tolerance = on_surface_tolerance * grid%h
      vw = self%wall_velocity(1:d)
      associate (skip => pass%skip, corrections => pass%corrections)
         do p = 1, particles%count
            if (any(particles%x(:, p) < self%box_lower(1:d)) .or. any(particles%x(:, p) > self%box_upper(1:d))) cycle
            world = grid%frame%world_point(particles%x(:, p))
            phi = shape_distance(self%shape, world)
            if (phi >= -tolerance) cycle
            if (skip(particles%material(p))) cycle
            n = grid%frame%grid_vector(shape_normal(self%shape, world, step))
            particles%x(:, p) = particles%x(:, p) - phi * n
            ! a moving structure: the velocity relative to its own (a fixed one keeps its arithmetic)
            before = particles%v(:, p)
            relative = before
            if (self%moving) relative = before - vw
            if (dot_product(relative, n) < 0.0_rp) then
               f = 0
               if (associated(pass%field)) f = pass%field(p)
               coulomb = .false.
               if (f > 0) coulomb = pass%field_friction(f) >= 0.0_rp
               if (coulomb) then
                  particles%v(:, p) = friction_node(pass%field_friction(f), before, vw, n, self%moving)
               else
                  particles%v(:, p) = self%condition%particle_velocity(before, vw, n, self%moving)
               end if
               dp = particles%mass(p) * (particles%v(:, p) - before)
               call self%record_particle_impulse(grid, pass, dp, particles%x(:, p))
               if (f > 0) call add_impulse(pass%field_impulse(:, f), dp, particles%x(:, p) - self%moment_point(1:d))
            end if
            corrections = corrections + 1
         end do
      end associate
   end subroutine keep_outside_structure

   !> A sensor on a face of a box whose faces are grid planes (not turned, on a grid that is not turned): the
   !> face, and the part of the surface it can wet along grid axis `along`, ends at the box's edges.
   subroutine box_face_interval(self, grid, along, point, wet_lo, wet_hi)
      class(structure_surface_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: along
      real(rp), intent(in) :: point(:)
      real(rp), intent(inout) :: wet_lo, wet_hi
      real(rp) :: lo(3), hi(3)
      if (self%shape%kind /= shape_box .or. grid%frame%rotated .or. abs(self%shape%rotation) > 0.0_rp) return
      call shape_bounds(self%shape, grid%dim, lo, hi)
      wet_lo = max(wet_lo, lo(along))
      wet_hi = min(wet_hi, hi(along))
   end subroutine box_face_interval
end module structure_surface
