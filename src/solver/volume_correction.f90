!> Fluid volume consistency: options against the artificial compaction of [Y17] section 5
!> (docs/volume-conservation.md). Not part of [Y17]; selected per fluid by `&material volume_correction`.
!>
!> Diagnosis (docs/volume-conservation.md section 2): with C0 and FOAL1 the particles' volumes V_p = m_p/rho_p
!> keep the fluid volume exactly, but the particles themselves crowd together: the cell-averaged rate of
!> deformation does not see velocity modes that bring particles of a cell closer, so nothing resists them,
!> and smoothing, which lowers the pressure, lets gravity drive them. Two corrections:
!>
!>   shifting        measure the crowding and move particles against it. Nodal occupancy
!>                     phi_i = sum_p N_ip V_p / V_i,   V_i = int N_i over the space open to the fluid
!>                   (inside the walls and the grid), is 1 where particles fill space as their volumes say
!>                   and > 1 where they crowd. Particles move down the gradient of the excess
!>                     psi_i = max(phi_i - 1, 0),   dx_p = -D h^2 sum_i grad N_i(x_p) psi_i
!>                   (D = shifting_coefficient per reference step, the automatic step at CFL 0.5; applied
!>                   every k steps with k D a for a step of a reference steps, k = 0.2 / (D a_max) for the
!>                   longest step the scene allows, so that its cost is a k-th; at most 0.1 h and D k a =
!>                   0.25 per application). One-sided: a node that is not
!>                   full (free surface, walls, spray) never pulls particles, so surfaces do not spread.
!>                   Mass, momentum and stress of each particle are kept.
!>                   Under gravity, V_i also leaves out the space above the free surface: a height function
!>                   (the highest particle top over each horizontal bin, all ranks) cuts the supports that
!>                   reach above it, so a crowded layer under the surface reads phi > 1 like any other,
!>                   and a node above the surface has psi = 0, so that the excess drains through it.
!>                   Before measuring, the particles of a shifting material in a cell share one density,
!>                   m_c / V_c (the cell's mass and volume kept): the cell-averaged rate of deformation of C0
!>                   and FOAL1 lets single particles' J wander (to 2.9 rho_0 in the floating block by 30 s,
!>                   10^7 rho_0 with the surface shifting), and phi weighs particles by their volume.
!>   eos_relaxation  pull the pressure back toward the equation of state p_EOS = K ln(rho/rho_0) after the
!>                   smoothing, p := p + r (p_EOS - p) (r = eos_relaxation_rate per reference step; a step
!>                   of a reference steps removes 1 - (1 - r)^a): smoothing may
!>                   then no longer drain the pressure. Seeding and inflow start such fluids at
!>                   rho = rho_0 exp(p/K), so that the hydrostatic state is an EOS state.
!>
!> The occupancy uses the particles of all materials (a solid also fills space), at x^n: the volumes are
!> equalised before the step's particle-to-grid transfer (prepare); the occupancy, the surface and the shifts
!> follow it (measure_excess), reading its stencils (3-D). The shifts are capped and added after the
!> position update, so the wall safeguard and the migration of the step see them. Costs nothing without a
!> fluid that selects it: it is a component of the step (step_component) only when a fluid selects it.
module volume_correction
   use kinds, only: rp, i8
   use communication_counters, only: count_collective, comm_volume, real_bytes
   use mpi_f08, only: MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_MAX
   use scene_description, only: scene_t, shifts_particles, relaxes_to_eos
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use grid_transfer, only: volume_to_grid, gradient_at_particles, transfer_block, extremes_rows
   use stencil_cache, only: stencil_cache_t
   use node_halo, only: sum_shared_nodes
   use particle_set, only: particle_set_t
   use constraint_list, only: constraint_list_t
   use cell_binning, only: cell_list_t, start_cell_list, bin_cell_mass_and_mean
   use newtonian_fluid, only: eos_pressure
   use step_component, only: step_component_t, step_state_t
   implicit none
   private

   public :: part_below, lowest_height      ! for the tests

   !> Samples per cell and axis of the quadrature of V_i (2-D, 3-D); midpoints, so a wall on a node or a
   !> cell face is exact.
   integer, parameter :: samples_per_cell(2:3) = [4, 2]
   !> Nodes open to the fluid over less than this fraction of h^dim are left out of the shifting: their
   !> occupancy is a ratio of two slivers.
   real(rp), parameter :: min_open_fraction = 0.2_rp
   !> A sample closer to a wall than this fraction of h lies on it.
   real(rp), parameter :: on_wall_tolerance = 1.0e-9_rp
   !> The shifting runs every k steps with k D per application, k the largest with k D <= this: the
   !> crowding builds over thousands of steps, so a k-th of the cost buys the same correction.
   real(rp), parameter :: coefficient_per_application = 0.2_rp
   !> Above this D k per application the explicit diffusion of the shifting is unstable (docs/input.md).
   real(rp), parameter :: stable_coefficient_per_application = 0.25_rp
   !> Largest shift per application, in cells (the particles' extent widens by it: particles_moved).
   real(rp), parameter :: max_shift_in_cells = 0.1_rp
   !> Horizontal bins of the height function per cell width (2-D, 3-D): finer than a particle at 3 per cell,
   !> so that a tilted surface is followed to a fraction of a particle.
   integer, parameter :: bins_per_cell(2:3) = [8, 4]
   !> Sub-cells per cell and axis of V_i at a node cut by the free surface (2-D, 3-D). Each sub-cell counts
   !> its exact part below the surface plane, weighted at that part's centroid height, so a surface normal
   !> to a grid axis is integrated exactly with any number; a turned one (2-D: the grid rotates about z)
   !> needs finer sub-cells. In 3-D gravity is normal to the grid's xy plane (the grid rotates about z):
   !> 2, a quarter of the cost of the surface measure at 4 (17 % of a 3-D step at 4, 3 % at 2).
   integer, parameter :: surface_samples_per_cell(2:3) = [8, 2]
   !> No particle over a bin yet.
   real(rp), parameter :: no_surface = -huge(1.0_rp)

   type, extends(step_component_t), public :: volume_corrector_t
      real(rp), allocatable :: shifting_coefficient(:)  !< per material: D, 0 without shifting
      real(rp), allocatable :: relaxation_rate(:)       !< per material: r, 0 without EOS relaxation
      real(rp), allocatable :: bulk_modulus(:), reference_density(:)
      logical :: shifting = .false.                 !< some material shifts
      logical :: relaxing = .false.                 !< some material relaxes its pressure to the EOS
      integer :: interval = 1                       !< steps between two applications of the shifting
      real(rp) :: reference_steps = 1.0_rp          !< this step's length in reference steps (step_state_t)
      logical :: shifting_now = .false.             !< this step applies it
      real(rp) :: gravity(3) = 0.0_rp               !< grid frame: the hydrostatic pressure change of a shift
      real(rp), allocatable :: open_volume(:)       !< V_i per local node [m^dim], walls only
      logical, allocatable :: fully_open(:)         !< no wall nor the grid's edge cuts the node's support
      real(rp), allocatable :: fluid_volume(:)      !< V_i cut by the free surface [m^dim]
      type(cell_list_t) :: occupied                 !< the cells holding one shifting material's particles
      real(rp), allocatable :: cell_mass(:)         !< per cell: that material's mass
      real(rp), allocatable :: cell_average(:, :)   !< per cell: its mean specific volume, then its inverse (work)
      real(rp), allocatable :: specific_volume(:, :) !< (1, p): 1 / rho_p of a material's slice (work, kept)
      logical :: surface_model = .false.            !< under gravity: V_i knows where the free surface is
      real(rp) :: up(3) = 0.0_rp                    !< against gravity, unit (grid frame)
      real(rp) :: horizontal(3, 2) = 0.0_rp         !< unit vectors normal to up (dim - 1 of them)
      real(rp), allocatable :: surface_height(:, :) !< highest particle top over each horizontal bin [m]
      real(rp) :: bin_lo(2) = 0.0_rp, bin_width = 0.0_rp
      logical, allocatable :: wall_activity(:)      !< walls' activity V_i was measured with
      real(rp), allocatable :: excess(:, :)         !< (1, node): occupancy, then psi_i
      real(rp), allocatable :: block_extremes(:, :) !< per block of the occupancy's transfer (grid_transfer)
      real(rp), allocatable :: shift(:, :)          !< (dim, p): displacement added after the position update, uncapped
      real(rp) :: longest_shift = 0.0_rp             !< the cap of a shift [m]
      !> shortcuts that give the same bits (a test compares them with the general way): where up is a grid axis
      !> the surface cut looks the height up once per column of sub-cells, takes the lowest height once per
      !> column of nodes and stops at the first row of sub-cells above the surface; the height function skips
      !> the blocks of particles that raise no bin; the walls far from a node are not tested at its samples; a
      !> cube root per run of particles of one mass and density; the occupancy's and the gradients' transfers
      !> read P2G's stencils (3-D). Off: the general way throughout
      logical :: shortcuts = .true.
   contains
      procedure :: init => corrector_init
      procedure :: reset_grid => corrector_reset_grid
      procedure :: prepare => corrector_prepare
      procedure :: measure_excess => corrector_measure_excess
      procedure :: apply_shifts => corrector_apply_shifts
      procedure :: relax_pressure => corrector_relax_pressure
      ! its stages of the step (step_component)
      procedure :: walls_placed => corrector_walls_placed
      procedure :: grid_summed => corrector_grid_summed
      procedure :: shifts_now => corrector_shifts_now
      procedure :: shift_particles => corrector_apply_shifts
      procedure :: particles_moved => corrector_widen_extent
      procedure :: stress_updated => corrector_stress_updated
      procedure :: layout_changed => corrector_reset_grid
   end type volume_corrector_t

contains

   !> The options of every material of the scene.
   !> `planned_reference_steps`: the longest step the scene's CFL numbers allow, in reference steps (the
   !> shifting's interval is chosen for it).
   subroutine corrector_init(self, scene, gravity, planned_reference_steps)
      class(volume_corrector_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      real(rp), intent(in) :: gravity(3), planned_reference_steps
      integer :: m, n
      self%gravity = gravity
      n = size(scene%materials)
      allocate (self%shifting_coefficient(n), self%relaxation_rate(n), self%bulk_modulus(n), &
                self%reference_density(n))
      do m = 1, n
         associate (spec => scene%materials(m))
            self%bulk_modulus(m) = spec%bulk_modulus
            self%reference_density(m) = spec%density
            self%shifting_coefficient(m) = 0.0_rp
            self%relaxation_rate(m) = 0.0_rp
            if (shifts_particles(spec)) self%shifting_coefficient(m) = spec%shifting_coefficient
            if (relaxes_to_eos(spec)) self%relaxation_rate(m) = spec%eos_relaxation_rate
         end associate
      end do
      self%shifting = any(self%shifting_coefficient > 0.0_rp)
      self%relaxing = any(self%relaxation_rate > 0.0_rp)
      self%surface_model = self%shifting .and. norm2(gravity) > 0.0_rp
      self%longest_shift = max_shift_in_cells * scene%grid%cell_size
      if (self%surface_model) call horizontal_frame(self, scene%grid%dim)
      if (self%shifting) self%interval = max(1, floor(coefficient_per_application / maxval(self%shifting_coefficient) &
                                                       / max(1.0_rp, planned_reference_steps) * (1.0_rp + 1.0e-12_rp)))
   end subroutine corrector_init

   !> The grid changed (layout): V_i is measured again at the next prepare.
   subroutine corrector_reset_grid(self)
      class(volume_corrector_t), intent(inout) :: self
      if (allocated(self%wall_activity)) deallocate (self%wall_activity)
   end subroutine corrector_reset_grid

   !> The stages of the step: prepare with the walls at t_n, measure after P2G, shift inside G2P (the
   !> extent widened by the longest shift), relax after the stress update.
   subroutine corrector_walls_placed(self, state)
      class(volume_corrector_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      self%reference_steps = state%reference_steps
      if (self%shifting) call self%prepare(state%domain, state%grid, state%constraints, state%particles, state%step)
   end subroutine corrector_walls_placed

   subroutine corrector_grid_summed(self, state)
      class(volume_corrector_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      if (self%shifting_now) call self%measure_excess(state%domain, state%grid, state%constraints, state%particles, &
                                                      state%stencils)
   end subroutine corrector_grid_summed

   logical function corrector_shifts_now(self) result(shifts)
      class(volume_corrector_t), intent(in) :: self
      shifts = self%shifting_now
   end function corrector_shifts_now

   subroutine corrector_widen_extent(self, state, extent)
      class(volume_corrector_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      real(rp), intent(inout) :: extent(3, 2)
      if (.not. self%shifting_now) return
      extent(:, 1) = extent(:, 1) - max_shift_in_cells * state%grid%h
      extent(:, 2) = extent(:, 2) + max_shift_in_cells * state%grid%h
   end subroutine corrector_widen_extent

   subroutine corrector_stress_updated(self, state)
      class(volume_corrector_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      if (self%relaxing) call self%relax_pressure(state%particles, state%reference_steps)
   end subroutine corrector_stress_updated

   !> At x^n, before the step's particle-to-grid transfer, on the steps that shift (every interval-th step; by
   !> the step number, so a restart keeps the rhythm): the open volumes where the walls changed and the cells'
   !> volumes equalised.
   subroutine corrector_prepare(self, domain, grid, constraints, particles, step)
      class(volume_corrector_t), intent(inout) :: self
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(in) :: constraints
      type(particle_set_t), intent(inout) :: particles
      integer(i8), intent(in) :: step

      self%shifting_now = self%shifting .and. mod(step, int(self%interval, i8)) == 0
      if (.not. self%shifting_now) return
      if (.not. allocated(self%wall_activity)) then
         call measure_open_volumes(self, grid, constraints)
      else if (any(self%wall_activity .neqv. constraints%activity())) then
         call measure_open_volumes(self, grid, constraints)
      end if
      call equalize_cell_volumes(self, grid, particles)
   end subroutine corrector_prepare

   !> After the step's particle-to-grid transfer, positions still x^n (the transfer does not read the
   !> densities prepare equalised), on the steps that shift: the occupancy, the height function of the free
   !> surface (whose skip of blocks below the surface reads the extremes the occupancy's transfer took), psi_i
   !> and the particles' shifts. Collective. `stencils` (3-D): the transfer's (src/transfer/stencil_cache.f90),
   !> which the occupancy and the gradients read with the shortcuts instead of locating the particles again.
   subroutine corrector_measure_excess(self, domain, grid, constraints, particles, stencils)
      class(volume_corrector_t), intent(inout) :: self
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(in) :: constraints
      type(particle_set_t), intent(in) :: particles
      type(stencil_cache_t), intent(in), optional, target :: stencils
      type(stencil_cache_t), pointer :: kept     ! the stencils read; disassociated (absent) the general way
      integer :: i
      real(rp) :: threshold

      if (.not. self%shifting_now) return
      kept => null()
      if (self%shortcuts .and. present(stencils)) kept => stencils
      if (allocated(self%excess)) then
         if (size(self%excess, 2) /= grid%node_count) deallocate (self%excess)
      end if
      if (.not. allocated(self%excess)) allocate (self%excess(1, grid%node_count))
      self%excess = 0.0_rp
      if (allocated(self%block_extremes)) then
         if (size(self%block_extremes, 2) < (particles%count - 1) / transfer_block + 1) deallocate (self%block_extremes)
      end if
      if (.not. allocated(self%block_extremes)) &
         allocate (self%block_extremes(extremes_rows, (size(particles%x, 2) - 1) / transfer_block + 1))
      ! the occupancy, and the extremes of each block of particles that the height function's skip reads
      call volume_to_grid(grid, particles, self%excess(1, :), kept, self%block_extremes)
      call sum_shared_nodes(domain, grid, self%excess)
      self%fluid_volume = self%open_volume
      if (self%surface_model) then
         call measure_surface_heights(self, domain, grid, particles)
         call cut_by_surface(self, grid, constraints)
      end if
      threshold = min_open_fraction * grid%h**grid%dim
      do i = 1, grid%node_count
         if (self%fluid_volume(i) >= threshold) then
            self%excess(1, i) = max(self%excess(1, i) / self%fluid_volume(i) - 1.0_rp, 0.0_rp)
         else
            self%excess(1, i) = 0.0_rp
         end if
      end do
      ! a node cut by the free surface to a sliver is empty (psi = 0: crowding below may push into it);
      ! one cut by walls to a sliver is unknown (the particle's own excess: walls neither sink nor source)
      call shifts_of_particles(self, grid, particles, self%open_volume >= threshold, kept)
   end subroutine corrector_measure_excess

   !> dx_p = -D k a h^2 sum_a grad N_a psi_a (k = interval, a the step in reference steps: D holds per
   !> reference step; D k a at most the stable 0.25) for the particles of shifting materials (the factor
   !> -D k a h^2 applied per cell by the transfer); the cap at 0.1 h comes with the application (apply_shifts).
   !> A node mostly closed by walls has no reliable occupancy: it takes the particle's own excess (the
   !> N-weighted mean over the reliable corners), so a wall is neither a sink nor a source (zero normal
   !> gradient), where psi = 0 would pull particles onto it.
   subroutine shifts_of_particles(self, grid, particles, reliable, stencils)
      type(volume_corrector_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      logical, intent(in) :: reliable(:)
      type(stencil_cache_t), intent(in), optional :: stencils
      integer :: m
      real(rp) :: coefficient
      if (allocated(self%shift)) then
         if (size(self%shift, 2) < particles%count) deallocate (self%shift)
      end if
      if (.not. allocated(self%shift)) allocate (self%shift(grid%dim, max(1, size(particles%x, 2))))
      do m = 1, size(self%shifting_coefficient)
         if (self%shifting_coefficient(m) <= 0.0_rp) cycle
         if (particles%material_last(m) < particles%material_first(m)) cycle
         coefficient = self%shifting_coefficient(m) * self%interval
         if (self%reference_steps /= 1.0_rp) &
            coefficient = min(stable_coefficient_per_application, coefficient * self%reference_steps)
         call gradient_at_particles(grid, particles, particles%material_first(m), particles%material_last(m), &
                                    self%excess(1, :), reliable, self%shift, stencils, factor=-coefficient * grid%h**2)
      end do
   end subroutine shifts_of_particles

   !> After the position update of the step (particle order unchanged since prepare), for the particles
   !> first:last. A shifted particle takes the hydrostatic pressure of its new place, p := p + rho g . dx
   !> (first-order Taylor step with grad p = rho g): without it, shifting mixes the pressures of different
   !> depths into noise.
   subroutine corrector_apply_shifts(self, particles, first, last)
      class(volume_corrector_t), intent(in) :: self
      type(particle_set_t), intent(inout) :: particles
      integer, intent(in) :: first, last
      integer :: m, dim
      if (.not. self%shifting_now) return
      dim = particles%dim
      do m = 1, size(self%shifting_coefficient)
         if (self%shifting_coefficient(m) <= 0.0_rp) cycle
         ! literal dimensions: the loops over the components unroll
         if (dim == 2) then
            call shift_particles(2, max(first, particles%material_first(m)), min(last, particles%material_last(m)))
         else
            call shift_particles(3, max(first, particles%material_first(m)), min(last, particles%material_last(m)))
         end if
      end do

   contains

      !> x_p += dx_p, dx_p at most longest_shift long, and sbar = -p/rho on the normal components: d(sbar) =
      !> -dp/rho = -g . dx (the dot product summed in the order of dot_product), for the particles lo..hi.
      !> The cap takes norm2 (scaled, a division per component) only where the plain sum of squares does not
      !> show the shift clearly shorter (most particles move far less than the cap).
      subroutine shift_particles(dim, lo, hi)
         integer, intent(in) :: dim, lo, hi
         real(rp), parameter :: clearly_shorter = 0.999_rp     ! squared length ratio: far above round-off
         real(rp) :: rise, squares, length, shift(dim)
         integer :: p, k
         do p = lo, hi
            squares = 0.0_rp
            do k = 1, dim
               shift(k) = self%shift(k, p)
               squares = squares + shift(k)**2
            end do
            if (squares >= clearly_shorter * self%longest_shift**2) then
               length = norm2(shift)
               if (length > self%longest_shift) shift = shift * (self%longest_shift / length)
            end if
            rise = 0.0_rp
            do k = 1, dim
               particles%x(k, p) = particles%x(k, p) + shift(k)
               rise = rise + self%gravity(k) * shift(k)
            end do
            particles%sbar(1:3, p) = particles%sbar(1:3, p) - rise
         end do
      end subroutine shift_particles
   end subroutine corrector_apply_shifts

   !> After the stress update and smoothing: p := p + r_a (K ln(rho/rho_0) - p), deviatoric stress kept;
   !> r_a = 1 - (1 - r)^a for a step of a reference steps, the part a reference steps of rate r remove.
   subroutine corrector_relax_pressure(self, particles, reference_steps)
      class(volume_corrector_t), intent(in) :: self
      type(particle_set_t), intent(inout) :: particles
      real(rp), intent(in) :: reference_steps
      integer :: m, p
      real(rp) :: pressure, change, rate, k, rho0
      do m = 1, size(self%relaxation_rate)
         if (self%relaxation_rate(m) <= 0.0_rp) cycle
         rate = self%relaxation_rate(m)
         if (reference_steps /= 1.0_rp) rate = 1.0_rp - (1.0_rp - rate)**reference_steps
         k = self%bulk_modulus(m)
         rho0 = self%reference_density(m)
         do p = particles%material_first(m), particles%material_last(m)
            associate (rho => particles%density(p), sbar => particles%sbar(:, p))
               pressure = -rho * (sbar(1) + sbar(2) + sbar(3)) / 3.0_rp
               change = rate * (eos_pressure(rho0, k, rho) - pressure)
               sbar(1:3) = sbar(1:3) - change / rho
            end associate
         end do
      end do
   end subroutine corrector_relax_pressure

   !> up = -g/|g| and dim - 1 unit vectors normal to it (grid frame) spanning the horizontal bins.
   subroutine horizontal_frame(self, dim)
      type(volume_corrector_t), intent(inout) :: self
      integer, intent(in) :: dim
      real(rp) :: axis(3)
      integer :: k
      self%up = -self%gravity / norm2(self%gravity)
      if (dim == 2) then
         self%up(3) = 0.0_rp
         self%up = self%up / norm2(self%up)
         self%horizontal(:, 1) = [self%up(2), -self%up(1), 0.0_rp]
         return
      end if
      ! the grid axis least aligned with up, made normal to it
      k = minloc(abs(self%up), 1)
      axis = 0.0_rp
      axis(k) = 1.0_rp
      axis = axis - dot_product(axis, self%up) * self%up
      self%horizontal(:, 1) = axis / norm2(axis)
      self%horizontal(:, 2) = [self%up(2) * self%horizontal(3, 1) - self%up(3) * self%horizontal(2, 1), &
                               self%up(3) * self%horizontal(1, 1) - self%up(1) * self%horizontal(3, 1), &
                               self%up(1) * self%horizontal(2, 1) - self%up(2) * self%horizontal(1, 1)]
   end subroutine horizontal_frame

   !> Within each cell, the particles of each shifting material share one density, m_c / V_c (mass and
   !> volume of the cell's particles of that material kept): C0's cell average ([Y17] eq. 4, through
   !> cell_binning, by particles%cell at x^n) applied to the specific volume 1/rho, whose mass-weighted
   !> mean is V_c / m_c. A particle's own J otherwise carries the history of the cells it crossed, and
   !> nothing in C0 or FOAL1 pulls it back (the pressure is the cell's), so it can drift without bound.
   !> The masses and the specific volumes are summed in one pass (bin_cell_mass_and_mean), and the new
   !> densities 1 / mean written in one more.
   subroutine equalize_cell_volumes(self, grid, particles)
      type(volume_corrector_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer :: m, first, last, n, p, i, c
      if (allocated(self%cell_mass)) then
         if (size(self%cell_mass) /= grid%cell_count) deallocate (self%cell_mass, self%cell_average)
      end if
      if (.not. allocated(self%cell_mass)) then
         allocate (self%cell_mass(grid%cell_count), self%cell_average(1, grid%cell_count))
         call start_cell_list(grid%cell_count, self%occupied, self%cell_mass)
      end if
      do m = 1, size(self%shifting_coefficient)
         if (self%shifting_coefficient(m) <= 0.0_rp) cycle
         first = particles%material_first(m)
         last = particles%material_last(m)
         if (last < first) cycle
         n = last - first + 1
         if (allocated(self%specific_volume)) then
            if (size(self%specific_volume, 2) < n) deallocate (self%specific_volume)
         end if
         if (.not. allocated(self%specific_volume)) allocate (self%specific_volume(1, size(particles%x, 2)))
         associate (specific_volume => self%specific_volume(1, 1:n))
            specific_volume = 1.0_rp / particles%density(first:last)
            call bin_cell_mass_and_mean(particles, first, last, specific_volume, self%occupied, self%cell_mass, &
                                        self%cell_average)
         end associate
         ! 1 / mean once per cell, then a plain gather
         do i = 1, self%occupied%count
            c = self%occupied%cells(i)
            self%cell_average(1, c) = 1.0_rp / self%cell_average(1, c)
         end do
         do p = first, last
            particles%density(p) = self%cell_average(1, particles%cell(p))
         end do
      end do
   end subroutine equalize_cell_volumes

   !> The height function of the free surface: over each horizontal bin, the highest top (x_p . up + l_p / 2,
   !> l_p = V_p^(1/dim)) of the particles, of every material, whose width l_p covers the bin. Bins span the
   !> grid box; the maximum is taken over all ranks. Collective.
   subroutine measure_surface_heights(self, domain, grid, particles)
      type(volume_corrector_t), intent(inout) :: self
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, parameter :: block_size = 4 * transfer_block   ! 256: whole blocks of the extremes
      integer :: dim, k, p, corner, n(2), first(2, block_size), last(2, block_size), i, j, b, e, covered(2, 2)
      real(rp) :: box_hi(3), x(3), u, lo(2), hi(2), top(block_size), third, width, width_mass, width_density, &
                  widths(block_size), block_top

      dim = grid%dim
      self%bin_width = grid%h / bins_per_cell(dim)
      box_hi = grid%origin + grid%global_cells * grid%h
      lo = huge(1.0_rp)
      hi = -huge(1.0_rp)
      x = 0.0_rp
      do corner = 0, 2**dim - 1
         do k = 1, dim
            x(k) = merge(box_hi(k), grid%origin(k), btest(corner, k - 1))
         end do
         do k = 1, dim - 1
            u = dot_product(x(1:dim), self%horizontal(1:dim, k))
            lo(k) = min(lo(k), u)
            hi(k) = max(hi(k), u)
         end do
      end do
      self%bin_lo = lo
      n = 1
      n(1:dim - 1) = max(1, ceiling((hi(1:dim - 1) - lo(1:dim - 1)) / self%bin_width))
      if (allocated(self%surface_height)) then
         if (any(shape(self%surface_height) /= n)) deallocate (self%surface_height)
      end if
      if (.not. allocated(self%surface_height)) allocate (self%surface_height(n(1), n(2)))
      self%surface_height = no_surface

      ! per block: the tops and bin ranges in a loop without stores to the bins (it vectorises in 2-D:
      ! sqrt and the divisions 8 particles at a time), then the maxima bin by bin. The blocks and their
      ! particles from the last to the first: sorted by cell, with the cells' last axis slowest, they come
      ! top down, so a bin is rarely raised after its first particles and the store is mostly skipped (a
      ! store per bin made every update wait for the one before: a store-to-load chain). The maximum does
      ! not depend on the order.
      third = 1.0_rp / 3.0_rp
      width_mass = -1.0_rp      ! no particle's: the first 3-D particle takes its cube root
      width_density = -1.0_rp
      width = 0.0_rp
      do b = 1 + ((particles%count - 1) / block_size) * block_size, 1, -block_size
         e = min(particles%count, b + block_size - 1)
         if (self%shortcuts) then
            ! most blocks lie below the surface layer: one bound of the whole block, from its particles'
            ! extremes, skips them before their roots and divisions (the correction 8 % cheaper on the tank)
            if (dim == 2) then
               if (block_stays_below(2, b, e)) cycle
            else
               if (block_stays_below(3, b, e)) cycle
            end if
         end if
         if (dim == 2) then
            do p = b, e
               call particle_reach(2, sqrt(particles%mass(p) / particles%density(p)), particles%x(1:2, p), &
                                   top(p - b + 1), first(:, p - b + 1), last(:, p - b + 1))
            end do
         else
            ! scalar: vectorised (the general way, shortcuts off, has no recurrence) gcc would take libmvec's
            ! vector pow, whose results need not be the scalar pow's bits
            !GCC$ novector
            do p = b, e
               ! the cube root (a call of pow) once per run of particles of equal mass and density: after
               ! equalize_cell_volumes the particles of a cell share their density, and lattices their mass
               if (.not. (self%shortcuts .and. abs(particles%mass(p) - width_mass) <= 0.0_rp .and. &
                          abs(particles%density(p) - width_density) <= 0.0_rp)) then   ! (a NaN takes its own)
                  width_mass = particles%mass(p)
                  width_density = particles%density(p)
                  width = (width_mass / width_density)**third
               end if
               widths(p - b + 1) = width
            end do
            ! the reaches in a loop of their own, which vectorises with the literal 3 (the divisions by the bin
            ! width 8 particles at a time)
            do p = b, e
               call particle_reach(3, widths(p - b + 1), particles%x(1:3, p), top(p - b + 1), first(:, p - b + 1), &
                                   last(:, p - b + 1))
            end do
         end if
         if (self%shortcuts) then
            ! a block whose highest top is no higher than every bin its particles' bins span would raise none:
            ! skipped (coming top down, every block below the surface layer is)
            covered(:, 1) = n + 1
            covered(:, 2) = 0
            block_top = -huge(1.0_rp)
            do p = 1, e - b + 1
               covered(:, 1) = min(covered(:, 1), first(:, p))
               covered(:, 2) = max(covered(:, 2), last(:, p))
               block_top = max(block_top, top(p))
            end do
            ! (a NaN top never raises a bin)
            if (block_top <= lowest_height(self%surface_height, covered(:, 1), covered(:, 2))) cycle
         end if
         do p = e - b + 1, 1, -1
            do j = first(2, p), last(2, p)
               do i = first(1, p), last(1, p)
                  if (top(p) > self%surface_height(i, j)) self%surface_height(i, j) = top(p)
               end do
            end do
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, self%surface_height, size(self%surface_height), MPI_DOUBLE_PRECISION, &
                         MPI_MAX, domain%comm)
      call count_collective(comm_volume, size(self%surface_height), real_bytes)

   contains

      !> Whether particles b..e would raise no bin, judged from bounds of the block, from the extremes of its
      !> blocks of the occupancy's transfer (block_extremes, which b..e cover exactly): the largest x . up
      !> and the extremes of x . horizontal over the blocks' boxes, and the widest particle l = (max m /
      !> min rho)^(1/dim). Each particle's own top and bins (particle_reach) lie within these (rounding is
      !> monotone; the margin covers a dot product the compiler fuses otherwise and the cube root), so a
      !> block the bound skips raises no bin: the heights are those of every block's particles, bit for bit.
      !> A NaN makes no skip.
      logical function block_stays_below(dim, b, e) result(below)
         integer, intent(in) :: dim, b, e
         real(rp) :: top_max, across_min(2), across_max(2), mass_max, density_min, half, margin, lo(3), hi(3)
         integer :: j, k, bin_first(2), bin_last(2)
         below = .true.
         if (e < b) return         ! no particle on this rank
         lo = huge(1.0_rp)
         hi = -huge(1.0_rp)
         mass_max = 0.0_rp
         density_min = huge(1.0_rp)
         do j = (b - 1) / transfer_block + 1, (e - 1) / transfer_block + 1
            lo = min(lo, self%block_extremes(1:3, j))
            hi = max(hi, self%block_extremes(4:6, j))
            mass_max = max(mass_max, self%block_extremes(7, j))
            density_min = min(density_min, self%block_extremes(8, j))
         end do
         ! the extremes of a linear function over the box lo:hi, at its corners
         top_max = box_maximum(self%up(1:dim), lo, hi)
         across_min = 0.0_rp
         across_max = 0.0_rp
         do k = 1, dim - 1
            across_min(k) = -box_maximum(-self%horizontal(1:dim, k), lo, hi)
            across_max(k) = box_maximum(self%horizontal(1:dim, k), lo, hi)
         end do
         margin = 1.0e-9_rp * self%bin_width + 1.0e-12_rp * max(abs(top_max), maxval(abs(across_min(1:dim - 1))), &
                                                               maxval(abs(across_max(1:dim - 1))))
         half = 0.5_rp * (mass_max / density_min)**(1.0_rp / dim) * (1.0_rp + 1.0e-12_rp) + margin
         below = .false.
         if (.not. (top_max + half + margin <= huge(1.0_rp))) return      ! NaN or overflow: no skip
         bin_first = 1
         bin_last = 1
         do k = 1, dim - 1
            ! clamped to the bins before the conversion (a far particle's bin number is no integer)
            bin_first(k) = max(1, 1 + floor(max((across_min(k) - self%bin_lo(k) - half) / self%bin_width, -1.0_rp)))
            bin_last(k) = min(n(k), 1 + floor(min((across_max(k) - self%bin_lo(k) + half) / self%bin_width, &
                                                  real(n(k), rp))))
         end do
         below = top_max + half + margin <= lowest_height(self%surface_height, bin_first, bin_last)
      end function block_stays_below

      !> The largest a . x over the box lo:hi (size(a) axes), at one of its corners.
      pure real(rp) function box_maximum(a, lo, hi) result(largest)
         real(rp), intent(in) :: a(:), lo(:), hi(:)
         integer :: i
         largest = 0.0_rp
         do i = 1, size(a)
            largest = largest + merge(a(i) * hi(i), a(i) * lo(i), a(i) >= 0.0_rp)
         end do
      end function box_maximum

      !> A particle of width `width` at x: its top x . up + width / 2 and the bins its width covers.
      pure subroutine particle_reach(dim, width, x, top, first, last)
         integer, intent(in) :: dim
         real(rp), intent(in) :: width, x(dim)
         real(rp), intent(out) :: top
         integer, intent(out) :: first(2), last(2)
         real(rp) :: half, u
         integer :: k
         half = 0.5_rp * width
         top = dot_product(x, self%up(1:dim)) + half
         first = 1
         last = 1
         do k = 1, dim - 1
            u = dot_product(x, self%horizontal(1:dim, k)) - self%bin_lo(k)
            ! a particle that only touches a bin's edge does not cover it (lattices tile exactly)
            first(k) = max(1, 1 + floor((u - half) / self%bin_width + 1.0e-9_rp))
            last(k) = min(n(k), 1 + floor((u + half) / self%bin_width - 1.0e-9_rp))
         end do
      end subroutine particle_reach
   end subroutine measure_surface_heights

   !> fluid_volume(i) = int N_i over the open space below the height function, for the nodes whose support
   !> reaches above it somewhere (the others keep V_i): surface_samples_per_cell^dim sub-cells per cell, each
   !> counted with its exact fraction below the local surface plane.
   !> Where up is the grid's last axis (gravity along it: the usual case), a column of sub-cells lies over
   !> one bin, whose height is looked up once per column: x . horizontal and x . up are then x's own
   !> coordinates, bit for bit, so the heights and surfaces are those of a lookup per sub-cell. A support there
   !> that no wall cuts takes the columns' sum in closed form (open_column_volume): the same integral as the
   !> sub-cells' sum, which it equals to round-off.
   subroutine cut_by_surface(self, grid, constraints)
      type(volume_corrector_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(in) :: constraints
      integer, parameter :: max_columns = (2 * maxval(surface_samples_per_cell))**2   ! per_axis**(dim - 1) at most
      integer :: dim, i, j, l, k, g(3), node, s(3), per_axis, first(2), last(2), nb(2), column
      real(rp) :: x_node(3), x(3), weight, sub, reach(2), rise, lowest, volume, extent(3), u, surface, share, &
                  rise_of_part, half_depth, sub_volume, column_height(max_columns), highest, &
                  sample_x(2 * maxval(surface_samples_per_cell), 3), axis_weight(2 * maxval(surface_samples_per_cell), 3)
      logical, allocatable :: counts(:), near(:)
      logical :: upright
      ! upright: the lowest height over the support of each column of nodes (horizontal node indices; the
      ! second is 0 in 2-D), taken when a node of the column first needs it (column_known)
      real(rp), allocatable :: column_lowest(:, :)
      logical, allocatable :: column_known(:, :)
      integer :: horizontal_node(2), second(2)

      dim = grid%dim
      counts = constraints%activity() .and. constraints%blocks_flow
      per_axis = 2 * surface_samples_per_cell(dim)
      sub = grid%h / surface_samples_per_cell(dim)
      sub_volume = sub**dim
      nb = shape(self%surface_height)
      rise = grid%h * sum(abs(self%up(1:dim)))                ! the support's top above its node
      extent = sub * abs(self%up)                              ! a sub-cell's depth along up, per axis
      half_depth = 0.5_rp * sum(extent(1:dim))
      do k = 1, dim - 1
         reach(k) = grid%h * sum(abs(self%horizontal(1:dim, k)))
      end do
      upright = self%shortcuts .and. grid_axis_up(self, dim)
      if (upright) then
         second = [0, 0]
         if (dim == 3) second = [grid%node_lo(2), grid%node_hi(2)]
         allocate (column_lowest(grid%node_lo(1):grid%node_hi(1), second(1):second(2)), &
                   column_known(grid%node_lo(1):grid%node_hi(1), second(1):second(2)))
         column_known = .false.
      end if
      horizontal_node = 0
      x_node = 0.0_rp
      x = 0.0_rp
      first = 1
      last = 1
      node = 0      ! the local flat index: the first axis fastest, as the loops go
      do l = grid%node_lo(3), grid%node_hi(3)
         do j = grid%node_lo(2), grid%node_hi(2)
            do i = grid%node_lo(1), grid%node_hi(1)
               node = node + 1
               g = [i, j, l]
               ! no particle in the support: phi = 0 whatever V_i is
               if (self%open_volume(node) <= 0.0_rp .or. self%excess(1, node) <= 0.0_rp) cycle
               x_node(1:dim) = grid%origin(1:dim) + g(1:dim) * grid%h
               if (upright) then
                  ! the bins over the support are those of every node of the column (x . horizontal is x's own
                  ! coordinate): one minimum per column, not one per node
                  horizontal_node(1:dim - 1) = g(1:dim - 1)
                  associate (known => column_known(horizontal_node(1), horizontal_node(2)), &
                             column_min => column_lowest(horizontal_node(1), horizontal_node(2)))
                     if (.not. known) column_min = lowest_over_support()
                     known = .true.
                     lowest = column_min
                  end associate
               else
                  lowest = lowest_over_support()
               end if
               if (lowest >= dot_product(x_node(1:dim), self%up(1:dim)) + rise) cycle   ! wholly below
               ! a node above the surface is in the air: psi = 0 there, so the crowding of the layer under
               ! the surface drains through it (a zero excess on the surface itself, where a node rarely is)
               if (surface_over(self, x_node, dim) < dot_product(x_node(1:dim), self%up(1:dim))) then
                  self%fluid_volume(node) = 0.0_rp
                  cycle
               end if
               call support_samples(grid, x_node, surface_samples_per_cell(dim), sample_x, axis_weight)
               if (.not. self%fully_open(node)) near = walls_near(self, grid, constraints, counts, x_node)
               volume = 0.0_rp
               if (upright) then
                  call column_heights(column_height)
                  if (self%fully_open(node)) then
                     volume = open_column_volume()
                  else
                     call add_upright_samples()
                  end if
               else
                  s = 1
                  do
                     weight = sub_volume
                     do k = 1, dim
                        x(k) = sample_x(s(k), k)
                        weight = weight * axis_weight(s(k), k)
                     end do
                     surface = surface_over(self, x, dim) - dot_product(x(1:dim), self%up(1:dim))
                     call add_sample()
                     if (.not. next_sample(s, dim, per_axis)) exit
                  end do
               end if
               self%fluid_volume(node) = min(volume, self%open_volume(node))
            end do
         end do
      end do

   contains

      !> volume += the sample at x (the host's x, `weight` = its N_i times sub_volume, `surface` = the surface's
      !> height above it), with its part below the surface and its open fraction; nothing if it lies wholly
      !> above the surface (as under no_surface).
      subroutine add_sample()
         if (.not. (surface > -half_depth)) return
         share = 1.0_rp
         if (surface < half_depth) call part_below(surface, extent(1:dim), share, rise_of_part)
         if (share < 1.0_rp) then
            ! N_i at the part's height (exact for a cut along a grid axis; N is linear there)
            weight = sub_volume
            do k = 1, dim
               weight = weight * (1.0_rp - abs(x(k) + rise_of_part * self%up(k) - x_node(k)) * grid%inv_h)
            end do
         end if
         weight = weight * share
         if (weight > 0.0_rp) then
            if (.not. self%fully_open(node)) weight = weight * open_fraction(grid, constraints, near, x)
            volume = volume + weight
         end if
      end subroutine add_sample

      !> The samples of the upright support in the general way's order (the first axis fastest, rows going
      !> up), each column of sub-cells with its own height: a sample wholly above its column's surface adds
      !> nothing, so it is skipped before its weight is formed, and a row whose bottom is above the highest
      !> column (rounding is monotone) ends the support. The same additions in the same order.
      subroutine add_upright_samples()
         integer :: row, c1, c2, columns_2
         columns_2 = merge(per_axis, 1, dim == 3)
         highest = maxval(column_height(1:per_axis**(dim - 1)))
         do row = 1, per_axis
            x(dim) = sample_x(row, dim)
            if (highest - x(dim) <= -half_depth) exit
            column = 0
            do c2 = 1, columns_2
               do c1 = 1, per_axis
                  column = column + 1
                  surface = column_height(column) - x(dim)
                  if (.not. (surface > -half_depth)) cycle
                  x(1) = sample_x(c1, 1)
                  weight = sub_volume * axis_weight(c1, 1)
                  if (dim == 3) then
                     x(2) = sample_x(c2, 2)
                     weight = weight * axis_weight(c2, 2)
                  end if
                  weight = weight * axis_weight(row, dim)
                  call add_sample()
               end do
            end do
         end do
      end subroutine add_upright_samples

      !> V_i cut by the surface for an upright support that no wall cuts, column by column in closed form. A
      !> column of sub-cells holds fluid from the support's bottom up to its height; N's horizontal factors are
      !> taken at the column's centre (exact: N is linear across it) and its factor along up is integrated
      !> exactly: h times the hat's integral from -1 to s = (height - x_node . up) / h clamped to [-1, 1],
      !> (1 + s)^2 / 2 below the node and 1 - (1 - s)^2 / 2 above. add_upright_samples computes the same
      !> integral (the midpoint rule on the whole sub-cells and the centroid of the part below the surface are
      !> exact for N linear in each sub-cell, whose edges include the node's), so the two differ by round-off;
      !> this takes per_axis^(dim - 1) terms where that takes up to per_axis^dim samples.
      real(rp) function open_column_volume() result(total)
         integer :: c1, c2, columns_2
         real(rp) :: s, hat_integral, horizontal_factor
         columns_2 = merge(per_axis, 1, dim == 3)
         total = 0.0_rp
         column = 0
         do c2 = 1, columns_2
            do c1 = 1, per_axis
               column = column + 1
               ! the height clamped to the support first (no_surface is -huge: no overflow)
               s = (min(max(column_height(column), x_node(dim) - grid%h), x_node(dim) + grid%h) - x_node(dim)) * grid%inv_h
               hat_integral = merge(0.5_rp * (1.0_rp + s)**2, 1.0_rp - 0.5_rp * (1.0_rp - s)**2, s <= 0.0_rp)
               horizontal_factor = axis_weight(c1, 1)
               if (dim == 3) horizontal_factor = horizontal_factor * axis_weight(c2, 2)
               total = total + horizontal_factor * hat_integral
            end do
         end do
         total = total * sub**(dim - 1) * grid%h
      end function open_column_volume

      !> The lowest height function over the bins the support of the node at x_node spans horizontally
      !> (no_surface if a bin has no particle over it).
      real(rp) function lowest_over_support() result(lowest)
         do k = 1, dim - 1
            u = dot_product(x_node(1:dim), self%horizontal(1:dim, k)) - self%bin_lo(k)
            first(k) = max(1, 1 + floor((u - reach(k)) / self%bin_width))
            last(k) = min(nb(k), 1 + floor((u + reach(k)) / self%bin_width))
         end do
         lowest = lowest_height(self%surface_height, first, last)
      end function lowest_over_support

      !> The height function over each column of sub-cells of the support of the node at x_node (columns
      !> numbered as the samples' horizontal indices, the first fastest), as surface_over gives it at any
      !> sample of the column.
      subroutine column_heights(height)
         real(rp), intent(out) :: height(:)
         real(rp) :: x_column(3)
         integer :: c(2), column
         x_column = x_node
         c = 1
         do column = 1, per_axis**(dim - 1)
            c(1) = 1 + mod(column - 1, per_axis)
            c(2) = 1 + (column - 1) / per_axis
            do k = 1, dim - 1
               x_column(k) = sample_x(c(k), k)
            end do
            height(column) = surface_over(self, x_column, dim)
         end do
      end subroutine column_heights
   end subroutine cut_by_surface

   !> The lowest height function over the bins first:last (per horizontal axis), huge if there are none: as
   !> minval, by a loop of min (minval's rules for NaN make gfortran emit a scalar loop with branches; no height
   !> is NaN).
   pure real(rp) function lowest_height(height, first, last) result(lowest)
      real(rp), intent(in) :: height(:, :)
      integer, intent(in) :: first(2), last(2)
      integer :: i, j
      lowest = huge(1.0_rp)
      do j = first(2), last(2)
         do i = first(1), last(1)
            lowest = min(lowest, height(i, j))
         end do
      end do
   end function lowest_height

   !> True if up is the grid's last axis and the horizontal directions its others, exactly (then a point's
   !> height and horizontal coordinates are its own coordinates, bit for bit).
   pure logical function grid_axis_up(self, dim) result(upright)
      type(volume_corrector_t), intent(in) :: self
      integer, intent(in) :: dim
      integer :: k, l
      ! exact comparisons, as inequalities of absolute differences
      upright = abs(self%up(dim) - 1.0_rp) <= 0.0_rp .and. maxval(abs(self%up(1:dim - 1))) <= 0.0_rp
      do k = 1, dim - 1
         do l = 1, dim
            upright = upright .and. abs(self%horizontal(l, k) - merge(1.0_rp, 0.0_rp, l == k)) <= 0.0_rp
         end do
      end do
   end function grid_axis_up

   !> The height function over point x: its bin's height (no_surface where no particle is).
   pure real(rp) function surface_over(self, x, dim) result(height)
      type(volume_corrector_t), intent(in) :: self
      real(rp), intent(in) :: x(3)
      integer, intent(in) :: dim
      integer :: bin(2), k
      bin = 1
      do k = 1, dim - 1
         bin(k) = min(size(self%surface_height, k), max(1, 1 + floor((dot_product(x(1:dim), &
                  self%horizontal(1:dim, k)) - self%bin_lo(k)) / self%bin_width)))
      end do
      height = self%surface_height(bin(1), bin(2))
   end function surface_over

   !> `fraction` of a box with depths m(k) = a_k |up_k| along up (edges a_k on the grid axes) that lies
   !> below the plane `distance` above its centre, exactly: the volume of a box cut by a plane
   !> (Scardovelli and Zaleski 2000, J. Comput. Phys. 164, eq. 2.12), F(alpha) = sum over the subsets S of
   !> the axes of (-1)^|S| (alpha - m_S)_+^n / (n! prod m), alpha the plane's height above the lowest corner.
   !> Axes along which the box has no depth drop out, so a plane on the faces of an aligned box gives
   !> exactly 0 or 1. `centroid`: the height of the part below the plane over the box's centre,
   !> alpha - int_0^alpha F / F(alpha) - sum(m)/2 (the same sums, one power higher).
   pure subroutine part_below(distance, m, fraction, centroid)
      real(rp), intent(in) :: distance, m(:)
      real(rp), intent(out) :: fraction, centroid
      real(rp), parameter :: factorial(3) = [1.0_rp, 2.0_rp, 6.0_rp]
      real(rp) :: depth(3), alpha, total, volume, moment, corner, sign
      integer :: n, k, subset
      n = 0
      do k = 1, size(m)
         if (m(k) > 1.0e-9_rp * sum(m)) then
            n = n + 1
            depth(n) = m(k)
         end if
      end do
      total = sum(depth(1:n))
      alpha = distance + 0.5_rp * total
      centroid = 0.0_rp
      if (alpha <= 0.0_rp) then
         fraction = 0.0_rp
         return
      end if
      if (alpha >= total) then
         fraction = 1.0_rp
         return
      end if
      volume = 0.0_rp
      moment = 0.0_rp
      do subset = 0, 2**n - 1
         corner = alpha
         do k = 1, n
            if (btest(subset, k - 1)) corner = corner - depth(k)
         end do
         if (corner <= 0.0_rp) cycle
         sign = merge(-1.0_rp, 1.0_rp, mod(popcnt(subset), 2) == 1)     ! (-1)^|S|
         volume = volume + sign * corner**n
         moment = moment + sign * corner**(n + 1)
      end do
      ! volume / (n! prod m) is F; moment / ((n+1)! prod m) its integral
      fraction = min(1.0_rp, max(0.0_rp, volume / (product(depth(1:n)) * factorial(n))))
      if (volume > 0.0_rp) centroid = alpha - moment / ((n + 1) * volume) - 0.5_rp * total
   end subroutine part_below

   !> V_i = int N_i over the part of the grid box in front of every active slip or no-slip wall, by
   !> midpoint quadrature (samples_per_cell^dim points in each of the 2^dim cells around the node).
   !> A feeder (prescribed) wall lets fluid through and does not count.
   subroutine measure_open_volumes(self, grid, constraints)
      type(volume_corrector_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(in) :: constraints
      integer :: dim, i, j, l, g(3), node, s(3), per_axis, k
      real(rp) :: x_node(3), x(3), weight, unit_weight, top(3), reach, sample_x(2 * maxval(samples_per_cell), 3), &
                  axis_weight(2 * maxval(samples_per_cell), 3)
      logical, allocatable :: counts(:), near(:)

      dim = grid%dim
      self%wall_activity = constraints%activity()
      counts = constraints%activity() .and. constraints%blocks_flow
      if (allocated(self%open_volume)) deallocate (self%open_volume, self%fully_open)
      allocate (self%open_volume(grid%node_count), self%fully_open(grid%node_count))
      per_axis = 2 * samples_per_cell(dim)
      unit_weight = (grid%h / samples_per_cell(dim))**dim
      top = grid%origin + grid%global_cells * grid%h
      reach = sqrt(real(dim, rp)) * grid%h
      x_node = 0.0_rp
      x = 0.0_rp
      do l = grid%node_lo(3), grid%node_hi(3)
         do j = grid%node_lo(2), grid%node_hi(2)
            do i = grid%node_lo(1), grid%node_hi(1)
               g = [i, j, l]
               node = grid%local_node(g(1:dim))
               x_node(1:dim) = grid%origin(1:dim) + g(1:dim) * grid%h
               self%fully_open(node) = support_is_open(x_node)
               if (self%fully_open(node)) then
                  self%open_volume(node) = grid%h**dim
                  cycle
               end if
               self%open_volume(node) = 0.0_rp
               near = walls_near(self, grid, constraints, counts, x_node)
               call support_samples(grid, x_node, samples_per_cell(dim), sample_x, axis_weight)
               s = 1
               do
                  ! sample point at the midpoint of sub-cell s, and its weight N_i(x)
                  weight = unit_weight
                  do k = 1, dim
                     x(k) = sample_x(s(k), k)
                     weight = weight * axis_weight(s(k), k)
                  end do
                  self%open_volume(node) = self%open_volume(node) + weight * open_fraction(grid, constraints, near, x)
                  if (.not. next_sample(s, dim, per_axis)) exit
               end do
            end do
         end do
      end do
   contains
      !> The whole support [x - h, x + h]^dim lies in the grid box and in front of every counted wall.
      logical function support_is_open(x_node) result(open)
         real(rp), intent(in) :: x_node(3)
         integer :: ww
         open = all(x_node(1:dim) - grid%h >= grid%origin(1:dim)) .and. all(x_node(1:dim) + grid%h <= top(1:dim))
         if (.not. open) return
         do ww = 1, constraints%count()
            if (.not. counts(ww)) cycle
            ! every point of the support is within reach of the node: in front by more than that, no cut
            if (constraints%items(ww)%item%clearly_in_front(grid, x_node(1:dim), reach)) cycle
            if (constraints%items(ww)%item%behind(grid, x_node(1:dim), reach, widen=reach)) then
               open = .false.
               return
            end if
         end do
      end function support_is_open
   end subroutine measure_open_volumes

   !> The samples of the support [x_node - h, x_node + h]^dim of a node, `per_cell` per cell and axis: along
   !> each axis k, sample_x(l, k) the centre of the l-th sub-cell and axis_weight(l, k) N's factor there
   !> (1 - |x - x_node| / h), so a sample's N_i is the product of its axes' factors.
   pure subroutine support_samples(grid, x_node, per_cell, sample_x, axis_weight)
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: x_node(3)
      integer, intent(in) :: per_cell
      real(rp), intent(out) :: sample_x(:, :), axis_weight(:, :)
      integer :: k, l
      do k = 1, grid%dim
         do l = 1, 2 * per_cell
            sample_x(l, k) = x_node(k) + grid%h * (-1.0_rp + (real(l, rp) - 0.5_rp) / per_cell)
            axis_weight(l, k) = 1.0_rp - abs(sample_x(l, k) - x_node(k)) * grid%inv_h
         end do
      end do
   end subroutine support_samples

   !> The counted walls that may cut the support [x_node - h, x_node + h]^dim: open_fraction skips every other
   !> one at every sample of the support, so with these alone it gives the same fractions. A planar wall is
   !> left out where the node lies farther in front of it than the support reaches (and the on-wall
   !> tolerance), or farther behind than its depth and two reaches (open_fraction widens the depth by one);
   !> a margin of 1e-6 h, far above the rounding of a distance, keeps the decision off the edge. A
   !> structure's surface always counts. Most nodes near the walls are near one of them: the box's other
   !> walls no longer cost a test per sample. Without the shortcuts: every counted wall.
   function walls_near(self, grid, constraints, counts, x_node) result(near)
      type(volume_corrector_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(in) :: constraints
      logical, intent(in) :: counts(:)
      real(rp), intent(in) :: x_node(3)
      logical :: near(constraints%count())
      real(rp) :: reach, margin
      integer :: ww, dim
      dim = grid%dim
      reach = sqrt(real(dim, rp)) * grid%h
      margin = 1.0e-6_rp * grid%h
      near = counts
      if (.not. self%shortcuts) return
      do ww = 1, constraints%count()
         if (.not. near(ww)) cycle
         near(ww) = constraints%items(ww)%item%may_cut_support(x_node(1:dim), &
                                                               reach + on_wall_tolerance * grid%h + margin, &
                                                               2.0_rp * reach, margin)
      end do
   end function walls_near

   !> 1 if the sample x is open, 0 if it is behind a counted wall or outside the grid box, 1/2 if it
   !> lies on a wall (a wall through the node at 45 degrees passes through samples: half is exact).
   real(rp) function open_fraction(grid, constraints, counts, x) result(fraction)
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(in) :: constraints
      logical, intent(in) :: counts(:)
      real(rp), intent(in) :: x(3)
      real(rp) :: on_wall, reach, top(3)
      integer :: ww, dim
      dim = grid%dim
      top = grid%origin + grid%global_cells * grid%h
      fraction = 0.0_rp
      if (any(x(1:dim) < grid%origin(1:dim)) .or. any(x(1:dim) > top(1:dim))) return
      fraction = 1.0_rp
      on_wall = on_wall_tolerance * grid%h
      reach = sqrt(real(dim, rp)) * grid%h
      do ww = 1, constraints%count()
         if (.not. counts(ww)) cycle
         ! widened: a sample of a node behind the wall may lie farther back than the wall's depth
         if (.not. constraints%items(ww)%item%behind(grid, x(1:dim), on_wall, widen=reach)) cycle
         if (constraints%items(ww)%item%behind(grid, x(1:dim), -on_wall, widen=reach)) then
            fraction = 0.0_rp
            return
         end if
         fraction = 0.5_rp
      end do
   end function open_fraction

   !> The next sub-cell index s of a node's support (per_axis along each of the dim axes); false after the last.
   logical function next_sample(s, dim, per_axis) result(more)
      integer, intent(inout) :: s(3)
      integer, intent(in) :: dim, per_axis
      integer :: k
      more = .false.
      do k = 1, dim
         if (s(k) < per_axis) then
            s(k) = s(k) + 1
            more = .true.
            return
         end if
         s(k) = 1
      end do
   end function next_sample

end module volume_correction
