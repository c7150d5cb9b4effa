!> Benchmark driver: `mpirun -np N flotsam_bench scene.nml steps [output]`. Runs a scene for a fixed
!> number of steps without output and prints one line of figures (scripts/bench collects them):
!>   dim ranks particles steps seconds particle_steps_per_s_per_core bytes_per_particle peak_bytes
!>   grid_nodes layouts cpu_seconds
!> preceded by a line of the timed steps' wall time per phase (phase_timers; the slowest rank's):
!>   phases <name>=<seconds> ...
!> and between the two by the table of what the timed steps sent per step and per rank, per category of
!> communication (communication_counters; docs/performance.md, "Scaling model"), a header and one row per
!> category and the total, each the mean over the ranks and the largest rank:
!>   comm category messages_mean messages_max bytes_mean bytes_max collectives_mean collectives_max
!>        collective_bytes_mean collective_bytes_max
!> Memory per particle is the growth of the resident set from before the solver is built to after the
!> timed steps, divided by the rank's particles (rank 0's view); peak_bytes the largest resident set
!> of a rank (VmHWM); grid_nodes the nodes of all ranks' grids at the end; layouts how often the
!> active region was laid out anew to follow the particles; cpu_seconds the processor time of the timed
!> steps (the largest rank's), which on a shared machine varies less than the wall time.
!> With `output`, it then times the output of the final state into the scene's output_dir (replaced):
!> one fields file (particles and grid, the mean of 3 writes), one checkpoint, and the per-step health
!> check of the time loop (the mean of 100 calls), and prints a second line:
!>   output dim ranks particles seconds_per_step fields_seconds checkpoint_seconds health_check_seconds
program flotsam_bench
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use kinds, only: rp, i8
   use mpi_io_choice, only: prefer_romio
   use mpi_f08, only: MPI_Init, MPI_Finalize, MPI_Comm_rank, MPI_Comm_size, MPI_Barrier, MPI_Wtime, MPI_COMM_WORLD, &
                      MPI_Allreduce, MPI_IN_PLACE, MPI_INTEGER, MPI_MAX, MPI_INTEGER8, MPI_SUM, MPI_DOUBLE_PRECISION
   use error_status, only: status_t
   use scene_description, only: scene_t
   use scene_reader, only: read_scene
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use output_directory, only: prepare_output_directory
   use run_progress, only: run_progress_t
   use xdmf_writer, only: output_entry_t
   use field_output, only: write_fields
   use checkpoint, only: write_checkpoint
   use health_check, only: particles_healthy
   use simulation, only: blow_up_speed, blow_up_densities
   use process_memory, only: resident_bytes, peak_resident_bytes
   use phase_timers, only: phase_names, phase_rebalance, phase_other
   use communication_counters, only: comm_counts_t, communication_totals, counts_between, comm_categories, &
                                     comm_category_names
   use run_summary, only: communication_table, comm_columns
   implicit none

   type(scene_t) :: scene
   type(status_t) :: status
   type(solver_t) :: solver
   type(diagnostics_t) :: diag
   character(len=4096) :: arg
   integer :: rank, n_ranks, steps, step, warm_up
   real(rp) :: t0, t1, rss_before, rss_after, cpu0, cpu1, cpu
   integer(i8) :: peak, nodes
   type(comm_counts_t) :: timed_counts

   call prefer_romio()     ! before MPI_Init: see src/domain/mpi_io_choice.f90
   call MPI_Init()
   call MPI_Comm_rank(MPI_COMM_WORLD, rank)
   call MPI_Comm_size(MPI_COMM_WORLD, n_ranks)
   if (command_argument_count() < 2 .or. command_argument_count() > 3) then
      if (rank == 0) write (error_unit, '(a)') 'usage: mpirun -np N flotsam_bench <scene.nml> <steps> [output]'
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

   rss_before = real(resident_bytes(), rp)
   call solver%init(scene, MPI_COMM_WORLD, status)
   if (.not. status%ok) then
      if (rank == 0) write (error_unit, '(a)') 'flotsam_bench: error: '//trim(status%message)
      call MPI_Finalize()
      error stop 2
   end if
   warm_up = max(1, steps / 20)
   call solver%balance_load(status)
   do step = 1, warm_up
      call advance()
   end do
   call MPI_Barrier(MPI_COMM_WORLD)
   call solver%timers%reset()
   t0 = MPI_Wtime()
   call solver%timers%switch_to(phase_other)
   call cpu_time(cpu0)
   timed_counts = communication_totals()
   do step = 1, steps
      call advance()
   end do
   timed_counts = counts_between(timed_counts, communication_totals())
   call cpu_time(cpu1)
   call MPI_Barrier(MPI_COMM_WORLD)
   t1 = MPI_Wtime()
   call solver%timers%switch_to(phase_other)
   cpu = cpu1 - cpu0
   call MPI_Allreduce(MPI_IN_PLACE, cpu, 1, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
   rss_after = real(resident_bytes(), rp)
   diag = solver%diagnostics()
   call print_phases()
   call print_communication()
   peak = peak_resident_bytes()
   call MPI_Allreduce(MPI_IN_PLACE, peak, 1, MPI_INTEGER8, MPI_MAX, MPI_COMM_WORLD)
   nodes = solver%grid%node_count
   call MPI_Allreduce(MPI_IN_PLACE, nodes, 1, MPI_INTEGER8, MPI_SUM, MPI_COMM_WORLD)
   if (rank == 0) write (output_unit, '(i0,1x,i0,1x,i0,1x,i0,1x,es12.5,1x,es12.5,1x,f10.1,3(1x,i0),1x,es12.5)') &
      scene%grid%dim, n_ranks, diag%particles, steps, t1 - t0, real(diag%particles, rp) * steps / ((t1 - t0) * n_ranks), &
      (rss_after - rss_before) / max(1, solver%particles%count), peak, nodes, solver%relayouts, cpu
   if (command_argument_count() == 3) call time_output((t1 - t0) / steps)
   call solver%free()
   call MPI_Finalize()

contains

   !> A step and, as in the time loop, the balance check every rebalance_interval steps.
   subroutine advance()
      call solver%advance()
      if (mod(solver%step, int(scene%run%rebalance_interval, i8)) == 0) then
         call solver%timers%switch_to(phase_rebalance)
         call solver%balance_load(status)
         call solver%timers%switch_to(phase_other)
      end if
      if (.not. status%ok) call bench_failure()
   end subroutine advance

   !> The `phases` line: each phase's seconds over the timed steps, the largest over the ranks.
   subroutine print_phases()
      real(rp) :: largest(size(phase_names))
      integer :: k
      call MPI_Allreduce(solver%timers%seconds, largest, size(largest), MPI_DOUBLE_PRECISION, MPI_MAX, MPI_COMM_WORLD)
      if (rank /= 0) return
      write (output_unit, '(a)', advance='no') 'phases'
      do k = 1, size(phase_names)
         write (output_unit, '(1x,a,"=",es10.3)', advance='no') trim(phase_names(k)), largest(k)
      end do
      write (output_unit, '(a)') ''
   end subroutine print_phases

   !> The `comm` table: per category what the timed steps sent per step and per rank (mean, largest rank).
   subroutine print_communication()
      real(rp) :: mean(comm_columns, comm_categories + 1), largest(comm_columns, comm_categories + 1)
      character(len=16) :: name
      integer :: k, j
      call communication_table(MPI_COMM_WORLD, timed_counts, int(steps, i8), mean, largest)
      if (rank /= 0) return
      write (output_unit, '(a)') 'comm category messages_mean messages_max bytes_mean bytes_max collectives_mean '// &
         'collectives_max collective_bytes_mean collective_bytes_max'
      do k = 1, comm_categories + 1
         name = 'total'
         if (k <= comm_categories) name = comm_category_names(k)
         write (output_unit, '(a,1x,a11,*(1x,es12.5))') 'comm', name, (mean(j, k), largest(j, k), j = 1, comm_columns)
      end do
   end subroutine print_communication

   !> Time the output of the current state: fields file, checkpoint, health check (see the header).
   subroutine time_output(step_seconds)
      real(rp), intent(in) :: step_seconds
      type(run_progress_t) :: progress
      type(output_entry_t) :: entry
      character(len=:), allocatable :: path
      real(rp) :: fields_seconds, checkpoint_seconds, health_seconds, speed_limit
      integer :: k, flags(3)
      logical :: healthy
      integer, parameter :: writes = 3, checks = 100

      call prepare_output_directory(scene%run%output_dir, .true., MPI_COMM_WORLD, status)
      if (.not. status%ok) call bench_failure()
      call MPI_Barrier(MPI_COMM_WORLD)
      t0 = MPI_Wtime()
      do k = 1, writes
         call write_fields(solver, trim(scene%run%output_dir), k - 1, entry, status)
      end do
      call MPI_Barrier(MPI_COMM_WORLD)
      fields_seconds = (MPI_Wtime() - t0) / writes
      t0 = MPI_Wtime()
      call write_checkpoint(solver, progress, trim(scene%run%output_dir), 1, path, status)
      call MPI_Barrier(MPI_COMM_WORLD)
      checkpoint_seconds = MPI_Wtime() - t0
      if (.not. status%ok) call bench_failure()
      speed_limit = blow_up_speed(solver)
      t0 = MPI_Wtime()
      ! as in the time loop: the local check (its flags travel with the step's reduction, no reduction here)
      do k = 1, checks
         healthy = particles_healthy(solver%particles, speed_limit, blow_up_densities(solver))
      end do
      health_seconds = (MPI_Wtime() - t0) / checks
      flags = merge(0, 1, healthy)
      call MPI_Allreduce(MPI_IN_PLACE, flags, 3, MPI_INTEGER, MPI_MAX, MPI_COMM_WORLD)
      healthy = flags(1) == 0
      if (.not. healthy) health_seconds = -health_seconds     ! a blown-up bench state: say so
      if (rank == 0) write (output_unit, '(a,1x,i0,1x,i0,1x,i0,4(1x,es12.5))') 'output', scene%grid%dim, n_ranks, &
         diag%particles, step_seconds, fields_seconds, checkpoint_seconds, health_seconds
   end subroutine time_output

   subroutine bench_failure()
      if (rank == 0) write (error_unit, '(a)') 'flotsam_bench: error: '//trim(status%message)
      call MPI_Finalize()
      error stop 2
   end subroutine bench_failure
end program flotsam_bench
