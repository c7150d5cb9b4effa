!> What every file of a run says about where it came from (docs/output.md, "Provenance"): the program
!> (version, git commit, build type), the number of ranks, the date, and the resolved scene.
!>
!>   HDF5 files   root attributes flotsam_version, flotsam_git_commit, flotsam_build_type, ranks, date,
!>                scene (the resolved namelist text) and scene_file (the file the run was started with)
!>   CSV files    after the header row, comment lines starting with '#': the first one names program,
!>                date, ranks and scene; a continued run adds a '#' line where it continues
!>   scene.nml    the resolved scene in the output folder, readable as a scene file
!>
!> Dates are ISO 8601 local time with its offset from UTC, e.g. 2025-06-01T14:03:59+02:00; a file
!> written by several ranks carries rank 0's.
module provenance
   use mpi_f08, only: MPI_Comm, MPI_Bcast, MPI_Comm_rank, MPI_CHARACTER
   use kinds, only: rp, i8
   use error_status, only: status_t
   use build_info, only: flotsam_version, flotsam_git_commit, flotsam_build_type
   use scene_description, only: scene_t
   use scene_record, only: scene_namelist_text
   use input_text, only: int_text, real_text
   use hdf5_file, only: hdf5_file_t
   use file_system, only: path_exists, rename_path
   use output_layout, only: scene_nml, previous_scene_nml, temporary_suffix
   use status_broadcast, only: broadcast_status
   implicit none
   private

   public :: current_date, agreed_date, program_text, written_by, continued_by, csv_reading_hint
   public :: write_provenance_attributes, write_scene_file

   !> The last comment line of every CSV file a run writes.
   character(len=*), parameter :: csv_reading_hint = "# read with: pandas.read_csv(path, comment='#')  or  "// &
                                                     "numpy.genfromtxt(path, delimiter=',', names=True)"

   !> The &run variables a continued run may not change: the fields files of one run share one set of
   !> datasets, which particles.xmf and grid.xmf describe for every output time.
   character(len=*), parameter :: fixed_on_restart(*) = [character(len=15) :: 'field_precision', 'particle_fields']

