!> Velocity fields with &contact (velocity_fields): one per body of a material in contact besides the common
!> field, meeting at a node by contact (body_contact, Bardenhagen et al. 2000), each with its own walls'
!> constraints; the rigid bodies on the fields' velocities (rigid_bodies).
module contact_velocity_fields
   use kinds, only: rp
   use background_grid, only: grid_t
   use node_halo, only: sum_shared_nodes
   use grid_transfer, only: particles_to_grid, update_velocity_and_remap, grid_to_particles
   use phase_timers, only: phase_grid_update, phase_walls, phase_halo, phase_grid_to_particles
   use body_contact, only: contact_t
   use velocity_fields, only: velocity_fields_t, transfer_state_t
   implicit none
   private

   type, extends(velocity_fields_t), public :: contact_fields_t
      type(contact_t) :: contact
   contains
      procedure :: size_nodes => contact_fields_size_nodes
      procedure :: to_grid => contact_fields_to_grid
      procedure :: update_nodes => contact_fields_update_nodes
      procedure :: remap => contact_fields_remap
      procedure :: kinematics => contact_fields_kinematics
      procedure :: keep_particles_inside => contact_fields_keep_particles_inside
      procedure :: strain_velocity => contact_fields_strain_velocity
      procedure :: has_fields_of => contact_fields_has_fields_of
   end type contact_fields_t

contains

   subroutine contact_fields_size_nodes(self, grid)
      class(contact_fields_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      call self%contact%size_nodes(grid, self%musl)
   end subroutine contact_fields_size_nodes

   !> Each particle's field, then P2G into the common rows and the fields' rows.
   subroutine contact_fields_to_grid(self, state)
      class(contact_fields_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      call self%contact%assign_fields(state%particles)
      call particles_to_grid(state%grid, state%particles, state%gravity, self%contact%particle_field, &
                             self%contact%field_row, stencils=state%stencils)
   end subroutine contact_fields_to_grid

   !> Every field's v^{n+1}, the walls on each (with the contact's friction), then the rigid bodies.
   subroutine contact_fields_update_nodes(self, state, dt)
      class(contact_fields_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      real(rp), intent(in) :: dt
      call self%contact%nodal_velocities(state%grid, dt, state%mass_tolerance)
      call state%timers%switch_to(phase_walls)
      call self%contact%apply_walls(state%constraints, state%grid, state%loads%step_impulse, state%loads%field_impulse)
      call state%timers%switch_to(phase_grid_update)
      if (state%rigid%active) &
         call state%rigid%solve(state%domain, state%grid, state%particles, state%constraints, dt, &
                                state%domain%rank == 0, state%loads%step_impulse, self%contact, &
                                state%loads%field_impulse)
   end subroutine contact_fields_update_nodes

   !> MUSL: the particle velocities, then every field's re-mapped velocities, with walls.
   subroutine contact_fields_remap(self, state)
      class(contact_fields_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      if (.not. self%musl) return
      associate (grid => state%grid, particles => state%particles, contact => self%contact)
         call update_velocity_and_remap(grid, particles, state%flip_fraction, contact%remapped, &
                                        contact%particle_field, contact%velocity, contact%increment, &
                                        state%stencils)
         if (state%rigid%active) call state%rigid%remap_correction(grid, particles, contact%remapped, &
                                                                  contact%particle_field)
         call state%timers%switch_to(phase_halo)
         call sum_shared_nodes(state%domain, grid, contact%remapped)
         call state%timers%switch_to(phase_grid_to_particles)
         call contact%remapped_velocities(state%constraints, grid, state%mass_tolerance)
      end associate
   end subroutine contact_fields_remap

   subroutine contact_fields_kinematics(self, state, dt, first, last, with_rate, uses_spin, d, w, extent)
      class(contact_fields_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      real(rp), intent(in) :: dt
      integer, intent(in) :: first, last
      logical, intent(in) :: with_rate, uses_spin
      real(rp), intent(inout), contiguous :: d(:, :), w(:, :)
      real(rp), intent(out) :: extent(3, 2)
      associate (contact => self%contact)
         if (self%musl) then
            call grid_to_particles(state%grid, state%particles, dt, state%flip_fraction, state%theta, &
                                   update_velocity=.false., compute_strain=with_rate, update_position=.true., &
                                   strain_velocity=contact%remapped, compute_spin=uses_spin, extent=extent, &
                                   field=contact%particle_field, velocity=contact%velocity, &
                                   increment=contact%increment, first=first, last=last, strain_rate=d, spin=w, &
                                   stencils=state%stencils)
         else
            call grid_to_particles(state%grid, state%particles, dt, state%flip_fraction, state%theta, &
                                   update_velocity=.true., compute_strain=with_rate, update_position=.true., &
                                   compute_spin=uses_spin, extent=extent, field=contact%particle_field, &
                                   velocity=contact%velocity, increment=contact%increment, first=first, &
                                   last=last, strain_rate=d, spin=w, &
                                   stencils=state%stencils)
         end if
      end associate
   end subroutine contact_fields_kinematics

   !> The safeguard with each body field's friction against the structures of its &contact.
   subroutine contact_fields_keep_particles_inside(self, state, lowest, highest, corrections)
      class(contact_fields_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      real(rp), intent(in) :: lowest(3), highest(3)
      integer, intent(inout) :: corrections
      call state%constraints%keep_particles_inside(state%grid, state%particles, lowest, highest, corrections, &
                                                   state%loads%step_impulse, self%contact%particle_field, &
                                                   self%contact%wall_friction(state%constraints%structure), &
                                                   state%loads%field_impulse, skip=state%rigid%rigid_material)
   end subroutine contact_fields_keep_particles_inside

   function contact_fields_strain_velocity(self) result(velocity)
      class(contact_fields_t), intent(in), target :: self
      real(rp), pointer, contiguous :: velocity(:, :)
      velocity => null()
      if (self%musl) velocity => self%contact%remapped
   end function contact_fields_strain_velocity

   pure logical function contact_fields_has_fields_of(self, m) result(own)
      class(contact_fields_t), intent(in) :: self
      integer, intent(in) :: m
      own = self%contact%contact_material(m)
   end function contact_fields_has_fields_of
end module contact_velocity_fields
