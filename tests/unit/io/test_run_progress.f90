!> Output times of src/io/run_progress.f90: k x interval to 15 digits (so 0.3, not 0.30000000000000004),
!> at most end_time, and the index recovered from the time alone (what a restart has).
module test_run_progress
   use kinds, only: rp, i8
   use run_progress, only: scheduled_output_time, output_index_of
   use input_text, only: real_text
   use assertions, only: assertEqual
   implicit none
   private

   public :: test_output_times_are_clean_multiples, test_output_index_is_recovered, test_output_times_stop_at_end

contains

   subroutine test_output_times_are_clean_multiples()
      integer(i8) :: k
      character(len=32) :: expected
      call assertEqual(0.3_rp, scheduled_output_time(3_i8, 0.1_rp, 10.0_rp), 0.0_rp, '3 x 0.1 is the double of 0.3')
      call assertEqual('0.3', real_text(scheduled_output_time(3_i8, 0.1_rp, 10.0_rp)), 'printed as 0.3')
      do k = 1, 200
         write (expected, '(f0.2)') real(k, rp) * 0.05_rp     ! the decimal k x 0.05, read back below
         call assertEqual(read_real(expected), scheduled_output_time(k, 0.05_rp, 100.0_rp), 0.0_rp, &
                          'k x 0.05 for k = '//trim(expected))
      end do
   end subroutine test_output_times_are_clean_multiples

   subroutine test_output_index_is_recovered()
      real(rp) :: intervals(4)
      integer(i8) :: k
      integer :: i
      intervals = [0.1_rp, 0.02_rp, 1.0_rp / 3.0_rp, 7.3e-4_rp]
      do i = 1, size(intervals)
         do k = 1, 3000
            call assertEqual(k, output_index_of(scheduled_output_time(k, intervals(i), 1.0e6_rp), intervals(i), 1.0e6_rp), &
                             'index of output k back from its time')
         end do
      end do
   end subroutine test_output_index_is_recovered

   subroutine test_output_times_stop_at_end()
      integer(i8) :: k
      call assertEqual(1.05_rp, scheduled_output_time(11_i8, 0.1_rp, 1.05_rp), 0.0_rp, 'capped at end_time')
      k = output_index_of(1.05_rp, 0.1_rp, 1.05_rp)
      call assertEqual(1.05_rp, scheduled_output_time(k, 0.1_rp, 1.05_rp), 0.0_rp, 'the end time has an index')
      call assertEqual(1.0_rp, scheduled_output_time(k - 1, 0.1_rp, 1.05_rp), 0.0_rp, 'the output before it')
   end subroutine test_output_times_stop_at_end

   real(rp) function read_real(text)
      character(len=*), intent(in) :: text
      read (text, *) read_real
   end function read_real
end module test_run_progress
