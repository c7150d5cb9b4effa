!> Forces and moments the material exerts on the walls, box sides, inlets and structures of a scene (loads.csv;
!> docs/loads.md, docs/theory.md section 3.2, algorithms.md section 9.1).
!>
!> Every step the walls record, per wall and rank, the momentum their constraints gave the material
!> (constraint: nodal constraint m_i (v^c - v^*), counted once per shared node, and the particle
!> safeguard m_p (v^c - v)). At the end of the step these are added, per entry of loads.csv (an inlet's
!> feeder and closing walls are one entry), to this rank's impulse since the last row: no communication
!> per step. A row sums the ranks' impulses (one reduction) and divides by the interval's length,
!> F = -J / (t - t_prev), so that no impulse is lost between rows. Each rank's impulse is saved in
!> checkpoints (checkpoint.f90): a restart on the same ranks continues the rows bit for bit.
!> The sensors on the walls (surface_sensors: wall-pressure gauges, then panels and load cells) add one
!> column each after the walls' in the step's record and one entry each after loads.csv's, summed and saved
!> the same way but written to gauges.csv and panels.csv: row_values leaves the gauges' interval means in
!> `sensor_pressure` and the panels' in `panel_values`.
!> With contact body fields (body_contact), every structure has one more entry per body field,
!> `<structure>_by_<body>`: the part of the structure's impulse given to that body's field (nodes and
!> safeguard); the structure's own entry keeps the total, the rest of which is the common field's.
module wall_loads
   use kinds, only: rp, name_len
   use communication_counters, only: count_collective, comm_records, real_bytes
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use scene_description, only: scene_t, gauge_wall_pressure, panel_load_cell
   use constraint, only: impulse_rows
   use surface_sensors, only: pressure_row
   use load_entries, only: load_entry_t, scene_load_entries, entries_before, entry_structure
   use body_contact, only: contact_body_names
   use world_frame, only: frame_t
   implicit none
   private

   type, public :: wall_loads_t
      integer :: dim = 2
      !> the scene's surfaces in loads.csv order (load_entries)
      type(load_entry_t), allocatable :: entries(:)
      !> one name per entry, then per structure and body field
      character(len=2 * name_len + 4), allocatable :: names(:)
      real(rp), allocatable :: step_impulse(:, :)        !< (impulse_rows, wall) this rank, this step
      integer :: fields = 0                              !< contact body fields
      integer :: first_structure = 0                     !< entries before the structures'
      integer :: structures = 0
      !> (impulse_rows, wall, field) body field f's part of step_impulse(:, wall)
      real(rp), allocatable :: field_impulse(:, :, :)
      real(rp), allocatable :: impulse(:, :)             !< (impulse_rows, entry) this rank, since last row
      integer :: sensors = 0                             !< gauges, panels, load cells: entries after the names'
      integer :: pressure_gauges = 0                     !< wall-pressure gauges: the first sensors
      !> per wall-pressure gauge, its mean pressure over the interval of the last row [Pa]
      real(rp), allocatable :: sensor_pressure(:)
      !> panels.csv: per panel its name and whether it is a load cell (no pressure column)
      character(len=name_len), allocatable :: panel_names(:)
      logical, allocatable :: load_cell(:)
      !> the panels' row of the interval of the last row, in panels.csv's column order [Pa, N; N/m in 2-D]
      real(rp), allocatable :: panel_values(:)
      !> time of the last row of loads.csv, gauges.csv and bodies.csv: the start of the interval now
      !> accumulating (0 at the start of a run; saved in checkpoints)
      real(rp) :: last_row_time = 0.0_rp
   contains
      procedure :: init => loads_init
      procedure :: begin_step => loads_begin_step
      procedure :: end_step => loads_end_step
      procedure :: row_values => loads_row_values
      procedure :: column_names => loads_column_names
      procedure :: panel_column_names => loads_panel_column_names
   end type wall_loads_t

