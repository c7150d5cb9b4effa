!> Benchmark driver: `mpirun -np N flotsam_bench scene.nml steps`. Runs a scene for a fixed number of
!> steps without output and prints one line of figures (scripts/bench collects them):
!>   dim ranks particles steps seconds particle_steps_per_s_per_core bytes_per_particle
!> Memory per particle is the growth of the resident set from before the solver is built to after the
!> timed steps, divided by the rank's particles (rank 0's view).
program flotsam_bench
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_Comm_size, MPI_Barrier, MPI_Wtime, MPI_COMM_WORLD
   use error_status, only: status_t
   use scene_description, only: scene_t
   use scene_reader, only: read_scene
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   implicit none

   type(scene_t) :: scene
   type(status_t) :: status
   type(solver_t) :: solver
   type(diagnostics_t) :: diag
   character(len=4096) :: arg
   integer :: rank, n_ranks, steps, step, warm_up
   real(rp) :: t0, t1, rss_before, rss_after

   call MPI_Init()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, n_ranks)
   if (command_argument_count() /= 2) then
      if (rank == 0) write (error_unit, '(a)') 'usage: mpirun -np N flotsam_bench <scene.nml> <steps>'
      call MPI_Finalize()
      error stop 2
   end if
   call get_command_argument(1, arg)
   call read_scene(trim(arg), MPI_COMM_WORLD, scene, status)
   if (.not. status%ok) then
      if (rank == 0) write (error_unit, '(a)') 'flotsam_bench: error: '//trim(status%message)
      call MPI_Finalize()
      error stop 2
   end if
   call get_command_argument(2, arg)
   read (arg, *) steps
   scene%run%progress_interval = 0.0_rp

   rss_before = resident_bytes()
   call solver%init(scene, MPI_COMM_WORLD, status)
   if (.not. status%ok) then
      if (rank == 0) write (error_unit, '(a)') 'flotsam_bench: error: '//trim(status%message)
      call MPI_Finalize()
      error stop 2
   end if
   warm_up = max(1, steps / 20)
   do step = 1, warm_up
      call solver%advance()
   end do
   call MPI_Barrier(MPI_COMM_WORLD)
   t0 = MPI_Wtime()
   do step = 1, steps
      call solver%advance()
   end do
   call MPI_Barrier(MPI_COMM_WORLD)
   t1 = MPI_Wtime()
   rss_after = resident_bytes()
   diag = solver%diagnostics()
   if (rank == 0) write (output_unit, '(i0,1x,i0,1x,i0,1x,i0,1x,es12.5,1x,es12.5,1x,f10.1)') scene%grid%dim, n_ranks, &
      diag%particles, steps, t1 - t0, real(diag%particles, rp) * steps / ((t1 - t0) * n_ranks), &
      (rss_after - rss_before) / max(1, solver%particles%count)
   call solver%free()
   call MPI_Finalize()

contains

   !> Resident set size of this process [bytes], from /proc/self/status (0 where unavailable).
   real(rp) function resident_bytes()
      integer :: unit, ios
      character(len=256) :: line
      integer(i8) :: kib
      resident_bytes = 0.0_rp
      open (newunit=unit, file='/proc/self/status', action='read', iostat=ios)
      if (ios /= 0) return
      do
         read (unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:6) == 'VmRSS:') then
            read (line(7:), *) kib
            resident_bytes = 1024.0_rp * real(kib, rp)
         end if
      end do
      close (unit)
   end function resident_bytes
end program flotsam_bench
