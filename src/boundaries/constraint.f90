!> A boundary constraint: a surface that holds the material back (algorithms.md sections 4.1-4.2,
!> docs/theory.md section 3.4). Planar walls, the box sides and an inlet's walls (planar_wall) and the
!> structures (structure_surface) extend it; constraint_list holds them in the order of loads.csv's
!> entries and constraint_factory builds them from the scene. docs/conventions.md, "Where to add ...",
!> says how to add one.
!>
!> A constraint surface has a signed distance phi (negative behind it) and a unit normal n pointing
!> into the material; its condition (surface_condition) says what it does there. The nodes it
!> constrains are found once per layout (find_nodes), by signed distance [R]: nodes with
!> -depth <= phi <= 0 (on the surface or behind it, within two cells).
!> A constraint may be active for a time window only (an inlet's opening and its closing wall).
!> It may move (wall_motion, docs/theory.md section 3.6): each step it is placed where its motion puts it
!> at the step's start, its node list is rebuilt there, and the conditions act on the velocity relative
!> to its mean velocity v_w over the step; the safeguard uses its place at the step's end.
!>
!> Loads (docs/theory.md section 3.2, algorithms.md section 9.1): the constraint's change of nodal
!> momentum m_i (v_i^c - v_i^*) and the safeguard's change of particle momentum m_p (v_p^c - v_p) are the
!> impulse the surface gives the material; constraints applied in turn each keep the change they made,
!> so the impulses at a corner split between them and add up exactly. A node shared with other ranks is
!> counted by one of them only (`counted`).
module constraint
   use kinds, only: rp
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use wall_motion, only: wall_motion_t
   use surface_sensors, only: sensor_taps_t, add_tap_impulse
   use surface_condition, only: surface_condition_t, condition_traits_t, friction_node
   implicit none
   private

   !> Rows of an impulse accumulator (impulse_rows, constraint): force impulse (3), then moment impulse (3),
   !> grid frame.
   integer, parameter, public :: impulse_rows = 6
   !> Nodes and particles farther behind a wall than this many cells are not its business [R]: a
   !> particle in a cell cut by the wall reaches nodes at most sqrt(dim) h behind it, and a baffle made of
   !> two walls back to back must not constrain the far side.
   real(rp), parameter :: depth_in_cells = 2.0_rp
   !> A node closer to the surface than this fraction of h counts as on it (round-off of node positions).
   real(rp), parameter, public :: on_surface_tolerance = 1.0e-9_rp

   !> What the particle safeguard of a step knows (constraint_list's keep_particles_inside fills it):
   !> lowest(1:dim), highest(1:dim) bound the particles' coordinates (a pass may be skipped when no
   !> particle can be behind the constraint), the particles of a material with skip(material) are left
   !> alone (rigid bodies meet the walls as bodies), `impulse` is the column of the impulse accumulator
   !> the constraint's impulse goes to, `corrections` counts the particles put back. With contact fields:
   !> each particle's `field` (0: the common one), the mu a structure applies to each field instead of
   !> its condition (`field_friction`, < 0: its condition) and each field's part of its impulse.
   type, public :: safeguard_pass_t
      real(rp) :: lowest(3) = -huge(1.0_rp), highest(3) = huge(1.0_rp)
      logical, allocatable :: skip(:)
      integer :: corrections = 0
      real(rp), pointer, contiguous :: impulse(:) => null()
      integer, pointer :: field(:) => null()
      real(rp), pointer :: field_friction(:) => null()
      real(rp), pointer :: field_impulse(:, :) => null()
      !> the sensors' columns of the impulse accumulator (panels and load cells take the safeguard's part)
      real(rp), pointer, contiguous :: sensor_impulse(:, :) => null()
   end type safeguard_pass_t

   type, abstract, public :: constraint_t
      class(surface_condition_t), allocatable :: condition
      type(condition_traits_t) :: traits   !< its condition's (set_condition)
      integer :: load = 0                  !< the entry of loads.csv its impulse goes to (0: none)
      real(rp) :: moment_point(3) = 0.0_rp !< the point its moment is taken about (grid frame)
      real(rp) :: depth = 0.0_rp           !< how far behind the surface it acts [m]
      real(rp) :: active_from = -huge(1.0_rp), active_until = huge(1.0_rp)
      logical :: active = .true.
      integer, allocatable :: nodes(:)     !< local nodes this rank constrains
      !> the impulse of node nodes(i) counts here: this rank owns the node (no other rank counts it)
      logical, allocatable :: counted(:)
      real(rp), allocatable :: arm(:, :)   !< node position - moment_point (3, i), grid frame [m]
      !> the unit normal (grid frame) it constrains node nodes(i) along: normals(:, i), or normals(:, 1) for
      !> all nodes of a surface with one normal (a planar wall)
      real(rp), allocatable :: normals(:, :)
      !> a moving constraint: its motion, its displacement d (world) now and where its node list was built,
      !> and its mean velocity over the current step (grid frame)
      logical :: moving = .false.
      type(wall_motion_t) :: motion
      real(rp) :: shift(3) = 0.0_rp, nodes_shift(3) = 0.0_rp
      real(rp) :: wall_velocity(3) = 0.0_rp
      !> the sensors on this surface (gauges, panels, load cells) and their taps on its nodes
      !> (surface_sensors): a counted node's impulse adds its share to the sensor's column of the impulse
      !> accumulator, after the constraints' columns
      type(sensor_taps_t) :: taps
   contains
      !> signed distance phi of a grid-frame point [m], and (optional) the unit normal (grid frame) there
      procedure(distance_interface), deferred :: distance
      !> on the surface or behind it (within `tolerance` in front), within depth (+ widen) and its extent
      procedure(behind_interface), deferred :: behind
      !> the local nodes it constrains, for the grid's current layout and the surface's current place
      procedure(nodes_interface), deferred :: find_nodes
      !> put it where displacement d (world) from its place in the scene puts it (its nodes stay)
      procedure(put_interface), deferred :: put
      !> the particle safeguard: particles behind it put back on it
      procedure(keep_out_interface), deferred :: keep_out
      !> true only if no point within `reach` of x can be behind it (a quick test; false: do not know)
      procedure :: clearly_in_front => unknown_front
      !> false only if the support of radius `reach` about the node x cannot meet its zone (volume_correction)
      procedure :: may_cut_support => always_may_cut
      !> narrow a sensor's wettable interval along grid axis `along` (a planar wall across it)
      procedure :: narrow_wet_interval => keep_interval
      !> narrow the wettable interval along grid axis `along` of a sensor on this surface itself (a box
      !> structure's face ends at its edges)
      procedure :: narrow_own_interval => keep_interval
      !> narrow a sensor's wettable interval lo .. hi of s along the line point + s tangent (grid frame; a
      !> planar wall the line crosses)
      procedure :: narrow_along_line => keep_line_interval
      procedure :: set_condition
      procedure :: set_activity
      procedure :: place
      procedure :: refresh
      procedure :: move
      procedure :: place_taps
      procedure :: first_particle_inside
      procedure :: node_normal
      procedure :: constrain
      procedure :: record_impulse
      procedure :: record_particle_impulse
      procedure :: keep_nodes
      procedure :: scan_nodes
   end type constraint_t

   !> One constraint of a list (an array of constraint_t of different types).
   type, public :: constraint_slot_t
      class(constraint_t), allocatable :: item
   end type constraint_slot_t

   abstract interface
      real(rp) function distance_interface(self, grid, x, normal) result(distance)
         import :: constraint_t, grid_t, rp
         class(constraint_t), intent(in) :: self
         type(grid_t), intent(in) :: grid
         real(rp), intent(in) :: x(:)
         real(rp), intent(out), optional :: normal(:)
      end function distance_interface

      logical function behind_interface(self, grid, x, tolerance, widen) result(behind)
         import :: constraint_t, grid_t, rp
         class(constraint_t), intent(in) :: self
         type(grid_t), intent(in) :: grid
         real(rp), intent(in) :: x(:), tolerance
         real(rp), intent(in), optional :: widen
      end function behind_interface

      subroutine nodes_interface(self, grid)
         import :: constraint_t, grid_t
         class(constraint_t), intent(inout) :: self
         type(grid_t), intent(in) :: grid
      end subroutine nodes_interface

      subroutine put_interface(self, grid, d)
         import :: constraint_t, grid_t, rp
         class(constraint_t), intent(inout) :: self
         type(grid_t), intent(in) :: grid
         real(rp), intent(in) :: d(3)
      end subroutine put_interface

      subroutine keep_out_interface(self, grid, particles, pass)
         import :: constraint_t, grid_t, particle_set_t, safeguard_pass_t
         class(constraint_t), intent(in) :: self
         type(grid_t), intent(in) :: grid
         type(particle_set_t), intent(inout) :: particles
         type(safeguard_pass_t), intent(inout) :: pass
      end subroutine keep_out_interface
   end interface

   public :: add_impulse, constraint_depth

