!> The `&gravity` group (docs/input.md): the body force per unit mass, world frame (scene%gravity). Here:
!> the reader's row, the namelist read, the scene.nml text and its check (validate_gravity); it is a
!> vector of the scene, no type.
module gravity_group
   use kinds, only: rp
   use input_text, only: real_list_text, int_text, group_context
   use scene_variables, only: variable_info_t
   use error_status, only: status_t
   use input_checks, only: check_real
   implicit none
   private

   public :: validate_gravity, read_gravity_group, gravity_value

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: gravity_variables(*) = [ &
      variable_info_t('gravity', 'acceleration', 'real3', .false.)]

contains

   !> Read one `&gravity ... /` (text) over `vector` [m/s^2].
   subroutine read_gravity_group(vector, ios, message, text)
      real(rp), intent(inout) :: vector(3)
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      real(rp) :: acceleration(3)
      namelist /gravity/ acceleration

      acceleration = vector
      read (text, nml=gravity, iostat=ios, iomsg=message)
      if (ios /= 0) return
      vector = acceleration
   end subroutine read_gravity_group

   !> The value of variable `name` as scene.nml writes it.
   function gravity_value(vector, name) result(text)
      real(rp), intent(in) :: vector(3)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      text = ''
      if (name == 'acceleration') text = real_list_text(vector)
   end function gravity_value

   subroutine validate_gravity(gravity, dim, path, status)
      real(rp), intent(in) :: gravity(3)
      integer, intent(in) :: dim
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      integer :: k
      do k = 1, dim
         call check_real(group_context(path, 'gravity', 0), 'acceleration('//int_text(k)//')', gravity(k), status)
      end do
   end subroutine validate_gravity
end module gravity_group
