!> SIGTERM and SIGINT, what a batch scheduler (or Ctrl-C) sends before ending a job, and SIGUSR1, which
!> mpirun forwards to every rank at once (Open MPI turns a SIGTERM to mpirun into a SIGTERM to the
!> ranks only after a delay, and sometimes not at all): the handler only records the signal, and the
!> time loop checkpoints and stops at the end of the step in which all ranks have seen it. A second
!> signal of the same kind ends the process at once (default action).
!>
!> The handler is installed through the C library's signal() (bind(C)), since -std=f2018 has no
!> SIGNAL intrinsic. Signal numbers are those of Linux (and every common POSIX system).
module termination_signals
   use, intrinsic :: iso_c_binding, only: c_int, c_funptr, c_funloc, c_null_funptr
   implicit none
   private

   integer(c_int), parameter, public :: sigint = 2, sigusr1 = 10, sigterm = 15

   public :: install_termination_handlers, received_termination_signal, signal_name

   !> The last signal received (0: none). Written only by the handler.
   integer(c_int), volatile, save :: received = 0

   interface
      function c_signal(signum, handler) bind(c, name='signal') result(previous)
         import :: c_int, c_funptr
         integer(c_int), value :: signum
         type(c_funptr), value :: handler
         type(c_funptr) :: previous
      end function c_signal
   end interface

contains

   !> Record SIGTERM, SIGINT and SIGUSR1 from now on (and forget any signal recorded before).
   subroutine install_termination_handlers()
      type(c_funptr) :: previous
      received = 0
      previous = c_signal(sigterm, c_funloc(on_termination_signal))
      previous = c_signal(sigint, c_funloc(on_termination_signal))
      previous = c_signal(sigusr1, c_funloc(on_termination_signal))
   end subroutine install_termination_handlers

   !> The signal received since the handlers were installed, 0 if none.
   integer function received_termination_signal()
      received_termination_signal = received
   end function received_termination_signal

   !> 'SIGTERM', 'SIGINT', 'SIGUSR1' or 'signal <n>'.
   pure function signal_name(signum) result(name)
      integer, intent(in) :: signum
      character(len=:), allocatable :: name
      character(len=12) :: number
      select case (signum)
      case (sigterm)
         name = 'SIGTERM'
      case (sigint)
         name = 'SIGINT'
      case (sigusr1)
         name = 'SIGUSR1'
      case default
         write (number, '(i0)') signum
         name = 'signal '//trim(number)
      end select
   end function signal_name

   !> Only async-signal-safe work: record the signal and make the next one of this kind fatal.
   subroutine on_termination_signal(signum) bind(c)
      integer(c_int), value :: signum
      type(c_funptr) :: previous
      received = signum
      previous = c_signal(signum, c_null_funptr)     ! SIG_DFL
   end subroutine on_termination_signal
end module termination_signals
