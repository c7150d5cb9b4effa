!> The run's output folder: created only once the scene is valid, never silently reused.
!>
!> A new run needs a folder that is empty of runs (or --overwrite, which removes the previous run's
!> files first, so that no old checkpoint or fields file can be mistaken for the new run's). A
!> restarted run continues in the folder of the run it continues. Both check that the folder can
!> really be written (by creating a file: access() does not know read-only file systems, and root
!> passes every permission check), and create the fields and checkpoints sub-folders.
module output_directory
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank
   use kinds, only: path_len
   use error_status, only: status_t
   use file_system, only: path_exists, make_directory, remove_file
   use output_layout, only: fields_folder, checkpoint_folder, fields_file, checkpoint_file, particles_xdmf, &
                            grid_xdmf, latest_checkpoint, temporary_suffix, loads_csv, gauges_csv, bodies_csv, panels_csv, &
                            scene_nml, previous_scene_nml
   use status_broadcast, only: broadcast_status
   implicit none
   private

   !> The file whose presence marks a folder as holding a previous run.
   character(len=*), parameter, public :: run_marker = 'diagnostics.csv'

   public :: prepare_output_directory, prepare_restart_directory

contains

   !> Rank 0 checks and creates `dir` for a new run; every rank gets the verdict. Collective.
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
                             '); choose another &run output_dir, pass --overwrite, or continue it with --restart')
         else if (.not. make_directory(dir)) then
            call status%fail('cannot create or write to output folder '//trim(dir)//' (&run output_dir)')
         end if
         if (status%ok) call check_writable(dir, status)
         if (status%ok .and. overwrite) call remove_previous_run(dir, status)
         if (status%ok) call make_sub_folders(dir, status)
      end if
      call broadcast_status(status, comm, 0)
   end subroutine prepare_output_directory

   !> Rank 0 checks that `dir` holds the run to continue and can be written. Collective.
   subroutine prepare_restart_directory(dir, comm, status)
      character(len=*), intent(in) :: dir
      type(MPI_Comm), intent(in) :: comm
      type(status_t), intent(inout) :: status
      integer :: rank
      call MPI_Comm_rank(comm, rank)
      if (rank == 0) then
         if (.not. path_exists(trim(dir)//'/'//run_marker)) then
            call status%fail('--restart: output folder '//trim(dir)//' (&run output_dir) holds no run to continue (no '// &
                             run_marker//')')
         end if
         if (status%ok) call check_writable(dir, status)
         if (status%ok) call make_sub_folders(dir, status)
      end if
      call broadcast_status(status, comm, 0)
   end subroutine prepare_restart_directory

   !> Create and remove a file in `dir`.
   subroutine check_writable(dir, status)
      character(len=*), intent(in) :: dir
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: probe
      integer :: unit, ios
      probe = trim(dir)//'/.flotsam_write_test'//temporary_suffix
      open (newunit=unit, file=probe, status='replace', action='write', iostat=ios)
      if (ios == 0) write (unit, '(a)', iostat=ios) 'flotsam'
      if (ios == 0) close (unit, status='delete', iostat=ios)
      if (ios /= 0) call status%fail('cannot write to output folder '//trim(dir)//' (&run output_dir)')
   end subroutine check_writable

   subroutine make_sub_folders(dir, status)
      character(len=*), intent(in) :: dir
      type(status_t), intent(inout) :: status
      if (.not. make_directory(trim(dir)//'/'//fields_folder)) then
         call status%fail('cannot create '//trim(dir)//'/'//fields_folder)
      else if (.not. make_directory(trim(dir)//'/'//checkpoint_folder)) then
         call status%fail('cannot create '//trim(dir)//'/'//checkpoint_folder)
      end if
   end subroutine make_sub_folders

   !> --overwrite: remove what a previous run wrote (its diagnostics, XDMF files, load series, scene files,
   !> fields files numbered 0, 1, ... and the checkpoints up to the latest one).
   subroutine remove_previous_run(dir, status)
      character(len=*), intent(in) :: dir
      type(status_t), intent(inout) :: status
      character(len=path_len) :: latest
      integer :: index, unit, ios, newest
      logical :: removed
      removed = .true.
      call remove(trim(dir)//'/'//run_marker, removed)
      call remove(trim(dir)//'/'//particles_xdmf, removed)
      call remove(trim(dir)//'/'//grid_xdmf, removed)
      call remove(trim(dir)//'/'//loads_csv, removed)
      call remove(trim(dir)//'/'//gauges_csv, removed)
      call remove(trim(dir)//'/'//bodies_csv, removed)
      call remove(trim(dir)//'/'//panels_csv, removed)
      call remove(trim(dir)//'/'//scene_nml, removed)
      index = 1
      do while (path_exists(trim(dir)//'/'//previous_scene_nml(index)) .and. removed)
         call remove(trim(dir)//'/'//previous_scene_nml(index), removed)
         index = index + 1
      end do
      index = 0
      do
         if (.not. path_exists(trim(dir)//'/'//fields_file(index))) exit
         call remove(trim(dir)//'/'//fields_file(index), removed)
         if (.not. removed) exit
         index = index + 1
      end do
      ! checkpoint numbers: the latest one names the highest
      newest = 0
      open (newunit=unit, file=trim(dir)//'/'//checkpoint_folder//'/'//latest_checkpoint, status='old', &
            action='read', iostat=ios)
      if (ios == 0) then
         read (unit, '(a)', iostat=ios) latest
         close (unit)
         index = scan(latest, '0123456789')
         if (ios == 0 .and. index > 0) read (latest(index:index + 5), '(i6)', iostat=ios) newest
         if (ios /= 0) newest = 0
      end if
      do index = newest, 1, -1
         call remove(trim(dir)//'/'//checkpoint_file(index), removed)
      end do
      call remove(trim(dir)//'/'//checkpoint_folder//'/'//latest_checkpoint, removed)
      if (.not. removed) call status%fail('--overwrite: cannot remove the previous run from output folder '//trim(dir))
   end subroutine remove_previous_run

   !> Remove file `path` if it exists; `removed` becomes false if it could not be removed.
   subroutine remove(path, removed)
      character(len=*), intent(in) :: path
      logical, intent(inout) :: removed
      if (.not. remove_file(path)) removed = .false.
   end subroutine remove
end module output_directory
