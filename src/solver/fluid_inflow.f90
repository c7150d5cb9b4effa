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
!> first_id + (inlet - 1) 2^40 + (k - 1) n_layer + index in the layer, independent of the rank count.
module fluid_inflow
   use kinds, only: rp, i8
   use scene_description, only: scene_t, inlet_spec_t, opening_tangent, opening_far_end, relaxes_to_eos
   use tensor_layout, only: n_components
   use background_grid, only: grid_t
   use domain_decomposition, only: domain_t
   use particle_set, only: particle_set_t
   use boundary_walls, only: wall_t, make_wall, wall_kind_slip, wall_kind_prescribed
   use newtonian_fluid, only: eos_density
   implicit none
   private

   !> Id range reserved for the particles of one inlet.
   integer(i8), parameter :: ids_per_inlet = 2_i8**40
   !> Relative tolerance of "L >= k Dp" (a layer due at exactly t must not be missed by round-off).
   real(rp), parameter :: layer_tolerance = 1.0e-9_rp
   !> Extent tolerance of the opening's nodes, in cells: only nodes on the opening itself are fed.
   real(rp), parameter :: opening_margin = 1.0e-6_rp

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
   contains
      procedure :: injected_length => inlet_injected_length
      procedure :: layers_due => inlet_layers_due
      procedure :: inject => inlet_inject
   end type inlet_t

   public :: build_inlets

contains

   !> The scene's inlets, and their walls appended to `walls` (after the scene's walls, so that the
   !> feeder's prescribed velocity wins where they meet). first_id: the first id after the bodies'. The
   !> walls of inlet i report to load entry n + i, n the number of walls before them (the loads.csv order).
   subroutine build_inlets(scene, grid, first_id, inlets, walls)
      type(scene_t), intent(in) :: scene
      type(grid_t), intent(in) :: grid
      integer(i8), intent(in) :: first_id
      type(inlet_t), allocatable, intent(out) :: inlets(:)
      type(wall_t), allocatable, intent(inout) :: walls(:)
      integer :: i, dim, load
      real(rp) :: far_end(3), lower(3), upper(3), margin, volume_across

      dim = scene%grid%dim
      load = size(walls)
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
            end if
            inlet%density = scene%materials(spec%material_index)%density
            if (relaxes_to_eos(scene%materials(spec%material_index))) &
               inlet%eos_bulk_modulus = scene%materials(spec%material_index)%bulk_modulus
            ! a layer carries rho0 Dp H (W): the particle masses add up to exactly that
            inlet%particle_mass = inlet%density * inlet%spacing * volume_across / product(inlet%across)
            inlet%first_id = first_id + (i - 1) * ids_per_inlet
            inlet%gravity_norm = norm2(scene%gravity(1:dim))
            if (inlet%gravity_norm > 0.0_rp) inlet%up(1:dim) = -scene%gravity(1:dim) / inlet%gravity_norm

            far_end = opening_far_end(spec, dim)
            inlet%stream_top = max(dot_product(inlet%up, spec%point), dot_product(inlet%up, far_end))
            lower = min(spec%point, far_end)
            upper = max(spec%point, far_end)
            margin = opening_margin * scene%grid%cell_size
            load = load + 1
            walls = [walls, make_wall(grid, spec%point, spec%direction, lower, upper, margin, wall_kind_prescribed, &
                                      velocity=spec%velocity * spec%direction, active_from=spec%start_time, &
                                      active_until=spec%end_time, load=load), &
                     make_wall(grid, spec%point, spec%direction, lower, upper, margin, wall_kind_slip, &
                               active_from=spec%end_time, load=load)]
            if (spec%start_time > 0.0_rp) &
               walls = [walls, make_wall(grid, spec%point, spec%direction, lower, upper, margin, wall_kind_slip, &
                                         active_until=spec%start_time, load=load)]
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

   !> L(t) = v0 (min(t, t_end) - t_start), 0 before the inlet opens [m].
   pure real(rp) function inlet_injected_length(self, t) result(length)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t
      length = self%spec%velocity * max(0.0_rp, min(t, self%spec%end_time) - self%spec%start_time)
   end function inlet_injected_length

   !> Create this rank's particles of the layers that come into existence between t_before and t_after.
   !> Returns how many particles this rank created.
   integer function inlet_inject(self, t_before, t_after, grid, domain, particles) result(created)
      class(inlet_t), intent(in) :: self
      real(rp), intent(in) :: t_before, t_after
      type(grid_t), intent(in) :: grid
      type(domain_t), intent(in) :: domain
      type(particle_set_t), intent(inout) :: particles
      integer(i8) :: k, first, last
      integer :: a, b, dim, c(3)
      real(rp) :: length, downstream, x(3), x_grid(3), v_grid(3), pressure, rho
      real(rp), allocatable :: sbar(:)

      created = 0
      first = self%layers_due(t_before) + 1
      last = self%layers_due(t_after)
      if (last < first) return
      dim = grid%dim
      allocate (sbar(n_components(dim)))
      length = self%injected_length(t_after)
      v_grid = 0.0_rp
      v_grid(1:dim) = grid%frame%grid_vector(self%spec%velocity * self%spec%direction(1:dim))
      x_grid = 0.0_rp
      do k = first, last
         downstream = length - (real(k, rp) - 0.5_rp) * self%spacing
         do b = 0, self%across(2) - 1
            do a = 0, self%across(1) - 1
               x = self%spec%point + downstream * self%spec%direction + (a + 0.5_rp) * self%across_spacing(1) * self%tangent
               if (dim == 3) x(3) = x(3) + (b + 0.5_rp) * self%across_spacing(2)
               x_grid(1:dim) = grid%frame%grid_point(x(1:dim))
               c = grid%cell_of_position(x_grid(1:dim))
               if (.not. domain%owns_cell(c(1:dim))) cycle
               sbar = 0.0_rp
               rho = self%density
               if (self%spec%hydrostatic) then
                  pressure = self%density * self%gravity_norm * max(0.0_rp, self%stream_top - dot_product(self%up, x))
                  if (self%eos_bulk_modulus > 0.0_rp) rho = eos_density(self%density, self%eos_bulk_modulus, pressure)
                  sbar(1:3) = -pressure / rho
               end if
               call particles%add(x_grid(1:dim), v_grid(1:dim), self%particle_mass, rho, sbar, &
                                  self%spec%material_index, &
                                  self%first_id + (k - 1) * product(int(self%across, i8)) + a + int(self%across(1), i8) * b)
               created = created + 1
            end do
         end do
      end do
   end function inlet_inject
end module fluid_inflow
