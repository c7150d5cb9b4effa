!> The step's components (step_component) of a scene, in the order the step calls them at each stage:
!> the inflow if the scene has inlets, the volume correction if a fluid selects one, the damping zones if
!> the scene has any. A scene with none of them has an empty list. A new component is one `if` here.
module step_component_factory
   use kinds, only: rp, i8
   use scene_description, only: scene_t
   use constraint_list, only: constraint_list_t
   use step_component, only: step_component_t, component_slot_t
   use phase_timers, only: phase_inflow, phase_volume_correction, phase_grid_to_particles
   use fluid_inflow, only: inflow_t, build_inlets
   use volume_correction, only: volume_corrector_t
   use damping_zone, only: damping_zones_t
   implicit none
   private

   public :: build_step_components

contains

   !> `first_id`: the first particle id after the bodies' (the inlets' ids follow); `gravity` in the grid
   !> frame; `constraints` built from the same scene (the inlets' feeders are constraints);
   !> `planned_reference_steps` the longest step the scene's CFL numbers allow, in reference steps.
   subroutine build_step_components(scene, first_id, gravity, planned_reference_steps, constraints, components)
      type(scene_t), intent(in) :: scene
      integer(i8), intent(in) :: first_id
      real(rp), intent(in) :: gravity(3), planned_reference_steps
      type(constraint_list_t), intent(in) :: constraints
      type(component_slot_t), allocatable, intent(out) :: components(:)
      type(inflow_t), allocatable :: inflow
      type(volume_corrector_t), allocatable :: volume
      type(damping_zones_t), allocatable :: damping

      allocate (components(0))
      if (allocated(scene%inlets)) then
         if (size(scene%inlets) > 0) then
            allocate (inflow)
            inflow%phase = phase_inflow
            call build_inlets(scene, first_id, constraints, inflow%inlets)
            call append(components, inflow)
         end if
      end if
      allocate (volume)
      call volume%init(scene, gravity, planned_reference_steps)
      if (volume%shifting .or. volume%relaxing) then
         volume%phase = phase_volume_correction
         call append(components, volume)
      end if
      if (allocated(scene%damping_zones)) then
         if (size(scene%damping_zones) > 0) then
            allocate (damping)
            ! a change of the particles' velocities right after G2P: charged to it
            damping%phase = phase_grid_to_particles
            call damping%init(scene)
            call append(components, damping)
         end if
      end if
   end subroutine build_step_components

   subroutine append(components, component)
      type(component_slot_t), allocatable, intent(inout) :: components(:)
      class(step_component_t), intent(in) :: component
      type(component_slot_t), allocatable :: longer(:)
      integer :: i
      allocate (longer(size(components) + 1))
      do i = 1, size(components)
         call move_alloc(components(i)%component, longer(i)%component)
      end do
      allocate (longer(size(longer))%component, source=component)
      call move_alloc(longer, components)
   end subroutine append
end module step_component_factory
