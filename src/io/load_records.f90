!> The time series a run writes for the loads question (docs/output.md, docs/loads.md):
!>   loads.csv   force and moment the material exerts on every wall, box side, inlet and structure (wall_loads)
!>   gauges.csv  the &gauge readings (fluid_gauges)
!>   bodies.csv  centroid, velocity, rotation and resultant force of every solid body (body_motion)
!>   panels.csv  force and mean pressure on every &panel, force on every load cell (wall_loads)
!> A file is written only if the scene has something for it. Rows come every `&run load_interval`
!> seconds of simulated time (at the first step end at or after each multiple of it, and at the end of
!> the run), or after every step with load_interval = 0; all four files share the row times. There is
!> no row at t = 0: a row's loads are averages over the interval that ends at its time.
!>
!> Layout: the header row first (so every CSV reader sees the column names), then comment lines
!> starting with '#' (program, date, ranks, scene, units, how to read it), then the rows:
!>   pandas.read_csv(path, comment='#')      numpy.genfromtxt(path, delimiter=',', names=True)
!> A restart cuts each file back to the rows up to the checkpoint's time and continues it.
module load_records
   use kinds, only: rp, name_len
   use error_status, only: status_t
   use provenance, only: written_by, continued_by, current_date, csv_reading_hint
   use mpm_solver, only: solver_t
   use body_motion, only: body_state_t
   use run_progress, only: run_progress_t
   use csv_writer, only: csv_writer_t, keep_rows_through_time
   use file_system, only: path_exists
   use output_layout, only: loads_csv, gauges_csv, bodies_csv, panels_csv
   use status_broadcast, only: broadcast_status
   implicit none
   private

   integer, parameter :: file_loads = 1, file_gauges = 2, file_bodies = 3, file_panels = 4, n_files = 4

   type, public :: load_records_t
      type(csv_writer_t) :: files(n_files)
      logical :: used(n_files) = .false.
   contains
      procedure :: open => records_open
      procedure :: due => records_due
      procedure :: write_rows => records_write_rows
      procedure :: close => records_close
   end type load_records_t

