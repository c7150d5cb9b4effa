!> Flotsam driver: `mpirun -np N flotsam scene.nml [override.nml ...] [--set '<namelist text>' ...]
!> [--overwrite] [--restart <checkpoint>|latest [--allow-scene-change]]`, or `flotsam --version`.
!> Overrides apply in command-line order. The only place that touches MPI_COMM_WORLD and the only
!> place that stops the program. A run starts its standard error with a banner (version, commit,
!> ranks, scene, output folder) and ends it with one line of outcome and cost (run_summary), so a
!> batch log shows what ran.
!>
!> Exit codes: 0 done; 2 scene, set-up or checkpoint refused; 3 output folder; 4 failure during the
!> run (including a blow-up); 5 stopped by SIGTERM/SIGINT after writing a checkpoint.
program flotsam
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use mpi_io_choice, only: prefer_romio
   use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_COMM_WORLD
   use kinds, only: path_len
   use error_status, only: status_t
   use scene_description, only: scene_t
   use scene_reader, only: read_scene, scene_override_t
   use scene_memory, only: scene_advice
   use output_directory, only: prepare_output_directory, prepare_restart_directory
   use mpm_solver, only: solver_t
   use run_progress, only: run_progress_t
   use checkpoint, only: read_checkpoint, latest_checkpoint_path
   use status_broadcast, only: broadcast_status
   use input_text, only: int_text, real_text
   use simulation, only: run_simulation
   use build_info, only: flotsam_version, flotsam_git_commit, flotsam_build_type
   use provenance, only: write_scene_file
   implicit none

   integer, parameter :: exit_scene = 2, exit_output_folder = 3, exit_run = 4, exit_signal = 5

   type(scene_t) :: scene
   type(status_t) :: status
   type(solver_t) :: solver
   type(run_progress_t) :: progress
   character(len=:), allocatable :: scene_path, restart_path, scene_warning
   type(scene_override_t), allocatable :: overrides(:)
   logical :: overwrite, allow_scene_change = .false.
   integer :: rank, exit_code, stopped_by

   call prefer_romio()     ! before MPI_Init: see src/domain/mpi_io_choice.f90
   call MPI_Init()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call parse_command_line(scene_path, overrides, overwrite, restart_path, exit_code)
   if (exit_code >= 0) call finish(exit_code)

   call read_scene(scene_path, MPI_COMM_WORLD, scene, status, overrides)
   if (.not. status%ok) call fail(status, exit_scene)
   if (overwrite) scene%run%overwrite = .true.

   if (len(restart_path) == 0) then
      call solver%init(scene, MPI_COMM_WORLD, status)
      if (.not. status%ok) call fail(status, exit_scene)
      call prepare_output_directory(scene%run%output_dir, scene%run%overwrite, MPI_COMM_WORLD, status)
      if (.not. status%ok) call fail(status, exit_output_folder)
      call write_scene_file(scene, MPI_COMM_WORLD, solver%domain%nranks, status)     ! <output_dir>/scene.nml
      if (.not. status%ok) call fail(status, exit_output_folder)
      call print_banner()
      call print_advice()
   else
      call solver%init(scene, MPI_COMM_WORLD, status, seed_particles=.false.)
      if (.not. status%ok) call fail(status, exit_scene)
      call prepare_restart_directory(scene%run%output_dir, MPI_COMM_WORLD, status)
      if (.not. status%ok) call fail(status, exit_output_folder)
      call resolve_restart_path(restart_path, status)
      call read_checkpoint(restart_path, scene, solver, progress, status, allow_scene_change, scene_warning)
      if (.not. status%ok) call fail(status, exit_scene)
      call write_scene_file(scene, MPI_COMM_WORLD, solver%domain%nranks, status, restart_path, solver%step)
      if (.not. status%ok) call fail(status, exit_scene)
      call print_banner()
      call print_advice()
      if (rank == 0 .and. len(scene_warning) > 0) write (error_unit, '(a)') 'flotsam: warning: '//scene_warning
      if (rank == 0) write (error_unit, '(a,i0,a)') 'flotsam: continuing '//restart_path//' from step ', &
         solver%step, ' (t = '//real_text(solver%time)//' s)'
   end if

   call run_simulation(solver, progress, status, stopped_by)
   if (stopped_by > 0) then
      if (rank == 0) write (error_unit, '(a)') 'flotsam: '//trim(status%message)
      call finish(exit_signal)
   end if
   if (.not. status%ok) call fail(status, exit_run)
   call solver%free()
   call finish(0)

