!> Where a run stands besides the solver state: the next output time, what the outputs so far wrote
!> (the XDMF files list them) and the number of the newest checkpoint. Saved in every checkpoint, so a
!> restarted run continues the same series of outputs and checkpoints.
!>
!> Output times are index x interval, not sums of intervals: output k is at k * output_interval rounded
!> to 15 significant digits (scheduled_output_time), so with output_interval = 0.1 the third is at
!> exactly the double nearest 0.3 and prints as 0.3 (3 * 0.1 is 0.30000000000000004, and three
!> additions of 0.1 drift further). The index is not stored: next_output_time, which checkpoints hold,
!> gives it back (output_index_of), so a restarted run continues the same times bit for bit.
module run_progress
   use kinds, only: rp, i8
   use xdmf_writer, only: output_entry_t
   implicit none
   private

   type, public :: run_progress_t
      real(rp) :: next_output_time = 0.0_rp        !< simulated time of the next output [s]
      integer(i8) :: next_output_index = 1         !< its index k: next_output_time = min(k interval, end)
      integer :: checkpoints_written = 0           !< number of the newest checkpoint (0: none yet)
      logical :: restarted = .false.               !< continued from a checkpoint
      integer(i8) :: restart_step = 0              !< step of that checkpoint
      integer :: n_outputs = 0                     !< outputs written: numbers 0 .. n_outputs - 1
      type(output_entry_t), allocatable :: outputs(:)   !< outputs(1:n_outputs): output 0, 1, ... in order
   contains
      procedure :: add_output => progress_add_output
      procedure :: output_count => progress_output_count
   end type run_progress_t

   public :: scheduled_output_time, output_index_of

contains

   !> Record output `entry` (its number is the count of outputs so far).
   subroutine progress_add_output(self, entry)
      class(run_progress_t), intent(inout) :: self
      type(output_entry_t), intent(in) :: entry
      type(output_entry_t), allocatable :: grown(:)
      if (.not. allocated(self%outputs)) allocate (self%outputs(16))
      if (self%n_outputs == size(self%outputs)) then
         allocate (grown(2 * size(self%outputs)))
         grown(1:self%n_outputs) = self%outputs(1:self%n_outputs)
         call move_alloc(grown, self%outputs)
      end if
      self%n_outputs = self%n_outputs + 1
      self%outputs(self%n_outputs) = entry
   end subroutine progress_add_output

   !> The time of output k: k * interval rounded to 15 significant digits (the round-off of the product
   !> is below that), and at most end_time [s].
   real(rp) function scheduled_output_time(k, interval, end_time) result(t)
      integer(i8), intent(in) :: k
      real(rp), intent(in) :: interval, end_time
      character(len=32) :: text
      t = real(k, rp) * interval
      write (text, '(es32.14e4)') t
      read (text, *) t
      t = min(t, end_time)
   end function scheduled_output_time

   !> The index of the output at `time` (a scheduled output time, or end_time): the first k whose
   !> scheduled time reaches it.
   integer(i8) function output_index_of(time, interval, end_time) result(k)
      real(rp), intent(in) :: time, interval, end_time
      k = max(1_i8, nint(min(time / interval, 1.0e15_rp), i8) - 1)
      do while (scheduled_output_time(k, interval, end_time) < time)
         k = k + 1
      end do
   end function output_index_of

   pure integer function progress_output_count(self)
      class(run_progress_t), intent(in) :: self
      progress_output_count = self%n_outputs
   end function progress_output_count
end module run_progress
