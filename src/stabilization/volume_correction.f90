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
!>                   (D = shifting_coefficient per step; applied every k steps with k D, k = 0.2 / D,
!>                   so that its cost is a k-th, at most 0.1 h per application). One-sided: a node that is not
!>                   full (free surface, walls, spray) never pulls particles, so surfaces do not spread.
!>                   Positions only: mass, momentum of each particle, J and stress are kept.
!>   eos_relaxation  pull the pressure back toward the equation of state p_EOS = K ln(rho/rho_0) after the
!>                   smoothing, p := p + r (p_EOS - p) (r = eos_relaxation_rate per step): smoothing may
!>                   then no longer drain the pressure. Seeding and inflow start such fluids at
!>                   rho = rho_0 exp(p/K), so that the hydrostatic state is an EOS state.
!>
!> The occupancy uses the particles of all materials (a solid also fills space), at x^n, before the step's
!> particle-to-grid transfer; the shifts are added after the position update, so the wall safeguard and
!> the migration of the step see them. Costs nothing without a fluid that selects it.
module volume_correction
   use kinds, only: rp, i8
   use scene_description, only: scene_t, shifts_particles, relaxes_to_eos
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use grid_transfer, only: volume_to_grid, gradient_at_particles
   use node_halo, only: sum_shared_nodes
   use particle_set, only: particle_set_t
   use boundary_walls, only: wall_t, wall_kind_prescribed, behind_wall
   use newtonian_fluid, only: eos_pressure
   implicit none
   private

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
   !> Largest shift per application, in cells (public: the active region widens the particles' extent by it).
   real(rp), parameter, public :: max_shift_in_cells = 0.1_rp

   type, public :: volume_corrector_t
      real(rp), allocatable :: shifting_coefficient(:)  !< per material: D, 0 without shifting
      real(rp), allocatable :: relaxation_rate(:)       !< per material: r, 0 without EOS relaxation
      real(rp), allocatable :: bulk_modulus(:), reference_density(:)
      logical :: shifting = .false.                 !< some material shifts
      logical :: relaxing = .false.                 !< some material relaxes its pressure to the EOS
      integer :: interval = 1                       !< steps between two applications of the shifting
      logical :: shifting_now = .false.             !< this step applies it
      real(rp) :: gravity(3) = 0.0_rp               !< grid frame: the hydrostatic pressure change of a shift
      real(rp), allocatable :: open_volume(:)       !< V_i per local node [m^dim]
      logical, allocatable :: wall_activity(:)      !< walls' activity V_i was measured with
      real(rp), allocatable :: excess(:, :)         !< (1, node): occupancy, then psi_i
      real(rp), allocatable :: shift(:, :)          !< (dim, p): displacement added after the position update
   contains
      procedure :: init => corrector_init
      procedure :: reset_grid => corrector_reset_grid
      procedure :: prepare => corrector_prepare
      procedure :: apply_shifts => corrector_apply_shifts
      procedure :: relax_pressure => corrector_relax_pressure
   end type volume_corrector_t

contains

   !> The options of every material of the scene.
   subroutine corrector_init(self, scene, gravity)
      class(volume_corrector_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      real(rp), intent(in) :: gravity(3)
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
      if (self%shifting) self%interval = max(1, floor(coefficient_per_application / maxval(self%shifting_coefficient) &
                                                       * (1.0_rp + 1.0e-12_rp)))
   end subroutine corrector_init

   !> The grid changed (layout): V_i is measured again at the next prepare.
   subroutine corrector_reset_grid(self)
      class(volume_corrector_t), intent(inout) :: self
      if (allocated(self%wall_activity)) deallocate (self%wall_activity)
   end subroutine corrector_reset_grid

   !> At x^n, before the step's particle-to-grid transfer: the shifts of step `step` (every interval-th
   !> step; by the step number, so a restart keeps the rhythm). Collective.
   subroutine corrector_prepare(self, domain, grid, walls, particles, step)
      class(volume_corrector_t), intent(inout) :: self
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(wall_t), intent(in) :: walls(:)
      type(particle_set_t), intent(in) :: particles
      integer(i8), intent(in) :: step
      integer :: i
      real(rp) :: threshold

      self%shifting_now = self%shifting .and. mod(step, int(self%interval, i8)) == 0
      if (.not. self%shifting_now) return
      if (.not. allocated(self%wall_activity)) then
         call measure_open_volumes(self, grid, walls)
      else if (any(self%wall_activity .neqv. walls%active)) then
         call measure_open_volumes(self, grid, walls)
      end if
      if (allocated(self%excess)) then
         if (size(self%excess, 2) /= grid%node_count) deallocate (self%excess)
      end if
      if (.not. allocated(self%excess)) allocate (self%excess(1, grid%node_count))

      self%excess = 0.0_rp
      call volume_to_grid(grid, particles, self%excess(1, :))
      call sum_shared_nodes(domain, grid, self%excess)
      threshold = min_open_fraction * grid%h**grid%dim
      do i = 1, grid%node_count
         if (self%open_volume(i) >= threshold) then
            self%excess(1, i) = max(self%excess(1, i) / self%open_volume(i) - 1.0_rp, 0.0_rp)
         else
            self%excess(1, i) = 0.0_rp
         end if
      end do
      call shifts_of_particles(self, grid, particles, self%open_volume >= threshold)
   end subroutine corrector_prepare

   !> dx_p = -D h^2 sum_a grad N_a psi_a for the particles of shifting materials, at most 0.1 h long.
   !> A node mostly closed by walls has no reliable occupancy: it takes the particle's own excess (the
   !> N-weighted mean over the reliable corners), so a wall is neither a sink nor a source (zero normal
   !> gradient), where psi = 0 would pull particles onto it.
   subroutine shifts_of_particles(self, grid, particles, reliable)
      type(volume_corrector_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      logical, intent(in) :: reliable(:)
      real(rp) :: length, scale, longest
      integer :: m, p
      if (allocated(self%shift)) then
         if (size(self%shift, 2) < particles%count) deallocate (self%shift)
      end if
      if (.not. allocated(self%shift)) allocate (self%shift(grid%dim, max(1, size(particles%x, 2))))
      longest = max_shift_in_cells * grid%h
      do m = 1, size(self%shifting_coefficient)
         if (self%shifting_coefficient(m) <= 0.0_rp) cycle
         if (particles%material_last(m) < particles%material_first(m)) cycle
         call gradient_at_particles(grid, particles, particles%material_first(m), particles%material_last(m), &
                                    self%excess(1, :), reliable, self%shift)
         scale = -self%shifting_coefficient(m) * self%interval * grid%h**2
         do p = particles%material_first(m), particles%material_last(m)
            self%shift(:, p) = scale * self%shift(:, p)
            length = norm2(self%shift(:, p))
            if (length > longest) self%shift(:, p) = self%shift(:, p) * (longest / length)
         end do
      end do
   end subroutine shifts_of_particles

   !> After the position update of the step (particle order unchanged since prepare). A shifted particle
   !> takes the hydrostatic pressure of its new place, p := p + rho g . dx (first-order Taylor step with
   !> grad p = rho g): without it, shifting mixes the pressures of different depths into noise.
   subroutine corrector_apply_shifts(self, particles)
      class(volume_corrector_t), intent(in) :: self
      type(particle_set_t), intent(inout) :: particles
      integer :: m, p, dim
      if (.not. self%shifting_now) return
      dim = particles%dim
      do m = 1, size(self%shifting_coefficient)
         if (self%shifting_coefficient(m) <= 0.0_rp) cycle
         do p = particles%material_first(m), particles%material_last(m)
            particles%x(:, p) = particles%x(:, p) + self%shift(:, p)
            ! sbar = -p/rho on the normal components: d(sbar) = -dp/rho = -g . dx
            particles%sbar(1:3, p) = particles%sbar(1:3, p) - dot_product(self%gravity(1:dim), self%shift(:, p))
         end do
      end do
   end subroutine corrector_apply_shifts

   !> After the stress update and smoothing: p := p + r (K ln(rho/rho_0) - p), deviatoric stress kept.
   subroutine corrector_relax_pressure(self, particles)
      class(volume_corrector_t), intent(in) :: self
      type(particle_set_t), intent(inout) :: particles
      integer :: m, p
      real(rp) :: pressure, change, rate, k, rho0
      do m = 1, size(self%relaxation_rate)
         if (self%relaxation_rate(m) <= 0.0_rp) cycle
         rate = self%relaxation_rate(m)
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

   !> V_i = int N_i over the part of the grid box in front of every active slip or no-slip wall, by
   !> midpoint quadrature (samples_per_cell^dim points in each of the 2^dim cells around the node).
   !> A feeder (prescribed) wall lets fluid through and does not count.
   subroutine measure_open_volumes(self, grid, walls)
      type(volume_corrector_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      type(wall_t), intent(in) :: walls(:)
      integer :: dim, i, j, l, g(3), node, s(3), per_axis, k
      real(rp) :: x_node(3), x(3), weight, unit_weight, top(3), reach
      logical, allocatable :: counts(:)

      dim = grid%dim
      self%wall_activity = walls%active
      counts = walls%active .and. walls%kind /= wall_kind_prescribed
      if (allocated(self%open_volume)) deallocate (self%open_volume)
      allocate (self%open_volume(grid%node_count))
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
               if (support_is_open(x_node)) then
                  self%open_volume(node) = grid%h**dim
                  cycle
               end if
               self%open_volume(node) = 0.0_rp
               s = 1
               do
                  ! sample point at the midpoint of sub-cell s, and its weight N_i(x)
                  weight = unit_weight
                  do k = 1, dim
                     x(k) = x_node(k) + grid%h * (-1.0_rp + (real(s(k), rp) - 0.5_rp) / samples_per_cell(dim))
                     weight = weight * (1.0_rp - abs(x(k) - x_node(k)) * grid%inv_h)
                  end do
                  self%open_volume(node) = self%open_volume(node) + weight * open_fraction(x)
                  if (.not. next_sample(s)) exit
               end do
            end do
         end do
      end do
   contains
      !> 1 if the sample x is open, 0 if it is behind a counted wall or outside the grid box, 1/2 if it
      !> lies on a wall (a wall through the node at 45 degrees passes through samples: half is exact).
      real(rp) function open_fraction(x) result(fraction)
         real(rp), intent(in) :: x(3)
         real(rp) :: on_wall
         integer :: ww
         fraction = 0.0_rp
         if (any(x(1:dim) < grid%origin(1:dim)) .or. any(x(1:dim) > top(1:dim))) return
         fraction = 1.0_rp
         on_wall = on_wall_tolerance * grid%h
         do ww = 1, size(walls)
            if (.not. counts(ww)) cycle
            ! widened: a sample of a node behind the wall may lie farther back than the wall's depth
            if (.not. behind_wall(walls(ww), grid, x(1:dim), on_wall, widen=reach)) cycle
            if (behind_wall(walls(ww), grid, x(1:dim), -on_wall, widen=reach)) then
               fraction = 0.0_rp
               return
            end if
            fraction = 0.5_rp
         end do
      end function open_fraction

      !> The whole support [x - h, x + h]^dim lies in the grid box and in front of every counted wall.
      logical function support_is_open(x_node) result(open)
         real(rp), intent(in) :: x_node(3)
         integer :: ww
         open = all(x_node(1:dim) - grid%h >= grid%origin(1:dim)) .and. all(x_node(1:dim) + grid%h <= top(1:dim))
         if (.not. open) return
         do ww = 1, size(walls)
            if (.not. counts(ww)) cycle
            ! every point of the support is within reach of the node: in front by more than that, no cut
            if (dot_product(walls(ww)%normal(1:dim), x_node(1:dim) - walls(ww)%point(1:dim)) > reach) cycle
            if (behind_wall(walls(ww), grid, x_node(1:dim), reach, widen=reach)) then
               open = .false.
               return
            end if
         end do
      end function support_is_open

      logical function next_sample(s) result(more)
         integer, intent(inout) :: s(3)
         integer :: kk
         more = .false.
         do kk = 1, dim
            if (s(kk) < per_axis) then
               s(kk) = s(kk) + 1
               more = .true.
               return
            end if
            s(kk) = 1
         end do
      end function next_sample
   end subroutine measure_open_volumes

end module volume_correction
