!> The `&panel` group (docs/input.md): a part of a wall's or structure's surface, or a box of the scene,
!> whose load is written to panels.csv (docs/loads.md, "Panels and load cells"). Everything about its
!> variables is here: their type and defaults (panel_spec_t), the kinds a panel may be, the rows the
!> reader knows them by (panel_variables), the namelist read (read_panel_group), the text scene.nml records
!> (panel_value) and the checks of its own values (validate_panel). What needs other groups (the wall it
!> names) is checked in sensor_validation; whether it lies on the wall's surface, by the solver (the
!> surface's place is known there).
module panel_group
   use kinds, only: rp, name_len
   use error_status, only: status_t
   use input_text, only: int_text, real_text, real_list_text, quoted, quoted_list, group_context, ordinal
   use input_checks, only: check_real, check_name, name_detail, inside_tolerance
   use scene_variables, only: variable_info_t, text_len, take_text
   use grid_group, only: grid_spec_t
   implicit none
   private

   public :: read_panel_group, panel_value, validate_panel

   !> Panel kinds (`&panel kind=`).
   !> a rectangle (2-D: a segment) on the surface of one wall or structure: force and mean pressure
   character(len=*), parameter, public :: panel_surface = 'surface'
   !> a box of the scene: the force on every constrained node in it (of one wall, or of all)
   character(len=*), parameter, public :: panel_load_cell = 'load_cell'
   character(len=*), parameter, public :: panel_kind_keywords(*) = [character(len=9) :: panel_surface, panel_load_cell]

   !> `&panel`: a part of a surface, or a box, whose load panels.csv gives (docs/loads.md).
   type, public :: panel_spec_t
      character(len=name_len) :: name = ''            !< column prefix in panels.csv (required)
      character(len=name_len) :: kind = panel_surface !< 'surface' or 'load_cell'
      !> the wall, box side or structure it lies on (its name in loads.csv); a load cell: '' = every one
      character(len=name_len) :: wall = ''
      !> corners of its bounding box, world frame [m] (required); a surface panel is the part of the surface
      !> inside it (a flat face: a box of zero thickness across it), a load cell the box itself
      real(rp) :: lower(3) = 0.0_rp, upper(3) = 0.0_rp
   end type panel_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: panel_variables(*) = [ &
      variable_info_t('panel', 'name', 'string', .true.), &
      variable_info_t('panel', 'kind', 'string', .false.), &
      variable_info_t('panel', 'wall', 'string', .false.), &
      variable_info_t('panel', 'lower', 'real3', .true.), &
      variable_info_t('panel', 'upper', 'real3', .true.)]

contains

   !> Read one `&panel ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_panel_group(spec, ios, message, text)
      type(panel_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, kind, wall
      real(rp) :: lower(3), upper(3)
      namelist /panel/ name, kind, wall, lower, upper

      name = spec%name
      kind = spec%kind
      wall = spec%wall
      lower = spec%lower
      upper = spec%upper
      read (text, nml=panel, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('kind', kind, spec%kind, ios, message, fold='lower')
      call take_text('wall', wall, spec%wall, ios, message)
      if (ios /= 0) return
      spec%lower = lower
      spec%upper = upper
   end subroutine read_panel_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function panel_value(panel, name) result(text)
      type(panel_spec_t), intent(in) :: panel
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(panel%name)
      case ('kind')
         text = quoted(panel%kind)
      case ('wall')
         text = quoted(panel%wall)
      case ('lower')
         text = real_list_text(panel%lower)
      case ('upper')
         text = real_list_text(panel%upper)
      case default
         text = ''
      end select
   end function panel_value

   !> Panel p of `panels`: a unique name, a known kind, finite corners (a surface panel's inside the scene box
   !> of &grid, within 1e-9 of a cell), lower <= upper, and an area: a surface panel spans dim - 1 axes at least (its face's
   !> tangents), a load cell all dim.
   subroutine validate_panel(panels, p, grid, path, status)
      type(panel_spec_t), intent(in) :: panels(:)
      integer, intent(in) :: p
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: tolerance
      integer :: k, other, spanned

      associate (panel => panels(p))
         if (len_trim(panel%name) == 0) then
            call status%fail(group_context(path, 'panel', p)//': variable name is required')
            return
         end if
         where = group_context(path, 'panel', p, name_detail(panel%name))
         call check_name(where, 'name', panel%name, status)
         if (.not. status%ok) return
         ! panels.csv is a file of its own: panel names need only differ from each other
         do other = 1, p - 1
            if (panels(other)%name == panel%name) then
               call status%fail(where//": variable name '"//trim(panel%name)//"' is already used by the "// &
                                ordinal(other)//' &panel')
               return
            end if
         end do
         if (all(panel%kind /= panel_kind_keywords)) then
            call status%fail(where//': variable kind must be one of '//quoted_list(panel_kind_keywords)//", got '"// &
                             trim(panel%kind)//"'")
            return
         end if
         do k = 1, grid%dim
            call check_real(where, 'lower('//int_text(k)//')', panel%lower(k), status)
            call check_real(where, 'upper('//int_text(k)//')', panel%upper(k), status)
         end do
         if (.not. status%ok) return
         tolerance = inside_tolerance * grid%cell_size
         spanned = 0
         do k = 1, grid%dim
            if (panel%upper(k) < panel%lower(k)) then
               call status%fail(where//': variable upper('//int_text(k)//') must be >= lower('//int_text(k)//') = '// &
                                real_text(panel%lower(k))//', got '//real_text(panel%upper(k)))
               return
            end if
            ! a load cell may reach past the scene box: it collects the constrained nodes inside it, some of
            ! which lie behind the box walls
            if (panel%kind /= panel_load_cell .and. (panel%lower(k) < grid%origin(k) - tolerance .or. &
                panel%upper(k) > grid%origin(k) + grid%extent(k) + tolerance)) then
               call status%fail(where//': variables lower('//int_text(k)//') .. upper('//int_text(k)// &
                                ') must lie in the scene box of &grid, '//real_text(grid%origin(k))//' .. '// &
                                real_text(grid%origin(k) + grid%extent(k))//', got '//real_text(panel%lower(k))// &
                                ' .. '//real_text(panel%upper(k)))
               return
            end if
            if (panel%upper(k) > panel%lower(k)) spanned = spanned + 1
         end do
         if (panel%kind == panel_load_cell .and. spanned < grid%dim) then
            call status%fail(where//': variables lower, upper must span a box of positive volume (upper > lower '// &
                             'along every axis) for a load_cell')
         else if (spanned < grid%dim - 1) then
            call status%fail(where//': variables lower, upper must span the panel''s face (upper > lower along '// &
                             merge('1 axis', '2 axes', grid%dim == 2)//'): the panel has zero area')
         end if
      end associate
   end subroutine validate_panel
end module panel_group
