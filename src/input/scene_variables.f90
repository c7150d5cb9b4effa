!> What every scene group's module (src/input/groups/) shares: the row that describes one variable to the
!> reader (its name and kind for messages, whether it is required), the namelist buffers' length, and the
!> copy of a read string into its field with the check of its length and the keyword's case.
module scene_variables
   use kinds, only: path_len
   use input_text, only: int_text, lower_case, upper_case
   implicit none
   private

   public :: take_text

   !> A variable of a group: its kind names the expected value in messages.
   type, public :: variable_info_t
      character(len=12) :: group
      character(len=26) :: name
      character(len=7) :: kind          !< real, real3, reals (a list), integer, logical, string or string2 (two strings)
      logical :: required
   end type variable_info_t

   !> Namelist buffers of string values are longer than the scene's fields, so that a value too long
   !> for its field is reported instead of cut.
   integer, parameter, public :: text_len = 2*path_len
   !> iostat of a group read whose string value is too long for its field (no run-time library uses it).
   integer, parameter, public :: value_too_long = huge(1)

contains

   !> After a successful read, store the string `value` of namelist variable `variable` in `target`,
   !> folded to lower or upper case (adjusted left) when `fold` says so; a value longer than `target`
   !> sets ios = value_too_long and a message naming the variable instead.
   subroutine take_text(variable, value, target, ios, message, fold)
      character(len=*), intent(in) :: variable, value
      character(len=*), intent(inout) :: target
      integer, intent(inout) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in), optional :: fold
      if (ios /= 0) return
      if (len_trim(value) > len(target)) then
         ios = value_too_long
         message = 'variable '//variable//' must be at most '//int_text(len(target))//' characters long, got '// &
                   int_text(len_trim(value))
         return
      end if
      target = value
      if (.not. present(fold)) return
      select case (fold)
      case ('lower')
         target = lower_case(adjustl(value))
      case ('upper')
         target = upper_case(adjustl(value))
      end select
   end subroutine take_text
end module scene_variables
