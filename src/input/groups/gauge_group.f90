!> The `&gauge` group (docs/input.md): a sensor of the fluid at a point, written to gauges.csv
!> (docs/loads.md). Everything about its variables is here: their type and defaults (gauge_spec_t), the
!> kinds a gauge may be, the rows the reader knows them by (gauge_variables), the namelist read
!> (read_gauge_group), the text scene.nml records (gauge_value) and the checks of its own values
!> (validate_gauge). scene_description holds the gauges of a scene; what needs other groups (the wall
!> of a wall_pressure gauge, the default radius from the cell size) is checked and resolved there.
!> A new variable of the group: its component, its row, its namelist variable, its case in gauge_value,
!> its check, and a row in docs/input.md.
module gauge_group
   use kinds, only: rp, name_len
   use error_status, only: status_t
   use input_text, only: int_text, real_text, real_list_text, quoted, quoted_list, group_context, ordinal
   use input_checks, only: check_real, check_name, name_detail, inside_tolerance
   use scene_variables, only: variable_info_t, text_len, take_text
   use grid_group, only: grid_spec_t
   implicit none
   private

   public :: read_gauge_group, gauge_value, validate_gauge

   !> Gauge kinds (`&gauge kind=`).
   character(len=*), parameter, public :: gauge_pressure = 'pressure'
   character(len=*), parameter, public :: gauge_level = 'level'
   !> a level that sees only the water standing on the point: spray and falling jets above a gap are not read
   character(len=*), parameter, public :: gauge_connected_level = 'connected_level'
   character(len=*), parameter, public :: gauge_velocity = 'velocity'
   !> the pressure a wall or structure takes over a patch of its surface, from its constraint's impulse
   character(len=*), parameter, public :: gauge_wall_pressure = 'wall_pressure'
   !> Accepted `&gauge kind=` keywords (stored lower case).
   character(len=*), parameter, public :: gauge_kind_keywords(*) = &
      [character(len=15) :: gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, gauge_wall_pressure]

   !> `&gauge`: a sensor of the fluid at a point, written to gauges.csv (docs/loads.md).
   type, public :: gauge_spec_t
      character(len=name_len) :: name = ''    !< column prefix in gauges.csv (required)
      character(len=name_len) :: kind = ''    !< 'pressure', 'level', 'connected_level', 'velocity' or 'wall_pressure' (required)
      real(rp) :: point(3) = 0.0_rp           !< where it measures, world frame [m] (required)
      !> pressure, velocity: radius of the sphere (disc in 2-D) it averages over; level: half-width of the
      !> column it looks in [m]; 0: resolved to the cell size (pressure, velocity) or half of it (level)
      real(rp) :: radius = 0.0_rp
      !> wall_pressure: the wall, box side or structure whose surface it lies on (its name in loads.csv)
      character(len=name_len) :: wall = ''
   end type gauge_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: gauge_variables(*) = [ &
      variable_info_t('gauge', 'name', 'string', .true.), &
      variable_info_t('gauge', 'kind', 'string', .true.), &
      variable_info_t('gauge', 'point', 'real3', .true.), &
      variable_info_t('gauge', 'radius', 'real', .false.), &
      variable_info_t('gauge', 'wall', 'string', .false.)]

contains

   !> Read one `&gauge ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_gauge_group(spec, ios, message, text)
      type(gauge_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, kind, wall
      real(rp) :: point(3), radius
      namelist /gauge/ name, kind, point, radius, wall

      name = spec%name
      kind = spec%kind
      point = spec%point
      radius = spec%radius
      wall = spec%wall
      read (text, nml=gauge, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('kind', kind, spec%kind, ios, message, fold='lower')
      call take_text('wall', wall, spec%wall, ios, message)
      if (ios /= 0) return
      spec%point = point
      spec%radius = radius
   end subroutine read_gauge_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function gauge_value(gauge, name) result(text)
      type(gauge_spec_t), intent(in) :: gauge
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(gauge%name)
      case ('kind')
         text = quoted(gauge%kind)
      case ('point')
         text = real_list_text(gauge%point)
      case ('radius')
         text = real_text(gauge%radius)
      case ('wall')
         text = quoted(gauge%wall)
      case default
         text = ''
      end select
   end function gauge_value

   !> Gauge g of `gauges`: a unique name, a known kind, a finite point inside the scene box of &grid
   !> (within 1e-9 of a cell), a radius >= 0.
   subroutine validate_gauge(gauges, g, grid, path, status)
      type(gauge_spec_t), intent(in) :: gauges(:)
      integer, intent(in) :: g
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: tolerance
      integer :: k, other

      associate (gauge => gauges(g))
         if (len_trim(gauge%name) == 0) then
            call status%fail(group_context(path, 'gauge', g)//': variable name is required')
            return
         end if
         where = group_context(path, 'gauge', g, name_detail(gauge%name))
         call check_name(where, 'name', gauge%name, status)
         if (.not. status%ok) return
         ! gauges.csv is a file of its own: gauge names need only differ from each other
         do other = 1, g - 1
            if (gauges(other)%name == gauge%name) then
               call status%fail(where//": variable name '"//trim(gauge%name)//"' is already used by the "// &
                                ordinal(other)//' &gauge')
               return
            end if
         end do
         if (all(gauge%kind /= gauge_kind_keywords)) then
            call status%fail(where//': variable kind must be one of '//quoted_list(gauge_kind_keywords)//", got '"// &
                             trim(gauge%kind)//"'")
            return
         end if
         do k = 1, grid%dim
            call check_real(where, 'point('//int_text(k)//')', gauge%point(k), status)
         end do
         call check_real(where, 'radius', gauge%radius, status, at_least=0.0_rp)
         if (.not. status%ok) return
         ! the scene box is axis-aligned in the world frame, whatever the grid's rotation (as for &inlet)
         tolerance = inside_tolerance * grid%cell_size
         do k = 1, grid%dim
            if (gauge%point(k) < grid%origin(k) - tolerance .or. &
                gauge%point(k) > grid%origin(k) + grid%extent(k) + tolerance) then
               call status%fail(where//': variable point('//int_text(k)//') must lie in the scene box of &grid, '// &
                                real_text(grid%origin(k))//' .. '//real_text(grid%origin(k) + grid%extent(k))// &
                                ', got '//real_text(gauge%point(k)))
               return
            end if
         end do
      end associate
   end subroutine validate_gauge
end module gauge_group
