!> Builds the constitutive model of each declared material (`&material model=`).
module material_factory
   use error_status, only: status_t
   use scene_description, only: material_spec_t, model_newtonian_fluid, model_linear_elastic, model_rigid
   use material_model, only: material_slot_t
   use newtonian_fluid, only: newtonian_fluid_t
   use linear_elastic, only: linear_elastic_t
   use rigid_material, only: rigid_material_t
   implicit none
   private

   public :: build_materials

contains

   subroutine build_materials(specs, materials, status)
      type(material_spec_t), intent(in) :: specs(:)
      type(material_slot_t), allocatable, intent(out) :: materials(:)
      type(status_t), intent(inout) :: status
      type(newtonian_fluid_t) :: fluid
      type(linear_elastic_t) :: solid
      type(rigid_material_t) :: rigid
      integer :: m

      allocate (materials(size(specs)))
      do m = 1, size(specs)
         select case (trim(specs(m)%model))
         case (model_newtonian_fluid)
            fluid%name = specs(m)%name
            fluid%reference_density = specs(m)%density
            fluid%is_fluid = .true.
            fluid%bulk_modulus = specs(m)%bulk_modulus
            fluid%viscosity = specs(m)%viscosity
            allocate (materials(m)%model, source=fluid)
         case (model_linear_elastic)
            solid%name = specs(m)%name
            solid%reference_density = specs(m)%density
            solid%is_fluid = .false.
            solid%uses_spin = .true.       ! the Jaumann rate
            call solid%set_from_young_poisson(specs(m)%youngs_modulus, specs(m)%poisson_ratio)
            allocate (materials(m)%model, source=solid)
         case (model_rigid)
            rigid%name = specs(m)%name
            rigid%reference_density = specs(m)%density
            rigid%is_fluid = .false.
            allocate (materials(m)%model, source=rigid)
         case default
            call status%fail('material '//trim(specs(m)%name)//': unknown model '//trim(specs(m)%model))
            return
         end select
      end do
   end subroutine build_materials
end module material_factory
