!> Rigid walls and fixed structures: nodal velocity constraints and the particle safeguard
!> (algorithms.md sections 4.1-4.2, docs/theory.md section 3.4).
!>
!> A constraint surface has a signed distance phi (negative behind it) and a unit normal n pointing
!> into the material. Two kinds share every operation below:
!>  - a planar wall: the part of a plane (point x_w, normal n_w) inside a world-frame box, its extent;
!>    phi(x) = n_w . (x - x_w), one normal for all its nodes;
!>  - a structure (`&structure`, `shaped`): the surface of a shape_t (shape_geometry), phi its exact
!>    signed distance, n = grad phi, evaluated once per node when the node list is built.
!> The nodes it constrains are found once per layout, by signed distance [R]: nodes with
!> -depth <= phi <= 0 (on the surface or behind it, within two cells); for a planar wall also with the
!> foot point x - phi n_w in the extent widened by `margin` (h for walls, the cells cut by the wall's
!> ends). On an aligned grid these are exactly the nodes on the wall's grid line.
!>   slip       [Y17] eq. 14, unilateral and frictionless: v := v - (v.n) n only where v.n < 0
!>   friction   unilateral with Coulomb friction mu where v.n < 0: the normal part removed, the tangential
!>              part shortened by mu |v.n| and never reversed (unilateral_velocity) [R]
!>   no_slip    v := 0
!>   prescribed v := v_0 (the feeder of an inlet, algorithms.md section 4.3)
!> A wall may be active for a time window only (an inlet's opening and its closing wall).
!> A `&wall` or a `&structure` may move (wall_motion, docs/theory.md section 3.6): each step it is placed
!> where its motion puts it at the step's start (a structure's shape translated), its node list is
!> rebuilt there, and the constraints act on the velocity relative to its mean velocity v_w over the
!> step; the safeguard uses its place at the step's end.
!>
!> Loads (docs/theory.md section 3.2, algorithms.md section 9.1): the constraint's change of nodal
!> momentum m_i (v_i^c - v_i^*) and the safeguard's change of particle momentum m_p (v_p^c - v_p) are the
!> impulse the wall gives the material; walls applied in turn each keep the change they made, so the
!> impulses at a corner split between the walls and add up exactly. A node shared with other ranks is
!> counted by one of them only (`counted`).
module boundary_walls
   use kinds, only: rp
   use scene_description, only: wall_spec_t, grid_spec_t, structure_spec_t, wall_no_slip, wall_friction
   use shape_geometry, only: shape_t, shape_distance, shape_normal, shape_bounds, translated_shape
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use wall_motion, only: wall_motion_t, prescribed_motion
   use time_table, only: time_table_t
   use wall_pressure_taps, only: pressure_taps_t, wall_sensor_t, tangent_axes
   use load_entries, only: load_entry_t, entry_of, entry_wall, entry_box_side, entry_structure, box_side_walls
   implicit none
   private

   integer, parameter, public :: wall_kind_slip = 1, wall_kind_no_slip = 2, wall_kind_prescribed = 3, &
                                 wall_kind_friction = 4
   !> Nodes and particles farther behind a wall than this many cells are not its business [R]: a
   !> particle in a cell cut by the wall reaches nodes at most sqrt(dim) h behind it, and a baffle made of
   !> two walls back to back must not constrain the far side.
   real(rp), parameter :: depth_in_cells = 2.0_rp
   !> A node closer to the wall than this fraction of h counts as on it (round-off of node positions).
   real(rp), parameter :: on_wall_tolerance = 1.0e-9_rp
   !> Step of the central differences of a shape's normal, in cells: far below the curvature of any
   !> resolved surface, far above the round-off of the distance (1e-16 m / 1e-4 h).
   real(rp), parameter :: normal_step_in_cells = 1.0e-4_rp

   type, public :: wall_t
      real(rp) :: normal(3) = 0.0_rp       !< unit normal pointing into the fluid (grid frame)
      real(rp) :: point(3) = 0.0_rp        !< a point on the wall (grid frame)
      real(rp) :: lower(3) = -huge(1.0_rp) !< extent: world-frame bounding box of the wall
      real(rp) :: upper(3) = huge(1.0_rp)
      real(rp) :: margin = 0.0_rp          !< tolerance of the extent test [m]
      real(rp) :: depth = 0.0_rp           !< how far behind the wall it acts [m]
      integer :: kind = wall_kind_slip
      real(rp) :: velocity(3) = 0.0_rp     !< prescribed velocity (grid frame)
      real(rp) :: active_from = -huge(1.0_rp), active_until = huge(1.0_rp)
      logical :: active = .true.
      integer :: axis = 0                  !< k if the grid-frame normal is +-e_k, else 0
      integer, allocatable :: nodes(:)     !< local nodes this rank constrains
      integer :: load = 0                  !< the entry of loads.csv this wall's impulse goes to (0: none)
      real(rp) :: moment_point(3) = 0.0_rp !< the point its moment is taken about (grid frame)
      !> the impulse of node nodes(i) counts here: this rank owns the node (no other rank counts it)
      logical, allocatable :: counted(:)
      real(rp), allocatable :: arm(:, :)   !< node position - moment_point (3, i), grid frame [m]
      real(rp) :: friction = 0.0_rp        !< Coulomb coefficient mu of kind friction [-]
      logical :: shaped = .false.          !< a structure: the surface of `shape`, a normal per node
      type(shape_t) :: shape               !< shaped: the obstacle, world frame
      !> shaped: grid-frame bounding box of the shape (the safeguard's quick rejection)
      real(rp) :: box_lower(3) = -huge(1.0_rp), box_upper(3) = huge(1.0_rp)
      real(rp), allocatable :: node_normal(:, :)   !< shaped: unit normal at node nodes(i) (dim, i), grid frame
      !> a moving wall or structure: its motion, its point and extent (a structure: its shape) in the scene
      !> (world frame), its displacement d (world) now and where its node list was built, and its mean
      !> velocity over the current step (grid frame)
      logical :: moving = .false.
      type(wall_motion_t) :: motion
      real(rp) :: rest_point(3) = 0.0_rp, rest_lower(3) = 0.0_rp, rest_upper(3) = 0.0_rp
      type(shape_t) :: rest_shape
      real(rp) :: shift(3) = 0.0_rp, nodes_shift(3) = 0.0_rp
      real(rp) :: wall_velocity(3) = 0.0_rp
      !> wall-pressure sensors on this wall and their taps on its nodes (wall_pressure_taps): a counted node's
      !> impulse adds dp . vector to the sensor's column of the impulse accumulator, after the walls' columns
      type(pressure_taps_t) :: taps
   end type wall_t

   !> Rows of an impulse accumulator (impulse_rows, wall): force impulse (3), then moment impulse (3), grid frame.
   integer, parameter, public :: impulse_rows = 6

   public :: build_walls, make_wall, make_structure, build_structures, set_wall_activity, &
             apply_wall_constraints, keep_particles_inside, behind_wall, wall_distance, unilateral_velocity, &
             first_particle_inside, surface_normal, move_walls, place_moving_walls, moving_wall_speed, &
             attach_wall_sensors

contains

   !> How far behind a wall its constraint acts, in cells: depth_in_cells, or with a stencil reaching 1.5 h
   !> from the particle per axis (bspline2) 1.5 sqrt(dim), the farthest a node it touches can lie behind a
   !> wall the particle is in front of (2.1 h in 2-D, 2.6 h in 3-D; docs/theory.md section 1.1) [R].
   pure real(rp) function wall_depth_in_cells(grid) result(depth)
      type(grid_t), intent(in) :: grid
      depth = depth_in_cells
      if (grid%ghost > 0) depth = max(depth_in_cells, 1.5_rp * sqrt(real(grid%dim, rp)))
   end function wall_depth_in_cells

   !> The walls of `&wall` groups (`specs`) and of the `&box_walls` sides of `spec`, with their local nodes,
   !> each reporting to its entry of loads.csv (`entries`, load_entries). With `gravity` (world frame) and
   !> `time`, a `&wall` with a motion moves (the solitary stroke needs g) and is placed where it is at `time`.
   subroutine build_walls(specs, spec, grid, entries, walls, gravity, time, tables)
      type(wall_spec_t), intent(in) :: specs(:)
      type(grid_spec_t), intent(in) :: spec
      type(grid_t), intent(in) :: grid
      type(load_entry_t), intent(in) :: entries(:)
      type(wall_t), allocatable, intent(out) :: walls(:)
      real(rp), intent(in), optional :: gravity(3), time
      type(time_table_t), intent(in), optional :: tables(:)   !< per spec, the table of a 'table' motion
      type(wall_spec_t), allocatable :: all_specs(:)
      integer :: w
      all_specs = [specs, box_side_walls(spec)]
      call build_walls_of(all_specs, size(specs), grid, entries, walls)
      if (.not. (present(gravity) .and. present(time))) return
      do w = 1, size(specs)
         if (present(tables)) then
            walls(w)%motion = prescribed_motion(specs(w)%motion, specs(w)%normal, gravity, grid%dim, tables(w))
         else
            walls(w)%motion = prescribed_motion(specs(w)%motion, specs(w)%normal, gravity, grid%dim)
         end if
         if (.not. walls(w)%motion%moving()) cycle
         walls(w)%moving = .true.
         walls(w)%rest_point = specs(w)%point
         walls(w)%rest_lower = specs(w)%lower
         walls(w)%rest_upper = specs(w)%upper
      end do
      call place_moving_walls(walls, grid, time)
      call refresh_moving_walls(walls, grid)
   end subroutine build_walls

   !> specs: the n_walls &wall groups, then the box sides in box_side_walls' order (the entries' order).
   subroutine build_walls_of(specs, n_walls, grid, entries, walls)
      type(wall_spec_t), intent(in) :: specs(:)
      integer, intent(in) :: n_walls
      type(grid_t), intent(in) :: grid
      type(load_entry_t), intent(in) :: entries(:)
      type(wall_t), allocatable, intent(out) :: walls(:)
      integer :: w, kind, load
      allocate (walls(size(specs)))
      do w = 1, size(specs)
         kind = condition_kind(specs(w)%condition)
         if (w <= n_walls) then
            load = entry_of(entries, entry_wall, w)
         else
            load = entry_of(entries, entry_box_side, w - n_walls)
         end if
         walls(w) = make_wall(grid, specs(w)%point, specs(w)%normal, specs(w)%lower, specs(w)%upper, grid%h, kind, &
                              load=load, moment_point=specs(w)%moment_point)
         walls(w)%friction = specs(w)%friction
      end do
   end subroutine build_walls_of

   !> Put every moving wall where its motion has it at `time` (point and extent; a structure: its shape and
   !> box); the node lists are left as they are (refresh_moving_walls).
   subroutine place_moving_walls(walls, grid, time)
      type(wall_t), intent(inout) :: walls(:)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: time
      integer :: w, dim
      real(rp) :: d(3)
      dim = grid%dim
      do w = 1, size(walls)
         if (.not. walls(w)%moving) cycle
         d = walls(w)%motion%displacement(time)
         walls(w)%shift = d
         if (walls(w)%shaped) then
            walls(w)%shape = translated_shape(walls(w)%rest_shape, d, dim)
            call set_structure_box(walls(w), grid)
            cycle
         end if
         walls(w)%point(1:dim) = grid%frame%grid_point(walls(w)%rest_point(1:dim) + d(1:dim))
         ! an unbounded side stays unbounded (huge + d rounds to huge)
         walls(w)%lower(1:dim) = walls(w)%rest_lower(1:dim) + d(1:dim)
         walls(w)%upper(1:dim) = walls(w)%rest_upper(1:dim) + d(1:dim)
      end do
   end subroutine place_moving_walls

   !> Step t0 -> t1: every moving wall placed at t0, its node list rebuilt if it moved since the list was
   !> made, and its velocity the mean over the step (the constraint's v_w).
   subroutine move_walls(walls, grid, t0, t1)
      type(wall_t), intent(inout) :: walls(:)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: t0, t1
      integer :: w, dim
      real(rp) :: v(3)
      dim = grid%dim
      call place_moving_walls(walls, grid, t0)
      call refresh_moving_walls(walls, grid)
      do w = 1, size(walls)
         if (.not. walls(w)%moving) cycle
         v = walls(w)%motion%mean_velocity(t0, t1)
         walls(w)%wall_velocity = 0.0_rp
         walls(w)%wall_velocity(1:dim) = grid%frame%grid_vector(v(1:dim))
      end do
   end subroutine move_walls

   !> The largest speed of the moving walls over [t0, t1] [m/s] (0 without any).
   real(rp) function moving_wall_speed(walls, t0, t1) result(speed)
      type(wall_t), intent(in) :: walls(:)
      real(rp), intent(in) :: t0, t1
      integer :: w
      speed = 0.0_rp
      do w = 1, size(walls)
         if (walls(w)%moving) speed = max(speed, walls(w)%motion%max_speed(t0, t1))
      end do
   end function moving_wall_speed

   !> Rebuild the node list of each moving wall whose displacement differs from the one its list was built
   !> at. Only the grid lines within the wall's depth are scanned when its normal is a grid axis (a piston:
   !> a few lines of nodes per step), the rank's whole box otherwise; a structure's box and depth.
   subroutine refresh_moving_walls(walls, grid)
      type(wall_t), intent(inout) :: walls(:)
      type(grid_t), intent(in) :: grid
      integer :: w, lo(3), hi(3), k
      real(rp) :: a, b
      do w = 1, size(walls)
         if (.not. walls(w)%moving) cycle
         if (all(walls(w)%shift == walls(w)%nodes_shift) .and. allocated(walls(w)%nodes)) cycle
         walls(w)%nodes_shift = walls(w)%shift
         if (walls(w)%shaped) then
            call find_structure_nodes(walls(w), grid)
            cycle
         end if
         lo = grid%node_lo
         hi = grid%node_hi
         k = walls(w)%axis
         if (k > 0) then
            ! nodes with -depth <= phi <= tolerance lie between these planes (one line more each side)
            a = walls(w)%point(k) - walls(w)%depth
            b = walls(w)%point(k) + walls(w)%depth
            lo(k) = max(lo(k), floor((a - grid%origin(k)) / grid%h) - 1)
            hi(k) = min(hi(k), ceiling((b - grid%origin(k)) / grid%h) + 1)
         end if
         if (allocated(walls(w)%nodes)) deallocate (walls(w)%nodes)
         if (allocated(walls(w)%counted)) deallocate (walls(w)%counted)
         if (allocated(walls(w)%arm)) deallocate (walls(w)%arm)
         call find_wall_nodes(walls(w), grid, lo, hi)
      end do
   end subroutine refresh_moving_walls

   !> The nodes of lo..hi (global node indices) a planar wall constrains, with its loads' bookkeeping.
   subroutine find_wall_nodes(wall, grid, lo, hi)
      type(wall_t), intent(inout) :: wall
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: lo(3), hi(3)
      integer :: dim, n, i, j, l, g(3)
      integer, allocatable :: found(:)
      logical, allocatable :: owned(:)
      real(rp) :: x(3)
      dim = grid%dim
      allocate (found(max(0, product(hi - lo + 1))), owned(max(0, product(hi - lo + 1))))
      n = 0
      x = 0.0_rp
      do l = lo(3), hi(3)
         do j = lo(2), hi(2)
            do i = lo(1), hi(1)
               g = [i, j, l]
               x(1:dim) = grid%origin(1:dim) + g(1:dim) * grid%h
               if (.not. behind_wall(wall, grid, x(1:dim), on_wall_tolerance * grid%h)) cycle
               n = n + 1
               found(n) = grid%local_node(g(1:dim))
               owned(n) = grid%owns_node(g(1:dim))
            end do
         end do
      end do
      call keep_nodes(wall, grid, found(1:n), owned(1:n))
      call place_taps(wall, grid)
   end subroutine find_wall_nodes

   !> The wall kind of a condition keyword ('slip', 'no_slip', 'friction').
   pure integer function condition_kind(condition) result(kind)
      character(len=*), intent(in) :: condition
      kind = wall_kind_slip
      if (condition == wall_no_slip) kind = wall_kind_no_slip
      if (condition == wall_friction) kind = wall_kind_friction
   end function condition_kind

   !> The structures of `&structure` groups appended to `walls`; each reports to its entry of loads.csv
   !> (`entries`). With `gravity` (world frame) and `time`, a structure with a motion moves and is
   !> placed where it is at `time` (`tables`: per spec, the table of a 'table' motion).
   subroutine build_structures(specs, grid, entries, walls, gravity, time, tables)
      type(structure_spec_t), intent(in) :: specs(:)
      type(grid_t), intent(in) :: grid
      type(load_entry_t), intent(in) :: entries(:)
      type(wall_t), allocatable, intent(inout) :: walls(:)
      real(rp), intent(in), optional :: gravity(3), time
      type(time_table_t), intent(in), optional :: tables(:)
      type(wall_t), allocatable :: structures(:)
      integer :: s
      allocate (structures(size(specs)))
      do s = 1, size(specs)
         structures(s) = make_structure(grid, specs(s)%shape, condition_kind(specs(s)%condition), specs(s)%friction, &
                                        entry_of(entries, entry_structure, s), specs(s)%moment_point)
         if (.not. (present(gravity) .and. present(time))) cycle
         if (present(tables)) then
            structures(s)%motion = prescribed_motion(specs(s)%motion, specs(s)%motion%direction, gravity, grid%dim, &
                                                     tables(s))
         else
            structures(s)%motion = prescribed_motion(specs(s)%motion, specs(s)%motion%direction, gravity, grid%dim)
         end if
         structures(s)%moving = structures(s)%motion%moving()
         structures(s)%rest_shape = specs(s)%shape
      end do
      if (present(gravity) .and. present(time)) then
         call place_moving_walls(structures, grid, time)
         call refresh_moving_walls(structures, grid)
      end if
      walls = [walls, structures]
   end subroutine build_structures

   !> A structure: the surface of the world-frame `shape` as a constraint of kind `kind` (friction mu), its
   !> impulse to loads.csv entry `load` with the moment about the world point `moment_point`, and the local
   !> nodes it constrains with the shape's outward normal at each (in the grid frame).
   function make_structure(grid, shape, kind, friction, load, moment_point) result(wall)
      type(grid_t), intent(in) :: grid
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: kind, load
      real(rp), intent(in) :: friction, moment_point(3)
      type(wall_t) :: wall
      integer :: dim
      dim = grid%dim
      wall%shaped = .true.
      wall%shape = shape
      wall%kind = kind
      wall%friction = friction
      wall%load = load
      wall%depth = wall_depth_in_cells(grid) * grid%h
      wall%moment_point = 0.0_rp
      wall%moment_point(1:dim) = grid%frame%grid_point(moment_point(1:dim))
      call set_structure_box(wall, grid)
      call find_structure_nodes(wall, grid)
   end function make_structure

   !> A structure's grid-frame box (box_lower, box_upper): that of the corners of its shape's world box.
   subroutine set_structure_box(wall, grid)
      type(wall_t), intent(inout) :: wall
      type(grid_t), intent(in) :: grid
      integer :: dim, k, corner
      real(rp) :: x(3), world(3), lower(3), upper(3)
      dim = grid%dim
      call shape_bounds(wall%shape, dim, lower, upper)
      wall%box_lower = huge(1.0_rp)
      wall%box_upper = -huge(1.0_rp)
      x = 0.0_rp
      world = 0.0_rp
      do corner = 0, 2**dim - 1
         do k = 1, dim
            world(k) = merge(upper(k), lower(k), btest(corner, k - 1))
         end do
         x(1:dim) = grid%frame%grid_point(world(1:dim))
         wall%box_lower(1:dim) = min(wall%box_lower(1:dim), x(1:dim))
         wall%box_upper(1:dim) = max(wall%box_upper(1:dim), x(1:dim))
      end do
   end subroutine set_structure_box

   !> The local nodes a structure constrains (-depth <= phi <= tolerance), with the shape's outward normal
   !> at each (grid frame) and its loads' bookkeeping: only the nodes of its box widened by depth + h.
   subroutine find_structure_nodes(wall, grid)
      type(wall_t), intent(inout) :: wall
      type(grid_t), intent(in) :: grid
      integer :: dim, n, i, j, l, g(3), lo(3), hi(3)
      integer, allocatable :: found(:)
      logical, allocatable :: owned(:)
      real(rp), allocatable :: normals(:, :)
      real(rp) :: x(3), world(3), phi, reach

      dim = grid%dim
      reach = wall%depth + grid%h
      lo = grid%node_lo
      hi = grid%node_hi
      ! the index range of the widened box (the test below decides; this only bounds the scan)
      lo(1:dim) = max(lo(1:dim), floor((wall%box_lower(1:dim) - reach - grid%origin(1:dim)) / grid%h) - 1)
      hi(1:dim) = min(hi(1:dim), ceiling((wall%box_upper(1:dim) + reach - grid%origin(1:dim)) / grid%h) + 1)
      allocate (found(max(0, product(hi - lo + 1))), owned(max(0, product(hi - lo + 1))), &
                normals(dim, max(0, product(hi - lo + 1))))
      n = 0
      x = 0.0_rp
      world = 0.0_rp
      do l = lo(3), hi(3)
         do j = lo(2), hi(2)
            do i = lo(1), hi(1)
               g = [i, j, l]
               x(1:dim) = grid%origin(1:dim) + g(1:dim) * grid%h
               if (any(x(1:dim) < wall%box_lower(1:dim) - reach) .or. any(x(1:dim) > wall%box_upper(1:dim) + reach)) cycle
               world(1:dim) = grid%frame%world_point(x(1:dim))
               phi = shape_distance(wall%shape, world(1:dim))
               if (phi > on_wall_tolerance * grid%h .or. phi < -wall%depth) cycle
               n = n + 1
               found(n) = grid%local_node(g(1:dim))
               owned(n) = grid%owns_node(g(1:dim))
               normals(:, n) = grid%frame%grid_vector(shape_normal(wall%shape, world(1:dim), &
                                                                   normal_step_in_cells * grid%h))
            end do
         end do
      end do
      if (allocated(wall%arm)) deallocate (wall%arm)
      call keep_nodes(wall, grid, found(1:n), owned(1:n))
      wall%node_normal = normals(:, 1:n)
      call place_taps(wall, grid)
   end subroutine find_structure_nodes

   !> The taps of the wall's sensors on its current nodes: each node's foot point on the surface and the
   !> surface's normal there (a structure's per node).
   subroutine place_taps(wall, grid)
      type(wall_t), intent(inout) :: wall
      type(grid_t), intent(in) :: grid
      real(rp), allocatable :: feet(:, :), normals(:, :)
      real(rp) :: x(grid%dim), phi
      integer :: i, dim
      if (.not. wall%taps%any()) return
      dim = grid%dim
      allocate (feet(dim, size(wall%nodes)), normals(dim, size(wall%nodes)))
      do i = 1, size(wall%nodes)
         x = grid%origin(1:dim) + grid%node_indices(wall%nodes(i)) * grid%h
         if (wall%shaped) then
            normals(:, i) = wall%node_normal(:, i)
         else
            normals(:, i) = wall%normal(1:dim)
         end if
         phi = wall_distance(wall, grid, x)
         feet(:, i) = x - phi * normals(:, i)
      end do
      call wall%taps%place(dim, grid%h, feet, normals)
   end subroutine place_taps

   !> Put the wall-pressure sensors `sensors` (their slot, point in the world frame, radius) on the walls
   !> of the loads.csv entries `entries` (per sensor), with the sensor's point moved onto the surface, the
   !> surface's normal there and the intervals it can be wetted along grid axes (the scene box, cut by the
   !> planar walls across them); then their taps. `offset` (per sensor) is how far the given point lay from
   !> the surface [m] (the caller refuses a point off it).
   subroutine attach_wall_sensors(walls, grid, sensors, entries, offset)
      type(wall_t), intent(inout) :: walls(:)
      type(grid_t), intent(in) :: grid
      type(wall_sensor_t), intent(in) :: sensors(:)
      integer, intent(in) :: entries(:)
      real(rp), intent(out) :: offset(:)
      type(wall_sensor_t) :: sensor
      real(rp) :: x(grid%dim), phi, tangents(grid%dim, grid%dim - 1)
      logical :: axes
      integer :: s, w, v, k, along, dim
      dim = grid%dim
      offset = huge(1.0_rp)
      do w = 1, size(walls)
         if (allocated(walls(w)%taps%sensors)) deallocate (walls(w)%taps%sensors)
         allocate (walls(w)%taps%sensors(0))
      end do
      do s = 1, size(sensors)
         do w = 1, size(walls)
            if (walls(w)%load /= entries(s)) cycle
            sensor = sensors(s)
            x = grid%frame%grid_point(sensors(s)%point(1:dim))
            phi = wall_distance(walls(w), grid, x)
            offset(s) = min(offset(s), abs(phi))
            sensor%normal = 0.0_rp
            sensor%normal(1:dim) = surface_normal(walls(w), grid, x)
            sensor%point = 0.0_rp
            sensor%point(1:dim) = x - phi * sensor%normal(1:dim)
            call tangent_axes(sensor%normal(1:dim), dim, tangents, axes)
            if (axes) then
               do k = 1, dim - 1
                  along = maxloc(abs(tangents(:, k)), 1)
                  sensor%wet_lo(along) = grid%origin(along)
                  sensor%wet_hi(along) = grid%origin(along) + grid%global_cells(along) * grid%h
                  ! a planar wall across this axis, with the sensor on its fluid side and in its extent
                  do v = 1, size(walls)
                     if (v == w .or. walls(v)%shaped .or. walls(v)%axis /= along) cycle
                     if (wall_distance(walls(v), grid, sensor%point(1:dim)) < -1.0e-9_rp * grid%h) cycle
                     if (.not. in_extent(walls(v), grid, sensor%point(1:dim))) cycle
                     if (walls(v)%normal(along) > 0.0_rp) then
                        sensor%wet_lo(along) = max(sensor%wet_lo(along), walls(v)%point(along))
                     else
                        sensor%wet_hi(along) = min(sensor%wet_hi(along), walls(v)%point(along))
                     end if
                  end do
               end do
            end if
            walls(w)%taps%sensors = [walls(w)%taps%sensors, sensor]
         end do
      end do
      do w = 1, size(walls)
         call place_taps(walls(w), grid)
      end do
   end subroutine attach_wall_sensors

   !> True if the foot of the grid-frame point x on the planar wall lies in the wall's extent.
   logical function in_extent(wall, grid, x)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      real(rp) :: foot(size(x))
      integer :: d
      d = size(x)
      foot = grid%frame%world_point(x - wall_distance(wall, grid, x) * wall%normal(1:d))
      in_extent = all(foot >= wall%lower(1:d) - wall%margin) .and. all(foot <= wall%upper(1:d) + wall%margin)
   end function in_extent

   !> A wall through the world point `point` with the world unit normal `normal`, its extent lower..upper
   !> (world) widened by `margin`, and the local nodes it constrains. Its impulse goes to entry `load` of
   !> loads.csv, its moment about the world point `moment_point` (default `point`).
   function make_wall(grid, point, normal, lower, upper, margin, kind, velocity, active_from, active_until, load, &
                      moment_point) result(wall)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: point(3), normal(3), lower(3), upper(3), margin
      integer, intent(in) :: kind
      real(rp), intent(in), optional :: velocity(3), active_from, active_until
      integer, intent(in), optional :: load
      real(rp), intent(in), optional :: moment_point(3)
      type(wall_t) :: wall
      integer :: dim

      dim = grid%dim
      wall%point = 0.0_rp
      wall%normal = 0.0_rp
      wall%point(1:dim) = grid%frame%grid_point(point(1:dim))
      wall%normal(1:dim) = grid%frame%grid_vector(normal(1:dim) / norm2(normal(1:dim)))
      wall%lower = lower
      wall%upper = upper
      wall%margin = margin
      wall%depth = wall_depth_in_cells(grid) * grid%h
      wall%kind = kind
      if (present(velocity)) wall%velocity(1:dim) = grid%frame%grid_vector(velocity(1:dim))
      if (present(active_from)) wall%active_from = active_from
      if (present(active_until)) wall%active_until = active_until
      if (present(load)) wall%load = load
      wall%moment_point = wall%point
      if (present(moment_point)) then
         if (all(abs(moment_point(1:dim)) < huge(1.0_rp))) wall%moment_point(1:dim) = grid%frame%grid_point(moment_point(1:dim))
      end if
      ! the axis fast path of the safeguard needs a normal with exactly one non-zero component
      if (count(abs(wall%normal(1:dim)) > 0.0_rp) == 1) wall%axis = maxloc(abs(wall%normal(1:dim)), 1)

      call find_wall_nodes(wall, grid, grid%node_lo, grid%node_hi)
   end function make_wall

   !> The wall's local nodes `nodes`, which of them this rank counts in the loads (`owned`), and each
   !> node's arm from the moment point (grid frame).
   subroutine keep_nodes(wall, grid, nodes, owned)
      type(wall_t), intent(inout) :: wall
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: nodes(:)
      logical, intent(in) :: owned(:)
      integer :: i, dim
      dim = grid%dim
      wall%nodes = nodes
      wall%counted = owned
      allocate (wall%arm(3, size(nodes)))
      wall%arm = 0.0_rp
      do i = 1, size(nodes)
         wall%arm(1:dim, i) = grid%origin(1:dim) + grid%node_indices(nodes(i)) * grid%h - wall%moment_point(1:dim)
      end do
   end subroutine keep_nodes

   !> True if the grid-frame point x lies on the wall or behind it (within `tolerance` in front), not
   !> farther behind than the wall's depth, with its foot point inside the wall's extent. `widen` [m]
   !> deepens the depth and widens the extent (whether a ball of that radius about x may touch the wall's
   !> zone).
   logical function behind_wall(wall, grid, x, tolerance, widen) result(behind)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:), tolerance
      real(rp), intent(in), optional :: widen
      real(rp) :: distance, foot(size(x)), extra
      integer :: d
      d = size(x)
      extra = 0.0_rp
      if (present(widen)) extra = widen
      distance = wall_distance(wall, grid, x)
      behind = distance <= tolerance .and. distance >= -(wall%depth + extra)
      if (.not. behind .or. wall%shaped) return
      foot = grid%frame%world_point(x - distance * wall%normal(1:d))
      behind = all(foot >= wall%lower(1:d) - (wall%margin + extra)) .and. &
               all(foot <= wall%upper(1:d) + (wall%margin + extra))
   end function behind_wall

   !> Signed distance phi of the grid-frame point x from the wall's plane or the structure's surface
   !> (negative behind it) [m].
   real(rp) function wall_distance(wall, grid, x) result(distance)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      if (wall%shaped) then
         distance = shape_distance(wall%shape, grid%frame%world_point(x))
      else
         distance = dot_product(wall%normal(1:size(x)), x - wall%point(1:size(x)))
      end if
   end function wall_distance

   !> Unit normal (grid frame) of the wall's plane, or of a structure's surface at the grid-frame point x.
   function surface_normal(wall, grid, x) result(n)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:)
      real(rp) :: n(size(x))
      if (wall%shaped) then
         n = grid%frame%grid_vector(shape_normal(wall%shape, grid%frame%world_point(x), normal_step_in_cells * grid%h))
      else
         n = wall%normal(1:size(x))
      end if
   end function surface_normal

   !> Walls act during [active_from, active_until) only.
   pure subroutine set_wall_activity(walls, time)
      type(wall_t), intent(inout) :: walls(:)
      real(rp), intent(in) :: time
      integer :: w
      do w = 1, size(walls)
         walls(w)%active = time >= walls(w)%active_from .and. time < walls(w)%active_until
      end do
   end subroutine set_wall_activity

   !> Constrain nodal velocities (eq. 14 for slip walls; Coulomb for friction; zero for no-slip walls; v_0
   !> for a feeder). A planar wall has one normal, a structure one per node. Walls are applied in turn,
   !> which is exact at a corner of two orthogonal walls (algorithms.md section 4.1); a prescribed velocity,
   !> listed after the scene's walls, wins. With `mass` (nodal masses) and `impulse`, impulse(:, w) gains
   !> the momentum wall w gives the counted nodes, m_i (v_i^c - v_i^*), and its moment (algorithms.md
   !> section 9.1). `friction` (per wall), where >= 0, makes wall w act as a friction wall with that mu
   !> instead of its own condition: a body field against a structure of its &contact (body_contact). Nodes
   !> with `skip(node)` are left alone (a rigid body's nodes: it meets the walls as a body, rigid_bodies).
   pure subroutine apply_wall_constraints(walls, dim, velocity, mass, impulse, friction, skip)
      type(wall_t), intent(in) :: walls(:)
      integer, intent(in) :: dim
      real(rp), intent(inout) :: velocity(:, :)
      real(rp), intent(in), optional :: mass(:)
      real(rp), intent(inout), optional :: impulse(:, :)
      real(rp), intent(in), optional :: friction(:)
      logical, intent(in), optional :: skip(:)
      integer :: w, i, node, kind
      real(rp) :: vn, before(dim), n(dim), mu, vw(dim)
      logical :: recording, masked
      recording = present(mass) .and. present(impulse)
      masked = present(skip)
      do w = 1, size(walls)
         if (.not. walls(w)%active) cycle
         if (.not. walls(w)%shaped) n = walls(w)%normal(1:dim)
         kind = walls(w)%kind
         mu = walls(w)%friction
         if (present(friction)) then
            if (friction(w) >= 0.0_rp) then
               kind = wall_kind_friction
               mu = friction(w)
            end if
         end if
         vw = walls(w)%wall_velocity(1:dim)
         do i = 1, size(walls(w)%nodes)
            node = walls(w)%nodes(i)
            if (masked) then
               if (skip(node)) cycle
            end if
            before = velocity(:, node)
            if (walls(w)%shaped) n = walls(w)%node_normal(:, i)
            if (walls(w)%moving) then
               ! the same conditions on the velocity relative to the wall's
               select case (kind)
               case (wall_kind_no_slip)
                  velocity(:, node) = vw
               case (wall_kind_friction)
                  if (dot_product(before - vw, n) >= 0.0_rp) cycle
                  velocity(:, node) = vw + unilateral_velocity(before - vw, n, mu)
               case default
                  vn = dot_product(before - vw, n)
                  if (vn >= 0.0_rp) cycle
                  velocity(:, node) = before - vn * n
               end select
               if (recording) then
                  if (walls(w)%counted(i)) call record_impulse(walls(w), w, size(walls), i, &
                                                               mass(node) * (velocity(:, node) - before), impulse)
               end if
               cycle
            end if
            select case (kind)
            case (wall_kind_no_slip)
               velocity(:, node) = 0.0_rp
            case (wall_kind_prescribed)
               velocity(:, node) = walls(w)%velocity(1:dim)
            case (wall_kind_friction)
               if (dot_product(before, n) >= 0.0_rp) cycle
               velocity(:, node) = unilateral_velocity(before, n, mu)
            case default
               vn = dot_product(before, n)
               if (vn >= 0.0_rp) cycle
               velocity(:, node) = before - vn * n
            end select
            if (recording) then
               if (walls(w)%counted(i)) call record_impulse(walls(w), w, size(walls), i, &
                                                            mass(node) * (velocity(:, node) - before), impulse)
            end if
         end do
      end do
   end subroutine apply_wall_constraints

   !> The impulse dp of the i-th node of `wall` (the w-th of n_walls) for the wall's load and its sensors'
   !> columns n_walls + slot of `impulse`.
   pure subroutine record_impulse(wall, w, n_walls, i, dp, impulse)
      type(wall_t), intent(in) :: wall
      integer, intent(in) :: w, n_walls, i
      real(rp), intent(in) :: dp(:)
      real(rp), intent(inout) :: impulse(:, :)
      integer :: t, column
      call add_impulse(impulse(:, w), dp, wall%arm(1:size(dp), i))
      if (.not. allocated(wall%taps%first)) return
      do t = wall%taps%first(i), wall%taps%first(i + 1) - 1
         column = n_walls + wall%taps%slot(t)
         ! a body field's accumulator (body_contact) has the walls' columns only
         if (column > size(impulse, 2)) cycle
         impulse(1, column) = impulse(1, column) + dot_product(dp, wall%taps%vector(:, t))
      end do
   end subroutine record_impulse

   !> The velocity v after a unilateral contact with Coulomb friction mu against a surface of unit normal
   !> n (pointing into the material): unchanged when separating (v.n >= 0); else the normal part v_n is
   !> removed and the tangential part v_t shortened by mu |v_n|, to zero at most (it sticks when
   !> |v_t| <= mu |v_n|, it is never reversed). Over a step this is the impulse of a normal force N dt =
   !> m |v_n| with a friction impulse at most mu N dt opposing the sliding [R] (the grid-node form of
   !> Bardenhagen et al. 2001's contact against a rigid surface, algorithms.md section 9.4).
   pure function unilateral_velocity(v, n, mu) result(constrained)
      real(rp), intent(in) :: v(:), n(:), mu
      real(rp) :: constrained(size(v))
      real(rp) :: vn, tangential(size(v)), speed, remaining
      vn = dot_product(v, n)
      if (vn >= 0.0_rp) then
         constrained = v
         return
      end if
      tangential = v - vn * n
      speed = norm2(tangential)
      remaining = speed + mu * vn
      if (remaining <= 0.0_rp) then
         constrained = 0.0_rp
      else
         constrained = tangential * (remaining / speed)
      end if
   end function unilateral_velocity

   !> impulse(1:3) += dp, impulse(4:6) += arm x dp (2-D: only the z component of the moment).
   pure subroutine add_impulse(impulse, dp, arm)
      real(rp), intent(inout) :: impulse(:)
      real(rp), intent(in) :: dp(:), arm(:)
      if (size(dp) == 2) then
         impulse(1:2) = impulse(1:2) + dp
         impulse(6) = impulse(6) + (arm(1) * dp(2) - arm(2) * dp(1))
      else
         impulse(1:3) = impulse(1:3) + dp
         impulse(4) = impulse(4) + (arm(2) * dp(3) - arm(3) * dp(2))
         impulse(5) = impulse(5) + (arm(3) * dp(1) - arm(1) * dp(3))
         impulse(6) = impulse(6) + (arm(1) * dp(2) - arm(2) * dp(1))
      end if
   end subroutine add_impulse

   !> Particle safeguard (algorithms.md section 4.2): a particle found behind a wall (inside its extent
   !> and depth) or inside a structure is put back onto its surface and loses its velocity component into
   !> it (with friction also what Coulomb allows). Counts corrections; impulse(:, w) gains the momentum (and
   !> its moment) that wall w gave the particles it corrected. With contact fields (all three or none):
   !> `field` (particle) the velocity field of each particle (0: the common one), `field_friction` (wall,
   !> field) the mu a structure applies to that field instead of its condition (< 0: its condition), and
   !> field_impulse(:, w, f) gains the part of impulse(:, w) given to field f's particles. The particles of a
   !> material with `skip(material)` are left alone: rigid bodies meet walls as bodies (rigid_bodies).
   !> lowest(1:dim), highest(1:dim): bounds on the particles' coordinates (the step's extent, which G2P
   !> takes as it moves them; wider is fine). They only let a wall's pass be skipped when no particle can
   !> be behind it; a pass of their own over the particles was 3 % of a 2-D step.
   subroutine keep_particles_inside(walls, grid, particles, lowest, highest, corrections, impulse, field, field_friction, &
                                    field_impulse, skip)
      type(wall_t), intent(in) :: walls(:)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      real(rp), intent(in) :: lowest(:), highest(:)
      integer, intent(inout) :: corrections
      real(rp), intent(inout) :: impulse(:, :)
      integer, intent(in), optional :: field(:)
      real(rp), intent(in), optional :: field_friction(:, :)
      real(rp), intent(inout), optional :: field_impulse(:, :, :)
      logical, intent(in), optional :: skip(:)
      integer :: w, p, d
      real(rp) :: distance, vn, before(particles%dim)
      logical, allocatable :: skipped(:)
      d = particles%dim
      if (.not. any(walls%active)) return
      if (present(skip)) then
         skipped = skip
      else
         allocate (skipped(max(1, maxval(particles%material(1:particles%count), 1))))
         skipped = .false.
      end if
      do w = 1, size(walls)
         if (.not. walls(w)%active) cycle
         if (walls(w)%shaped) then
            ! no particle in the structure's box: skip the pass
            if (any(highest(1:d) < walls(w)%box_lower(1:d)) .or. any(lowest(1:d) > walls(w)%box_upper(1:d))) cycle
            if (present(field)) then
               call keep_outside_structure(walls(w), grid, particles, corrections, impulse(:, w), skipped, field, &
                                           field_friction(w, :), field_impulse(:, w, :))
            else
               call keep_outside_structure(walls(w), grid, particles, corrections, impulse(:, w), skipped)
            end if
            cycle
         end if
         if (walls(w)%axis > 0) then
            ! no particle behind it: skip the pass (the usual case; x - x0 is monotonic in x)
            associate (k => walls(w)%axis)
               if (walls(w)%normal(k) > 0.0_rp .and. lowest(k) - walls(w)%point(k) >= 0.0_rp) cycle
               if (walls(w)%normal(k) < 0.0_rp .and. highest(k) - walls(w)%point(k) <= 0.0_rp) cycle
            end associate
            if (walls(w)%moving) then
               call keep_inside_moving_wall(walls(w), grid, particles, corrections, impulse(:, w), skipped)
            else
               call keep_inside_axis_wall(walls(w), grid, particles, corrections, impulse(:, w), skipped)
            end if
            cycle
         end if
         if (walls(w)%moving) then
            call keep_inside_moving_wall(walls(w), grid, particles, corrections, impulse(:, w), skipped)
            cycle
         end if
         associate (n => walls(w)%normal(1:d), x0 => walls(w)%point(1:d))
            do p = 1, particles%count
               distance = dot_product(particles%x(:, p) - x0, n)
               if (distance >= 0.0_rp) cycle
               if (skipped(particles%material(p))) cycle
               if (.not. behind_wall(walls(w), grid, particles%x(:, p), 0.0_rp)) cycle
               particles%x(:, p) = particles%x(:, p) - distance * n
               vn = dot_product(particles%v(:, p), n)
               if (vn < 0.0_rp) then
                  if (walls(w)%kind == wall_kind_friction) then
                     before = particles%v(:, p)
                     particles%v(:, p) = unilateral_velocity(before, n, walls(w)%friction)
                     call add_impulse(impulse(:, w), particles%mass(p) * (particles%v(:, p) - before), &
                                      particles%x(:, p) - walls(w)%moment_point(1:d))
                  else
                     particles%v(:, p) = particles%v(:, p) - vn * n
                     call add_impulse(impulse(:, w), -particles%mass(p) * vn * n, &
                                      particles%x(:, p) - walls(w)%moment_point(1:d))
                  end if
               end if
               corrections = corrections + 1
            end do
         end associate
      end do
   end subroutine keep_particles_inside

   !> The safeguard of a structure: a particle with phi < 0 moves to its foot point x - phi n on the
   !> surface (n = grad phi at x) and loses its normal velocity into the structure (friction: Coulomb's
   !> share of the tangential one too); of a moving structure, of its velocity relative to v_w. Unlike a
   !> wall's, it acts at any depth: a structure is solid.
   !> A particle put on a curved surface lands at phi = 0 only to round-off; counting it inside only below
   !> -on_wall_tolerance h keeps the next step's decision (and its change of velocity) from depending on
   !> that round-off, which differs with the number of ranks. With `field` (particle), a particle of body
   !> field f > 0 meets Coulomb friction field_friction(f) if that is >= 0, and its impulse is also added
   !> to field_impulse(:, f).
   subroutine keep_outside_structure(wall, grid, particles, corrections, impulse, skip, field, field_friction, field_impulse)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer, intent(inout) :: corrections
      real(rp), intent(inout) :: impulse(:)
      logical, intent(in) :: skip(:)
      integer, intent(in), optional :: field(:)
      real(rp), intent(in), optional :: field_friction(:)
      real(rp), intent(inout), optional :: field_impulse(:, :)
      integer :: p, d, f, kind
      real(rp) :: world(particles%dim), phi, n(particles%dim), before(particles%dim), step, tolerance, mu
      real(rp) :: dp(particles%dim), relative(particles%dim), vw(particles%dim)
      d = particles%dim
      step = normal_step_in_cells * grid%h
      tolerance = on_wall_tolerance * grid%h
      vw = wall%wall_velocity(1:d)
      do p = 1, particles%count
         if (any(particles%x(:, p) < wall%box_lower(1:d)) .or. any(particles%x(:, p) > wall%box_upper(1:d))) cycle
         world = grid%frame%world_point(particles%x(:, p))
         phi = shape_distance(wall%shape, world)
         if (phi >= -tolerance) cycle
         if (skip(particles%material(p))) cycle
         n = grid%frame%grid_vector(shape_normal(wall%shape, world, step))
         particles%x(:, p) = particles%x(:, p) - phi * n
         ! a moving structure: the velocity relative to its own (a fixed one keeps its arithmetic)
         before = particles%v(:, p)
         relative = before
         if (wall%moving) relative = before - vw
         if (dot_product(relative, n) < 0.0_rp) then
            kind = wall%kind
            mu = wall%friction
            f = 0
            if (present(field)) f = field(p)
            if (f > 0) then
               if (field_friction(f) >= 0.0_rp) then
                  kind = wall_kind_friction
                  mu = field_friction(f)
               end if
            end if
            if (kind == wall_kind_friction) then
               particles%v(:, p) = unilateral_velocity(relative, n, mu)
               if (wall%moving) particles%v(:, p) = vw + particles%v(:, p)
            else
               particles%v(:, p) = before - dot_product(relative, n) * n
            end if
            dp = particles%mass(p) * (particles%v(:, p) - before)
            call add_impulse(impulse, dp, particles%x(:, p) - wall%moment_point(1:d))
            if (f > 0) call add_impulse(field_impulse(:, f), dp, particles%x(:, p) - wall%moment_point(1:d))
         end if
         corrections = corrections + 1
      end do
   end subroutine keep_outside_structure

   !> The first of the local particles that lies inside the structure `wall` (phi < 0), 0 if none; its
   !> depth -phi [m].
   integer function first_particle_inside(wall, grid, particles, depth) result(found)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(out) :: depth
      integer :: p
      real(rp) :: phi
      found = 0
      depth = 0.0_rp
      do p = 1, particles%count
         phi = wall_distance(wall, grid, particles%x(:, p))
         if (phi < 0.0_rp) then
            found = p
            depth = -phi
            return
         end if
      end do
   end function first_particle_inside

   !> The safeguard of a moving wall (at its place at the step's end): a particle behind it goes back onto
   !> it and gets at least the wall's normal velocity, v - v_w losing its part into the wall (friction:
   !> Coulomb's share of the tangential part too).
   subroutine keep_inside_moving_wall(wall, grid, particles, corrections, impulse, skip)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer, intent(inout) :: corrections
      real(rp), intent(inout) :: impulse(:)
      logical, intent(in) :: skip(:)
      integer :: p, d
      real(rp) :: distance, vn, before(particles%dim), vw(particles%dim)
      d = particles%dim
      vw = wall%wall_velocity(1:d)
      associate (n => wall%normal(1:d), x0 => wall%point(1:d))
         do p = 1, particles%count
            distance = dot_product(particles%x(:, p) - x0, n)
            if (distance >= 0.0_rp) cycle
            if (skip(particles%material(p))) cycle
            if (.not. behind_wall(wall, grid, particles%x(:, p), 0.0_rp)) cycle
            particles%x(:, p) = particles%x(:, p) - distance * n
            before = particles%v(:, p)
            vn = dot_product(before - vw, n)
            if (vn < 0.0_rp) then
               if (wall%kind == wall_kind_friction) then
                  particles%v(:, p) = vw + unilateral_velocity(before - vw, n, wall%friction)
               else
                  particles%v(:, p) = before - vn * n
               end if
               call add_impulse(impulse, particles%mass(p) * (particles%v(:, p) - before), &
                                particles%x(:, p) - wall%moment_point(1:d))
            end if
            corrections = corrections + 1
         end do
      end associate
   end subroutine keep_inside_moving_wall

   !> The safeguard for a wall normal to grid axis k: the same operation without the dot products.
   subroutine keep_inside_axis_wall(wall, grid, particles, corrections, impulse, skip)
      type(wall_t), intent(in) :: wall
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer, intent(inout) :: corrections
      real(rp), intent(inout) :: impulse(:)
      logical, intent(in) :: skip(:)
      integer :: p, k
      real(rp) :: sense, x0, dp(particles%dim)
      k = wall%axis
      sense = wall%normal(k)
      x0 = wall%point(k)
      do p = 1, particles%count
         if (sense * (particles%x(k, p) - x0) >= 0.0_rp) cycle
         if (skip(particles%material(p))) cycle
         if (.not. behind_wall(wall, grid, particles%x(:, p), 0.0_rp)) cycle
         particles%x(k, p) = x0
         if (sense * particles%v(k, p) < 0.0_rp) then
            if (wall%kind == wall_kind_friction) then
               dp = particles%v(:, p)
               particles%v(:, p) = unilateral_velocity(dp, wall%normal(1:particles%dim), wall%friction)
               dp = particles%mass(p) * (particles%v(:, p) - dp)
            else
               dp = 0.0_rp
               dp(k) = -particles%mass(p) * particles%v(k, p)
               particles%v(k, p) = 0.0_rp
            end if
            call add_impulse(impulse, dp, particles%x(:, p) - wall%moment_point(1:particles%dim))
         end if
         corrections = corrections + 1
      end do
   end subroutine keep_inside_axis_wall
end module boundary_walls
