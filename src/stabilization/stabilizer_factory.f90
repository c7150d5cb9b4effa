!> Builds the stabilization scheme of each material from its `&material stabilization=` keyword and
!> options (docs/input.md): 'none' (standard MPM: no object, no cost), 'C0', 'NB', 'FOAL1'.
module stabilizer_factory
   use error_status, only: status_t
   use scene_description, only: material_spec_t
   use stabilizer, only: stabilizer_slot_t
   use c0_anti_locking, only: c0_anti_locking_t
   use node_based_anti_locking, only: node_based_anti_locking_t
   use foal1_smoothing, only: foal1_smoothing_t
   implicit none
   private

   public :: build_stabilizers

contains

   subroutine build_stabilizers(specs, schemes, status)
      type(material_spec_t), intent(in) :: specs(:)
      type(stabilizer_slot_t), allocatable, intent(out) :: schemes(:)
      type(status_t), intent(inout) :: status
      type(c0_anti_locking_t) :: c0
      type(node_based_anti_locking_t) :: nb
      type(foal1_smoothing_t) :: foal1
      integer :: m
      allocate (schemes(size(specs)))
      do m = 1, size(specs)
         select case (trim(specs(m)%stabilization))
         case ('none')
            continue
         case ('C0')
            c0%material = m
            c0%volumetric_only = specs(m)%volumetric_only
            allocate (schemes(m)%scheme, source=c0)
         case ('NB')
            nb%material = m
            allocate (schemes(m)%scheme, source=nb)
         case ('FOAL1')
            foal1%material = m
            foal1%options%gamma_max = specs(m)%gamma_max
            foal1%options%both_cells_oscillate = specs(m)%oscillation_rule == 'AND'
            foal1%pressure_only = specs(m)%smoothed_variables == 'pressure'
            foal1%cell_averaging = specs(m)%cell_averaging
            allocate (schemes(m)%scheme, source=foal1)
         case default
            call status%fail('material '//trim(specs(m)%name)//': unknown stabilization '//trim(specs(m)%stabilization))
            return
         end select
      end do
   end subroutine build_stabilizers
end module stabilizer_factory
