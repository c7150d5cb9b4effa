!> The `&inlet` group (docs/input.md, docs/theory.md section 3.1): an opening through which fluid enters.
!> Here: the type and defaults of its variables (inlet_spec_t), the reader's rows (inlet_variables), the
!> namelist read, the scene.nml text (inlet_value) and the opening's geometry every user of an inlet
!> reads (opening_tangent, opening_far_end, has_velocity_file), and its checks (validate_inlet: its
!> material by name, its opening inside the scene box).
module inlet_group
   use kinds, only: rp, name_len, path_len
   use input_text, only: int_text, real_text, real_list_text, quoted, logical_text, group_context
   use scene_variables, only: variable_info_t, text_len, take_text
   use error_status, only: status_t
   use input_checks, only: check_real, check_name, inside_tolerance, axis_letter
   use grid_group, only: grid_spec_t
   use material_group, only: material_spec_t, model_newtonian_fluid, find_material
   implicit none
   private

   public :: validate_inlet, read_inlet_group, inlet_value, has_velocity_file, opening_tangent, opening_far_end

   !> `&inlet`: an opening through which fluid enters at a constant speed, or at the speed (and height) of
   !> a time table `velocity_file` (a hydrograph; algorithms.md section 4.3).
   !> The opening lies in the plane through `point` normal to `direction` (the flow direction, world
   !> frame); it spans `height` along t = (-d_y, d_x, 0) from `point` and, in 3-D, `width` along z.
   type, public :: inlet_spec_t
      character(len=name_len) :: name = ''    !< name in loads.csv; resolved default 'inlet_<k>'
      character(len=name_len) :: material = ''
      integer :: material_index = 0           !< derived: position in scene%materials
      real(rp) :: point(3) = 0.0_rp           !< lower end of the opening [m]
      real(rp) :: direction(3) = 0.0_rp       !< flow direction (made unit when resolved)
      real(rp) :: height = 0.0_rp             !< size of the opening along t [m] (H of rho v H)
      real(rp) :: width = 0.0_rp              !< 3-D: size of the opening along z [m]
      real(rp) :: velocity = 0.0_rp           !< inflow speed v0 [m/s]; 0: not given (velocity_file)
      !> a time table (t, velocity[, height]) of the inflow; '' none. Resolved: the absolute path
      character(len=path_len) :: velocity_file = ''
      character(len=16) :: velocity_checksum = ''   !< time_table checksum of the table's numbers ('' not given)
      !> the fluid enters with the table's column `height` (<= height, the opening's size) instead of height
      logical :: height_from_file = .false.
      real(rp) :: start_time = 0.0_rp         !< the inlet opens [s]
      real(rp) :: end_time = huge(1.0_rp)     !< the inlet closes and acts as a wall [s]
      integer :: particles_per_cell = 2       !< particles per cell per direction
      logical :: hydrostatic = .false.        !< new particles carry the hydrostatic pressure below the stream top
   end type inlet_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: inlet_variables(*) = [ &
      variable_info_t('inlet', 'name', 'string', .false.), &
      variable_info_t('inlet', 'material', 'string', .true.), &
      variable_info_t('inlet', 'point', 'real3', .true.), &
      variable_info_t('inlet', 'direction', 'real3', .true.), &
      variable_info_t('inlet', 'height', 'real', .true.), &
      variable_info_t('inlet', 'width', 'real', .false.), &
      variable_info_t('inlet', 'velocity', 'real', .false.), &
      variable_info_t('inlet', 'velocity_file', 'string', .false.), &
      variable_info_t('inlet', 'velocity_checksum', 'string', .false.), &
      variable_info_t('inlet', 'height_from_file', 'logical', .false.), &
      variable_info_t('inlet', 'start_time', 'real', .false.), &
      variable_info_t('inlet', 'end_time', 'real', .false.), &
      variable_info_t('inlet', 'particles_per_cell', 'integer', .false.), &
      variable_info_t('inlet', 'hydrostatic', 'logical', .false.)]

