!> Tests of the run-control helpers of src/io/: termination signals are recorded, not fatal; a
!> diagnostics file is cut back to the rows of a restart point.
module test_run_control
   use, intrinsic :: iso_c_binding, only: c_int
   use kinds, only: i8
   use assertions, only: assertTrue, assertEqual
   use error_status, only: status_t
   use termination_signals, only: install_termination_handlers, received_termination_signal, signal_name, sigterm
   use csv_writer, only: keep_rows_until
   implicit none
   private

   public :: test_sigterm_is_recorded, test_rows_after_restart_step_are_dropped

   interface
      function c_raise(signum) bind(c, name='raise') result(r)
         import :: c_int
         integer(c_int), value :: signum
         integer(c_int) :: r
      end function c_raise
   end interface

contains

   subroutine test_sigterm_is_recorded()
      integer(c_int) :: r
      call install_termination_handlers()
      call assertEqual(0, received_termination_signal(), 'nothing yet')
      r = c_raise(sigterm)
      call assertEqual(0, int(r), 'raise')
      call assertEqual(15, received_termination_signal(), 'SIGTERM recorded, process alive')
      call assertEqual('SIGTERM', signal_name(received_termination_signal()), 'name')
   end subroutine test_sigterm_is_recorded

   !> Rows up to step 20 stay; later rows and a row cut short by a crash go.
   subroutine test_rows_after_restart_step_are_dropped()
      type(status_t) :: status
      integer :: unit, ios, n
      character(len=100) :: line, lines(10)
      open (newunit=unit, file='rows.csv', status='replace', action='write')
      write (unit, '(a)') 'time,step,value', '0.0,0,1.5', '0.1,10,2.5', '0.2,20,3.5', '0.3,30,4.5', '0.4,4'
      close (unit)
      call keep_rows_until('rows.csv', 2, 20_i8, status)
      call assertTrue(status%ok, 'keep_rows_until: '//trim(status%message))
      open (newunit=unit, file='rows.csv', status='old', action='read')
      n = 0
      do
         read (unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         n = n + 1
         lines(n) = line
      end do
      close (unit)
      call assertEqual(4, n, 'header and 3 rows')
      call assertEqual('0.2,20,3.5', lines(min(n, 4)), 'last row kept')

      call keep_rows_until('rows.csv', 2, 5_i8, status)
      open (newunit=unit, file='rows.csv', status='old', action='read')
      n = 0
      do
         read (unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         n = n + 1
      end do
      close (unit)
      call assertEqual(2, n, 'header and the row of step 0')
   end subroutine test_rows_after_restart_step_are_dropped
end module test_run_control
