!> The `&contact` group (docs/input.md, docs/contact.md): which bodies meet with velocity fields of their
!> own, and their Coulomb friction. Here: the type and defaults of its variables (contact_spec_t), the
!> reader's rows (contact_variables), the namelist read and the scene.nml text (contact_value). Its checks
!> all name other groups (the materials and structures it pairs) and stay with the scene's validation.
module contact_group
   use kinds, only: rp, name_len
   use input_text, only: real_text, quoted
   use scene_variables, only: variable_info_t, text_len, take_text
   implicit none
   private

   public :: read_contact_group, contact_value

   !> `&contact`: bodies of two solid materials (or of one, against each other), or of a solid material and
   !> a `&structure`, in contact with their own velocity fields, separating and sliding with Coulomb
   !> friction (docs/contact.md).
   type, public :: contact_spec_t
      character(len=name_len) :: between(2) = ''   !< two material names (may be the same), or a material and a structure
      real(rp) :: friction = 0.0_rp                !< Coulomb coefficient mu >= 0
      integer :: material_index(2) = 0             !< derived: positions in scene%materials (0: a structure)
      integer :: structure_index(2) = 0            !< derived: positions in scene%structures (0: a material)
   end type contact_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: contact_variables(*) = [ &
      variable_info_t('contact', 'between', 'string2', .true.), &
      variable_info_t('contact', 'friction', 'real', .false.)]

contains

   !> Read one `&contact ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_contact_group(spec, ios, message, text)
      type(contact_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: between(2)
      real(rp) :: friction
      namelist /contact/ between, friction

      between = spec%between
      friction = spec%friction
      read (text, nml=contact, iostat=ios, iomsg=message)
      call take_text('between', between(1), spec%between(1), ios, message)
      call take_text('between', between(2), spec%between(2), ios, message)
      if (ios /= 0) return
      spec%friction = friction
   end subroutine read_contact_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function contact_value(contact, name) result(text)
      type(contact_spec_t), intent(in) :: contact
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('between')
         text = quoted(contact%between(1))//', '//quoted(contact%between(2))
      case ('friction')
         text = real_text(contact%friction)
      case default
         text = ''
      end select
   end function contact_value
end module contact_group
