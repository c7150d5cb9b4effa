!> Flotsam driver: `mpirun -np N flotsam scene.nml [--overwrite]`.
!> The only place that touches MPI_COMM_WORLD and the only place that stops the program.
program flotsam
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_COMM_WORLD
   use error_status, only: status_t
   use scene_description, only: scene_t
   use scene_reader, only: read_scene
   use output_directory, only: prepare_output_directory
   use mpm_solver, only: solver_t
   use simulation, only: run_simulation
   implicit none

   type(scene_t) :: scene
   type(status_t) :: status
   type(solver_t) :: solver
   character(len=:), allocatable :: scene_path
   logical :: overwrite
   integer :: rank, exit_code

   call MPI_Init()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call parse_command_line(scene_path, overwrite, exit_code)
   if (exit_code >= 0) call finish(exit_code)

   call read_scene(scene_path, MPI_COMM_WORLD, scene, status)
   if (.not. status%ok) call fail(status, 2)
   if (overwrite) scene%run%overwrite = .true.

   call solver%init(scene, MPI_COMM_WORLD, status)
   if (.not. status%ok) call fail(status, 2)
   call prepare_output_directory(scene%run%output_dir, scene%run%overwrite, MPI_COMM_WORLD, status)
   if (.not. status%ok) call fail(status, 3)

   call run_simulation(solver, status)
   if (.not. status%ok) call fail(status, 4)
   call solver%free()
   call finish(0)

contains

   !> Read `flotsam <scene.nml> [--overwrite]`. exit_code >= 0 means: stop now with that code.
   subroutine parse_command_line(path, overwrite, exit_code)
      character(len=:), allocatable, intent(out) :: path
      logical, intent(out) :: overwrite
      integer, intent(out) :: exit_code
      character(len=4096) :: arg
      integer :: i
      overwrite = .false.
      exit_code = -1
      path = ''
      do i = 1, command_argument_count()
         call get_command_argument(i, arg)
         select case (trim(arg))
         case ('-h', '--help')
            if (rank == 0) call print_usage(output_unit)
            exit_code = 0
            return
         case ('--overwrite')
            overwrite = .true.
         case default
            if (arg(1:1) == '-' .or. len(path) > 0) then
               if (rank == 0) write (error_unit, '(a)') 'flotsam: error: unexpected argument '//trim(arg)
               exit_code = 2
               return
            end if
            path = trim(arg)
         end select
      end do
      if (len(path) == 0) then
         if (rank == 0) call print_usage(error_unit)
         exit_code = 2
      end if
   end subroutine parse_command_line

   subroutine print_usage(unit)
      integer, intent(in) :: unit
      write (unit, '(a)') 'usage: mpirun -np N flotsam <scene.nml> [--overwrite]', &
         '  <scene.nml>   scene file of Fortran namelists (see docs/input.md)', &
         '  --overwrite   allow replacing a previous run in the output folder', &
         '  -h, --help    print this text'
   end subroutine print_usage

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
