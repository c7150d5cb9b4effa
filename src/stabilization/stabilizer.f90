!> Interface of the anti-locking and smoothing schemes applied per material (algorithms.md sections 2, 3).
!>
!> A scheme acts on the contiguous slice of one material's particles at three points of a step:
!>   prepare            before grid-to-particle, while the particles are still at x^n (cell binning);
!>   filter_strain_rate between the kinematics and the stress update (filter part A, d -> d~);
!>   filter_stress      after the stress update (filter part B and smoothing, sbar -> sbar~).
!> Standard MPM ('none') has no scheme object at all, so it costs nothing.
module stabilizer
   use kinds, only: rp
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use stencil_cache, only: stencil_cache_t
   implicit none
   private

   !> What a stage works on besides the particles: the slice first:last of its material's particles, the
   !> decomposition (halo exchanges), the grid and dt.
   type, public :: stage_context_t
      integer :: first = 1, last = 0
      type(domain_t), pointer :: domain => null()
      type(grid_t), pointer :: grid => null()
      real(rp) :: dt = 0.0_rp
      !> the step's length in steps of the automatic length at the reference CFL number (1 at the default
      !> step and with a fixed dt; mpm_solver's blend_per_step): a smoothing that would act once per step
      !> acts in smoothing_passes(reference_steps) passes instead, so that it acts at one rate per unit time
      real(rp) :: reference_steps = 1.0_rp
      !> the material is the only one with particles, on every rank: the grid's mass row of the step's P2G
      !> is its nodal mass (NB uses it)
      logical :: sole_material = .false.
      type(stencil_cache_t), pointer :: stencils => null()   !< P2G's stencils of this step (3-D; valid until G2P)
      !> the scheme takes the material's rate of deformation from strain_velocity(1:dim, node), the nodal
      !> velocities G2P would form it from, and G2P leaves the particles' rates out (the solver sets it where
      !> a C0 or FOAL1 scheme takes_rate_from_grid and the step allows it: c0_anti_locking). More rows than dim
      !> are other velocity fields (contact), not read.
      logical :: rate_from_grid = .false.
      real(rp), pointer, contiguous :: strain_velocity(:, :) => null()
   end type stage_context_t

   type, abstract, public :: stabilizer_t
      integer :: material = 0     !< material index whose particles this scheme filters
   contains
      procedure(stage_interface), deferred :: prepare
      procedure(stage_interface), deferred :: filter_strain_rate
      procedure(stage_interface), deferred :: filter_stress
   end type stabilizer_t

   abstract interface
      subroutine stage_interface(self, context, particles)
         import :: stabilizer_t, stage_context_t, particle_set_t
         class(stabilizer_t), intent(inout) :: self
         type(stage_context_t), intent(in) :: context
         type(particle_set_t), intent(inout) :: particles
      end subroutine stage_interface
   end interface

   public :: smoothing_passes

   !> A material's scheme; unallocated means standard MPM.
   type, public :: stabilizer_slot_t
      class(stabilizer_t), allocatable :: scheme
   end type stabilizer_slot_t
contains

   !> How a smoothing that acts once per reference step acts in a step of `reference_steps` reference steps
   !> (docs/theory.md 5.1): in `passes` = ceiling(reference_steps) passes, each taking the part `share` =
   !> reference_steps / passes of its change. A step shorter than the reference takes one pass of that part
   !> (a part of a limited increment stays within the limits); a longer one takes the whole change more than
   !> once, each pass from the values the last left, rather than once scaled (beyond the whole change a
   !> limited flux is no longer limited). At the reference step: one whole pass.
   pure subroutine smoothing_passes(reference_steps, passes, share)
      real(rp), intent(in) :: reference_steps
      integer, intent(out) :: passes
      real(rp), intent(out) :: share
      ! the step's length is a quotient of two computed steps: 1 + 1e-12 is the reference step
      real(rp), parameter :: slack = 1.0e-9_rp
      passes = max(1, ceiling(reference_steps - slack))
      share = min(1.0_rp, reference_steps / passes)
   end subroutine smoothing_passes
end module stabilizer