contains

   !> Read `flotsam <scene.nml> [override.nml ...] [--set <text> ...] [--overwrite] [--restart <checkpoint>]`.
   !> exit_code >= 0 means: stop now with that code.
   subroutine parse_command_line(path, overrides, overwrite, restart, exit_code)
      character(len=:), allocatable, intent(out) :: path, restart
      type(scene_override_t), allocatable, intent(out) :: overrides(:)
      logical, intent(out) :: overwrite
      integer, intent(out) :: exit_code
      character(len=4096) :: arg
      integer :: i, length
      logical :: restart_follows, restart_given, set_follows
      allocate (overrides(0))
      set_follows = .false.
      overwrite = .false.
      restart_given = .false.
      exit_code = -1
      path = ''
      restart = ''
      restart_follows = .false.
      do i = 1, command_argument_count()
         call get_command_argument(i, arg, length)
         if (length > len(arg)) then
            if (rank == 0) write (error_unit, '(a)') 'flotsam: error: argument '//int_text(i)//' is longer than '// &
               int_text(len(arg))//' characters'
            exit_code = exit_scene
            return
         end if
         if (set_follows) then
            call add_override(overrides, trim(arg), .true.)
            set_follows = .false.
            cycle
         end if
         if (restart_follows) then
            restart = trim(arg)
            restart_follows = .false.
            cycle
         end if
         select case (trim(arg))
         case ('-h', '--help')
            if (rank == 0) call print_usage(output_unit)
            exit_code = 0
            return
         case ('--version')
            if (rank == 0) call print_version(output_unit)
            exit_code = 0
            return
         case ('--overwrite')
            overwrite = .true.
         case ('--allow-scene-change')
            allow_scene_change = .true.
         case ('--restart')
            restart_follows = .true.
            restart_given = .true.
         case ('--set')
            set_follows = .true.
         case default
            if (arg(1:10) == '--restart=') then
               restart = trim(arg(11:))
               restart_given = .true.
            else if (arg(1:6) == '--set=') then
               call add_override(overrides, trim(arg(7:)), .true.)
            else if (arg(1:1) /= '-' .and. len(path) > 0) then
               call add_override(overrides, trim(arg), .false.)    ! an override file
            else if (arg(1:1) == '-') then
               if (rank == 0) write (error_unit, '(a)') 'flotsam: error: unexpected argument '//trim(arg)
               exit_code = exit_scene
               return
            else
               path = trim(arg)
            end if
         end select
      end do
      if (set_follows) then
         if (rank == 0) write (error_unit, '(a)') "flotsam: error: --set needs namelist text, e.g. --set '&grid rotation = 45 /'"
         exit_code = exit_scene
      else if (restart_given .and. len(restart) == 0) then
         if (rank == 0) write (error_unit, '(a)') 'flotsam: error: --restart needs a checkpoint file (or latest)'
         exit_code = exit_scene
      else if (len(path) == 0) then
         if (rank == 0) call print_usage(error_unit)
         exit_code = exit_scene
      else if (allow_scene_change .and. len(restart) == 0) then
         if (rank == 0) write (error_unit, '(a)') 'flotsam: error: --allow-scene-change applies to a restart only '// &
            '(--restart <checkpoint>)'
         exit_code = exit_scene
      else if (len(restart) > 0 .and. overwrite) then
         if (rank == 0) write (error_unit, '(a)') 'flotsam: error: --restart continues a run; it cannot be '// &
            'combined with --overwrite'
         exit_code = exit_scene
      end if
   end subroutine parse_command_line

   !> Append an override (element by element: gfortran's array constructor pads the deferred-length
   !> component of every element to the longest).
   subroutine add_override(overrides, source, is_text)
      type(scene_override_t), allocatable, intent(inout) :: overrides(:)
      character(len=*), intent(in) :: source
      logical, intent(in) :: is_text
      type(scene_override_t), allocatable :: grown(:)
      integer :: i
      allocate (grown(size(overrides) + 1))
      do i = 1, size(overrides)
         grown(i)%source = overrides(i)%source
         grown(i)%is_text = overrides(i)%is_text
      end do
      grown(size(grown))%source = source
      grown(size(grown))%is_text = is_text
      call move_alloc(grown, overrides)
   end subroutine add_override

   !> `--restart latest` names the newest checkpoint of the scene's output folder. Collective.
   subroutine resolve_restart_path(path, status)
      character(len=:), allocatable, intent(inout) :: path
      type(status_t), intent(inout) :: status
      character(len=path_len) :: resolved
      if (path /= 'latest') return
      resolved = ''
      if (rank == 0) resolved = latest_checkpoint_path(scene%run%output_dir, status)
      call broadcast_status(status, MPI_COMM_WORLD, 0)
      if (.not. status%ok) call fail(status, exit_scene)
      call broadcast_path(resolved)
      path = trim(resolved)
   end subroutine resolve_restart_path

   subroutine broadcast_path(text)
      use mpi_f08, only: MPI_Bcast, MPI_CHARACTER
      character(len=*), intent(inout) :: text
      call MPI_Bcast(text, len(text), MPI_CHARACTER, 0, MPI_COMM_WORLD)
   end subroutine broadcast_path

   subroutine print_usage(unit)
      integer, intent(in) :: unit
      write (unit, '(a)') 'usage: mpirun -np N flotsam <scene.nml> [override.nml ...] [--set <text> ...]', &
         '                                 [--overwrite] [--restart <checkpoint> [--allow-scene-change]]', &
         '  <scene.nml>               scene file of Fortran namelists (see docs/input.md)', &
         '  override.nml              namelist file applied on top of the scene (in order)', &
         "  --set '<namelist text>'   the same, inline: --set '&grid rotation = 45 /'", &
         '                            --set "&material name = ''water'', stabilization = ''C0'' /"', &
         '  --overwrite               replace a previous run in the output folder', &
         '  --restart <checkpoint>    continue the run from a checkpoint file of its output folder;', &
         '                            --restart latest takes the newest one (see docs/output.md)', &
         '  --version                 print the version, git commit, build type, MPI and HDF5 libraries', &
         '  --allow-scene-change      with --restart: continue although the scene changes more than', &
         '                            end_time and the output and checkpoint settings (a warning lists it)', &
         '  -h, --help                print this text', &
         'exit codes: 0 done, 2 scene or checkpoint refused, 3 output folder, 4 run failed,', &
         '            5 stopped by SIGTERM/SIGINT (a checkpoint was written)'
   end subroutine print_usage

   !> `flotsam --version`: what this binary is and the libraries it runs on.
   subroutine print_version(unit)
      use mpi_f08, only: MPI_Get_library_version, MPI_MAX_LIBRARY_VERSION_STRING
      use hdf5, only: h5get_libversion_f
      integer, intent(in) :: unit
      character(len=MPI_MAX_LIBRARY_VERSION_STRING) :: mpi_library
      integer :: length, major, minor, release, error, i
      call MPI_Get_library_version(mpi_library, length)
      ! Open MPI's string ends in a newline; keep the text on one line
      do i = 1, length
         if (iachar(mpi_library(i:i)) < 32) mpi_library(i:i) = ' '
      end do
      call h5get_libversion_f(major, minor, release, error)
      write (unit, '(a)') 'flotsam '//flotsam_version, &
         'commit '//flotsam_git_commit, &
         'build type '//flotsam_build_type, &
         'MPI library '//trim(mpi_library(1:length))
      if (error == 0) then
         write (unit, '(a)') 'HDF5 library '//int_text(major)//'.'//int_text(minor)//'.'//int_text(release)
      else
         write (unit, '(a)') 'HDF5 library unknown'
      end if
   end subroutine print_version

   !> Rank 0 names what runs: version, commit, ranks, scene file (and its overrides), output folder.
   subroutine print_banner()
      use mpi_f08, only: MPI_Comm_size
      integer :: ranks
      character(len=:), allocatable :: changes
      call MPI_Comm_size(MPI_COMM_WORLD, ranks)
      if (rank /= 0) return
      changes = ''
      if (size(overrides) == 1) changes = ' with 1 override'
      if (size(overrides) > 1) changes = ' with '//int_text(size(overrides))//' overrides'
      write (error_unit, '(a)') 'flotsam '//flotsam_version//' (commit '//flotsam_git_commit//', '// &
         flotsam_build_type//' build) on '//int_text(ranks)//' rank'//trim(merge('s', ' ', ranks > 1))// &
         ': scene '//scene_path//changes//', output folder '//trim(scene%run%output_dir)
      flush (error_unit)
   end subroutine print_banner

   !> A valid scene likely to fail (scene_advice): one warning line from rank 0; the run goes on.
   subroutine print_advice()
      character(len=:), allocatable :: advice
      advice = scene_advice(scene, new_line('a')//'flotsam: warning: ')
      if (rank == 0 .and. len(advice) > 0) write (error_unit, '(a)') 'flotsam: warning: '//advice
   end subroutine print_advice

   !> Every rank holds the same failed status: rank 0 reports it, all ranks exit with `code`.
   subroutine fail(failed, code)
      type(status_t), intent(in) :: failed
      integer, intent(in) :: code
      if (rank == 0) write (error_unit, '(a)') 'flotsam: error: '//trim(failed%message)
      call finish(code)
   end subroutine fail

   subroutine finish(code)
      integer, intent(in) :: code
      call MPI_Finalize()
      ! a plain stop with a code sets the exit status without error stop's per-rank backtrace
      stop code, quiet=.true.
   end subroutine finish
end program flotsam
