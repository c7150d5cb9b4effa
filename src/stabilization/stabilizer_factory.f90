!> Builds the stabilization scheme of each material from its `&material stabilization=` keyword.
module stabilizer_factory
   use error_status, only: status_t
   use scene_description, only: material_spec_t
   use stabilizer, only: stabilizer_slot_t
   implicit none
   private

   public :: build_stabilizers

contains

   subroutine build_stabilizers(specs, schemes, status)
      type(material_spec_t), intent(in) :: specs(:)
      type(stabilizer_slot_t), allocatable, intent(out) :: schemes(:)
      type(status_t), intent(inout) :: status
      integer :: m
      allocate (schemes(size(specs)))
      do m = 1, size(specs)
         select case (trim(specs(m)%stabilization))
         case ('none')
            continue
         case default
            call status%fail('material '//trim(specs(m)%name)//': stabilization '//trim(specs(m)%stabilization)// &
                             ' is not available in this build yet')
            return
         end select
      end do
   end subroutine build_stabilizers
end module stabilizer_factory
