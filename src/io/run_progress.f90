!> Where a run stands besides the solver state: the next output time, what the outputs so far wrote
!> (the XDMF files list them) and the number of the newest checkpoint. Saved in every checkpoint, so a
!> restarted run continues the same series of outputs and checkpoints.
module run_progress
   use kinds, only: rp, i8
   use xdmf_writer, only: output_entry_t
   implicit none
   private

   type, public :: run_progress_t
      real(rp) :: next_output_time = 0.0_rp        !< simulated time of the next output [s]
      integer :: checkpoints_written = 0           !< number of the newest checkpoint (0: none yet)
      logical :: restarted = .false.               !< continued from a checkpoint
      integer(i8) :: restart_step = 0              !< step of that checkpoint
      integer :: n_outputs = 0                     !< outputs written: numbers 0 .. n_outputs - 1
      type(output_entry_t), allocatable :: outputs(:)   !< outputs(1:n_outputs): output 0, 1, ... in order
   contains
      procedure :: add_output => progress_add_output
      procedure :: output_count => progress_output_count
   end type run_progress_t

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

   pure integer function progress_output_count(self)
      class(run_progress_t), intent(in) :: self
      progress_output_count = self%n_outputs
   end function progress_output_count
end module run_progress