contains

   !> Rank 0 starts the files the scene has columns for, or for a restart cuts them back to the
   !> checkpoint's time and continues them. Collective (the status is broadcast).
   subroutine records_open(self, solver, progress, status)
      class(load_records_t), intent(inout) :: self
      type(solver_t), intent(in) :: solver
      type(run_progress_t), intent(in) :: progress
      type(status_t), intent(inout) :: status
      character(len=*), parameter :: names(n_files) = [character(len=10) :: loads_csv, gauges_csv, bodies_csv, panels_csv]
      character(len=:), allocatable :: path, masses
      integer :: f
      self%used(file_loads) = size(solver%loads%names) > 0
      self%used(file_gauges) = solver%gauges%count() > 0
      self%used(file_bodies) = solver%bodies%count() > 0
      self%used(file_panels) = size(solver%loads%panel_names) > 0
      ! the bodies' masses for bodies.csv's header (measured on every rank: collective)
      masses = ''
      if (self%used(file_bodies) .and. .not. progress%restarted) masses = body_masses(solver)
      if (solver%domain%rank == 0) then
         do f = 1, n_files
            if (.not. self%used(f) .or. .not. status%ok) cycle
            path = trim(solver%run%output_dir)//'/'//trim(names(f))
            if (progress%restarted) then
               if (.not. path_exists(path)) then
                  call status%fail('--restart: '//path//' is missing: the run to continue wrote it')
                  cycle
               end if
               call keep_rows_through_time(path, solver%time, status)
               if (status%ok) call self%files(f)%open(path, '', status, append=.true.)
               call self%files(f)%write_row(continued_by(solver%step, solver%time, solver%domain%nranks, current_date()))
            else
               call self%files(f)%open(path, header_row(solver, f), status)
               if (status%ok) call write_comments(self%files(f), solver, f, masses)
            end if
         end do
      end if
      call broadcast_status(status, solver%domain%comm, 0)
   end subroutine records_open

   !> True after a step that ends at or after the next row time (or the run's end). The same on every
   !> rank (time and step only).
   logical function records_due(self, solver) result(due)
      class(load_records_t), intent(in) :: self
      type(solver_t), intent(in) :: solver
      real(rp) :: interval, next
      due = .false.
      if (.not. any(self%used)) return
      interval = solver%run%load_interval
      due = interval <= 0.0_rp .or. solver%time >= solver%run%end_time * (1.0_rp - 1.0e-12_rp) .or. &
            solver%step >= solver%run%max_steps
      if (due) return
      ! the first multiple of the interval after the previous row
      next = (aint(solver%loads%last_row_time / interval + 1.0e-9_rp) + 1.0_rp) * interval
      due = solver%time >= next * (1.0_rp - 1.0e-12_rp)
   end function records_due

   !> Measure and write one row of every file at the solver's time. Collective (a few reductions);
   !> rank 0 writes.
   subroutine records_write_rows(self, solver)
      class(load_records_t), intent(inout) :: self
      type(solver_t), intent(inout) :: solver
      real(rp) :: interval
      real(rp), allocatable :: values(:)
      interval = solver%time - solver%loads%last_row_time
      if (interval <= 0.0_rp) return
      ! the loads' row also gives the wall-pressure gauges' and the panels' means (sensor_pressure,
      ! panel_values): taken before the gauges
      if (self%used(file_loads) .or. solver%loads%sensors > 0) then
         values = solver%loads%row_values(solver%grid%frame, interval, solver%domain%comm, solver%domain%nranks)
         if (solver%domain%rank == 0 .and. self%used(file_loads)) &
            call self%files(file_loads)%write_row(row_text(solver%time, values))
      end if
      if (self%used(file_gauges)) then
         values = solver%gauges%sample(solver%particles, solver%materials, solver%grid%frame, solver%domain%comm, &
                                       solver%loads%sensor_pressure)
         if (solver%domain%rank == 0) call self%files(file_gauges)%write_row(row_text(solver%time, values))
      end if
      if (self%used(file_panels) .and. solver%domain%rank == 0) &
         call self%files(file_panels)%write_row(row_text(solver%time, solver%loads%panel_values))
      if (self%used(file_bodies)) then
         values = solver%bodies%row_values(solver%bodies%measure(solver%particles, solver%grid%frame, solver%domain%comm), &
                                           solver%grid%frame, interval)
         if (solver%domain%rank == 0) call self%files(file_bodies)%write_row(row_text(solver%time, values))
      end if
      solver%loads%last_row_time = solver%time
   end subroutine records_write_rows

   subroutine records_close(self)
      class(load_records_t), intent(inout) :: self
      integer :: f
      do f = 1, n_files
         call self%files(f)%close()
      end do
   end subroutine records_close

   !> `time` and the values, comma separated, each in as many digits as it takes to read it back exactly.
   function row_text(time, values) result(line)
      real(rp), intent(in) :: time, values(:)
      character(len=:), allocatable :: line
      character(len=40) :: field
      integer :: i
      write (field, '(g0)') time
      line = trim(adjustl(field))
      do i = 1, size(values)
         write (field, '(g0)') values(i)
         line = line//','//trim(adjustl(field))
      end do
   end function row_text

   function header_row(solver, f) result(line)
      type(solver_t), intent(in) :: solver
      integer, intent(in) :: f
      character(len=:), allocatable :: line
      select case (f)
      case (file_loads)
         line = joined(solver%loads%column_names())
      case (file_gauges)
         line = joined(solver%gauges%column_names())
      case (file_panels)
         line = joined(solver%loads%panel_column_names())
      case default
         line = joined(solver%bodies%column_names())
      end select
   end function header_row

   function joined(columns) result(line)
      character(len=*), intent(in) :: columns(:)
      character(len=:), allocatable :: line
      integer :: i
      line = 'time'
      do i = 1, size(columns)
         line = line//','//trim(columns(i))
      end do
   end function joined

   !> '<name> <mass>; ...' of the solid bodies at the start [kg, kg/m in 2-D]. Collective.
   function body_masses(solver) result(text)
      type(solver_t), intent(in) :: solver
      character(len=:), allocatable :: text
      type(body_state_t) :: state
      character(len=40) :: field
      integer :: b
      state = solver%bodies%measure(solver%particles, solver%grid%frame, solver%domain%comm)
      text = ''
      do b = 1, solver%bodies%count()
         write (field, '(g0)') state%mass(b)
         if (b > 1) text = text//'; '
         text = text//trim(solver%bodies%bodies(b)%name)//' '//trim(adjustl(field))
      end do
   end function body_masses

   !> What the file holds, in which units, from which scene and program, and how to read it; `masses`
   !> (bodies.csv): the bodies' masses.
   subroutine write_comments(file, solver, f, masses)
      type(csv_writer_t), intent(inout) :: file
      type(solver_t), intent(in) :: solver
      integer, intent(in) :: f
      character(len=*), intent(in) :: masses
      character(len=:), allocatable :: force, moment, per_depth
      if (solver%grid%dim == 2) then
         force = 'N/m'
         moment = 'N m/m'
         per_depth = ' (2-D plane strain: per metre of depth)'
      else
         force = 'N'
         moment = 'N m'
         per_depth = ''
      end if
      call file%write_row(written_by(solver%domain%nranks, current_date(), solver%scene%source_file))
      select case (f)
      case (file_loads)
         call file%write_row('# loads.csv: force <name>_f* and moment <name>_m* the material exerts on each wall, box '// &
                             'side, inlet and structure, world frame; each row is the mean over the interval since the '// &
                             'previous row (impulse / interval); moments about each wall''s moment_point (default its '// &
                             'point; box sides: the side''s lower corner; structures: the shape''s centre)')
         call file%write_row('# units: time s; _fx _fy _fz '//force//'; _mx _my _mz '//moment//per_depth)
      case (file_gauges)
         call file%write_row('# gauges.csv: readings of the &gauge sensors at the row''s time, world frame; '// &
                             '<name>_samples = fluid particles the gauge saw (0: none, the value is then 0); a '// &
                             'wall_pressure gauge (no _samples) is the mean pressure its wall took over its patch '// &
                             'in the interval since the previous row')
         call file%write_row('# units: time s; _pressure Pa; _level m (free surface above the gauge point); '// &
                             '_vx _vy _vz m/s; _samples count')
      case (file_panels)
         call file%write_row('# panels.csv: per &panel the force <name>_f* the material exerts on its part of its '// &
                             'wall''s surface, world frame, and <name>_pressure its mean pressure (normal force / '// &
                             'area); per load cell (kind load_cell) the force on the constrained nodes in its box; '// &
                             'each row is the mean over the interval since the previous row (impulse / interval); '// &
                             'panels tiling a face add up to its force in loads.csv')
         call file%write_row('# units: time s; _pressure Pa; _fx _fy _fz '//force//per_depth)
      case default
         call file%write_row('# bodies.csv: per solid &body its centroid, centroid velocity, rotation (2-D: angle '// &
                             'about z, counter-clockwise, continuous; 3-D: rotation vector = angle * unit axis) at the '// &
                             'row''s time, and the resultant force of fluid, walls and bodies on it (change of momentum '// &
                             '/ interval - weight, mean over the interval since the previous row), world frame')
         call file%write_row('# units: time s; _x _y _z m; _vx _vy _vz m/s; _angle _rx _ry _rz rad; _fx _fy _fz '// &
                             force//per_depth)
         call file%write_row('# mass ('//trim(merge('kg/m', 'kg  ', solver%grid%dim == 2))//'): '//masses)
      end select
      call file%write_row(csv_reading_hint)
   end subroutine write_comments
end module load_records
