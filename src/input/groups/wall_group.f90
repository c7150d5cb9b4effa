!> The `&wall` group (docs/input.md): a plane wall in any orientation, its condition, its name in loads.csv
!> and its prescribed motion. Here: the type and defaults of its variables (wall_spec_t), the reader's
!> rows (wall_variables), the namelist read and the scene.nml text (wall_value); its motion's variables
!> are motion_spec's. Its checks (motion, friction, names) stay with the scene's validation.
module wall_group
   use kinds, only: rp, name_len
   use input_text, only: real_text, real_list_text, quoted
   use grid_group, only: wall_condition_keywords
   use scene_variables, only: variable_info_t, text_len, take_text
   use grid_group, only: wall_slip
   use motion_spec, only: motion_spec_t, motion_to_locals, take_motion, motion_value
   implicit none
   private

   public :: read_wall_group, wall_value

   !> `&wall condition = 'free'`: a wall that constrains nothing and reports a zero load (free_condition).
   character(len=*), parameter, public :: wall_free = 'free'
   !> Accepted `&wall condition=` keywords.
   character(len=*), parameter, public :: wall_group_condition_keywords(*) = [character(len=8) :: &
                                                                              wall_condition_keywords, wall_free]
   !> `&wall`: a plane wall (a segment in 2-D, a planar patch in 3-D), world frame. The wall is the part
   !> of the plane through `point` with inward unit normal `normal` that lies inside the box lower..upper
   !> (unbounded by default). The solver turns the `&box_walls` sides into walls of this kind.
   type, public :: wall_spec_t
      real(rp) :: point(3) = 0.0_rp           !< a point of the wall [m]
      real(rp) :: normal(3) = 0.0_rp          !< normal pointing into the fluid, any length (made unit by make_wall)
      real(rp) :: lower(3) = -huge(1.0_rp)    !< extent of the wall: lower corner of its bounding box [m]
      real(rp) :: upper(3) = huge(1.0_rp)     !< upper corner [m]
      character(len=name_len) :: condition = wall_slip
      real(rp) :: friction = 0.0_rp           !< Coulomb coefficient mu of condition 'friction' [-]
      character(len=name_len) :: name = ''    !< name in loads.csv; resolved default 'wall_<k>'
      !> point the moment of the wall's load is taken about [m]; huge: not given, resolved to the component
      !> of `point`
      real(rp) :: moment_point(3) = huge(1.0_rp)
      type(motion_spec_t) :: motion           !< a prescribed rigid translation (motion, motion_start, ...)
   end type wall_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: wall_variables(*) = [ &
      variable_info_t('wall', 'point', 'real3', .true.), &
      variable_info_t('wall', 'normal', 'real3', .true.), &
      variable_info_t('wall', 'lower', 'real3', .false.), &
      variable_info_t('wall', 'upper', 'real3', .false.), &
      variable_info_t('wall', 'condition', 'string', .false.), &
      variable_info_t('wall', 'friction', 'real', .false.), &
      variable_info_t('wall', 'name', 'string', .false.), &
      variable_info_t('wall', 'moment_point', 'real3', .false.), &
      variable_info_t('wall', 'motion', 'string', .false.), &
      variable_info_t('wall', 'motion_start', 'real', .false.), &
      variable_info_t('wall', 'wave_height', 'real', .false.), &
      variable_info_t('wall', 'water_depth', 'real', .false.), &
      variable_info_t('wall', 'motion_file', 'string', .false.), &
      variable_info_t('wall', 'motion_checksum', 'string', .false.), &
      variable_info_t('wall', 'wave_period', 'real', .false.), &
      variable_info_t('wall', 'wave_order', 'integer', .false.), &
      variable_info_t('wall', 'ramp_time', 'real', .false.), &
      variable_info_t('wall', 'spectrum', 'string', .false.), &
      variable_info_t('wall', 'significant_wave_height', 'real', .false.), &
      variable_info_t('wall', 'peak_period', 'real', .false.), &
      variable_info_t('wall', 'gamma', 'real', .false.), &
      variable_info_t('wall', 'wave_seed', 'integer', .false.), &
      variable_info_t('wall', 'wave_duration', 'real', .false.)]

contains

   !> Read one `&wall ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_wall_group(spec, ios, message, text)
      type(wall_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: condition, name, motion, motion_file, motion_checksum, spectrum
      real(rp) :: point(3), normal(3), lower(3), upper(3), moment_point(3), friction, motion_start, wave_height, &
                  water_depth, motion_direction(3), wave_period, ramp_time, significant_wave_height, peak_period, &
                  gamma, wave_duration
      integer :: wave_order, wave_seed
      namelist /wall/ point, normal, lower, upper, condition, friction, name, moment_point, motion, motion_start, &
         wave_height, water_depth, motion_file, motion_checksum, wave_period, wave_order, ramp_time, spectrum, &
         significant_wave_height, peak_period, gamma, wave_seed, wave_duration

      point = spec%point
      normal = spec%normal
      lower = spec%lower
      upper = spec%upper
      condition = spec%condition
      friction = spec%friction
      name = spec%name
      moment_point = spec%moment_point
      call motion_to_locals(spec%motion, motion, motion_start, wave_height, water_depth, motion_direction, motion_file, &
                            motion_checksum, wave_period, wave_order, ramp_time, spectrum, significant_wave_height, &
                            peak_period, gamma, wave_seed, wave_duration)
      read (text, nml=wall, iostat=ios, iomsg=message)
      call take_text('condition', condition, spec%condition, ios, message, fold='lower')
      call take_text('name', name, spec%name, ios, message)
      call take_motion(motion, motion_start, wave_height, water_depth, motion_direction, motion_file, motion_checksum, &
                       wave_period, wave_order, ramp_time, spectrum, significant_wave_height, peak_period, gamma, &
                       wave_seed, wave_duration, spec%motion, ios, message)
      if (ios /= 0) return
      spec%point = point
      spec%normal = normal
      spec%lower = lower
      spec%upper = upper
      spec%friction = friction
      spec%moment_point = moment_point
   end subroutine read_wall_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function wall_value(wall, name) result(text)
      type(wall_spec_t), intent(in) :: wall
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('point')
         text = real_list_text(wall%point)
      case ('normal')
         text = real_list_text(wall%normal)
      case ('lower')
         text = real_list_text(wall%lower)
      case ('upper')
         text = real_list_text(wall%upper)
      case ('condition')
         text = quoted(wall%condition)
      case ('friction')
         text = real_text(wall%friction)
      case ('name')
         text = quoted(wall%name)
      case ('moment_point')
         text = real_list_text(wall%moment_point)
      case default
         text = motion_value(wall%motion, name)
      end select
   end function wall_value
end module wall_group
