!> The time loop of a run: steps to the end time, a diagnostics row at every output time (the step is
!> shortened to land on it), progress lines, and a stop on a non-finite state.
module simulation
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm_rank
   use error_status, only: status_t
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t, diagnostics_header, diagnostics_row
   use csv_writer, only: csv_writer_t
   use progress_reporter, only: progress_reporter_t
   use status_broadcast, only: broadcast_status
   implicit none
   private

   public :: run_simulation

contains

   !> Run `solver` to its end time (or max_steps), writing diagnostics.csv in the output folder.
   !> Collective. On return `status` is identical on every rank.
   subroutine run_simulation(solver, status)
      type(solver_t), intent(inout) :: solver
      type(status_t), intent(inout) :: status
      type(csv_writer_t) :: csv
      type(progress_reporter_t) :: progress
      type(diagnostics_t) :: diag
      real(rp) :: next_output, end_time, interval
      integer :: rank

      call MPI_Comm_rank(solver%domain%comm, rank)
      end_time = solver%run%end_time
      interval = solver%run%output_interval
      if (rank == 0) call csv%open(trim(solver%run%output_dir)//'/diagnostics.csv', diagnostics_header(), status)
      call broadcast_status(status, solver%domain%comm, 0)
      if (.not. status%ok) return

      diag = solver%diagnostics()
      if (rank == 0) call csv%write_row(diagnostics_row(diag))
      call progress%start(solver%run%progress_interval, solver%time, end_time)
      next_output = min(solver%time + interval, end_time)

      do while (solver%time < end_time * (1.0_rp - 1.0e-12_rp) .and. solver%step < solver%run%max_steps)
         ! land exactly on the next output time
         if (solver%time + solver%dt * (1.0_rp + 1.0e-9_rp) >= next_output) solver%dt = next_output - solver%time
         call solver%advance()
         call progress%update(solver%time, solver%step, diag%particles, rank == 0)
         if (solver%time >= next_output * (1.0_rp - 1.0e-12_rp) .or. solver%step >= solver%run%max_steps) then
            diag = solver%diagnostics()
            if (rank == 0) call csv%write_row(diagnostics_row(diag))
            if (.not. (ieee_is_finite(diag%kinetic_energy) .and. ieee_is_finite(diag%fluid_volume))) then
               call status%fail('the solution is no longer finite at step '//int_text(solver%step))
               exit
            end if
            next_output = min(next_output + interval, end_time)
         end if
      end do
      if (rank == 0) call csv%close()
   end subroutine run_simulation

   pure function int_text(i) result(text)
      use kinds, only: i8
      integer(i8), intent(in) :: i
      character(len=:), allocatable :: text
      character(len=24) :: buffer
      write (buffer, '(i0)') i
      text = trim(buffer)
   end function int_text
end module simulation
