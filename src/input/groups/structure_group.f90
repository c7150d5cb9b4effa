!> The `&structure` group (docs/input.md): a fixed or moving solid the material meets (a box, cylinder,
!> sphere, polygon or extruded polygon), its condition and motion. Here: the type and defaults of its
!> variables (structure_spec_t), the reader's rows (structure_variables), the namelist read, the scene.nml
!> text (structure_value) and its shape (structure_shape); its shape's and motion's variables are
!> shape_input's and motion_spec's. Its checks stay with the scene's validation.
module structure_group
   use kinds, only: rp, name_len
   use shape_geometry, only: shape_t, box_corners, max_vertices
   use input_text, only: real_text, real_list_text, quoted
   use scene_variables, only: variable_info_t, text_len, take_text
   use grid_group, only: wall_slip
   use motion_spec, only: motion_spec_t, motion_to_locals, take_motion, motion_value
   use shape_input, only: shape_value, shape_to_locals, locals_to_shape
   implicit none
   private

   public :: read_structure_group, structure_value, structure_shape

   !> `&structure`: a rigid obstacle of any shape and orientation (world frame) whose surface constrains
   !> the material like a wall (unilateral; slip, no-slip or Coulomb friction); fixed, or translated by a
   !> prescribed motion.
   type, public :: structure_spec_t
      character(len=name_len) :: name = ''    !< name in loads.csv; resolved default 'structure_<k>'
      type(shape_t) :: shape                  !< the obstacle (shape_geometry: negative distance inside)
      !> box: corners lower..upper as an alternative to centre and size (huge: not given; resolved into
      !> the shape and cleared)
      real(rp) :: lower(3) = huge(1.0_rp)
      real(rp) :: upper(3) = huge(1.0_rp)
      character(len=name_len) :: condition = wall_slip
      real(rp) :: friction = 0.0_rp           !< Coulomb coefficient mu of condition 'friction' [-]
      !> point the moment of its load is taken about [m]; huge: not given, resolved to the shape's centre
      real(rp) :: moment_point(3) = huge(1.0_rp)
      type(motion_spec_t) :: motion           !< a prescribed rigid translation (as a &wall's)
   end type structure_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: structure_variables(*) = [ &
      variable_info_t('structure', 'name', 'string', .false.), &
      variable_info_t('structure', 'shape', 'string', .false.), &
      variable_info_t('structure', 'centre', 'real3', .false.), &
      variable_info_t('structure', 'size', 'real3', .false.), &
      variable_info_t('structure', 'rotation', 'real', .false.), &
      variable_info_t('structure', 'rotation_axis', 'real3', .false.), &
      variable_info_t('structure', 'radius', 'real', .false.), &
      variable_info_t('structure', 'axis', 'real3', .false.), &
      variable_info_t('structure', 'length', 'real', .false.), &
      variable_info_t('structure', 'vertices', 'reals', .false.), &
      variable_info_t('structure', 'z_range', 'reals', .false.), &
      variable_info_t('structure', 'lower', 'real3', .false.), &
      variable_info_t('structure', 'upper', 'real3', .false.), &
      variable_info_t('structure', 'condition', 'string', .false.), &
      variable_info_t('structure', 'friction', 'real', .false.), &
      variable_info_t('structure', 'moment_point', 'real3', .false.), &
      variable_info_t('structure', 'motion', 'string', .false.), &
      variable_info_t('structure', 'motion_start', 'real', .false.), &
      variable_info_t('structure', 'wave_height', 'real', .false.), &
      variable_info_t('structure', 'water_depth', 'real', .false.), &
      variable_info_t('structure', 'motion_direction', 'real3', .false.), &
      variable_info_t('structure', 'motion_file', 'string', .false.), &
      variable_info_t('structure', 'motion_checksum', 'string', .false.), &
      variable_info_t('structure', 'wave_period', 'real', .false.), &
      variable_info_t('structure', 'wave_order', 'integer', .false.), &
      variable_info_t('structure', 'ramp_time', 'real', .false.), &
      variable_info_t('structure', 'spectrum', 'string', .false.), &
      variable_info_t('structure', 'significant_wave_height', 'real', .false.), &
      variable_info_t('structure', 'peak_period', 'real', .false.), &
      variable_info_t('structure', 'gamma', 'real', .false.), &
      variable_info_t('structure', 'wave_seed', 'integer', .false.), &
      variable_info_t('structure', 'wave_duration', 'real', .false.)]

contains

   !> Read one `&structure ... /` (text) over `spec`'s values (scene_reader's read_group).
   !> `vertices` is a flat list x1, y1, x2, y2, ...: a list that is given replaces the whole polygon (an
   !> override with fewer vertices must not keep the old ones beyond it).
   subroutine read_structure_group(spec, ios, message, text)
      type(structure_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, shape, condition, motion, motion_file, motion_checksum, spectrum
      real(rp) :: centre(3), size(3), rotation, rotation_axis(3), radius, axis(3), length, vertices(2 * max_vertices), &
                  z_range(2), lower(3), upper(3), friction, moment_point(3), motion_start, wave_height, water_depth, &
                  motion_direction(3), wave_period, ramp_time, significant_wave_height, peak_period, gamma, wave_duration
      integer :: wave_order, wave_seed
      namelist /structure/ name, shape, centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range, &
         lower, upper, condition, friction, moment_point, motion, motion_start, wave_height, water_depth, &
         motion_direction, motion_file, motion_checksum, wave_period, wave_order, ramp_time, spectrum, &
         significant_wave_height, peak_period, gamma, wave_seed, wave_duration

      name = spec%name
      shape = spec%shape%kind
      call shape_to_locals(spec%shape, centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range)
      lower = spec%lower
      upper = spec%upper
      condition = spec%condition
      friction = spec%friction
      moment_point = spec%moment_point
      call motion_to_locals(spec%motion, motion, motion_start, wave_height, water_depth, motion_direction, motion_file, &
                            motion_checksum, wave_period, wave_order, ramp_time, spectrum, significant_wave_height, &
                            peak_period, gamma, wave_seed, wave_duration)
      read (text, nml=structure, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('shape', shape, spec%shape%kind, ios, message, fold='lower')
      call take_text('condition', condition, spec%condition, ios, message, fold='lower')
      call take_motion(motion, motion_start, wave_height, water_depth, motion_direction, motion_file, motion_checksum, &
                       wave_period, wave_order, ramp_time, spectrum, significant_wave_height, peak_period, gamma, &
                       wave_seed, wave_duration, spec%motion, ios, message)
      if (ios /= 0) return
      call locals_to_shape(centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range, spec%shape)
      spec%lower = lower
      spec%upper = upper
      spec%friction = friction
      spec%moment_point = moment_point
   end subroutine read_structure_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function structure_value(structure, name) result(text)
      type(structure_spec_t), intent(in) :: structure
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(structure%name)
      case ('lower')
         text = real_list_text(structure%lower)
      case ('upper')
         text = real_list_text(structure%upper)
      case ('condition')
         text = quoted(structure%condition)
      case ('friction')
         text = real_text(structure%friction)
      case ('moment_point')
         text = real_list_text(structure%moment_point)
      case default
         ! the shape's variables, else the motion's
         text = shape_value(structure%shape, name)
         if (len(text) == 0) text = motion_value(structure%motion, name)
      end select
   end function structure_value

   !> The shape of a `&structure` (validated) in a `dim`-D scene: a box given by its corners lower..upper
   !> as centre and size (resolve_scene stores it so).
   pure function structure_shape(structure, dim) result(shape)
      type(structure_spec_t), intent(in) :: structure
      integer, intent(in) :: dim
      type(shape_t) :: shape
      shape = structure%shape
      if (structure%lower(1) < huge(1.0_rp)) shape = box_corners(shape, structure%lower, structure%upper, dim)
   end function structure_shape
end module structure_group
