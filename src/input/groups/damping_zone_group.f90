!> The `&damping_zone` group (docs/input.md): a box of the scene in which the fluid's velocity is relaxed
!> toward a target, at a rate that grows smoothly from the zone's inner face to its outer one: the passive
!> absorbing end of a wave flume (docs/theory.md section 3.9). Everything about its variables is here: their
!> type and defaults (damping_zone_spec_t), the rows the reader knows them by (damping_zone_variables), the
!> namelist read (read_damping_zone_group), the text scene.nml records (damping_zone_value) and the checks of
!> its own values (validate_damping_zone). The solver's part is src/solver/damping_zone.f90.
module damping_zone_group
   use kinds, only: rp, name_len
   use error_status, only: status_t
   use input_text, only: int_text, real_text, real_list_text, quoted, quoted_list, group_context, ordinal
   use input_checks, only: check_real, check_upper_above_lower, check_name, name_detail
   use scene_variables, only: variable_info_t, text_len, take_text
   use grid_group, only: grid_spec_t
   implicit none
   private

   public :: read_damping_zone_group, damping_zone_value, validate_damping_zone

   !> `&damping_zone ramp=`: the axis and sense along which the rate grows from 0 to `rate`; 'none': `rate`
   !> everywhere in the box.
   character(len=*), parameter, public :: ramp_keywords(*) = [character(len=4) :: 'x+', 'x-', 'y+', 'y-', 'z+', 'z-', &
                                                                                'none']

   !> `&damping_zone`: where and how fast the fluid's velocity relaxes toward `target_velocity`.
   type, public :: damping_zone_spec_t
      character(len=name_len) :: name = ''       !< its name in messages (required)
      !> corners of the box, world frame [m] (required)
      real(rp) :: lower(3) = 0.0_rp, upper(3) = 0.0_rp
      !> the relaxation rate at the zone's outer face [1/s] (required, > 0): v - v_t falls as exp(-rate t) there
      real(rp) :: rate = 0.0_rp
      character(len=name_len) :: ramp = 'x+'     !< along which axis and sense the rate grows (ramp_keywords)
      real(rp) :: target_velocity(3) = 0.0_rp     !< the velocity the fluid relaxes to, world frame [m/s]
   end type damping_zone_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: damping_zone_variables(*) = [ &
      variable_info_t('damping_zone', 'name', 'string', .true.), &
      variable_info_t('damping_zone', 'lower', 'real3', .true.), &
      variable_info_t('damping_zone', 'upper', 'real3', .true.), &
      variable_info_t('damping_zone', 'rate', 'real', .true.), &
      variable_info_t('damping_zone', 'ramp', 'string', .false.), &
      variable_info_t('damping_zone', 'target_velocity', 'real3', .false.)]

contains

   !> Read one `&damping_zone ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_damping_zone_group(spec, ios, message, text)
      type(damping_zone_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, ramp
      real(rp) :: lower(3), upper(3), rate, target_velocity(3)
      namelist /damping_zone/ name, lower, upper, rate, ramp, target_velocity

      name = spec%name
      ramp = spec%ramp
      lower = spec%lower
      upper = spec%upper
      rate = spec%rate
      target_velocity = spec%target_velocity
      read (text, nml=damping_zone, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('ramp', ramp, spec%ramp, ios, message, fold='lower')
      if (ios /= 0) return
      spec%lower = lower
      spec%upper = upper
      spec%rate = rate
      spec%target_velocity = target_velocity
   end subroutine read_damping_zone_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function damping_zone_value(zone, name) result(text)
      type(damping_zone_spec_t), intent(in) :: zone
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(zone%name)
      case ('lower')
         text = real_list_text(zone%lower)
      case ('upper')
         text = real_list_text(zone%upper)
      case ('rate')
         text = real_text(zone%rate)
      case ('ramp')
         text = quoted(zone%ramp)
      case ('target_velocity')
         text = real_list_text(zone%target_velocity)
      case default
         text = ''
      end select
   end function damping_zone_value

   !> Zone z of `zones`: a unique name, finite corners with upper > lower along every axis of the grid, a
   !> positive finite rate, a known ramp along an axis of the grid, a finite target velocity.
   subroutine validate_damping_zone(zones, z, grid, path, status)
      type(damping_zone_spec_t), intent(in) :: zones(:)
      integer, intent(in) :: z
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: k, other

      associate (zone => zones(z))
         if (len_trim(zone%name) == 0) then
            call status%fail(group_context(path, 'damping_zone', z)//': variable name is required')
            return
         end if
         where = group_context(path, 'damping_zone', z, name_detail(zone%name))
         call check_name(where, 'name', zone%name, status)
         if (.not. status%ok) return
         do other = 1, z - 1
            if (zones(other)%name == zone%name) then
               call status%fail(where//": variable name '"//trim(zone%name)//"' is already used by the "// &
                                ordinal(other)//' &damping_zone')
               return
            end if
         end do
         do k = 1, grid%dim
            call check_real(where, 'lower('//int_text(k)//')', zone%lower(k), status)
            call check_real(where, 'upper('//int_text(k)//')', zone%upper(k), status)
            call check_real(where, 'target_velocity('//int_text(k)//')', zone%target_velocity(k), status)
         end do
         call check_real(where, 'rate', zone%rate, status)
         if (.not. status%ok) return
         call check_upper_above_lower(where, zone%lower, zone%upper, grid%dim, status)
         if (.not. status%ok) return
         if (zone%rate <= 0.0_rp) then
            call status%fail(where//': variable rate must be > 0 [1/s] (the relaxation rate at the outer face), got '// &
                             real_text(zone%rate))
            return
         end if
         if (all(zone%ramp /= ramp_keywords)) then
            call status%fail(where//': variable ramp must be one of '//quoted_list(ramp_keywords)//", got '"// &
                             trim(zone%ramp)//"'")
            return
         end if
         if (zone%ramp(1:1) == 'z' .and. grid%dim == 2) &
            call status%fail(where//": variable ramp must lie in the plane of a 2-D grid (x or y), got '"// &
                             trim(zone%ramp)//"'")
      end associate
   end subroutine validate_damping_zone
end module damping_zone_group