contains

   !> The date and time now, ISO 8601 with the offset from UTC (without it if the system gives none).
   function current_date() result(text)
      character(len=:), allocatable :: text
      character(len=8) :: day
      character(len=10) :: time
      character(len=5) :: zone
      call date_and_time(day, time, zone)
      text = day(1:4)//'-'//day(5:6)//'-'//day(7:8)//'T'//time(1:2)//':'//time(3:4)//':'//time(5:6)
      if (len_trim(zone) == 5) text = text//zone(1:3)//':'//zone(4:5)
   end function current_date

   !> Rank 0's current_date on every rank of `comm` (the ranks' clocks may straddle a second). Collective.
   function agreed_date(comm) result(text)
      type(MPI_Comm), intent(in) :: comm
      character(len=:), allocatable :: text
      character(len=32) :: buffer
      integer :: rank
      call MPI_Comm_rank(comm, rank)
      buffer = ''
      if (rank == 0) buffer = current_date()
      call MPI_Bcast(buffer, len(buffer), MPI_CHARACTER, 0, comm)
      text = trim(buffer)
   end function agreed_date

   !> "flotsam 0.9.0 (commit 6197ee4a1b2c, Release build)"
   pure function program_text() result(text)
      character(len=:), allocatable :: text
      text = 'flotsam '//flotsam_version//' (commit '//flotsam_git_commit//', '//flotsam_build_type//' build)'
   end function program_text

   !> The first comment line of a CSV file: "# written by flotsam ... on <date> by <n> ranks from scene
   !> <file> (resolved: scene.nml)"; without `source` the scene part is left out.
   function written_by(ranks, date, source) result(line)
      integer, intent(in) :: ranks
      character(len=*), intent(in) :: date
      character(len=*), intent(in), optional :: source
      character(len=:), allocatable :: line
      line = '# written by '//program_text()//' on '//date//' by '//rank_count(ranks)
      if (present(source)) line = line//' from scene '//trim(source)//' (resolved: '//scene_nml//')'
   end function written_by

   !> The comment line a continued run writes where its rows start.
   function continued_by(step, time, ranks, date) result(line)
      integer(i8), intent(in) :: step
      real(rp), intent(in) :: time
      integer, intent(in) :: ranks
      character(len=*), intent(in) :: date
      character(len=:), allocatable :: line
      line = '# continued from the checkpoint at step '//int_text(step)//' (t = '//real_text(time)//' s) by '// &
             program_text()//' on '//date//' by '//rank_count(ranks)
   end function continued_by

   !> "1 rank", "4 ranks"
   pure function rank_count(ranks) result(text)
      integer, intent(in) :: ranks
      character(len=:), allocatable :: text
      text = int_text(ranks)//' rank'
      if (ranks /= 1) text = text//'s'
   end function rank_count

   !> Root attributes of an HDF5 file: program, date, resolved scene and, when given, the number of ranks
   !> (a checkpoint has its own `ranks`). Collective: every rank passes the same values.
   subroutine write_provenance_attributes(file, scene, date, status, ranks)
      type(hdf5_file_t), intent(inout) :: file
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: date
      type(status_t), intent(inout) :: status
      integer, intent(in), optional :: ranks
      call file%write_attribute('flotsam_version', flotsam_version, status)
      call file%write_attribute('flotsam_git_commit', flotsam_git_commit, status)
      call file%write_attribute('flotsam_build_type', flotsam_build_type, status)
      if (present(ranks)) call file%write_attribute('ranks', ranks, status)
      call file%write_attribute('date', date, status)
      call file%write_attribute('scene', scene_namelist_text(scene), status)
      call file%write_attribute('scene_file', trim(scene%source_file), status)
   end subroutine write_provenance_attributes

   !> Write the resolved scene to <output_dir>/scene.nml. A new run writes it. A continued run
   !> (`checkpoint` and `step` given) leaves an existing scene.nml alone when the scene is the same;
   !> when it differs (e.g. a later end_time) the previous one is kept as scene_<k>.nml (the first
   !> free k = 1, 2, ...) and the new one says where it continues. A continued run that changes a
   !> variable of fixed_on_restart is refused. Collective: rank 0 writes, the status is broadcast.
   subroutine write_scene_file(scene, comm, ranks, status, checkpoint, step)
      type(scene_t), intent(in) :: scene
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: ranks
      type(status_t), intent(inout) :: status
      character(len=*), intent(in), optional :: checkpoint
      integer(i8), intent(in), optional :: step
      character(len=:), allocatable :: header
      integer :: rank

      call MPI_Comm_rank(comm, rank)
      if (rank == 0 .and. status%ok) then
         header = '! '//scene_nml//': the resolved scene of the run in this folder (every variable, after the '// &
                  'command-line overrides,'//new_line('a')// &
                  '! with the derived defaults filled in); `flotsam '//scene_nml//'` runs it again (give it another '// &
                  'output_dir or --overwrite).'//new_line('a')// &
                  '! written by '//program_text()//' on '//current_date()//' by '//rank_count(ranks)//' from '// &
                  'scene '//trim(scene%source_file)//new_line('a')
         if (present(checkpoint) .and. present(step)) then
            call continue_scene_file(scene, header, checkpoint, step, status)
         else
            call write_text(trim(scene%run%output_dir)//'/'//scene_nml, header//new_line('a')// &
                            scene_namelist_text(scene), status)
         end if
      end if
      call broadcast_status(status, comm, 0)
   end subroutine write_scene_file

   !> The serial part of write_scene_file for a continued run.
   subroutine continue_scene_file(scene, header, checkpoint, step, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: header, checkpoint
      integer(i8), intent(in) :: step
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: dir, path, text, previous, kept, note, variable
      integer :: k, v

      dir = trim(scene%run%output_dir)
      path = dir//'/'//scene_nml
      text = scene_namelist_text(scene)
      kept = ''
      if (path_exists(path)) then       ! (a folder of an older flotsam has none)
         previous = namelist_lines(file_text(path, status))
         if (.not. status%ok) return
         if (previous == text) return    ! the same scene: the file of the run's start stays
         do v = 1, size(fixed_on_restart)
            variable = trim(fixed_on_restart(v))
            if (line_of(previous, variable) /= line_of(text, variable)) then
               call status%fail('--restart: &run '//variable//' differs from the run in '//dir//' ('// &
                                line_of(previous, variable)//' in '//path//'); the fields files of one run have '// &
                                'one set of datasets: keep it, or start a new run in another output_dir')
               return
            end if
         end do
         k = 1
         do while (path_exists(dir//'/'//previous_scene_nml(k)))
            k = k + 1
         end do
         kept = previous_scene_nml(k)
         if (.not. rename_path(path, dir//'/'//kept)) then
            call status%fail('cannot rename '//path//' to '//dir//'/'//kept)
            return
         end if
      end if
      note = '! continued from '//checkpoint//' at step '//int_text(step)
      if (len(kept) > 0) note = note//'; the scene before the restart is kept as '//kept
      call write_text(path, header//note//new_line('a')//new_line('a')//text, status)
   end subroutine continue_scene_file

   !> The line of `text` that sets &run `variable` ('' if there is none).
   function line_of(text, variable) result(line)
      character(len=*), intent(in) :: text, variable
      character(len=:), allocatable :: line
      integer :: start, length
      line = ''
      start = index(text, new_line('a')//'   '//variable//' = ')
      if (start == 0) return
      start = start + 1
      length = index(text(start:), new_line('a')) - 1
      if (length < 0) length = len(text) - start + 1
      line = trim(adjustl(text(start:start + length - 1)))
   end function line_of

   !> `text` without its comment lines (starting with '!') and the blank lines right after them.
   function namelist_lines(text) result(kept)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: kept
      integer :: start, length
      logical :: in_header
      kept = ''
      start = 1
      in_header = .true.
      do while (start <= len(text))
         length = index(text(start:), new_line('a'))
         if (length == 0) length = len(text) - start + 2
         associate (line => text(start:start + length - 2))
            if (len(line) > 0) then
               if (line(1:1) == '!') then
                  start = start + length
                  cycle
               end if
            end if
            if (.not. (in_header .and. len_trim(line) == 0)) then
               kept = kept//line//new_line('a')
               in_header = .false.
            end if
         end associate
         start = start + length
      end do
   end function namelist_lines

   !> The whole content of the file `path`.
   function file_text(path, status) result(text)
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: text
      integer :: unit, ios, size_bytes
      character(len=256) :: message
      open (newunit=unit, file=path, access='stream', form='unformatted', status='old', action='read', &
            iostat=ios, iomsg=message)
      if (ios == 0) inquire (unit=unit, size=size_bytes, iostat=ios, iomsg=message)
      if (ios == 0) then
         allocate (character(len=max(size_bytes, 0)) :: text)
         if (size_bytes > 0) read (unit, iostat=ios, iomsg=message) text
         close (unit)
      end if
      if (ios /= 0) then
         call status%fail('cannot read '//path//': '//trim(message))
         text = ''
      end if
   end function file_text

   !> Write `text` to `path` under a temporary name and rename it when complete.
   subroutine write_text(path, text, status)
      character(len=*), intent(in) :: path, text
      type(status_t), intent(inout) :: status
      integer :: unit, ios
      character(len=256) :: message
      open (newunit=unit, file=path//temporary_suffix, access='stream', form='unformatted', status='replace', &
            action='write', iostat=ios, iomsg=message)
      if (ios == 0) write (unit, iostat=ios, iomsg=message) text
      if (ios == 0) close (unit, iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail('cannot write '//path//temporary_suffix//': '//trim(message))
      else if (.not. rename_path(path//temporary_suffix, path)) then
         call status%fail('cannot rename '//path//temporary_suffix//' to '//path)
      end if
   end subroutine write_text
end module provenance
