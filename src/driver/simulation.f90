!> The time loop of a run: steps to the end time, and at every output time a diagnostics row and the
!> fields files (the step is shortened to land on it); checkpoints every N steps, every T seconds of
!> wall time, at the end and on SIGTERM/SIGINT; a stop within the step in which the solution stops
!> being finite or blows up (docs/output.md).
!>
!> Every rebalance_interval steps and at every output time the decomposition is rebalanced by particle
!> count if it has drifted (solver%balance_load).
!>
!> After every step the ranks agree, in one small reduction, on four flags: an unhealthy particle
!> somewhere, a termination signal received somewhere, (rank 0's clock) a wall-time checkpoint
!> being due, and particle arrays that could not grow (out of memory) somewhere. All ranks therefore
!> take the same branch in the same step.
module simulation
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use communication_counters, only: comm_counts_t, communication_totals, counts_between
   use mpm_solver, only: solver_t, flag_unhealthy, flag_no_memory
   use run_diagnostics, only: diagnostics_t, diagnostics_header, diagnostics_row, diagnostics_comments
   use provenance, only: written_by, continued_by, current_date, csv_reading_hint
   use csv_writer, only: csv_writer_t, keep_rows_until
   use load_records, only: load_records_t
   use run_summary, only: write_run_summary, write_timing, write_communication
   use phase_timers, only: phase_health, phase_loads, phase_diagnostics, phase_output, phase_checkpoint, phase_rebalance, &
                           phase_other, phase_names
   use progress_reporter, only: progress_reporter_t
   use status_broadcast, only: broadcast_status, agree_on_status
   use health_check, only: describe_unhealthy_particle
   use termination_signals, only: install_termination_handlers, received_termination_signal, signal_name
   use run_progress, only: run_progress_t, scheduled_output_time, output_index_of
   use xdmf_writer, only: output_entry_t, write_particles_xdmf, write_grid_xdmf
   use field_output, only: write_fields, particle_xdmf_attributes, grid_xdmf_attributes
   use checkpoint, only: write_checkpoint
   use output_layout, only: particles_xdmf, grid_xdmf, fields_file
   use output_directory, only: run_marker
   use input_text, only: int_text, real_text
   implicit none
   private

   public :: run_simulation, blow_up_speed, blow_up_densities

   !> The default speed limit is this multiple of the fastest wave speed of the materials.
   real(rp), parameter :: speed_limit_factor = 10.0_rp
   real(rp), parameter :: density_limit_factor = 100.0_rp

   !> Positions of the flags agreed on after every step.
   !> The time loop's flags after flag_unhealthy and flag_no_memory (mpm_solver): they travel with the
   !> step's reduction (solver_t%loop_flags).
   integer, parameter :: flag_signal = 3, flag_wall_checkpoint = 4, loop_flag_count = 4

   !> What the time loop keeps from step to step besides the solver and the run's progress.
   type :: time_loop_t
      type(csv_writer_t) :: csv                   !< diagnostics.csv (rank 0)
      type(load_records_t) :: records             !< loads.csv, gauges.csv, bodies.csv
      type(progress_reporter_t) :: reporter       !< progress lines and the wall clock
      type(diagnostics_t) :: diag                 !< the latest diagnostics row
      character(len=:), allocatable :: dir        !< the output folder
      character(len=:), allocatable :: checkpoint_path   !< the latest checkpoint written
      character(len=:), allocatable :: outcome    !< run_summary.csv: finished, blew_up, ...
      real(rp) :: end_time = 0.0_rp, interval = 0.0_rp   !< &run end_time and output_interval [s]
      real(rp) :: speed_limit = 0.0_rp, density_limits(2) = 0.0_rp   !< blow-up limits
      real(rp) :: last_checkpoint_wall = 0.0_rp   !< reporter's clock at the latest checkpoint [s]
      integer(i8) :: last_checkpoint_step = 0, first_step = 0, particle_steps = 0
      type(comm_counts_t) :: first_counts          !< communication_counters at the start of the loop
   end type time_loop_t

contains

   !> Run `solver` to its end time (or max_steps), writing into the output folder. `progress` is the
   !> default for a new run, or what read_checkpoint restored. On return `stopped_by` is 0 if the run
   !> reached its end, else the signal that stopped it (a checkpoint was written). Collective; on return
   !> `status` is identical on every rank.
   subroutine run_simulation(solver, progress, status, stopped_by)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      type(status_t), intent(inout) :: status
      integer, intent(out) :: stopped_by
      type(time_loop_t) :: loop
      integer :: flags(4)

      stopped_by = 0
      call start_run(solver, progress, loop, status)
      if (.not. status%ok) return
      do while (solver%time < loop%end_time * (1.0_rp - 1.0e-12_rp) .and. solver%step < solver%run%max_steps)
         call take_step(solver, progress, loop, flags)
         ! particles that found no room (inflow, migration): the state is incomplete, stop before reading it
         if (flags(flag_no_memory) > 0) then
            call solver%check_particle_memory(status)
            exit
         end if
         if (flags(flag_unhealthy) > 0) then
            call report_blow_up(solver, progress, loop%speed_limit, loop%density_limits, status)
            loop%outcome = 'blew_up'
            exit
         end if
         ! loads, gauges and bodies: before a checkpoint of this step, which then holds the next interval's start
         if (loop%records%due(solver)) then
            call solver%timers%switch_to(phase_loads)
            call loop%records%write_rows(solver)
            call solver%timers%switch_to(phase_other)
         end if
         call output_if_due(solver, progress, loop, status)
         if (.not. status%ok) exit
         call checkpoint_if_due(solver, progress, loop, flags, status)
         if (.not. status%ok) exit
         if (flags(flag_signal) > 0) then
            stopped_by = flags(flag_signal)
            loop%outcome = 'stopped_by_signal'
            call status%fail('stopped by '//signal_name(stopped_by)//' at step '//int_text(solver%step)//' (t = '// &
                             real_text(solver%time)//' s); checkpoint written: '//loop%checkpoint_path// &
                             '; continue with --restart '//loop%checkpoint_path)
            exit
         end if
      end do
      call finish_run(solver, progress, loop, status)
   end subroutine run_simulation

   !> Open diagnostics.csv and the load records, balance a new run and write its output at the start
   !> time (a restart has its outputs up to the checkpoint: only the XDMF files are rewritten), then start
   !> the clocks. Collective; on failure the files are closed again.
   subroutine start_run(solver, progress, loop, status)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      type(time_loop_t), intent(inout) :: loop
      type(status_t), intent(inout) :: status

      loop%dir = trim(solver%run%output_dir)
      loop%end_time = solver%run%end_time
      loop%interval = solver%run%output_interval
      loop%speed_limit = blow_up_speed(solver)
      loop%density_limits = blow_up_densities(solver)
      ! the flags travel with the step's reduction (take_step)
      if (allocated(solver%loop_flags)) deallocate (solver%loop_flags)
      allocate (solver%loop_flags(loop_flag_count))
      solver%speed_limit = loop%speed_limit
      solver%density_limits = loop%density_limits
      call open_diagnostics(solver, progress, loop%csv, status)
      if (.not. status%ok) return
      call loop%records%open(solver, progress, status)
      ! a restart continues in the checkpoint's layout (read_checkpoint); a new run starts balanced
      if (status%ok .and. .not. progress%restarted) call solver%balance_load(status)
      if (.not. status%ok) then
         call loop%csv%close()
         call loop%records%close()
         return
      end if
      loop%diag = solver%diagnostics()
      if (progress%restarted) then
         progress%next_output_index = output_index_of(progress%next_output_time, loop%interval, loop%end_time)
         ! continued past the end_time it reached (a later end_time): its output there is written, so the
         ! next one is an interval on, not a step of length 0 to land on it again
         if (progress%next_output_time <= solver%time) then
            progress%next_output_index = progress%next_output_index + 1
            progress%next_output_time = scheduled_output_time(progress%next_output_index, loop%interval, loop%end_time)
         end if
         call write_xdmf(solver, progress, status)
      else
         if (solver%domain%rank == 0) call loop%csv%write_row(diagnostics_row(loop%diag))
         call write_output(solver, progress, status)
         progress%next_output_index = 1
         progress%next_output_time = scheduled_output_time(progress%next_output_index, loop%interval, loop%end_time)
      end if
      call agree_on_status(status, solver%domain%comm)
      if (.not. status%ok) then
         call loop%csv%close()
         call loop%records%close()
         return
      end if
      call install_termination_handlers()
      call loop%reporter%start(solver%run%progress_interval, solver%time, loop%end_time)
      loop%last_checkpoint_wall = loop%reporter%elapsed()
      loop%last_checkpoint_step = solver%step
      loop%first_step = solver%step
      loop%first_counts = communication_totals()
      loop%particle_steps = 0
      loop%outcome = 'finished'
      call solver%timers%reset()
      call solver%timers%switch_to(phase_other)
   end subroutine start_run

   !> One step, shortened to land exactly on the next output time, and the flags all ranks agree on: an
   !> unhealthy particle, particle arrays that could not grow, a termination signal, a wall-time checkpoint
   !> due. No reduction of their own: they travel with the step's (solver_t%loop_flags), so the signal and
   !> the wall clock are read as the step starts, the particles' health as it ends.
   subroutine take_step(solver, progress, loop, flags)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(in) :: progress
      type(time_loop_t), intent(inout) :: loop
      integer, intent(out) :: flags(4)
      logical :: landing

      ! land exactly on the next output time (time + (next - time) may miss it by one ulp)
      landing = solver%time + solver%dt * (1.0_rp + 1.0e-9_rp) >= progress%next_output_time
      if (landing) solver%dt = progress%next_output_time - solver%time
      loop%particle_steps = loop%particle_steps + solver%particles%count
      call solver%timers%switch_to(phase_health)
      solver%loop_flags = 0
      solver%loop_flags(flag_signal) = received_termination_signal()
      if (solver%domain%rank == 0 .and. solver%run%checkpoint_interval_wall > 0.0_rp) then
         if (loop%reporter%elapsed() - loop%last_checkpoint_wall >= solver%run%checkpoint_interval_wall) &
            solver%loop_flags(flag_wall_checkpoint) = 1
      end if
      call solver%timers%switch_to(phase_other)
      call solver%advance()
      flags = solver%loop_flags
      if (landing) solver%time = progress%next_output_time
      call loop%reporter%update(solver%time, solver%step, loop%diag%particles, solver%domain%rank == 0)
      call solver%timers%switch_to(phase_other)
   end subroutine take_step

   !> At an output time (or the last step of max_steps): rebalance, a diagnostics row and the fields;
   !> between outputs the periodic balance check. Collective.
   subroutine output_if_due(solver, progress, loop, status)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      type(time_loop_t), intent(inout) :: loop
      type(status_t), intent(inout) :: status
      logical :: at_output

      at_output = solver%time >= progress%next_output_time * (1.0_rp - 1.0e-12_rp) .or. &
                  solver%step >= solver%run%max_steps
      ! between steps, and before an output so that its shares are balanced ones
      if (at_output .or. mod(solver%step, int(solver%run%rebalance_interval, i8)) == 0) then
         call solver%timers%switch_to(phase_rebalance)
         call solver%balance_load(status)
         call solver%timers%switch_to(phase_other)
         if (.not. status%ok) return
      end if
      if (.not. at_output) return
      call solver%timers%switch_to(phase_diagnostics)
      loop%diag = solver%diagnostics()
      if (solver%domain%rank == 0) call loop%csv%write_row(diagnostics_row(loop%diag))
      call solver%timers%switch_to(phase_output)
      call write_output(solver, progress, status)
      call solver%timers%switch_to(phase_other)
      if (.not. status%ok) return
      ! an output forced by max_steps before the output time keeps the schedule: a run continued
      ! from its checkpoint must still land on the output time it had not reached
      if (solver%time >= progress%next_output_time * (1.0_rp - 1.0e-12_rp)) then
         progress%next_output_index = progress%next_output_index + 1
         progress%next_output_time = scheduled_output_time(progress%next_output_index, loop%interval, loop%end_time)
      end if
   end subroutine output_if_due

   !> A checkpoint when a signal arrived, the wall-time interval has passed or the step is a multiple of
   !> checkpoint_interval_steps. Collective.
   subroutine checkpoint_if_due(solver, progress, loop, flags, status)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      type(time_loop_t), intent(inout) :: loop
      integer, intent(in) :: flags(4)
      type(status_t), intent(inout) :: status
      logical :: checkpoint_due

      checkpoint_due = flags(flag_signal) > 0 .or. flags(flag_wall_checkpoint) > 0
      if (solver%run%checkpoint_interval_steps > 0) &
         checkpoint_due = checkpoint_due .or. mod(solver%step, solver%run%checkpoint_interval_steps) == 0
      if (.not. checkpoint_due) return
      call solver%timers%switch_to(phase_checkpoint)
      call write_checkpoint(solver, progress, loop%dir, solver%run%checkpoints_kept, loop%checkpoint_path, status)
      call solver%timers%switch_to(phase_other)
      if (.not. status%ok) return
      loop%last_checkpoint_wall = loop%reporter%elapsed()
      loop%last_checkpoint_step = solver%step
   end subroutine checkpoint_if_due

   !> The final checkpoint (unless the loop just wrote it, or failed), close the files, and write
   !> run_summary.csv, timing.csv and communication.csv. Collective.
   subroutine finish_run(solver, progress, loop, status)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      type(time_loop_t), intent(inout) :: loop
      type(status_t), intent(inout) :: status
      type(status_t) :: summary_status     ! a summary that cannot be written must not hide the run's own status

      call solver%timers%switch_to(phase_checkpoint)
      if (status%ok .and. loop%last_checkpoint_step /= solver%step) &
         call write_checkpoint(solver, progress, loop%dir, solver%run%checkpoints_kept, loop%checkpoint_path, status)
      call loop%csv%close()
      call loop%records%close()
      call solver%timers%switch_to(phase_other)
      if (.not. status%ok .and. loop%outcome == 'finished') loop%outcome = 'failed'
      if (loop%outcome == 'finished' .and. solver%time < loop%end_time * (1.0_rp - 1.0e-12_rp)) loop%outcome = 'max_steps'
      call write_run_summary(loop%dir, solver%domain%comm, loop%reporter%elapsed(), solver%step - loop%first_step, &
                             loop%particle_steps, loop%outcome, solver%time, summary_status)
      call write_timing(loop%dir, solver%domain%comm, solver%timers%seconds, phase_names, summary_status)
      call write_communication(loop%dir, solver%domain%comm, counts_between(loop%first_counts, communication_totals()), &
                               solver%step - loop%first_step, summary_status)
      if (status%ok .and. .not. summary_status%ok) status = summary_status
   end subroutine finish_run

   !> The particle speed taken as a blow-up [m/s]: &run speed_limit, or by default 10 times the fastest
   !> wave speed of the materials at their reference density (no physical flow of the scene comes near
   !> it; a numerical instability passes it within a few steps of starting to grow). [R]
   real(rp) function blow_up_speed(solver) result(speed)
      type(solver_t), intent(in) :: solver
      integer :: m
      speed = solver%run%speed_limit
      if (speed > 0.0_rp) return
      do m = 1, size(solver%materials)
         associate (model => solver%materials(m)%model)
            speed = max(speed, speed_limit_factor * model%wave_speed(model%reference_density))
         end associate
      end do
      ! only materials without waves (rigid bodies): no speed is a blow-up
      if (speed == 0.0_rp) speed = huge(1.0_rp)
   end function blow_up_speed

   !> The densities taken as a blow-up [kg/m^3]: below the lightest material's reference density or above
   !> the heaviest's by density_limit_factor. No flow of a weakly compressible fluid or an elastic solid
   !> comes near it; a particle's J that runs away under a smoothed pressure (the stress is the cell's, the
   !> J the particle's own) passes it at sane speeds, which the speed limit cannot see. [R]
   function blow_up_densities(solver) result(limits)
      type(solver_t), intent(in) :: solver
      real(rp) :: limits(2)
      integer :: m
      limits = [huge(1.0_rp), 0.0_rp]
      do m = 1, size(solver%materials)
         limits(1) = min(limits(1), solver%materials(m)%model%reference_density / density_limit_factor)
         limits(2) = max(limits(2), solver%materials(m)%model%reference_density * density_limit_factor)
      end do
   end function blow_up_densities

   !> Rank 0 opens diagnostics.csv: new with its header, or for a restart cut back to the rows up to the
   !> checkpoint's step and continued. Collective (the status is broadcast).
   subroutine open_diagnostics(solver, progress, csv, status)
      type(solver_t), intent(in) :: solver
      type(run_progress_t), intent(in) :: progress
      type(csv_writer_t), intent(inout) :: csv
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: path
      path = trim(solver%run%output_dir)//'/'//run_marker
      if (solver%domain%rank == 0) then
         if (progress%restarted) then
            call keep_rows_until(path, 2, progress%restart_step, status)       ! column 2: step
            if (status%ok) call csv%open(path, diagnostics_header(), status, append=.true.)
            if (status%ok) call csv%write_row(continued_by(progress%restart_step, solver%time, solver%domain%nranks, &
                                                           current_date()))
         else
            call csv%open(path, diagnostics_header(), status)
            call csv%write_row(written_by(solver%domain%nranks, current_date(), solver%scene%source_file)// &
                               new_line('a')//diagnostics_comments(solver%grid%dim)// &
                               new_line('a')//csv_reading_hint)
         end if
      end if
      call broadcast_status(status, solver%domain%comm, 0)
   end subroutine open_diagnostics

   !> The fields file of the next output number and the XDMF files listing it. Collective.
   subroutine write_output(solver, progress, status)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      type(status_t), intent(inout) :: status
      type(output_entry_t) :: entry
      if (.not. status%ok) return
      if (.not. (solver%run%particle_output .or. solver%run%grid_output)) return
      call write_fields(solver, trim(solver%run%output_dir), progress%output_count(), entry, status)
      if (.not. status%ok) return
      call progress%add_output(entry)
      call write_xdmf(solver, progress, status)
   end subroutine write_output

   !> Rank 0 rewrites particles.xmf and grid.xmf for the outputs so far. Collective (status broadcast).
   subroutine write_xdmf(solver, progress, status)
      type(solver_t), intent(in) :: solver
      type(run_progress_t), intent(in) :: progress
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: dir
      integer :: n
      dir = trim(solver%run%output_dir)
      n = progress%output_count()
      if (solver%domain%rank == 0 .and. n > 0) then
         if (solver%run%particle_output) call write_particles_xdmf(dir//'/'//particles_xdmf, progress%outputs(1:n), &
                                                                   particle_xdmf_attributes(solver), status)
         if (solver%run%grid_output) call write_grid_xdmf(dir//'/'//grid_xdmf, progress%outputs(1:n), &
                                                          grid_xdmf_attributes(solver), solver%grid%dim, &
                                                          solver%grid%h, status, solver%grid%frame%rotated)
      end if
      call broadcast_status(status, solver%domain%comm, 0)
   end subroutine write_xdmf

   !> Some rank holds an unhealthy particle: name the lowest such rank's first one, write the state as
   !> a last output for inspection, and fail. Collective.
   subroutine report_blow_up(solver, progress, speed_limit, density_limits, status)
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(inout) :: progress
      real(rp), intent(in) :: speed_limit, density_limits(2)
      type(status_t), intent(inout) :: status
      type(status_t) :: output_status
      character(len=:), allocatable :: description, inspection
      character(len=name_len) :: names(size(solver%materials))
      integer :: particle, m
      do m = 1, size(solver%materials)
         names(m) = solver%materials(m)%model%name
      end do
      call describe_unhealthy_particle(solver%particles, solver%grid%frame, speed_limit, names, particle, description, &
                                       density_limits)
      if (particle > 0) call status%fail('the solution blew up at step '//int_text(solver%step)//' (t = '// &
                                         real_text(solver%time)//' s) on rank '//int_text(solver%domain%rank)//': '// &
                                         description)
      call agree_on_status(status, solver%domain%comm)
      inspection = fields_file(progress%output_count())
      call write_output(solver, progress, output_status)
      if (output_status%ok) then
         if (solver%run%particle_output .or. solver%run%grid_output) &
            status%message = trim(status%message)//'; the state was written to '//trim(solver%run%output_dir)// &
                             '/'//inspection//' for inspection'
      else
         status%message = trim(status%message)//'; writing the state for inspection failed: '//trim(output_status%message)
      end if
   end subroutine report_blow_up
end module simulation
