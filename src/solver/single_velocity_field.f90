!> One velocity field on the grid (velocity_fields): the grid's own nodal arrays, and with MUSL the re-mapped
!> momentum. The rigid bodies take their nodes' increments before the walls hold the other nodes
!> (rigid_bodies).
module single_velocity_field
   use kinds, only: rp
   use background_grid, only: grid_t, row_mass
   use node_halo, only: sum_shared_nodes
   use grid_transfer, only: particles_to_grid, update_velocity_and_remap, grid_to_particles
   use phase_timers, only: phase_grid_update, phase_walls, phase_halo, phase_grid_to_particles
   use velocity_fields, only: velocity_fields_t, transfer_state_t
   implicit none
   private

   type, extends(velocity_fields_t), public :: single_field_t
      real(rp), allocatable :: remapped_momentum(:, :)   !< MUSL: (dim, node) re-mapped momentum, then velocity
   contains
      procedure :: size_nodes => single_size_nodes
      procedure :: to_grid => single_to_grid
      procedure :: update_nodes => single_update_nodes
      procedure :: remap => single_remap
      procedure :: kinematics => single_kinematics
      procedure :: keep_particles_inside => single_keep_particles_inside
      procedure :: strain_velocity => single_strain_velocity
   end type single_field_t

contains

   subroutine single_size_nodes(self, grid)
      class(single_field_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      if (allocated(self%remapped_momentum)) deallocate (self%remapped_momentum)
      if (self%musl) allocate (self%remapped_momentum(grid%dim, grid%node_count))
   end subroutine single_size_nodes

   subroutine single_to_grid(self, state)
      class(single_field_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      call particles_to_grid(state%grid, state%particles, state%gravity, stencils=state%stencils)
   end subroutine single_to_grid

   !> v^n = P/m, v^{n+1} = v^n + dt f/m, the rigid bodies, the walls, dv = v^{n+1} - v^n (contains the wall
   !> correction).
   subroutine single_update_nodes(self, state, dt)
      class(single_field_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      real(rp), intent(in) :: dt
      integer :: dim, mom, frc
      real(rp), allocatable :: before_walls(:, :)
      dim = state%grid%dim
      mom = state%grid%row_momentum
      frc = state%grid%row_force
      associate (grid => state%grid, acc => state%grid%accumulated, v => state%grid%velocity, &
                 dv => state%grid%velocity_increment, constraints => state%constraints, timers => state%timers, &
                 rigid => state%rigid)
         if (dim == 2) then
            call nodal_velocities_2d(size(acc, 1), grid%node_count, acc, mom, frc, dt, state%mass_tolerance, v, dv)
         else
            call nodal_velocities_3d(size(acc, 1), grid%node_count, acc, mom, frc, dt, state%mass_tolerance, v, dv)
         end if
         if (rigid%active) then
            ! rigid bodies first, on the increments before the walls: a body meets the walls as a body
            ! (rigid_bodies), and the walls then hold the other nodes only
            dv = v - dv
            call rigid%solve(state%domain, grid, state%particles, constraints, dt, state%domain%rank == 0, &
                             state%loads%step_impulse)
            before_walls = v
            call timers%switch_to(phase_walls)
            call constraints%constrain(dim, v, acc(row_mass, :), state%loads%step_impulse, skip=rigid%held)
            call timers%switch_to(phase_grid_update)
            dv = dv + (v - before_walls)
         else
            call timers%switch_to(phase_walls)
            ! the walls' impulse on the nodes is the load on them (algorithms.md section 9.1); the MUSL re-map
            ! applies the walls again to velocities only, which moves no momentum
            call constraints%constrain(dim, v, acc(row_mass, :), state%loads%step_impulse)
            call timers%switch_to(phase_grid_update)
            dv = v - dv
         end if
      end associate
   end subroutine single_update_nodes

   !> MUSL: update the particle velocities, then nodal velocities from their momentum, with walls.
   subroutine single_remap(self, state)
      class(single_field_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      if (.not. self%musl) return
      associate (grid => state%grid, particles => state%particles, timers => state%timers)
         call update_velocity_and_remap(grid, particles, state%flip_fraction, self%remapped_momentum, &
                                        stencils=state%stencils)
         if (state%rigid%active) call state%rigid%remap_correction(grid, particles, self%remapped_momentum)
         call timers%switch_to(phase_halo)
         call sum_shared_nodes(state%domain, grid, self%remapped_momentum)
         call timers%switch_to(phase_grid_to_particles)
         call momenta_to_velocities(grid%accumulated, state%mass_tolerance, self%remapped_momentum)
         call timers%switch_to(phase_walls)
         call state%constraints%constrain(grid%dim, self%remapped_momentum)
         call timers%switch_to(phase_grid_to_particles)
      end associate
   end subroutine single_remap

   subroutine single_kinematics(self, state, dt, first, last, with_rate, uses_spin, d, w, extent)
      class(single_field_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      real(rp), intent(in) :: dt
      integer, intent(in) :: first, last
      logical, intent(in) :: with_rate, uses_spin
      real(rp), intent(inout), contiguous :: d(:, :), w(:, :)
      real(rp), intent(out) :: extent(3, 2)
      if (self%musl) then
         call grid_to_particles(state%grid, state%particles, dt, state%flip_fraction, state%theta, &
                                update_velocity=.false., compute_strain=with_rate, update_position=.true., &
                                strain_velocity=self%remapped_momentum, compute_spin=uses_spin, &
                                extent=extent, first=first, last=last, strain_rate=d, spin=w, &
                                stencils=state%stencils)
      else
         call grid_to_particles(state%grid, state%particles, dt, state%flip_fraction, state%theta, &
                                update_velocity=.true., compute_strain=with_rate, update_position=.true., &
                                compute_spin=uses_spin, extent=extent, first=first, last=last, &
                                strain_rate=d, spin=w, &
                                stencils=state%stencils)
      end if
   end subroutine single_kinematics

   subroutine single_keep_particles_inside(self, state, lowest, highest, corrections)
      class(single_field_t), intent(inout) :: self
      type(transfer_state_t), intent(inout) :: state
      real(rp), intent(in) :: lowest(3), highest(3)
      integer, intent(inout) :: corrections
      call state%constraints%keep_particles_inside(state%grid, state%particles, lowest, highest, corrections, &
                                                   state%loads%step_impulse, skip=state%rigid%rigid_material)
   end subroutine single_keep_particles_inside

   function single_strain_velocity(self) result(velocity)
      class(single_field_t), intent(in), target :: self
      real(rp), pointer, contiguous :: velocity(:, :)
      velocity => null()
      if (self%musl) velocity => self%remapped_momentum
   end function single_strain_velocity

   ! dv := v^n = P/m (for now), v := v^{n+1} = v^n + dt f/m before the walls; 0 where m is below the
   ! tolerance. Per dimension (with one routine and the dimension a literal at the calls, only the loop
   ! over the components vectorised), the node's rows read before the test: so the 2-D loop vectorises
   ! (with sections of run-time length read under the test it stayed scalar). The same operations as before.
   pure subroutine nodal_velocities_2d(rows, n, acc, mom, frc, dt, tolerance, v, dv)
      integer, intent(in) :: rows, n, mom, frc
      real(rp), intent(in) :: acc(rows, n), dt, tolerance
      real(rp), intent(inout) :: v(2, n), dv(2, n)
      real(rp) :: m, momentum(2), force(2)
      integer :: i, k
      do i = 1, n
         m = acc(row_mass, i)
         momentum = acc(mom:mom + 1, i)     ! read whatever the mass: the loads need no mask
         force = acc(frc:frc + 1, i)
         if (m > tolerance) then
            do k = 1, 2
               dv(k, i) = momentum(k) / m
               v(k, i) = dv(k, i) + dt * force(k) / m
            end do
         else
            do k = 1, 2
               dv(k, i) = 0.0_rp
               v(k, i) = 0.0_rp
            end do
         end if
      end do
   end subroutine nodal_velocities_2d

   pure subroutine nodal_velocities_3d(rows, n, acc, mom, frc, dt, tolerance, v, dv)
      integer, intent(in) :: rows, n, mom, frc
      real(rp), intent(in) :: acc(rows, n), dt, tolerance
      real(rp), intent(inout) :: v(3, n), dv(3, n)
      real(rp) :: m, momentum(3), force(3)
      integer :: i, k
      do i = 1, n
         m = acc(row_mass, i)
         momentum = acc(mom:mom + 2, i)     ! read whatever the mass: the loads need no mask
         force = acc(frc:frc + 2, i)
         if (m > tolerance) then
            do k = 1, 3
               dv(k, i) = momentum(k) / m
               v(k, i) = dv(k, i) + dt * force(k) / m
            end do
         else
            do k = 1, 3
               dv(k, i) = 0.0_rp
               v(k, i) = 0.0_rp
            end do
         end if
      end do
   end subroutine nodal_velocities_3d

   !> momentum(:, i) / m_i at the nodes whose mass m_i = accumulated(row_mass, i) exceeds `tolerance`, 0
   !> elsewhere (MUSL's re-mapped velocities). Per dimension without inner loops, so that it vectorises.
   pure subroutine momenta_to_velocities(accumulated, tolerance, momentum)
      real(rp), intent(in), contiguous :: accumulated(:, :)
      real(rp), intent(in) :: tolerance
      real(rp), intent(inout), contiguous :: momentum(:, :)
      if (size(momentum, 1) == 2) then
         call divide_2d(size(accumulated, 1), size(momentum, 2), accumulated, momentum)
      else
         call divide_3d(size(accumulated, 1), size(momentum, 2), accumulated, momentum)
      end if
   contains
      pure subroutine divide_2d(rows, n, accumulated, momentum)
         integer, intent(in) :: rows, n
         real(rp), intent(in) :: accumulated(rows, n)
         real(rp), intent(inout) :: momentum(2, n)
         integer :: i
         do i = 1, n
            if (accumulated(row_mass, i) > tolerance) then
               momentum(1, i) = momentum(1, i) / accumulated(row_mass, i)
               momentum(2, i) = momentum(2, i) / accumulated(row_mass, i)
            else
               momentum(1, i) = 0.0_rp
               momentum(2, i) = 0.0_rp
            end if
         end do
      end subroutine divide_2d
      pure subroutine divide_3d(rows, n, accumulated, momentum)
         integer, intent(in) :: rows, n
         real(rp), intent(in) :: accumulated(rows, n)
         real(rp), intent(inout) :: momentum(3, n)
         integer :: i
         do i = 1, n
            if (accumulated(row_mass, i) > tolerance) then
               momentum(1, i) = momentum(1, i) / accumulated(row_mass, i)
               momentum(2, i) = momentum(2, i) / accumulated(row_mass, i)
               momentum(3, i) = momentum(3, i) / accumulated(row_mass, i)
            else
               momentum(1, i) = 0.0_rp
               momentum(2, i) = 0.0_rp
               momentum(3, i) = 0.0_rp
            end if
         end do
      end subroutine divide_3d
   end subroutine momenta_to_velocities
end module single_velocity_field
