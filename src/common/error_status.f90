!> Error reporting without stopping: library code returns a status, only the driver aborts
!> (style.md, lesson 8). A status carries one human-readable message.
module error_status
   use kinds, only: message_len
   implicit none
   private

   !> Outcome of an operation: `ok` unless `fail` was called.
   type, public :: status_t
      logical :: ok = .true.
      character(len=message_len) :: message = ''
   contains
      procedure :: fail => status_fail
      procedure :: reset => status_reset
   end type status_t

contains

   !> Record a failure; the first message wins so the root cause is reported.
   subroutine status_fail(self, message)
      class(status_t), intent(inout) :: self
      character(len=*), intent(in) :: message
      if (self%ok) self%message = message
      self%ok = .false.
   end subroutine status_fail

   subroutine status_reset(self)
      class(status_t), intent(inout) :: self
      self%ok = .true.
      self%message = ''
   end subroutine status_reset
end module error_status
