!> The boundary constraints of a run, as one list in the order of loads.csv's entries (load_entries;
!> built by constraint_factory): what the step asks of its boundary. Constraints are applied in turn,
!> which is exact at a corner of two orthogonal walls (algorithms.md section 4.1); an inlet's feeder,
!> listed after the scene's walls, wins. Constraint w's impulse goes to column w of an impulse accumulator
!> (impulse_rows, w), its sensors' after every constraint's (wall_loads).
module constraint_list
   use kinds, only: rp
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use surface_sensors, only: surface_sensor_t, tangent_axes, patch_weight, sensor_panel, sensor_load_cell
   use constraint, only: constraint_t, constraint_slot_t, safeguard_pass_t
   implicit none
   private

   type, public :: constraint_list_t
      type(constraint_slot_t), allocatable :: items(:)
      !> per constraint: its &structure's number (0: not one), its loads.csv entry (0: none) and whether it
      !> closes the fluid's space (its condition's traits); whether it acts now: activity()
      integer, allocatable :: structure(:), loads(:)
      logical, allocatable :: blocks_flow(:)
      integer, allocatable :: feeder(:)      !< per &inlet: the constraint that is its feeder
   contains
      procedure :: count => list_count
      procedure :: append
      procedure :: set_activity => list_set_activity
      procedure :: activity => list_activity
      procedure :: constrain => list_constrain
      procedure :: keep_particles_inside
      procedure :: move => list_move
      procedure :: place => list_place
      procedure :: moving_speed
      procedure :: attach_sensors
      procedure :: of_structure
   end type constraint_list_t