contains

   !> Read one `&inlet ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_inlet_group(spec, ios, message, text)
      type(inlet_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, material, velocity_file, velocity_checksum
      real(rp) :: point(3), direction(3), height, width, velocity, start_time, end_time
      integer :: particles_per_cell
      logical :: hydrostatic, height_from_file
      namelist /inlet/ name, material, point, direction, height, width, velocity, velocity_file, velocity_checksum, &
         height_from_file, start_time, end_time, particles_per_cell, hydrostatic

      name = spec%name
      material = spec%material
      point = spec%point
      direction = spec%direction
      height = spec%height
      width = spec%width
      velocity = spec%velocity
      velocity_file = spec%velocity_file
      velocity_checksum = spec%velocity_checksum
      height_from_file = spec%height_from_file
      start_time = spec%start_time
      end_time = spec%end_time
      particles_per_cell = spec%particles_per_cell
      hydrostatic = spec%hydrostatic
      read (text, nml=inlet, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('material', material, spec%material, ios, message)
      call take_text('velocity_file', velocity_file, spec%velocity_file, ios, message)
      call take_text('velocity_checksum', velocity_checksum, spec%velocity_checksum, ios, message, fold='lower')
      if (ios /= 0) return
      spec%point = point
      spec%direction = direction
      spec%height = height
      spec%width = width
      spec%velocity = velocity
      spec%height_from_file = height_from_file
      spec%start_time = start_time
      spec%end_time = end_time
      spec%particles_per_cell = particles_per_cell
      spec%hydrostatic = hydrostatic
   end subroutine read_inlet_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function inlet_value(inlet, name) result(text)
      type(inlet_spec_t), intent(in) :: inlet
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(inlet%name)
      case ('material')
         text = quoted(inlet%material)
      case ('point')
         text = real_list_text(inlet%point)
      case ('direction')
         text = real_list_text(inlet%direction)
      case ('height')
         text = real_text(inlet%height)
      case ('width')
         text = real_text(inlet%width)
      case ('velocity')
         text = real_text(inlet%velocity)
      case ('velocity_file')
         text = quoted(inlet%velocity_file)
      case ('velocity_checksum')
         text = quoted(inlet%velocity_checksum)
      case ('height_from_file')
         text = logical_text(inlet%height_from_file)
      case ('start_time')
         text = real_text(inlet%start_time)
      case ('end_time')
         text = real_text(inlet%end_time)
      case ('particles_per_cell')
         text = int_text(inlet%particles_per_cell)
      case ('hydrostatic')
         text = logical_text(inlet%hydrostatic)
      case default
         text = ''
      end select
   end function inlet_value

   !> The inlet's speed (and height) follow the time table of its velocity_file.
   pure logical function has_velocity_file(inlet)
      type(inlet_spec_t), intent(in) :: inlet
      has_velocity_file = len_trim(inlet%velocity_file) > 0
   end function has_velocity_file

   !> The in-plane direction along which an inlet's `height` runs: t = (-d_y, d_x, 0), d the unit
   !> flow direction.
   pure function opening_tangent(inlet) result(tangent)
      type(inlet_spec_t), intent(in) :: inlet
      real(rp) :: tangent(3), d(2)
      d = inlet%direction(1:2) / norm2(inlet%direction(1:2))
      tangent = [-d(2), d(1), 0.0_rp]
   end function opening_tangent

   !> The corner of an inlet's opening opposite `point`: point + height t (+ width e_z in 3-D).
   pure function opening_far_end(inlet, dim) result(far_end)
      type(inlet_spec_t), intent(in) :: inlet
      integer, intent(in) :: dim
      real(rp) :: far_end(3)
      far_end = inlet%point + inlet%height * opening_tangent(inlet)
      if (dim == 3) far_end(3) = far_end(3) + inlet%width
   end function opening_far_end

   subroutine validate_inlet(inlet, i, materials, grid, path, status)
      type(inlet_spec_t), intent(in) :: inlet
      integer, intent(in) :: i
      type(material_spec_t), intent(in) :: materials(:)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: far_end(3), tolerance
      integer :: k, m, dim

      dim = grid%dim
      where = group_context(path, 'inlet', i, "material '"//trim(inlet%material)//"'")
      call check_name(where, 'name', inlet%name, status)
      if (.not. status%ok) return
      m = find_material(materials, inlet%material)
      if (m == 0) then
         call status%fail(where//': variable material must name a declared &material, got '''//trim(inlet%material)//"'")
         return
      else if (materials(m)%model /= model_newtonian_fluid) then
         call status%fail(where//": variable material must name a '"//model_newtonian_fluid//"' material, got '"// &
                          trim(inlet%material)//"' (model '"//trim(materials(m)%model)//"')")
         return
      end if
      do k = 1, dim
         call check_real(where, 'point('//int_text(k)//')', inlet%point(k), status)
         call check_real(where, 'direction('//int_text(k)//')', inlet%direction(k), status)
      end do
      call check_real(where, 'height', inlet%height, status, greater_than=0.0_rp)
      if (dim == 3) call check_real(where, 'width', inlet%width, status, greater_than=0.0_rp)
      if (has_velocity_file(inlet)) then
         ! velocity = 0 is the default: a scene record writes it beside the file
         if (abs(inlet%velocity) > 0.0_rp) then
            call status%fail(where//': variables velocity and velocity_file exclude each other: give a constant '// &
                             'speed or a time table of it, not both')
            return
         end if
      else
         if (len_trim(inlet%velocity_checksum) > 0) then
            call status%fail(where//': variable velocity_checksum belongs to velocity_file, which is not given')
            return
         else if (inlet%height_from_file) then
            call status%fail(where//': variable height_from_file needs velocity_file (a time table with a column '// &
                             'height)')
            return
         else if (abs(inlet%velocity) == 0.0_rp) then
            call status%fail(where//': give variable velocity (a constant inflow speed > 0) or velocity_file (a '// &
                             'time table of t and velocity)')
            return
         end if
         call check_real(where, 'velocity', inlet%velocity, status, greater_than=0.0_rp)
      end if
      call check_real(where, 'start_time', inlet%start_time, status, at_least=0.0_rp)
      call check_real(where, 'end_time', inlet%end_time, status, greater_than=inlet%start_time)
      if (.not. status%ok) return
      if (inlet%particles_per_cell < 1) then
         call status%fail(where//': variable particles_per_cell must be >= 1, got '//int_text(inlet%particles_per_cell))
         return
      end if
      if (norm2(inlet%direction(1:dim)) < tiny(1.0_rp)**0.25_rp) then
         call status%fail(where//': variable direction must not be zero: it is the direction of the inflow')
         return
      end if
      if (dim == 3 .and. abs(inlet%direction(3)) > 0.0_rp) then
         call status%fail(where//': variable direction(3) must be 0 (the opening spans height in the x-y plane and '// &
                          'width along z), got '//real_text(inlet%direction(3)))
         return
      end if
      ! both ends of the opening must lie in the scene box
      far_end = opening_far_end(inlet, dim)
      tolerance = inside_tolerance * grid%cell_size
      do k = 1, dim
         if (inlet%point(k) < grid%origin(k) - tolerance .or. &
             inlet%point(k) > grid%origin(k) + grid%extent(k) + tolerance) then
            call status%fail(where//': variable point('//int_text(k)//') must lie in the scene box of &grid, '// &
                             real_text(grid%origin(k))//' .. '//real_text(grid%origin(k) + grid%extent(k))//', got '// &
                             real_text(inlet%point(k)))
         else if (far_end(k) < grid%origin(k) - tolerance .or. &
                  far_end(k) > grid%origin(k) + grid%extent(k) + tolerance) then
            call status%fail(where//': variables point, direction, height and width put the far end of the opening '// &
                             'outside the scene box of &grid ('//axis_letter(k)//' = '//real_text(far_end(k))//')')
         end if
         if (.not. status%ok) return
      end do
   end subroutine validate_inlet
end module inlet_group