contains

   !> The entries of the scene in loads.csv order (load_entries: the &wall groups, the &box_walls sides
   !> that are walls, the &inlet groups, the &structure groups), then per structure and contact body field.
   subroutine loads_init(self, scene)
      class(wall_loads_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      character(len=name_len), allocatable :: bodies(:)
      character(len=2 * name_len + 4) :: entry
      integer :: n_structures, e, s, f
      self%dim = scene%grid%dim
      self%entries = scene_load_entries(scene)
      allocate (self%names(size(self%entries)))
      do e = 1, size(self%entries)
         self%names(e) = self%entries(e)%name
      end do
      n_structures = 0
      if (allocated(scene%structures)) n_structures = size(scene%structures)
      self%first_structure = entries_before(self%entries, entry_structure)
      self%structures = n_structures
      ! the entries per structure and body field: only with contact fields, so other scenes keep their columns
      bodies = contact_body_names(scene)
      self%fields = size(bodies)
      do s = 1, n_structures
         do f = 1, self%fields
            entry = trim(scene%structures(s)%name)//'_by_'//trim(bodies(f))
            self%names = [self%names, entry]
         end do
      end do
      self%pressure_gauges = 0
      if (allocated(scene%gauges)) self%pressure_gauges = count(scene%gauges%kind == gauge_wall_pressure)
      allocate (self%panel_names(0), self%load_cell(0), self%panel_values(0))
      if (allocated(scene%panels)) then
         self%panel_names = scene%panels%name
         self%load_cell = scene%panels%kind == panel_load_cell
      end if
      self%sensors = self%pressure_gauges + size(self%panel_names)
      allocate (self%impulse(impulse_rows, size(self%names) + self%sensors), self%sensor_pressure(self%pressure_gauges))
      self%impulse = 0.0_rp
      self%sensor_pressure = 0.0_rp
   end subroutine loads_init

   !> Clear this step's record of the walls (the walls of the current layout: their number never changes)
   !> and of the wall-pressure gauges (a column each after the walls').
   subroutine loads_begin_step(self, n_walls)
      class(wall_loads_t), intent(inout) :: self
      integer, intent(in) :: n_walls
      if (.not. allocated(self%step_impulse)) allocate (self%step_impulse(impulse_rows, n_walls + self%sensors))
      if (size(self%step_impulse, 2) /= n_walls + self%sensors) then
         deallocate (self%step_impulse)
         allocate (self%step_impulse(impulse_rows, n_walls + self%sensors))
      end if
      self%step_impulse = 0.0_rp
      if (allocated(self%field_impulse)) then
         if (size(self%field_impulse, 2) /= n_walls) deallocate (self%field_impulse)
      end if
      if (.not. allocated(self%field_impulse)) allocate (self%field_impulse(impulse_rows, n_walls, self%fields))
      self%field_impulse = 0.0_rp
   end subroutine loads_begin_step

   !> Add this step's impulses to this rank's impulse since the last row (per loads.csv entry).
   !> `loads` (per constraint): the entry its impulse goes to (0: none; constraint_list's loads).
   subroutine loads_end_step(self, loads)
      class(wall_loads_t), intent(inout) :: self
      integer, intent(in) :: loads(:)
      integer :: w, s, f, e
      do w = 1, size(loads)
         if (loads(w) > 0) self%impulse(:, loads(w)) = self%impulse(:, loads(w)) + self%step_impulse(:, w)
      end do
      do s = 1, self%sensors
         e = size(self%names) + s
         self%impulse(:, e) = self%impulse(:, e) + self%step_impulse(:, size(loads) + s)
      end do
      if (self%fields == 0) return
      ! a structure's entry: its fields' entries follow the structures' (load_entries)
      do w = 1, size(loads)
         s = loads(w) - self%first_structure
         if (s < 1 .or. s > self%structures) cycle
         do f = 1, self%fields
            e = self%first_structure + self%structures + (s - 1) * self%fields + f
            self%impulse(:, e) = self%impulse(:, e) + self%field_impulse(:, w, f)
         end do
      end do
   end subroutine loads_end_step

   !> The row of loads.csv for the interval of length `interval` that ends now, in the world frame, and
   !> the impulse cleared for the next interval: per entry the force the material exerts on the wall
   !> (fx, fy[, fz]) and its moment (2-D mz; 3-D mx, my, mz) [N, N m; per metre of depth in 2-D]; the
   !> wall-pressure gauges' interval means go to sensor_pressure. Collective (one small reduction; none on
   !> one rank).
   function loads_row_values(self, frame, interval, comm, nranks) result(values)
      class(wall_loads_t), intent(inout) :: self
      type(frame_t), intent(in) :: frame
      real(rp), intent(in) :: interval
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: nranks
      real(rp), allocatable :: values(:)
      real(rp) :: total(impulse_rows, size(self%impulse, 2))
      integer :: e, at, d, s
      d = self%dim
      total = self%impulse
      if (nranks > 1 .and. size(total) > 0) then
         call MPI_Allreduce(MPI_IN_PLACE, total, size(total), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
         call count_collective(comm_records, size(total), real_bytes)
      end if
      allocate (values(size(self%names) * merge(3, 6, d == 2)))
      at = 0
      do e = 1, size(self%names)
         ! the material's force on the wall is minus the impulse the wall gave the material
         values(at + 1:at + d) = -frame%world_vector(total(1:d, e)) / interval
         at = at + d
         if (d == 2) then
            values(at + 1) = -total(6, e) / interval     ! a rotation about z keeps m_z
            at = at + 1
         else
            values(at + 1:at + 3) = -frame%world_vector(total(4:6, e)) / interval
            at = at + 3
         end if
      end do
      ! a gauge's column holds sum w dp . n / |patch| (p dt) in its pressure row
      do s = 1, self%pressure_gauges
         self%sensor_pressure(s) = total(pressure_row, size(self%names) + s) / interval
      end do
      ! a panel's: the same and sum w dp (-F dt) in its force rows; a load cell's the force rows only
      self%panel_values = [real(rp) ::]
      do s = 1, size(self%panel_names)
         e = size(self%names) + self%pressure_gauges + s
         if (.not. self%load_cell(s)) self%panel_values = [self%panel_values, total(pressure_row, e) / interval]
         self%panel_values = [self%panel_values, -frame%world_vector(total(1:d, e)) / interval]
      end do
      self%impulse = 0.0_rp
   end function loads_row_values

   !> Column names of panels.csv after `time`, in the order of panel_values: per panel _pressure (not for a
   !> load cell) and the force _fx, _fy[, _fz].
   function loads_panel_column_names(self) result(columns)
      class(wall_loads_t), intent(in) :: self
      character(len=name_len + 9), allocatable :: columns(:)
      character(len=*), parameter :: force(3) = ['_fx', '_fy', '_fz']
      integer :: p, k
      allocate (columns(0))
      do p = 1, size(self%panel_names)
         if (.not. self%load_cell(p)) columns = [character(len=name_len + 9) :: columns, trim(self%panel_names(p))//'_pressure']
         do k = 1, self%dim
            columns = [character(len=name_len + 9) :: columns, trim(self%panel_names(p))//force(k)]
         end do
      end do
   end function loads_panel_column_names

   !> Column names of loads.csv after `time`, in the order of row_values.
   function loads_column_names(self) result(columns)
      class(wall_loads_t), intent(in) :: self
      character(len=2 * name_len + 7), allocatable :: columns(:)
      character(len=*), parameter :: suffixes_2d(3) = ['_fx', '_fy', '_mz']
      character(len=*), parameter :: suffixes_3d(6) = ['_fx', '_fy', '_fz', '_mx', '_my', '_mz']
      integer :: e, s, n
      n = merge(3, 6, self%dim == 2)
      allocate (columns(n * size(self%names)))
      do e = 1, size(self%names)
         do s = 1, n
            if (self%dim == 2) then
               columns((e - 1) * n + s) = trim(self%names(e))//suffixes_2d(s)
            else
               columns((e - 1) * n + s) = trim(self%names(e))//suffixes_3d(s)
            end if
         end do
      end do
   end function loads_column_names
end module wall_loads
