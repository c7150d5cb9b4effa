!> `run_summary.csv` in the output folder: what a run cost, one row written when the run ends (also
!> when it stopped early), so that batch studies can put cost beside accuracy:
!>   wall_seconds, steps, particle_steps, particle_steps_per_second_per_core, ranks,
!>   peak_memory_bytes (largest rank), peak_memory_bytes_total (all ranks), outcome
!> Steps and particle-steps count this invocation only (a restarted run reports its continuation).
!> The same figures end the run's standard error, one line for a batch log:
!>   flotsam: end of run: finished, 480 steps to t = 1.0 s in 12.3 s wall time, 8.6e+05 particle-steps/s
!> `timing.csv` beside it: the time loop's wall time per phase (phase_timers), one row per phase:
!>   phase, seconds_max (the slowest rank's), seconds_mean (over the ranks), share (of the mean loop time)
!> and a last row `total` (seconds_max: the largest of the ranks' sums, not the sum of the maxima).
!> `communication.csv`: what the time loop sent per step and per rank, per category of communication
!> (communication_counters), one row per category and a last row `total`:
!>   category, messages_mean, messages_max, bytes_mean, bytes_max, collectives_mean, collectives_max,
!>   collective_bytes_mean, collective_bytes_max (mean and largest over the ranks).
!> All have the CSV layout of every file a run writes: header row, '#' comment lines (provenance, units).
module run_summary
   use, intrinsic :: iso_fortran_env, only: error_unit
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_Comm_rank, MPI_Comm_size, MPI_IN_PLACE, MPI_INTEGER8, &
                      MPI_DOUBLE_PRECISION, MPI_SUM, MPI_MAX
   use error_status, only: status_t
   use process_memory, only: peak_resident_bytes
   use input_text, only: int_text, real_text
   use output_layout, only: temporary_suffix
   use file_system, only: rename_path
   use provenance, only: written_by, current_date, csv_reading_hint
   use communication_counters, only: comm_counts_t, comm_categories, comm_category_names
   implicit none
   private

   character(len=*), parameter, public :: run_summary_file = 'run_summary.csv', timing_file = 'timing.csv', &
                                          communication_file = 'communication.csv'

   !> Columns of the communication table: per step per rank messages, bytes, collectives, collective bytes.
   integer, parameter, public :: comm_columns = 4

   public :: write_run_summary, write_timing, communication_table, write_communication

contains

   !> Collective over `comm`: rank 0 writes <dir>/run_summary.csv (replacing it) with the totals and
   !> prints the final line on standard error. local_particle_steps: the sum over this invocation's
   !> steps of this rank's particle count; simulated_time: the time the run stopped at [s]; outcome:
   !> finished, max_steps, blew_up, stopped_by_signal or failed.
   subroutine write_run_summary(dir, comm, wall_seconds, steps, local_particle_steps, outcome, simulated_time, status)
      character(len=*), intent(in) :: dir, outcome
      type(MPI_Comm), intent(in) :: comm
      real(rp), intent(in) :: wall_seconds, simulated_time
      integer(i8), intent(in) :: steps, local_particle_steps
      type(status_t), intent(inout) :: status
      integer(i8) :: particle_steps, peak(1), total(1)
      integer :: rank, ranks, unit
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
      call print_final_line(outcome, steps, simulated_time, wall_seconds, rate * ranks)
      if (.not. opened(dir, run_summary_file, unit, status)) return
      write (unit, '(a)') 'wall_seconds,steps,particle_steps,particle_steps_per_second_per_core,ranks,'// &
         'peak_memory_bytes,peak_memory_bytes_total,outcome'
      write (unit, '(a)') written_by(ranks, current_date()), &
         '# run_summary.csv: what this invocation of flotsam cost (a continued run reports its continuation)', &
         '# units: wall_seconds s; steps count; particle_steps count (sum over the steps of the particle count); '// &
         'particle_steps_per_second_per_core 1/s; ranks count; peak_memory_bytes B (the largest rank''s peak '// &
         'resident set); peak_memory_bytes_total B (all ranks); outcome: finished, max_steps, blew_up, stopped_by_signal '// &
         'or failed', csv_reading_hint
      write (unit, '(a)') real_text(wall_seconds)//','//int_text(steps)//','//int_text(particle_steps)//','// &
         real_text(rate)//','//int_text(ranks)//','//int_text(peak(1))//','//int_text(total(1))//','//outcome
      call publish(dir, run_summary_file, unit, status)
   end subroutine write_run_summary

   !> Collective over `comm`: rank 0 writes <dir>/timing.csv (replacing it) from every rank's `seconds`
   !> of the phases `names`.
   subroutine write_timing(dir, comm, seconds, names, status)
      character(len=*), intent(in) :: dir
      type(MPI_Comm), intent(in) :: comm
      real(rp), intent(in) :: seconds(:)
      character(len=*), intent(in) :: names(:)
      type(status_t), intent(inout) :: status
      real(rp) :: largest(size(seconds)), mean(size(seconds)), total, largest_total
      integer :: rank, ranks, unit, k

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      call MPI_Allreduce(seconds, largest, size(seconds), MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(seconds, mean, size(seconds), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call MPI_Allreduce(sum(seconds), largest_total, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      if (rank /= 0) return
      mean = mean / ranks
      total = sum(mean)
      if (.not. opened(dir, timing_file, unit, status)) return
      write (unit, '(a)') 'phase,seconds_max,seconds_mean,share'
      write (unit, '(a)') written_by(ranks, current_date()), &
         '# timing.csv: wall time of this invocation''s time loop per phase; the last row, total, has the '// &
         'largest of the ranks'' sums and their mean', &
         '# units: seconds_max s (the slowest rank''s); seconds_mean s (mean over the ranks); share - (of the '// &
         'mean total)', csv_reading_hint
      do k = 1, size(seconds)
         write (unit, '(a)') trim(names(k))//','//real_text(largest(k))//','//real_text(mean(k))//','// &
            real_text(merge(mean(k) / total, 0.0_rp, total > 0.0_rp))
      end do
      write (unit, '(a)') 'total,'//real_text(largest_total)//','//real_text(total)//',1'
      call publish(dir, timing_file, unit, status)
   end subroutine write_timing

   !> Per category (and a last row, the sum of all) the mean over the ranks and the largest rank's
   !> messages, bytes, collective calls and collective bytes per step, from this rank's `counts` over
   !> `steps` steps. Collective over `comm` (two reductions, which are not counted themselves).
   subroutine communication_table(comm, counts, steps, mean, largest)
      type(MPI_Comm), intent(in) :: comm
      type(comm_counts_t), intent(in) :: counts
      integer(i8), intent(in) :: steps
      real(rp), intent(out) :: mean(comm_columns, comm_categories + 1), largest(comm_columns, comm_categories + 1)
      integer(i8) :: local(comm_columns, comm_categories + 1), summed(comm_columns, comm_categories + 1)
      integer :: ranks
      call MPI_Comm_size(comm, ranks)
      local(1, 1:comm_categories) = counts%messages
      local(2, 1:comm_categories) = counts%bytes
      local(3, 1:comm_categories) = counts%collectives
      local(4, 1:comm_categories) = counts%collective_bytes
      local(:, comm_categories + 1) = sum(local(:, 1:comm_categories), dim=2)
      call MPI_Allreduce(local, summed, size(local), MPI_INTEGER8, MPI_SUM, comm)
      mean = real(summed, rp) / (real(ranks, rp) * max(1_i8, steps))
      call MPI_Allreduce(MPI_IN_PLACE, local, size(local), MPI_INTEGER8, MPI_MAX, comm)
      largest = real(local, rp) / max(1_i8, steps)
   end subroutine communication_table

   !> Collective over `comm`: rank 0 writes <dir>/communication.csv (replacing it) from every rank's
   !> `counts` over the loop's `steps` steps (communication_table).
   subroutine write_communication(dir, comm, counts, steps, status)
      character(len=*), intent(in) :: dir
      type(MPI_Comm), intent(in) :: comm
      type(comm_counts_t), intent(in) :: counts
      integer(i8), intent(in) :: steps
      type(status_t), intent(inout) :: status
      real(rp) :: mean(comm_columns, comm_categories + 1), largest(comm_columns, comm_categories + 1)
      character(len=16) :: names(comm_categories + 1)
      integer :: rank, ranks, unit, k, j
      character(len=:), allocatable :: row

      call communication_table(comm, counts, steps, mean, largest)
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      if (rank /= 0) return
      if (.not. opened(dir, communication_file, unit, status)) return
      write (unit, '(a)') 'category,messages_mean,messages_max,bytes_mean,bytes_max,collectives_mean,'// &
         'collectives_max,collective_bytes_mean,collective_bytes_max'
      write (unit, '(a)') written_by(ranks, current_date()), &
         '# communication.csv: what one rank sent per step of this invocation''s time loop, per category '// &
         '(docs/performance.md, Scaling model); mean over the ranks and the largest rank; the last row, total, '// &
         'sums the categories per rank', &
         '# units: messages count/step (point-to-point); bytes B/step; collectives count/step; '// &
         'collective_bytes B/step (payload: the buffer one rank holds after the call)', csv_reading_hint
      names(1:comm_categories) = comm_category_names
      names(comm_categories + 1) = 'total'
      do k = 1, comm_categories + 1
         row = trim(names(k))
         do j = 1, comm_columns
            row = row//','//real_text(mean(j, k))//','//real_text(largest(j, k))
         end do
         write (unit, '(a)') row
      end do
      call publish(dir, communication_file, unit, status)
   end subroutine write_communication

   !> The run's last line on standard error (rank 0): what ended it and what it cost.
   subroutine print_final_line(outcome, steps, simulated_time, wall_seconds, particle_steps_per_second)
      character(len=*), intent(in) :: outcome
      integer(i8), intent(in) :: steps
      real(rp), intent(in) :: simulated_time, wall_seconds, particle_steps_per_second
      character(len=64) :: cost, time
      character(len=:), allocatable :: exact
      write (cost, '(f0.1,a,es8.2)') wall_seconds, ' s wall time, ', particle_steps_per_second
      if (cost(1:1) == '.') cost = '0'//cost(1:len(cost) - 1)
      ! an output time prints as it was meant (1.0); a time between outputs in 6 digits, not 17
      exact = real_text(simulated_time)
      if (len(exact) <= 12) then
         time = exact
      else
         write (time, '(es12.5)') simulated_time
      end if
      write (error_unit, '(a)') 'flotsam: end of run: '//outcome//', '//int_text(steps)//' steps to t = '// &
         trim(adjustl(time))//' s in '//trim(cost)//' particle-steps/s'
      flush (error_unit)
   end subroutine print_final_line

   !> Open <dir>/<name>.tmp for writing as `unit`; false (and status failed) if it cannot be.
   logical function opened(dir, name, unit, status)
      character(len=*), intent(in) :: dir, name
      integer, intent(out) :: unit
      type(status_t), intent(inout) :: status
      integer :: ios
      character(len=256) :: message
      open (newunit=unit, file=dir//'/'//name//temporary_suffix, status='replace', action='write', iostat=ios, &
            iomsg=message)
      opened = ios == 0
      if (.not. opened) call status%fail('cannot write '//dir//'/'//name//': '//trim(message))
   end function opened

   !> Close `unit` and rename <dir>/<name>.tmp to its final name (the file is complete).
   subroutine publish(dir, name, unit, status)
      character(len=*), intent(in) :: dir, name
      integer, intent(in) :: unit
      type(status_t), intent(inout) :: status
      close (unit)
      if (.not. rename_path(dir//'/'//name//temporary_suffix, dir//'/'//name)) &
         call status%fail('cannot rename '//dir//'/'//name//temporary_suffix)
   end subroutine publish
end module run_summary
