!> The grid's velocity field(s) and the transfers through them (algorithms.md section 1.2, steps 1, 2 and 4):
!> P2G, the nodal update with the walls' constraints (eq. 14) and the rigid bodies' projection, MUSL's
!> re-map, G2P and the particles' safeguard. One field (single_velocity_field) or, with &contact, one per
!> body besides the common one, meeting at a node by contact (contact_velocity_fields). The solver holds
!> one extension of velocity_fields_t and calls the stages of the step through it, so the step names no
!> field layout; the update scheme (USL, MUSL) is an option of the fields, whose re-map is empty under USL.
module velocity_fields
   use kinds, only: rp
   use background_grid, only: grid_t
   use wall_loads, only: wall_loads_t
   use rigid_bodies, only: rigid_set_t
   use phase_timers, only: phase_timers_t
   use step_component, only: step_state_t
   implicit none
   private

   !> What the transfers read and change: the step's state (the components' too), the loads, rigid bodies
   !> and timers, and the transfer options.
   type, extends(step_state_t), public :: transfer_state_t
      type(wall_loads_t), pointer :: loads => null()          !< the walls' impulse of the step
      type(rigid_set_t), pointer :: rigid => null()           !< the rigid bodies (none: inactive)
      type(phase_timers_t), pointer :: timers => null()
      real(rp) :: gravity(3) = 0.0_rp                         !< grid frame
      real(rp) :: mass_tolerance = 0.0_rp                     !< nodes lighter than this carry no velocity
      real(rp) :: flip_fraction = 0.0_rp, theta = 0.0_rp      !< &run flip_fraction, theta
   end type transfer_state_t

   type, abstract, public :: velocity_fields_t
      logical :: musl = .false.       !< MUSL: the rate of deformation from re-mapped nodal velocities
   contains
      procedure(size_interface), deferred :: size_nodes
      procedure(stage_interface), deferred :: to_grid
      procedure(update_interface), deferred :: update_nodes
      procedure(stage_interface), deferred :: remap
      procedure(kinematics_interface), deferred :: kinematics
      procedure(safeguard_interface), deferred :: keep_particles_inside
      procedure(strain_velocity_interface), deferred :: strain_velocity
      procedure :: has_fields_of => no_fields_of
   end type velocity_fields_t

   abstract interface
      !> Size the node arrays to the grid's local nodes (after a new layout).
      subroutine size_interface(self, grid)
         import :: velocity_fields_t, grid_t
         class(velocity_fields_t), intent(inout) :: self
         type(grid_t), intent(in) :: grid
      end subroutine size_interface

      !> to_grid: step 1, P2G (mass, momentum, forces; before the ghost-node sums). remap: MUSL's new particle
      !> velocities and their re-mapped nodal velocities, with the walls (nothing under USL).
      subroutine stage_interface(self, state)
         import :: velocity_fields_t, transfer_state_t
         class(velocity_fields_t), intent(inout) :: self
         type(transfer_state_t), intent(inout) :: state
      end subroutine stage_interface

      !> Step 2: v^{n+1} = v^n + dt f / m on the summed nodes, the rigid bodies, the walls (their impulse is
      !> the load on them), dv = v^{n+1} - v^n.
      subroutine update_interface(self, state, dt)
         import :: velocity_fields_t, transfer_state_t, rp
         class(velocity_fields_t), intent(inout) :: self
         type(transfer_state_t), intent(inout) :: state
         real(rp), intent(in) :: dt
      end subroutine update_interface

      !> Step 4 for particles first:last: positions (and USL velocities), their rate of deformation into d
      !> (with_rate) and spin into w (uses_spin); `extent` the extent of their new positions.
      subroutine kinematics_interface(self, state, dt, first, last, with_rate, uses_spin, d, w, extent)
         import :: velocity_fields_t, transfer_state_t, rp
         class(velocity_fields_t), intent(inout) :: self
         type(transfer_state_t), intent(inout) :: state
         real(rp), intent(in) :: dt
         integer, intent(in) :: first, last
         logical, intent(in) :: with_rate, uses_spin
         real(rp), intent(inout), contiguous :: d(:, :), w(:, :)
         real(rp), intent(out) :: extent(3, 2)
      end subroutine kinematics_interface

      !> The safeguard (algorithms.md section 4.2) over the particles between lowest and highest (grid
      !> frame); `corrections` counts the particles it put back.
      subroutine safeguard_interface(self, state, lowest, highest, corrections)
         import :: velocity_fields_t, transfer_state_t, rp
         class(velocity_fields_t), intent(inout) :: self
         type(transfer_state_t), intent(inout) :: state
         real(rp), intent(in) :: lowest(3), highest(3)
         integer, intent(inout) :: corrections
      end subroutine safeguard_interface

      !> MUSL: the nodal velocities the rate of deformation is formed from (rows 1:dim: the common field's);
      !> USL: not associated.
      function strain_velocity_interface(self) result(velocity)
         import :: velocity_fields_t, rp
         class(velocity_fields_t), intent(in), target :: self
         real(rp), pointer, contiguous :: velocity(:, :)
      end function strain_velocity_interface
   end interface

contains

   !> True if material m's bodies have velocity fields of their own (contact).
   pure logical function no_fields_of(self, m) result(own)
      class(velocity_fields_t), intent(in) :: self
      integer, intent(in) :: m
      own = .false.
   end function no_fields_of
end module velocity_fields
