!> A feature of the step that acts at fixed stages of it (algorithms.md section 1.2), present only when
!> the scene declares it: the solver holds the scene's components as one list (step_component_factory)
!> and calls each stage of every component in list order; a scene without such features has an empty
!> list, and its step runs no test for them. Today: the inflow (fluid_inflow), the fluid volume
!> correction (volume_correction) and the damping zones (damping_zone). A new one extends
!> step_component_t, overrides the stages it uses (each default does nothing) and is added in
!> step_component_factory (docs/conventions.md, "Where to add ...").
!>
!> The stages, in the order the step reaches them:
!>   before_walls_move   t_n, before the moving walls are placed (an inlet's feeder gets its speed)
!>   walls_placed        the constraints at t_n, before P2G
!>   grid_summed         after P2G and the ghost-node sums, positions x^n
!>   shift_particles     inside G2P, per block of particles, after their new positions (shifts_now tells)
!>   particles_moved     after G2P, with the particles' extent (which a component may widen)
!>   stress_updated      after the constitutive update and the stress filter
!>   end_step            after the safeguard and the loads: particles it creates (their count)
!> and, outside the step: layout_changed (new grid arrays), and for a component that creates particles,
!> the queries the time step, the mass tolerance and the schemes' skipping read (signal_speed,
!> lightest_particle, supplies).
module step_component
   use kinds, only: rp, i8
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use constraint_list, only: constraint_list_t
   use stencil_cache, only: stencil_cache_t
   use material_model, only: material_slot_t
   implicit none
   private

   !> What a stage reads and changes: the solver's parts (pointers), the step's interval and number.
   type, public :: step_state_t
      type(domain_t), pointer :: domain => null()
      type(grid_t), pointer :: grid => null()
      type(particle_set_t), pointer :: particles => null()
      type(constraint_list_t), pointer :: constraints => null()
      type(stencil_cache_t), pointer :: stencils => null()     !< P2G's stencils at x^n (3-D)
      real(rp) :: time = 0.0_rp                 !< t_n [s]
      real(rp) :: dt = 0.0_rp                   !< the step runs to t_n + dt
      !> dt in automatic steps at the reference CFL number (stage_context_t's): a correction made per step
      !> acts at one rate per unit time with it
      real(rp) :: reference_steps = 1.0_rp
      integer(i8) :: step = 0                   !< n
   end type step_state_t

   type, abstract, public :: step_component_t
      !> the timing.csv phase (phase_timers) its stages are charged to
      integer :: phase = 0
   contains
      procedure :: before_walls_move => no_stage
      procedure :: walls_placed => no_stage
      procedure :: grid_summed => no_stage
      procedure :: shifts_now => shifts_nothing
      procedure :: shift_particles => shift_nothing
      procedure :: particles_moved => keep_extent
      procedure :: stress_updated => no_stage
      procedure :: end_step => create_nothing
      procedure :: layout_changed => no_change
      procedure :: signal_speed => no_signal
      procedure :: lightest_particle => no_particle
      procedure :: supplies => supplies_nothing
   end type step_component_t

   !> One entry of the solver's list.
   type, public :: component_slot_t
      class(step_component_t), allocatable :: component
   end type component_slot_t

contains

   subroutine no_stage(self, state)
      class(step_component_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
   end subroutine no_stage

   !> True if this step's G2P is to call shift_particles (a clock read per block otherwise wasted).
   logical function shifts_nothing(self) result(shifts)
      class(step_component_t), intent(in) :: self
      shifts = .false.
   end function shifts_nothing

   !> Particles first:last have their new positions (G2P): the component may move them further.
   subroutine shift_nothing(self, particles, first, last)
      class(step_component_t), intent(in) :: self
      type(particle_set_t), intent(inout) :: particles
      integer, intent(in) :: first, last
   end subroutine shift_nothing

   !> After G2P; `extent` (grid frame, lowest and highest position per axis) bounds the particles after
   !> every later move of the step: a component that moves particles further widens it.
   subroutine keep_extent(self, state, extent)
      class(step_component_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      real(rp), intent(inout) :: extent(3, 2)
   end subroutine keep_extent

   !> The number of particles it appended to state%particles.
   integer function create_nothing(self, state) result(created)
      class(step_component_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      created = 0
   end function create_nothing

   !> The grid's local nodes changed (a new layout): forget what was sized or measured on them.
   subroutine no_change(self)
      class(step_component_t), intent(inout) :: self
   end subroutine no_change

   !> The largest signal speed [m/s] of the particles it is about to create at `time`: with `fixed_step`
   !> their largest speed, else the wave speed of their material at their density plus their speed. 0: none.
   real(rp) function no_signal(self, time, materials, dim, fixed_step) result(speed)
      class(step_component_t), intent(in) :: self
      real(rp), intent(in) :: time
      type(material_slot_t), intent(in) :: materials(:)
      integer, intent(in) :: dim
      logical, intent(in) :: fixed_step
      speed = 0.0_rp
   end function no_signal

   !> The smallest mass of a particle it may create [kg] (huge: none).
   real(rp) function no_particle(self) result(mass)
      class(step_component_t), intent(in) :: self
      mass = huge(1.0_rp)
   end function no_particle

   !> True if it has begun by `time` to create particles of material m (for good: particles it created may
   !> still exist when it has stopped).
   logical function supplies_nothing(self, m, time) result(supplies)
      class(step_component_t), intent(in) :: self
      integer, intent(in) :: m
      real(rp), intent(in) :: time
      supplies = .false.
   end function supplies_nothing
end module step_component
