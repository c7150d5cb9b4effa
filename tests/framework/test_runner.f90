!> Runner of the Flotsam test framework: runs test procedures, decides pass/fail, prints the summary.
!>
!> A test fails when any assertion fails during it (assertions counts them); an MPI test fails when
!> an assertion fails on ANY rank of its communicator. Rank 0 prints one result line per test and
!> the summary line `N passed, N failed`; finish_tests returns the exit status (0 or 1), equal on
!> every rank. The generated drivers (serial_driver.f90.in, mpi_driver.f90.in) are the only callers.
module test_runner
   use, intrinsic :: iso_fortran_env, only: output_unit
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Comm_dup, MPI_Comm_free, MPI_Allreduce, &
                      MPI_Wtime, MPI_INTEGER, MPI_SUM, MPI_MAX
   use kinds, only: rp, i8
   use assertions, only: set_current_test, failure_count
   implicit none
   private

   public :: test_proc, mpi_test_proc, run_test, run_mpi_test, finish_tests

   abstract interface
      !> A serial test: a module procedure without arguments.
      subroutine test_proc()
      end subroutine test_proc

      !> An MPI test: gets the communicator to work on (never MPI_COMM_WORLD itself).
      subroutine mpi_test_proc(comm)
         import :: MPI_Comm
         type(MPI_Comm), intent(in) :: comm
      end subroutine mpi_test_proc
   end interface

   !> finish_tests() for serial drivers, finish_tests(comm) for MPI drivers.
   interface finish_tests
      module procedure finish_serial_tests, finish_mpi_tests
   end interface finish_tests

   integer :: n_passed = 0
   integer :: n_failed = 0

contains

   !> Run one serial test and print its result.
   subroutine run_test(name, proc)
      character(len=*), intent(in) :: name
      procedure(test_proc) :: proc
      integer :: failures_before
      integer(i8) :: start, finish, rate
      call set_current_test(name)
      failures_before = failure_count()
      call system_clock(start, rate)
      call proc()
      call system_clock(finish)
      call record_result(name, failure_count() - failures_before, merge(1, 0, failure_count() > failures_before), 1, &
                         real(finish - start, rp) / real(max(rate, 1_i8), rp), .true.)
      call set_current_test('(between tests)')
   end subroutine run_test

   !> Run one MPI test on a duplicate of `comm` (so stray messages of a test cannot reach the runner's
   !> collectives or the next test); collective over `comm`.
   subroutine run_mpi_test(name, proc, comm)
      character(len=*), intent(in) :: name
      procedure(mpi_test_proc) :: proc
      type(MPI_Comm), intent(in) :: comm
      type(MPI_Comm) :: test_comm
      integer :: rank, n_ranks, failures_before, local(2), total(2)
      real(rp) :: start
      character(len=48) :: label
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      label = ''
      if (n_ranks > 1) write (label, '(" [rank ", i0, " of ", i0, "]")') rank, n_ranks
      call set_current_test(name, trim(label))
      call MPI_Comm_dup(comm, test_comm)
      failures_before = failure_count()
      start = MPI_Wtime()
      call proc(test_comm)
      ! (failed assertions, failing ranks) summed over the ranks: every rank gets the same verdict.
      local = [failure_count() - failures_before, merge(1, 0, failure_count() > failures_before)]
      call MPI_Allreduce(local, total, 2, MPI_INTEGER, MPI_SUM, comm)
      call MPI_Comm_free(test_comm)
      call record_result(name, total(1), total(2), n_ranks, MPI_Wtime() - start, rank == 0)
      call set_current_test('(between tests)')
   end subroutine run_mpi_test

   subroutine record_result(name, n_assertions_failed, n_ranks_failed, n_ranks, seconds, prints)
      character(len=*), intent(in) :: name
      integer, intent(in) :: n_assertions_failed, n_ranks_failed, n_ranks
      real(rp), intent(in) :: seconds
      logical, intent(in) :: prints
      character(len=16) :: time_text
      write (time_text, '(f16.3)') seconds
      if (n_ranks_failed == 0) then
         n_passed = n_passed + 1
         if (prints) write (output_unit, '("PASSED ", a, " (", a, " s)")') name, trim(adjustl(time_text))
      else
         n_failed = n_failed + 1
         if (prints) then
            if (n_ranks > 1) then
               write (output_unit, '("FAILED ", a, ": ", i0, " assertion(s) failed on ", i0, " of ", i0, " ranks")') &
                  name, n_assertions_failed, n_ranks_failed, n_ranks
            else
               write (output_unit, '("FAILED ", a, ": ", i0, " assertion(s) failed")') name, n_assertions_failed
            end if
         end if
      end if
      if (prints) flush (output_unit)
   end subroutine record_result

   !> Print `N passed, N failed` and return the exit status: 1 if any test failed, else 0.
   integer function finish_serial_tests() result(status)
      write (output_unit, '(i0, " passed, ", i0, " failed")') n_passed, n_failed
      flush (output_unit)
      status = merge(1, 0, n_failed > 0)
   end function finish_serial_tests

   !> As finish_serial_tests, collective over `comm`: rank 0 prints, every rank returns the same status.
   integer function finish_mpi_tests(comm) result(status)
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, local(2), global(2)
      ! The counts already agree after run_mpi_test; the reduction keeps the status collective anyway.
      local = [n_passed, n_failed]
      call MPI_Allreduce(local, global, 2, MPI_INTEGER, MPI_MAX, comm)
      call MPI_Comm_rank(comm, rank)
      if (rank == 0) then
         write (output_unit, '(i0, " passed, ", i0, " failed")') global(1), global(2)
         flush (output_unit)
      end if
      status = merge(1, 0, global(2) > 0)
   end function finish_mpi_tests
end module test_runner
