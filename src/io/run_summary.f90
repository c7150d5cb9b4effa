!> `run_summary.csv` in the output folder: what a run cost, one row written when the run ends (also
!> when it stopped early), so that batch studies can put cost beside accuracy:
!>   wall_seconds, steps, particle_steps, particle_steps_per_second_per_core, ranks,
!>   peak_memory_bytes (largest rank), peak_memory_bytes_total (all ranks), outcome
!> Steps and particle-steps count this invocation only (a restarted run reports its continuation).
!> `timing.csv` beside it: the time loop's wall time per phase (phase_timers), one row per phase:
!>   phase, seconds_max (the slowest rank's), seconds_mean (over the ranks), share (of the mean loop time)
!> and a last row `total`.
module run_summary
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_Comm_rank, MPI_Comm_size, MPI_IN_PLACE, MPI_INTEGER8, &
                      MPI_DOUBLE_PRECISION, MPI_SUM, MPI_MAX
   use error_status, only: status_t
   use process_memory, only: peak_resident_bytes
   use input_text, only: int_text, real_text
   use output_layout, only: temporary_suffix
   use file_system, only: rename_path
   implicit none
   private

   character(len=*), parameter, public :: run_summary_file = 'run_summary.csv', timing_file = 'timing.csv'

   public :: write_run_summary, write_timing

contains

   !> Collective over `comm`: rank 0 writes <dir>/run_summary.csv (replacing it) with the totals.
   !> local_particle_steps: the sum over this invocation's steps of this rank's particle count.
   subroutine write_run_summary(dir, comm, wall_seconds, steps, local_particle_steps, outcome, status)
      character(len=*), intent(in) :: dir, outcome
      type(MPI_Comm), intent(in) :: comm
      real(rp), intent(in) :: wall_seconds
      integer(i8), intent(in) :: steps, local_particle_steps
      type(status_t), intent(inout) :: status
      integer(i8) :: particle_steps, peak(1), total(1)
      integer :: rank, ranks, unit, ios
      character(len=256) :: message
      real(rp) :: rate

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      particle_steps = local_particle_steps
      call MPI_Allreduce(MPI_IN_PLACE, particle_steps, 1, MPI_INTEGER8, MPI_SUM, comm)
      peak = peak_resident_bytes()
      total = peak
      call MPI_Allreduce(MPI_IN_PLACE, peak, 1, MPI_INTEGER8, MPI_MAX, comm)
      call MPI_Allreduce(MPI_IN_PLACE, total, 1, MPI_INTEGER8, MPI_SUM, comm)
      if (rank /= 0) return
      rate = 0.0_rp
      if (wall_seconds > 0.0_rp) rate = real(particle_steps, rp) / (wall_seconds * ranks)
      open (newunit=unit, file=dir//'/'//run_summary_file//temporary_suffix, status='replace', action='write', &
            iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail('cannot write '//dir//'/'//run_summary_file//': '//trim(message))
         return
      end if
      write (unit, '(a)') 'wall_seconds,steps,particle_steps,particle_steps_per_second_per_core,ranks,'// &
         'peak_memory_bytes,peak_memory_bytes_total,outcome'
      write (unit, '(a)') real_text(wall_seconds)//','//int_text(steps)//','//int_text(particle_steps)//','// &
         real_text(rate)//','//int_text(ranks)//','//int_text(peak(1))//','//int_text(total(1))//','//outcome
      close (unit)
      if (.not. rename_path(dir//'/'//run_summary_file//temporary_suffix, dir//'/'//run_summary_file)) &
         call status%fail('cannot rename '//dir//'/'//run_summary_file//temporary_suffix)
   end subroutine write_run_summary

   !> Collective over `comm`: rank 0 writes <dir>/timing.csv (replacing it) from every rank's `seconds`
   !> of the phases `names`.
   subroutine write_timing(dir, comm, seconds, names, status)
      character(len=*), intent(in) :: dir
      type(MPI_Comm), intent(in) :: comm
      real(rp), intent(in) :: seconds(:)
      character(len=*), intent(in) :: names(:)
      type(status_t), intent(inout) :: status
      real(rp) :: largest(size(seconds)), mean(size(seconds)), total
      integer :: rank, ranks, unit, ios, k
      character(len=256) :: message

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      call MPI_Allreduce(seconds, largest, size(seconds), MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(seconds, mean, size(seconds), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      if (rank /= 0) return
      mean = mean / ranks
      total = sum(mean)
      open (newunit=unit, file=dir//'/'//timing_file//temporary_suffix, status='replace', action='write', &
            iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail('cannot write '//dir//'/'//timing_file//': '//trim(message))
         return
      end if
      write (unit, '(a)') 'phase,seconds_max,seconds_mean,share'
      do k = 1, size(seconds)
         write (unit, '(a)') trim(names(k))//','//real_text(largest(k))//','//real_text(mean(k))//','// &
            real_text(merge(mean(k) / total, 0.0_rp, total > 0.0_rp))
      end do
      write (unit, '(a)') 'total,'//real_text(sum(largest))//','//real_text(total)//',1'
      close (unit)
      if (.not. rename_path(dir//'/'//timing_file//temporary_suffix, dir//'/'//timing_file)) &
         call status%fail('cannot rename '//dir//'/'//timing_file//temporary_suffix)
   end subroutine write_timing
end module run_summary
