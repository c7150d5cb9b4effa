!> The run's output folder: created only once the scene is valid, never silently reused.
module output_directory
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank
   use error_status, only: status_t
   use file_system, only: path_exists, make_directory
   use status_broadcast, only: broadcast_status
   implicit none
   private

   !> The file whose presence marks a folder as holding a previous run.
   character(len=*), parameter, public :: run_marker = 'diagnostics.csv'

   public :: prepare_output_directory

contains

   !> Rank 0 checks and creates `dir`; every rank gets the verdict. Collective.
   subroutine prepare_output_directory(dir, overwrite, comm, status)
      character(len=*), intent(in) :: dir
      logical, intent(in) :: overwrite
      type(MPI_Comm), intent(in) :: comm
      type(status_t), intent(inout) :: status
      integer :: rank
      call MPI_Comm_rank(comm, rank)
      if (rank == 0) then
         if (path_exists(trim(dir)//'/'//run_marker) .and. .not. overwrite) then
            call status%fail('output folder '//trim(dir)//' already holds a previous run ('//run_marker// &
                             '); choose another &run output_dir or pass --overwrite')
         else if (.not. make_directory(dir)) then
            call status%fail('cannot create or write to output folder '//trim(dir)//' (&run output_dir)')
         end if
      end if
      call broadcast_status(status, comm, 0)
   end subroutine prepare_output_directory
end module output_directory