contains

   !> How far behind a surface its constraint acts [m]: depth_in_cells h, or with a stencil reaching 1.5 h
   !> from the particle per axis (bspline2) 1.5 sqrt(dim) h, the farthest a node it touches can lie behind a
   !> wall the particle is in front of (2.1 h in 2-D, 2.6 h in 3-D; docs/theory.md section 1.1) [R].
   pure real(rp) function constraint_depth(grid) result(depth)
      type(grid_t), intent(in) :: grid
      depth = depth_in_cells
      if (grid%ghost > 0) depth = max(depth_in_cells, 1.5_rp * sqrt(real(grid%dim, rp)))
      depth = depth * grid%h
   end function constraint_depth

   !> Its condition (a copy) and the condition's traits.
   pure subroutine set_condition(self, condition)
      class(constraint_t), intent(inout) :: self
      class(surface_condition_t), intent(in) :: condition
      if (allocated(self%condition)) deallocate (self%condition)
      allocate (self%condition, source=condition)
      self%traits = condition%traits()
   end subroutine set_condition

   !> Active during [active_from, active_until), and only if its condition holds at all.
   pure subroutine set_activity(self, time)
      class(constraint_t), intent(inout) :: self
      real(rp), intent(in) :: time
      self%active = time >= self%active_from .and. time < self%active_until .and. self%traits%holds
   end subroutine set_activity

   !> A moving constraint put where its motion has it at `time`; its node list is left as it is (refresh).
   subroutine place(self, grid, time)
      class(constraint_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: time
      if (.not. self%moving) return
      self%shift = self%motion%displacement(time)
      call self%put(grid, self%shift)
   end subroutine place

   !> A moving constraint's node list rebuilt if its displacement differs from the one the list was built at.
   subroutine refresh(self, grid)
      class(constraint_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      if (.not. self%moving) return
      if (all(self%shift == self%nodes_shift) .and. allocated(self%nodes)) return
      self%nodes_shift = self%shift
      call self%find_nodes(grid)
   end subroutine refresh

   !> Step t0 -> t1: placed at t0, its node list rebuilt if it moved since the list was made, and its
   !> velocity the mean over the step (the conditions' v_w).
   subroutine move(self, grid, t0, t1)
      class(constraint_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: t0, t1
      real(rp) :: v(3)
      integer :: dim
      call self%place(grid, t0)
      call self%refresh(grid)
      if (.not. self%moving) return
      dim = grid%dim
      v = self%motion%mean_velocity(t0, t1)
      self%wall_velocity = 0.0_rp
      self%wall_velocity(1:dim) = grid%frame%grid_vector(v(1:dim))
   end subroutine move

   !> The local nodes `nodes`, which of them this rank counts in the loads (`owned`), and each node's arm
   !> from the moment point (grid frame).
   subroutine keep_nodes(self, grid, nodes, owned)
      class(constraint_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: nodes(:)
      logical, intent(in) :: owned(:)
      integer :: i, dim
      dim = grid%dim
      self%nodes = nodes
      self%counted = owned
      if (allocated(self%arm)) deallocate (self%arm)
      allocate (self%arm(3, size(nodes)))
      self%arm = 0.0_rp
      do i = 1, size(nodes)
         self%arm(1:dim, i) = grid%origin(1:dim) + grid%node_indices(nodes(i)) * grid%h - self%moment_point(1:dim)
      end do
   end subroutine keep_nodes

   !> Its nodes among lo..hi (global node indices): those on the surface or behind it within its depth
   !> (behind, within on_surface_tolerance h in front), with its loads' bookkeeping and its taps; with
   !> `with_normals` the normal at each (else its one normal stays).
   subroutine scan_nodes(self, grid, lo, hi, with_normals)
      class(constraint_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: lo(3), hi(3)
      logical, intent(in) :: with_normals
      integer :: dim, n, i, j, l, g(3)
      integer, allocatable :: found(:)
      logical, allocatable :: owned(:)
      real(rp), allocatable :: normals(:, :)
      real(rp) :: x(3), phi
      dim = grid%dim
      allocate (found(max(0, product(hi - lo + 1))), owned(max(0, product(hi - lo + 1))))
      allocate (normals(dim, merge(max(0, product(hi - lo + 1)), 0, with_normals)))
      n = 0
      x = 0.0_rp
      do l = lo(3), hi(3)
         do j = lo(2), hi(2)
            do i = lo(1), hi(1)
               g = [i, j, l]
               x(1:dim) = grid%origin(1:dim) + g(1:dim) * grid%h
               if (.not. self%behind(grid, x(1:dim), on_surface_tolerance * grid%h)) cycle
               n = n + 1
               found(n) = grid%local_node(g(1:dim))
               owned(n) = grid%owns_node(g(1:dim))
               if (with_normals) phi = self%distance(grid, x(1:dim), normals(:, n))
            end do
         end do
      end do
      call self%keep_nodes(grid, found(1:n), owned(1:n))
      if (with_normals) self%normals = normals(:, 1:n)
      call self%place_taps(grid)
   end subroutine scan_nodes

   !> The taps of its sensors on its current nodes: each node's foot point on the surface and the
   !> surface's normal there.
   subroutine place_taps(self, grid)
      class(constraint_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), allocatable :: points(:, :), feet(:, :), normals(:, :)
      real(rp) :: phi
      integer :: i, dim
      if (.not. self%taps%any()) return
      dim = grid%dim
      allocate (points(dim, size(self%nodes)), feet(dim, size(self%nodes)), normals(dim, size(self%nodes)))
      do i = 1, size(self%nodes)
         points(:, i) = grid%origin(1:dim) + grid%node_indices(self%nodes(i)) * grid%h
         normals(:, i) = self%node_normal(i, dim)
         phi = self%distance(grid, points(:, i))
         feet(:, i) = points(:, i) - phi * normals(:, i)
      end do
      call self%taps%place(dim, grid%h, points, feet, normals, grid%frame)
   end subroutine place_taps

   !> The normal it constrains its i-th node along (grid frame).
   pure function node_normal(self, i, dim) result(n)
      class(constraint_t), intent(in) :: self
      integer, intent(in) :: i, dim
      real(rp) :: n(dim)
      n = self%normals(1:dim, min(i, size(self%normals, 2)))
   end function node_normal

   !> Constrain the nodal velocities of its nodes (the condition's law along each node's normal). With
   !> `mass` (nodal masses) and `impulse`, impulse(:, column) gains the momentum it gives the counted nodes,
   !> m_i (v_i^c - v_i^*), and its moment (algorithms.md section 9.1); its sensors' columns are
   !> n_columns + slot. `friction` >= 0 makes it act as a friction
   !> surface with that mu instead of its own condition: a body field against a structure of its &contact
   !> (body_contact). Nodes with `skip(node)` are left alone (a rigid body's nodes: it meets the surfaces as
   !> a body, rigid_bodies).
   pure subroutine constrain(self, dim, velocity, column, n_columns, mass, impulse, friction, skip)
      class(constraint_t), intent(in) :: self
      integer, intent(in) :: dim, column, n_columns
      real(rp), intent(inout) :: velocity(:, :)
      real(rp), intent(in), optional :: mass(:)
      real(rp), intent(inout), optional :: impulse(:, :)
      real(rp), intent(in), optional :: friction
      logical, intent(in), optional :: skip(:)
      integer :: i, node, last
      real(rp) :: before(dim), after(dim), vw(dim), mu
      logical :: recording, masked, coulomb
      recording = present(mass) .and. present(impulse)
      masked = present(skip)
      coulomb = .false.
      mu = 0.0_rp
      if (present(friction)) then
         coulomb = friction >= 0.0_rp
         mu = friction
      end if
      vw = self%wall_velocity(1:dim)
      last = size(self%normals, 2)
      do i = 1, size(self%nodes)
         node = self%nodes(i)
         if (masked) then
            if (skip(node)) cycle
         end if
         before = velocity(:, node)
         if (coulomb) then
            after = friction_node(mu, before, vw, self%normals(:, min(i, last)), self%moving)
         else
            after = self%condition%constrain_node(before, vw, self%normals(:, min(i, last)), self%moving)
         end if
         velocity(:, node) = after
         ! an unchanged node takes no impulse (m (v^c - v^*) = +0 would add nothing either)
         if (all(after == before)) cycle
         if (recording) then
            if (self%counted(i)) call self%record_impulse(column, n_columns, i, mass(node) * (after - before), impulse)
         end if
      end do
   end subroutine constrain

   !> The impulse dp of its i-th node for its load (column `column`) and its sensors' columns
   !> n_columns + slot of `impulse`.
   pure subroutine record_impulse(self, column, n_columns, i, dp, impulse)
      class(constraint_t), intent(in) :: self
      integer, intent(in) :: column, n_columns, i
      real(rp), intent(in) :: dp(:)
      real(rp), intent(inout) :: impulse(:, :)
      integer :: t
      call add_impulse(impulse(:, column), dp, self%arm(1:size(dp), i))
      if (.not. allocated(self%taps%first)) return
      do t = self%taps%first(i), self%taps%first(i + 1) - 1
         call add_tap_impulse(self%taps, t, dp, impulse(:, n_columns + 1:))
      end do
   end subroutine record_impulse

   !> The safeguard's impulse dp on a particle it put back onto the surface at x (grid frame): the load's
   !> column of the pass (add_impulse, about the moment point) and its panels' and load cells' columns.
   subroutine record_particle_impulse(self, grid, pass, dp, x)
      class(constraint_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(safeguard_pass_t), intent(inout) :: pass
      real(rp), intent(in) :: dp(:), x(:)
      real(rp) :: normal(size(x)), phi
      integer :: d
      d = size(dp)
      call add_impulse(pass%impulse, dp, x - self%moment_point(1:d))
      if (.not. self%taps%force_sensors .or. .not. associated(pass%sensor_impulse)) return
      phi = self%distance(grid, x, normal)
      call self%taps%add_point_impulse(d, grid%h, x, normal, grid%frame, dp, pass%sensor_impulse)
   end subroutine record_particle_impulse

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

   !> The first of the local particles that lies behind it (phi < 0), 0 if none; its depth -phi [m].
   integer function first_particle_inside(self, grid, particles, depth) result(found)
      class(constraint_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(out) :: depth
      integer :: p
      real(rp) :: phi
      found = 0
      depth = 0.0_rp
      do p = 1, particles%count
         phi = self%distance(grid, particles%x(:, p))
         if (phi < 0.0_rp) then
            found = p
            depth = -phi
            return
         end if
      end do
   end function first_particle_inside

   logical function unknown_front(self, grid, x, reach)
      class(constraint_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x(:), reach
      unknown_front = .false.
   end function unknown_front

   logical function always_may_cut(self, x, ahead, extra, margin) result(may)
      class(constraint_t), intent(in) :: self
      real(rp), intent(in) :: x(:), ahead, extra, margin
      may = .true.
   end function always_may_cut

   subroutine keep_line_interval(self, grid, point, tangent, lo, hi)
      class(constraint_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: point(:), tangent(:)
      real(rp), intent(inout) :: lo, hi
   end subroutine keep_line_interval

   subroutine keep_interval(self, grid, along, point, wet_lo, wet_hi)
      class(constraint_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: along
      real(rp), intent(in) :: point(:)
      real(rp), intent(inout) :: wet_lo, wet_hi
   end subroutine keep_interval
end module constraint