contains

   pure integer function list_count(self) result(n)
      class(constraint_list_t), intent(in) :: self
      n = 0
      if (allocated(self%items)) n = size(self%items)
   end function list_count

   !> Add `item` at the end (its structure number `structure`, 0 if it is not a structure); returns its place.
   subroutine append(self, item, structure, place)
      class(constraint_list_t), intent(inout) :: self
      class(constraint_t), intent(in) :: item
      integer, intent(in) :: structure
      integer, intent(out), optional :: place
      type(constraint_slot_t), allocatable :: grown(:)
      integer :: i, n
      n = self%count()
      allocate (grown(n + 1))
      do i = 1, n
         call move_alloc(self%items(i)%item, grown(i)%item)
      end do
      allocate (grown(n + 1)%item, source=item)
      call move_alloc(grown, self%items)
      if (.not. allocated(self%structure)) allocate (self%structure(0), self%loads(0), self%blocks_flow(0))
      self%structure = [self%structure, structure]
      self%loads = [self%loads, item%load]
      self%blocks_flow = [self%blocks_flow, item%traits%blocks_flow]
      if (present(place)) place = n + 1
   end subroutine append

   !> The constraint that is &structure s.
   pure integer function of_structure(self, s) result(w)
      class(constraint_list_t), intent(in) :: self
      integer, intent(in) :: s
      w = findloc(self%structure, s, 1)
   end function of_structure

   pure subroutine list_set_activity(self, time)
      class(constraint_list_t), intent(inout) :: self
      real(rp), intent(in) :: time
      integer :: w
      do w = 1, self%count()
         call self%items(w)%item%set_activity(time)
      end do
   end subroutine list_set_activity

   !> Per constraint: it acts now (its activity window holds the time of the last set_activity).
   pure function list_activity(self) result(active)
      class(constraint_list_t), intent(in) :: self
      logical :: active(self%count())
      integer :: w
      do w = 1, self%count()
         active(w) = self%items(w)%item%active
      end do
   end function list_activity

   !> Constrain nodal velocities, each active constraint in turn (constraint_t%constrain_nodes). With
   !> `mass` and `impulse`, impulse(:, w) gains what constraint w gives the counted nodes. `friction`
   !> (per constraint), where >= 0, makes constraint w a friction surface with that mu (body_contact); nodes
   !> with `skip(node)` are left alone (rigid_bodies).
   pure subroutine list_constrain(self, dim, velocity, mass, impulse, friction, skip)
      class(constraint_list_t), intent(in) :: self
      integer, intent(in) :: dim
      real(rp), intent(inout) :: velocity(:, :)
      real(rp), intent(in), optional :: mass(:)
      real(rp), intent(inout), optional :: impulse(:, :)
      real(rp), intent(in), optional :: friction(:)
      logical, intent(in), optional :: skip(:)
      integer :: w, n
      n = self%count()
      do w = 1, n
         associate (c => self%items(w)%item)
            if (.not. c%active) cycle
            if (present(friction)) then
               call c%constrain(dim, velocity, w, n, mass, impulse, friction(w), skip)
            else
               call c%constrain(dim, velocity, w, n, mass, impulse, skip=skip)
            end if
         end associate
      end do
   end subroutine list_constrain

   !> Particle safeguard (algorithms.md section 4.2): a particle found behind an active constraint is put
   !> back onto its surface as the constraint says (its keep_out). Counts corrections; impulse(:, w) gains
   !> the momentum (and its moment) that constraint w gave the particles it corrected. With contact fields
   !> (all three or none): `field` (particle) the velocity field of each particle (0: the common one),
   !> `field_friction` (constraint, field) the mu a structure applies to that field instead of its condition
   !> (< 0: its condition), and field_impulse(:, w, f) gains the part of impulse(:, w) given to field f's
   !> particles. Columns of `impulse` after the constraints' are the sensors' (surface_sensors: panels and
   !> load cells gain their part of the safeguard's impulse). The particles of a material with
   !> `skip(material)` are left alone: rigid bodies meet the walls as bodies (rigid_bodies). lowest(1:dim),
   !> highest(1:dim): bounds on the particles' coordinates (the step's extent, which G2P takes as it moves
   !> them; wider is fine). They only let a pass be skipped when no particle can be behind a constraint; a
   !> pass of their own over the particles was 3 % of a 2-D step.
   subroutine keep_particles_inside(self, grid, particles, lowest, highest, corrections, impulse, field, &
                                    field_friction, field_impulse, skip)
      class(constraint_list_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      real(rp), intent(in) :: lowest(:), highest(:)
      integer, intent(inout) :: corrections
      real(rp), intent(inout), target, contiguous :: impulse(:, :)
      integer, intent(in), optional, target :: field(:)
      real(rp), intent(in), optional, target :: field_friction(:, :)
      real(rp), intent(inout), optional, target :: field_impulse(:, :, :)
      logical, intent(in), optional :: skip(:)
      type(safeguard_pass_t) :: pass
      integer :: w, d
      if (.not. any(self%activity())) return
      d = size(lowest)
      pass%lowest(1:d) = lowest(1:d)
      pass%highest(1:d) = highest(1:d)
      if (present(skip)) then
         pass%skip = skip
      else
         allocate (pass%skip(max(1, maxval(particles%material(1:particles%count), 1))))
         pass%skip = .false.
      end if
      pass%corrections = corrections
      if (present(field)) pass%field => field
      ! the sensors' columns follow the constraints' (panels and load cells take the safeguard's part)
      if (size(impulse, 2) > self%count()) pass%sensor_impulse => impulse(:, self%count() + 1:)
      do w = 1, self%count()
         associate (c => self%items(w)%item)
            if (.not. c%active) cycle
            pass%impulse => impulse(:, w)
            if (present(field)) then
               pass%field_friction => field_friction(w, :)
               pass%field_impulse => field_impulse(:, w, :)
            end if
            call c%keep_out(grid, particles, pass)
         end associate
      end do
      corrections = pass%corrections
   end subroutine keep_particles_inside

   !> Step t0 -> t1: every moving constraint placed at t0, its node list rebuilt if it moved, its velocity
   !> the mean over the step.
   subroutine list_move(self, grid, t0, t1)
      class(constraint_list_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: t0, t1
      integer :: w
      do w = 1, self%count()
         call self%items(w)%item%move(grid, t0, t1)
      end do
   end subroutine list_move

   !> Every moving constraint put where its motion has it at `time` (node lists unchanged).
   subroutine list_place(self, grid, time)
      class(constraint_list_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: time
      integer :: w
      do w = 1, self%count()
         call self%items(w)%item%place(grid, time)
      end do
   end subroutine list_place

   !> The largest speed of the moving constraints over [t0, t1] [m/s] (0 without any).
   real(rp) function moving_speed(self, t0, t1) result(speed)
      class(constraint_list_t), intent(in) :: self
      real(rp), intent(in) :: t0, t1
      integer :: w
      speed = 0.0_rp
      do w = 1, self%count()
         associate (c => self%items(w)%item)
            if (c%moving) speed = max(speed, c%motion%max_speed(t0, t1))
         end associate
      end do
   end function moving_speed

   !> Put the sensors `sensors` (gauges: their point in the world frame and radius; panels and load cells:
   !> their box) on the constraints of the loads.csv entries `entries` (per sensor; 0: every constraint, a
   !> load cell without a wall). A gauge's or panel's centre is moved onto the surface, with the surface's
   !> normal there and the intervals it can be wetted along grid axes (the scene box, cut by the planar
   !> walls across them); then their taps. `offset` (per sensor) is how far the given point (a panel: its
   !> box, along the normal) lay from the surface [m], `outside` the part of a panel's area that lies off
   !> the wettable surface (the caller refuses a sensor off its surface; both 0 for load cells).
   subroutine attach_sensors(self, grid, sensors, entries, offset, outside)
      class(constraint_list_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(surface_sensor_t), intent(in) :: sensors(:)
      integer, intent(in) :: entries(:)
      real(rp), intent(out) :: offset(:), outside(:)
      type(surface_sensor_t) :: sensor
      real(rp) :: x(grid%dim), phi, tangents(grid%dim, grid%dim - 1), weight, area, thickness
      logical :: axes
      integer :: s, w, v, k, along, dim
      dim = grid%dim
      offset = huge(1.0_rp)
      outside = 0.0_rp
      do w = 1, self%count()
         associate (taps => self%items(w)%item%taps)
            if (allocated(taps%sensors)) deallocate (taps%sensors)
            allocate (taps%sensors(0))
         end associate
      end do
      do s = 1, size(sensors)
         if (sensors(s)%kind == sensor_load_cell) offset(s) = 0.0_rp
         do w = 1, self%count()
            associate (c => self%items(w)%item)
               if (c%load /= entries(s) .and. entries(s) /= 0) cycle
               sensor = sensors(s)
               if (sensor%kind == sensor_load_cell) then
                  c%taps%sensors = [c%taps%sensors, sensor]
                  cycle
               end if
               if (sensor%kind == sensor_panel) sensor%point(1:dim) = 0.5_rp * (sensor%lower(1:dim) + sensor%upper(1:dim))
               x = grid%frame%grid_point(sensor%point(1:dim))
               sensor%normal = 0.0_rp
               phi = c%distance(grid, x, sensor%normal(1:dim))
               thickness = 0.0_rp
               if (sensor%kind == sensor_panel) &
                  thickness = abs(dot_product(grid%frame%grid_vector(sensor%upper(1:dim) - sensor%lower(1:dim)), &
                                              sensor%normal(1:dim)))
               offset(s) = min(offset(s), max(0.0_rp, abs(phi) - 0.5_rp * thickness))
               sensor%point = 0.0_rp
               sensor%point(1:dim) = x - phi * sensor%normal(1:dim)
               call tangent_axes(sensor%normal(1:dim), dim, tangents, axes)
               if (.not. axes .and. sensor%kind == sensor_panel) then
                  ! the tangent lines through the panel's centre, cut by the planar walls they cross
                  do k = 1, dim - 1
                     do v = 1, self%count()
                        if (v == w) cycle
                        call self%items(v)%item%narrow_along_line(grid, sensor%point(1:dim), tangents(:, k), &
                                                                  sensor%tangent_lo(k), sensor%tangent_hi(k))
                     end do
                  end do
               end if
               if (axes) then
                  do k = 1, dim - 1
                     along = maxloc(abs(tangents(:, k)), 1)
                     sensor%wet_lo(along) = grid%origin(along)
                     sensor%wet_hi(along) = grid%origin(along) + grid%global_cells(along) * grid%h
                     do v = 1, self%count()
                        if (v == w) cycle
                        call self%items(v)%item%narrow_wet_interval(grid, along, sensor%point(1:dim), &
                                                                    sensor%wet_lo(along), sensor%wet_hi(along))
                     end do
                     ! a panel on a box structure: its face ends at the box's edges
                     if (sensor%kind == sensor_panel) &
                        call c%narrow_own_interval(grid, along, sensor%point(1:dim), sensor%wet_lo(along), &
                                                   sensor%wet_hi(along))
                  end do
               end if
               call sensor%set_patch(dim, grid%frame, grid%origin(1:dim), grid%h)
               if (sensor%kind == sensor_panel) then
                  call patch_weight(sensor, dim, grid%h, sensor%point(1:dim), weight, area)
                  outside(s) = 1.0_rp - area / product(sensor%patch_hi(1:dim - 1) - sensor%patch_lo(1:dim - 1))
               end if
               c%taps%sensors = [c%taps%sensors, sensor]
            end associate
         end do
      end do
      do w = 1, self%count()
         call self%items(w)%item%place_taps(grid)
      end do
   end subroutine attach_sensors
end module constraint_list
