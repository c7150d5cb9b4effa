!> The velocity fields of a scene (velocity_fields): one per body of a material in contact besides the
!> common one if some &contact applies (contact_velocity_fields), else the one field
!> (single_velocity_field); with the scene's update scheme.
module velocity_fields_factory
   use scene_description, only: scene_t
   use body_motion, only: body_motion_t
   use velocity_fields, only: velocity_fields_t
   use single_velocity_field, only: single_field_t
   use contact_velocity_fields, only: contact_fields_t
   implicit none
   private

   public :: build_velocity_fields

contains

   !> `bodies`: the scene's tracked bodies (their id ranges are the contact's fields).
   subroutine build_velocity_fields(scene, bodies, n_materials, fields)
      type(scene_t), intent(in) :: scene
      type(body_motion_t), intent(in) :: bodies
      integer, intent(in) :: n_materials
      class(velocity_fields_t), allocatable, intent(out) :: fields
      type(contact_fields_t), allocatable :: contact
      allocate (contact)
      call contact%contact%init(scene, bodies, n_materials)
      if (contact%contact%active) then
         call move_alloc(contact, fields)
      else
         allocate (single_field_t :: fields)
      end if
      fields%musl = scene%run%update_scheme == 'MUSL'
   end subroutine build_velocity_fields
end module velocity_fields_factory
