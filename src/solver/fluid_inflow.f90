!> Fluid inflow through an opening (algorithms.md section 4.3 [R]).
!>
!> While the inlet is open, fluid of height H (and width W in 3-D) enters at speed v0: the injected
!> length is L(t) = v0 (min(t, t_end) - t_start), and layer k (k = 1, 2, ...) of particles, one layer per
!> particle spacing Dp = h / ppc along the flow, exists from the moment L >= k Dp. A new layer is placed
!> where the fluid it represents is by then: centred at L - (k - 1/2) Dp downstream of the opening. Each
!> layer carries rho0 Dp H (W), so the mass flux is rho0 v0 H exactly, up to the last partial layer
!> (< rho0 Dp H) when the inlet closes. The number of layers is a function of time alone, so a restart
!> needs no inflow state.
!> The nodes on and just behind the opening carry v0 while it is open (the "feeder" of section 4.3, so
!> back-pressure cannot push the stream out) and become a slip wall once it closes (and before it opens).
!> Every rank creates the particles of a layer that fall in its own cells; ids are
!> first_id + (inlet - 1) 2^40 + (k - 1) n_layer + index in the layer, independent of the rank count
!> (n_layer: the particles across the whole opening).
!>
!> A hydrograph (`velocity_file`, a time table v(t) [and H(t)], piecewise linear in t): L(t) is the table's
!> exact integral of v from t_start, so the layers are still a function of time alone, and new particles
!> and the feeder carry v at the end of the step. With height_from_file, layer k holds exactly the fluid
!> that entered while L went from (k - 1) Dp to k Dp: mass rho0 int v H dt over [t_(k-1), t_k], with
!> L(t_k) = k Dp (found by bisection in t, the integral of the product of the two linear pieces by
!> Simpson's rule, exact for it); its height is the mean Hk = mass / (rho0 Dp (W)), and it gets
!> nint(Hk / Dp) particles across (at least 1) spaced evenly over Hk, so the mass flux is rho0 v H exactly
!> up to the last partial layer, and the particle spacing stays near Dp as H changes [R].
module fluid_inflow
   use kinds, only: rp, i8
   use scene_description, only: scene_t, inlet_spec_t, opening_tangent, opening_far_end, relaxes_to_eos, &
                                has_velocity_file
   use time_table, only: time_table_t
   use tensor_layout, only: n_components
   use background_grid, only: grid_t
   use domain_decomposition, only: domain_t
   use particle_set, only: particle_set_t
   use constraint_list, only: constraint_list_t
   use newtonian_fluid, only: eos_density
   use material_model, only: material_slot_t
   use step_component, only: step_component_t, step_state_t
   implicit none
   private

   !> Id range reserved for the particles of one inlet.
   integer(i8), parameter :: ids_per_inlet = 2_i8**40
   !> Relative tolerance of "L >= k Dp" (a layer due at exactly t must not be missed by round-off).
   real(rp), parameter :: layer_tolerance = 1.0e-9_rp

   type, public :: inlet_t
      type(inlet_spec_t) :: spec
      real(rp) :: tangent(3) = 0.0_rp          !< world direction of `height`: (-d_y, d_x, 0)
      real(rp) :: spacing = 0.0_rp             !< Dp along the flow [m]
      integer :: across(2) = 1                 !< particles across the opening: along the tangent, along z
      real(rp) :: across_spacing(2) = 1.0_rp   !< their spacing [m]
      real(rp) :: particle_mass = 0.0_rp, density = 0.0_rp
      real(rp) :: eos_bulk_modulus = 0.0_rp     !< > 0: particles enter in the EOS state of their pressure
      real(rp) :: up(3) = 0.0_rp, gravity_norm = 0.0_rp, stream_top = 0.0_rp
      integer(i8) :: first_id = 0
      logical :: hydrograph = .false.          !< the speed (and height) follow `table`
      type(time_table_t) :: table              !< velocity_file: columns velocity[, height]
      real(rp) :: depth = 1.0_rp               !< W in 3-D, 1 in 2-D [m]
      integer :: feeder = 0                    !< the constraint that is its feeder (prescribed velocity)
   contains
      procedure :: injected_length => inlet_injected_length
      procedure :: layers_due => inlet_layers_due
      procedure :: speed => inlet_speed
      procedure :: peak_speed => inlet_peak_speed
      procedure :: layer_mass => inlet_layer_mass
      procedure :: time_of_length => inlet_time_of_length
      procedure :: feed => inlet_feed
      procedure :: inject => inlet_inject
   end type inlet_t

   !> The scene's inlets as a component of the step (step_component): the feeders' speeds before the walls
   !> move, the new layers at the end of the step.
   type, extends(step_component_t), public :: inflow_t
      type(inlet_t), allocatable :: inlets(:)
   contains
      procedure :: before_walls_move => inflow_feed
      procedure :: end_step => inflow_inject
      procedure :: signal_speed => inflow_signal_speed
      procedure :: lightest_particle => inflow_lightest_particle
      procedure :: supplies => inflow_supplies
   end type inflow_t

   public :: build_inlets

contains

   !> A hydrograph's feeder carries the speed of the fluid injected at the end of this step.
   subroutine inflow_feed(self, state)
      class(inflow_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      integer :: i
      do i = 1, size(self%inlets)
         call self%inlets(i)%feed(state%constraints, state%grid, state%time + state%dt)
      end do
   end subroutine inflow_feed

   !> The layers due within the step, this rank's particles of them.
   integer function inflow_inject(self, state) result(created)
      class(inflow_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      integer :: i
      created = 0
      do i = 1, size(self%inlets)
         created = created + self%inlets(i)%inject(state%time, state%time + state%dt, state%grid, state%domain, &
                                                   state%particles)
      end do
   end function inflow_inject

   !> An inlet that is not closed yet counts as a particle of its fluid at rho0 moving at v0 (a hydrograph:
   !> its largest speed until it closes): the step must resolve the fluid it is about to create. With a
   !> fixed step, the speed alone.
   real(rp) function inflow_signal_speed(self, time, materials, dim, fixed_step) result(speed)
      class(inflow_t), intent(in) :: self
      real(rp), intent(in) :: time
      type(material_slot_t), intent(in) :: materials(:)
      integer, intent(in) :: dim
      logical, intent(in) :: fixed_step
      integer :: i
      speed = 0.0_rp
      do i = 1, size(self%inlets)
         associate (inlet => self%inlets(i), spec => self%inlets(i)%spec)
            if (time >= spec%end_time) cycle
            if (fixed_step) then
               speed = max(speed, inlet%peak_speed(time))
            else
               speed = max(speed, materials(spec%material_index)%model%wave_speed(inlet%density) &
                           + sqrt(sum((inlet%peak_speed(time) * spec%direction(1:dim))**2)))
            end if
         end associate
      end do
   end function inflow_signal_speed

   real(rp) function inflow_lightest_particle(self) result(mass)
      class(inflow_t), intent(in) :: self
      integer :: i
      mass = huge(1.0_rp)
      do i = 1, size(self%inlets)
         mass = min(mass, self%inlets(i)%particle_mass)
      end do
   end function inflow_lightest_particle

   !> An inlet of material m that has opened by `time`.
   logical function inflow_supplies(self, m, time) result(supplies)
      class(inflow_t), intent(in) :: self
      integer, intent(in) :: m
      real(rp), intent(in) :: time
      integer :: i
      supplies = .false.
      do i = 1, size(self%inlets)
         if (self%inlets(i)%spec%material_index == m .and. time >= self%inlets(i)%spec%start_time) supplies = .true.
      end do
   end function inflow_supplies

   !> The scene's inlets; their feeder and closing walls are constraints (constraint_factory), inlet i's
   !> feeder constraints%feeder(i). first_id: the first id after the bodies'.
   subroutine build_inlets(scene, first_id, constraints, inlets)
      type(scene_t), intent(in) :: scene
      integer(i8), intent(in) :: first_id
      type(constraint_list_t), intent(in) :: constraints
      type(inlet_t), allocatable, intent(out) :: inlets(:)
      integer :: i, dim
      real(rp) :: far_end(3), volume_across

      dim = scene%grid%dim
      if (.not. allocated(scene%inlets)) then
         allocate (inlets(0))
         return
      end if
      allocate (inlets(size(scene%inlets)))
      do i = 1, size(inlets)
         associate (inlet => inlets(i), spec => scene%inlets(i))
            inlet%spec = spec
            inlet%tangent = opening_tangent(spec)
            inlet%spacing = scene%grid%cell_size / spec%particles_per_cell
            inlet%across = 1
            inlet%across(1) = max(1, nint(spec%height / inlet%spacing))
            if (dim == 3) inlet%across(2) = max(1, nint(spec%width / inlet%spacing))
            inlet%across_spacing(1) = spec%height / inlet%across(1)
            volume_across = spec%height
            if (dim == 3) then
               inlet%across_spacing(2) = spec%width / inlet%across(2)
               volume_across = spec%height * spec%width
               inlet%depth = spec%width
            end if
            inlet%density = scene%materials(spec%material_index)%density
            if (relaxes_to_eos(scene%materials(spec%material_index))) &
               inlet%eos_bulk_modulus = scene%materials(spec%material_index)%bulk_modulus
            ! a layer carries rho0 Dp H (W): the particle masses add up to exactly that
            inlet%particle_mass = inlet%density * inlet%spacing * volume_across / product(inlet%across)
            inlet%first_id = first_id + (i - 1) * ids_per_inlet
            inlet%hydrograph = has_velocity_file(spec)
            if (inlet%hydrograph) inlet%table = scene%inlet_tables(i)
            inlet%gravity_norm = norm2(scene%gravity(1:dim))
            if (inlet%gravity_norm > 0.0_rp) inlet%up(1:dim) = -scene%gravity(1:dim) / inlet%gravity_norm

            far_end = opening_far_end(spec, dim)
            inlet%stream_top = max(dot_product(inlet%up, spec%point), dot_product(inlet%up, far_end))
            inlet%feeder = constraints%feeder(i)
         end associate
      end do
   end subroutine build_inlets

   !> Number of layers that exist at time t: floor(L(t) / Dp).
   pure integer(i8) function inlet_layers_due(self, t) result(layers)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t
      layers = 0
      if (t <= self%spec%start_time) return
      layers = floor(self%injected_length(t) / self%spacing + layer_tolerance, i8)
   end function inlet_layers_due

   !> L(t) = v0 (min(t, t_end) - t_start), or the integral of the table's v over [t_start, min(t, t_end)];
   !> 0 before the inlet opens [m].
   pure real(rp) function inlet_injected_length(self, t) result(length)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp), allocatable :: area(:)
      if (self%hydrograph) then
         area = self%table%integral(self%spec%start_time, max(self%spec%start_time, min(t, self%spec%end_time)))
         length = area(1)
      else
         length = self%spec%velocity * max(0.0_rp, min(t, self%spec%end_time) - self%spec%start_time)
      end if
   end function inlet_injected_length

   !> The inflow speed at time t [m/s]: v0, or the table's v(t).
   pure real(rp) function inlet_speed(self, t) result(speed)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp), allocatable :: v(:)
      speed = self%spec%velocity
      if (.not. self%hydrograph) return
      v = self%table%value_at(t)
      speed = v(1)
   end function inlet_speed

   !> The largest inflow speed from t until the inlet closes (the time step must resolve it): v0, or the
   !> largest of v(t) and of the table's rows before t_end (v is linear between rows).
   pure real(rp) function inlet_peak_speed(self, t) result(speed)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp), allocatable :: v(:)
      integer :: r
      speed = self%spec%velocity
      if (.not. self%hydrograph) return
      v = self%table%value_at(t)
      speed = v(1)
      v = self%table%value_at(self%spec%end_time)
      speed = max(speed, v(1))
      do r = 1, size(self%table%time)
         if (self%table%time(r) > t .and. self%table%time(r) < self%spec%end_time) &
            speed = max(speed, self%table%values(1, r))
      end do
   end function inlet_peak_speed

   !> Mass of layer k [kg, kg/m in 2-D]: rho0 Dp H (W), or with height_from_file rho0 (W) times the
   !> integral of v H dt over the times the layer entered, [t_(k-1), t_k] with L(t_k) = k Dp.
   pure real(rp) function inlet_layer_mass(self, k) result(mass)
      class(inlet_t), intent(in) :: self
      integer(i8), intent(in) :: k
      if (.not. (self%hydrograph .and. self%spec%height_from_file)) then
         mass = self%particle_mass * product(self%across)
         return
      end if
      mass = self%density * self%depth * flux_integral(self%table, self%time_of_length(real(k - 1, rp) * self%spacing), &
                                                  self%time_of_length(real(k, rp) * self%spacing))
   end function inlet_layer_mass

   !> The time at which L(t) = length (the first such time where v = 0 for a while): bisection in
   !> [t_start, t_end], to round-off; a function of `length` alone.
   pure real(rp) function inlet_time_of_length(self, length) result(t)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: length
      real(rp) :: lower, upper, middle
      integer :: i
      lower = self%spec%start_time
      t = lower
      if (length <= 0.0_rp) return
      upper = min(self%spec%end_time, max(self%table%time(size(self%table%time)), lower))
      ! beyond the table the speed is held: L grows linearly, so an upper end is found by doubling
      ! (a table ending at v = 0 may never reach `length`: 1000 doublings stay far below huge)
      do i = 1, 1000
         if (self%injected_length(upper) >= length .or. upper >= self%spec%end_time) exit
         upper = lower + 2.0_rp * (upper - lower) + 1.0_rp
      end do
      upper = min(upper, self%spec%end_time)
      do i = 1, 200
         middle = 0.5_rp * (lower + upper)
         if (.not. (middle > lower .and. middle < upper)) exit
         if (self%injected_length(middle) < length) then
            lower = middle
         else
            upper = middle
         end if
      end do
      t = upper
   end function inlet_time_of_length

   !> Set the feeder wall's prescribed velocity to the inflow speed at time t (a hydrograph; a constant
   !> inlet's feeder keeps v0 from build_inlets).
   subroutine inlet_feed(self, constraints, grid, t)
      class(inlet_t), intent(in) :: self
      type(constraint_list_t), intent(inout) :: constraints
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: t
      integer :: dim
      if (.not. self%hydrograph) return
      dim = grid%dim
      call constraints%items(self%feeder)%item%condition%prescribe( &
         grid%frame%grid_vector(self%speed(t) * self%spec%direction(1:dim)))
   end subroutine inlet_feed

   !> The integral of v H dt over [t0, t1] for a table of columns (velocity, height): per piece between
   !> rows both are linear, their product quadratic, so Simpson's rule is exact on each piece.
   pure real(rp) function flux_integral(table, t0, t1) result(total)
      type(time_table_t), intent(in) :: table
      real(rp), intent(in) :: t0, t1
      real(rp) :: a, b
      integer :: r
      total = 0.0_rp
      a = t0
      do r = 1, size(table%time) + 1
         if (a >= t1) exit
         b = t1
         if (r <= size(table%time)) b = min(t1, table%time(r))
         if (b > a) then
            total = total + (b - a) / 6.0_rp * (product_at(a) + 4.0_rp * product_at(0.5_rp * (a + b)) + product_at(b))
            a = b
         end if
      end do
   contains
      pure real(rp) function product_at(t)
         real(rp), intent(in) :: t
         real(rp) :: v(size(table%columns))
         v = table%value_at(t)
         product_at = v(1) * v(2)
      end function product_at
   end function flux_integral

   !> Create this rank's particles of the layers that come into existence between t_before and t_after.
   !> Returns how many particles this rank created.
   integer function inlet_inject(self, t_before, t_after, grid, domain, particles) result(created)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t_before, t_after
      type(grid_t), intent(in) :: grid
      type(domain_t), intent(in) :: domain
      type(particle_set_t), intent(inout) :: particles
      integer(i8) :: k, first, last
      integer :: a, b, dim, c(3), n_across
      real(rp) :: length, downstream, x(3), x_grid(3), v_grid(3), pressure, rho, spacing_across, mass, stream_top, &
                  layer_height, layer_mass
      real(rp), allocatable :: sbar(:)

      created = 0
      first = self%layers_due(t_before) + 1
      last = self%layers_due(t_after)
      if (last < first) return
      dim = grid%dim
      allocate (sbar(n_components(dim)))
      length = self%injected_length(t_after)
      v_grid = 0.0_rp
      v_grid(1:dim) = grid%frame%grid_vector(self%speed(t_after) * self%spec%direction(1:dim))
      x_grid = 0.0_rp
      n_across = self%across(1)
      spacing_across = self%across_spacing(1)
      mass = self%particle_mass
      stream_top = self%stream_top
      do k = first, last
         downstream = length - (real(k, rp) - 0.5_rp) * self%spacing
         if (self%hydrograph .and. self%spec%height_from_file) then
            ! the layer's mean height Hk, nint(Hk / Dp) particles across it (never more than the opening holds)
            layer_mass = self%layer_mass(k)
            layer_height = layer_mass / (self%density * self%spacing * self%depth)
            n_across = min(self%across(1), max(1, nint(layer_height / self%spacing)))
            spacing_across = layer_height / n_across
            mass = layer_mass / (n_across * self%across(2))
            stream_top = max(dot_product(self%up, self%spec%point), &
                             dot_product(self%up, self%spec%point + layer_height * self%tangent))
         end if
         do b = 0, self%across(2) - 1
            do a = 0, n_across - 1
               x = self%spec%point + downstream * self%spec%direction + (a + 0.5_rp) * spacing_across * self%tangent
               if (dim == 3) x(3) = x(3) + (b + 0.5_rp) * self%across_spacing(2)
               x_grid(1:dim) = grid%frame%grid_point(x(1:dim))
               c = grid%cell_of_position(x_grid(1:dim))
               if (.not. domain%owns_cell(c(1:dim))) cycle
               sbar = 0.0_rp
               rho = self%density
               if (self%spec%hydrostatic) then
                  pressure = self%density * self%gravity_norm * max(0.0_rp, stream_top - dot_product(self%up, x))
                  if (self%eos_bulk_modulus > 0.0_rp) rho = eos_density(self%density, self%eos_bulk_modulus, pressure)
                  sbar(1:3) = -pressure / rho
               end if
               call particles%add(x_grid(1:dim), v_grid(1:dim), mass, rho, sbar, self%spec%material_index, &
                                  self%first_id + (k - 1) * product(int(self%across, i8)) + a + int(n_across, i8) * b)
               created = created + 1
            end do
         end do
      end do
   end function inlet_inject
end module fluid_inflow
