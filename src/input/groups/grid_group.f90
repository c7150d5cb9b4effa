!> The `&grid` and `&box_walls` groups (docs/input.md): the background grid (dimension, cell size, scene
!> box, rotation, shape function) and the conditions of the scene box's sides, both held by grid_spec_t.
!> Here: the type and defaults of their variables, the wall condition keywords, the reader's rows
!> (grid_variables, box_walls_variables), the namelist reads and the scene.nml texts (grid_value,
!> box_walls_value), the names of the box sides (side_name) and the checks of their values
!> (validate_grid, validate_box_walls).
module grid_group
   use kinds, only: rp, name_len
   use input_text, only: int_text, real_text, real_list_text, quoted, quoted_list, group_context
   use scene_variables, only: variable_info_t, text_len, take_text
   use error_status, only: status_t
   use input_checks, only: check_real, check_name, axis_letter
   implicit none
   private

   public :: validate_grid, validate_box_walls, side_name, read_grid_group, grid_value, read_box_walls_group, &
             box_walls_value, critical_courant_number

   !> Wall condition keywords of the box sides (`&box_walls`).
   character(len=*), parameter, public :: wall_none = 'none'
   character(len=*), parameter, public :: wall_slip = 'slip'      ! [Y17] eq. 14, unilateral, frictionless
   character(len=*), parameter, public :: wall_no_slip = 'no_slip'
   !> Unilateral with Coulomb friction (`&wall`, `&box_walls`, `&structure` with `friction` = mu).
   character(len=*), parameter, public :: wall_friction = 'friction'

   !> Accepted `&grid shape_function=` keywords (stored lower case; docs/theory.md section 1.1).
   character(len=*), parameter, public :: shape_function_keywords(*) = [character(len=8) :: 'linear', 'bspline2']
   !> Accepted `&box_walls` keywords (stored lower case).
   character(len=*), parameter, public :: wall_keywords(*) = [character(len=8) :: wall_none, wall_slip, wall_no_slip, &
                                                              wall_friction]
   !> Accepted `&structure condition=` keywords (stored lower case).
   character(len=*), parameter, public :: wall_condition_keywords(*) = [character(len=8) :: wall_slip, wall_no_slip, &
                                                                        wall_friction]
   !> `&grid` and `&box_walls`: the scene box (world frame), the grid that covers it, and the box's walls.
   !> The grid may be rotated against the world by `rotation` about z, pivoting on `origin` (the paper's
   !> theta_g); it is axis-aligned in its own frame and covers the rotated box with whole cells.
   type, public :: grid_spec_t
      integer :: dim = 2                      !< 2 (plane strain) or 3
      real(rp) :: cell_size = 0.0_rp          !< cell edge h [m]
      real(rp) :: origin(3) = 0.0_rp          !< lower corner of the scene box (world frame) [m]
      real(rp) :: extent(3) = 0.0_rp          !< edge lengths of the scene box [m], whole multiples of cell_size
      real(rp) :: rotation = 0.0_rp           !< grid rotation theta_g, counter-clockwise about z [degrees]
      !> 'linear' (multilinear, 2**dim nodes per particle) or 'bspline2' (quadratic B-spline, 3**dim nodes)
      character(len=name_len) :: shape_function = 'linear'
      integer :: ncells(3) = 1                !< derived: extent / cell_size (1 on unused axes)
      !> wall condition per side: (1, k) lower side, (2, k) upper side of axis k
      character(len=name_len) :: wall(2, 3) = wall_none
      !> name of each side's wall in loads.csv (`&box_walls x_min_name` ...); resolved default 'x_min' ...
      !> for a side that is a wall, '' for an open side
      character(len=name_len) :: wall_name(2, 3) = ''
      real(rp) :: wall_friction = 0.0_rp      !< Coulomb mu of the sides whose condition is 'friction'
   end type grid_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: grid_variables(*) = [ &
      variable_info_t('grid', 'dim', 'integer', .false.), &
      variable_info_t('grid', 'cell_size', 'real', .true.), &
      variable_info_t('grid', 'origin', 'real3', .false.), &
      variable_info_t('grid', 'extent', 'real3', .true.), &
      variable_info_t('grid', 'rotation', 'real', .false.), &
      variable_info_t('grid', 'shape_function', 'string', .false.)]

   !> The variables of &box_walls (a side's condition and name, the friction of the friction sides).
   type(variable_info_t), parameter, public :: box_walls_variables(*) = [ &
      variable_info_t('box_walls', 'x_min', 'string', .false.), &
      variable_info_t('box_walls', 'x_max', 'string', .false.), &
      variable_info_t('box_walls', 'y_min', 'string', .false.), &
      variable_info_t('box_walls', 'y_max', 'string', .false.), &
      variable_info_t('box_walls', 'z_min', 'string', .false.), &
      variable_info_t('box_walls', 'z_max', 'string', .false.), &
      variable_info_t('box_walls', 'x_min_name', 'string', .false.), &
      variable_info_t('box_walls', 'x_max_name', 'string', .false.), &
      variable_info_t('box_walls', 'y_min_name', 'string', .false.), &
      variable_info_t('box_walls', 'y_max_name', 'string', .false.), &
      variable_info_t('box_walls', 'z_min_name', 'string', .false.), &
      variable_info_t('box_walls', 'z_max_name', 'string', .false.), &
      variable_info_t('box_walls', 'friction', 'real', .false.)]

   !> Relative tolerance of "extent is a whole multiple of cell_size".
   real(rp), parameter :: multiple_tolerance = 1.0e-9_rp
   !> Largest number of cells along one axis and in the whole grid (default integers index them).
   real(rp), parameter :: max_cells = real(huge(1), rp)
contains

   !> Read one `&grid ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_grid_group(spec, ios, message, text)
      type(grid_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      integer :: dim
      real(rp) :: cell_size, origin(3), extent(3), rotation
      character(len=text_len) :: shape_function
      namelist /grid/ dim, cell_size, origin, extent, rotation, shape_function

      dim = spec%dim
      cell_size = spec%cell_size
      origin = spec%origin
      extent = spec%extent
      rotation = spec%rotation
      shape_function = spec%shape_function
      read (text, nml=grid, iostat=ios, iomsg=message)
      if (ios /= 0) return
      spec%dim = dim
      spec%cell_size = cell_size
      spec%origin = origin
      spec%extent = extent
      spec%rotation = rotation
      call take_text('shape_function', shape_function, spec%shape_function, ios, message, fold='lower')
   end subroutine read_grid_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function grid_value(grid, name) result(text)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('dim')
         text = int_text(grid%dim)
      case ('cell_size')
         text = real_text(grid%cell_size)
      case ('origin')
         text = real_list_text(grid%origin)
      case ('extent')
         text = real_list_text(grid%extent)
      case ('rotation')
         text = real_text(grid%rotation)
      case ('shape_function')
         text = quoted(grid%shape_function)
      case default
         text = ''
      end select
   end function grid_value

   !> Read one `&box_walls ... /` (text) over the sides of `spec`.
   subroutine read_box_walls_group(spec, ios, message, text)
      type(grid_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: x_min, x_max, y_min, y_max, z_min, z_max
      character(len=text_len) :: x_min_name, x_max_name, y_min_name, y_max_name, z_min_name, z_max_name
      character(len=text_len) :: sides(2, 3), names(2, 3)
      character(len=*), parameter :: side_variables(2, 3) = reshape([character(len=5) :: 'x_min', 'x_max', &
                                                                     'y_min', 'y_max', 'z_min', 'z_max'], [2, 3])
      real(rp) :: friction
      integer :: s, d
      namelist /box_walls/ x_min, x_max, y_min, y_max, z_min, z_max, &
         x_min_name, x_max_name, y_min_name, y_max_name, z_min_name, z_max_name, friction

      x_min = spec%wall(1, 1)
      x_max = spec%wall(2, 1)
      y_min = spec%wall(1, 2)
      y_max = spec%wall(2, 2)
      z_min = spec%wall(1, 3)
      z_max = spec%wall(2, 3)
      x_min_name = spec%wall_name(1, 1)
      x_max_name = spec%wall_name(2, 1)
      y_min_name = spec%wall_name(1, 2)
      y_max_name = spec%wall_name(2, 2)
      z_min_name = spec%wall_name(1, 3)
      z_max_name = spec%wall_name(2, 3)
      friction = spec%wall_friction
      read (text, nml=box_walls, iostat=ios, iomsg=message)
      sides = reshape([character(len=text_len) :: x_min, x_max, y_min, y_max, z_min, z_max], [2, 3])
      names = reshape([character(len=text_len) :: x_min_name, x_max_name, y_min_name, y_max_name, z_min_name, &
                       z_max_name], [2, 3])
      do d = 1, 3
         do s = 1, 2
            call take_text(side_variables(s, d), sides(s, d), spec%wall(s, d), ios, message, fold='lower')
         end do
      end do
      do d = 1, 3
         do s = 1, 2
            call take_text(side_variables(s, d)//'_name', names(s, d), spec%wall_name(s, d), ios, message)
         end do
      end do
      if (ios == 0) spec%wall_friction = friction
   end subroutine read_box_walls_group

   !> The value of &box_walls variable `name` as scene.nml writes it.
   !> `x_min` ... `z_max`: the side's condition; `x_min_name` ...: its name; `friction`: the sides' mu.
   function box_walls_value(grid, name) result(text)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      integer :: axis, side
      text = ''
      if (name == 'friction') then
         text = real_text(grid%wall_friction)
         return
      end if
      if (len(name) < 5) return
      axis = index('xyz', name(1:1))
      side = 0
      if (name(2:5) == '_min') side = 1
      if (name(2:5) == '_max') side = 2
      if (axis == 0 .or. side == 0) return
      if (name(6:) == '') then
         text = quoted(grid%wall(side, axis))
      else if (name(6:) == '_name') then
         text = quoted(grid%wall_name(side, axis))
      end if
   end function box_walls_value

   subroutine validate_grid(grid, path, status)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: cells, total_cells
      integer :: k

      where = group_context(path, 'grid', 0)
      if (grid%dim /= 2 .and. grid%dim /= 3) then
         call status%fail(where//': variable dim must be 2 or 3, got '//int_text(grid%dim))
         return
      end if
      call check_real(where, 'cell_size', grid%cell_size, status, greater_than=0.0_rp)
      do k = 1, grid%dim
         call check_real(where, 'origin('//int_text(k)//')', grid%origin(k), status)
      end do
      do k = 1, grid%dim
         call check_real(where, 'extent('//int_text(k)//')', grid%extent(k), status, greater_than=0.0_rp)
      end do
      call check_real(where, 'rotation', grid%rotation, status, at_least=-360.0_rp, at_most=360.0_rp)
      if (all(grid%shape_function /= shape_function_keywords)) then
         call status%fail(where//': variable shape_function must be one of '//quoted_list(shape_function_keywords)// &
                          ", got '"//trim(grid%shape_function)//"'")
      end if
      if (.not. status%ok) return

      total_cells = 1.0_rp
      do k = 1, grid%dim
         cells = grid%extent(k) / grid%cell_size
         if (cells > max_cells) then
            call status%fail(where//': variable extent('//int_text(k)//') gives '//real_text(cells)// &
                             ' cells of size cell_size = '//real_text(grid%cell_size)//', more than '// &
                             int_text(huge(1)))
            return
         end if
         if (abs(real(nint(cells), rp) * grid%cell_size - grid%extent(k)) > multiple_tolerance * grid%extent(k)) then
            call status%fail(where//': variable extent('//int_text(k)//') must be a whole multiple of cell_size = '// &
                             real_text(grid%cell_size)//', got '//real_text(grid%extent(k)))
            return
         end if
         total_cells = total_cells * real(nint(cells), rp)
      end do
      if (total_cells > max_cells) then
         call status%fail(where//': variables extent and cell_size give '//real_text(total_cells)// &
                          ' cells, more than '//int_text(huge(1)))
      end if
   end subroutine validate_grid

   !> `&box_walls`: each side's condition keyword (open in 2-D along z), the Coulomb coefficient of the
   !> friction sides, and the names of the sides that are walls.
   subroutine validate_box_walls(grid, path, status)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, variable
      integer :: k, side

      where = group_context(path, 'box_walls', 0)
      do k = 1, 3
         do side = 1, 2
            variable = axis_letter(k)//merge('_min', '_max', side == 1)
            if (all(grid%wall(side, k) /= wall_keywords)) then
               call status%fail(where//': variable '//variable//' must be one of '//quoted_list(wall_keywords)// &
                                ", got '"//trim(grid%wall(side, k))//"'")
               return
            end if
            if (k > grid%dim .and. grid%wall(side, k) /= wall_none) then
               call status%fail(where//': variable '//variable//" must be '"//wall_none//"' in 2-D (dim = 2), got '"// &
                                trim(grid%wall(side, k))//"'")
               return
            end if
         end do
      end do
      call check_real(where, 'friction', grid%wall_friction, status, at_least=0.0_rp)
      if (status%ok .and. grid%wall_friction > 0.0_rp .and. all(grid%wall /= wall_friction)) &
         call status%fail(where//': variable friction is the Coulomb coefficient of the sides whose condition is '''// &
                          wall_friction//"', and no side is: give a side 'friction' or leave friction out")
      if (.not. status%ok) return
      ! a name labels the loads of a wall: an open side has none
      do k = 1, 3
         do side = 1, 2
            variable = side_name(side, k)
            if (len_trim(grid%wall_name(side, k)) == 0) cycle
            if (grid%wall(side, k) == wall_none) then
               call status%fail(where//': variable '//variable//"_name names side "//variable//", which is not a wall ("// &
                                variable//" = '"//wall_none//"')")
               return
            end if
            call check_name(where, variable//'_name', grid%wall_name(side, k), status)
            if (.not. status%ok) return
         end do
      end do
   end subroutine validate_box_walls

   !> Name of a side of the scene box, and its `&box_walls` variable: `x_min` (side 1, axis 1) ... `z_max`.
   pure function side_name(side, axis) result(name)
      integer, intent(in) :: side, axis
      character(len=5) :: name
      name = axis_letter(axis)//merge('_min', '_max', side == 1)
   end function side_name

   !> The CFL number of the automatic step dt = cfl h / (sqrt(dim) c) at the critical step of the grid's
   !> shape functions (docs/theory.md section 5.1, scripts/critical_step.py) [D]: dt_crit = h / c for
   !> multilinear functions in every dimension, 1.54 h / c for quadratic B-splines (the smallest over the
   !> quadratures), so sqrt(dim) and 1.54 sqrt(dim).
   pure real(rp) function critical_courant_number(grid) result(cfl)
      type(grid_spec_t), intent(in) :: grid
      real(rp), parameter :: bspline2_critical_step = 1.54_rp   ! [h / c]
      cfl = sqrt(real(grid%dim, rp))
      if (grid%shape_function == 'bspline2') cfl = bspline2_critical_step * cfl
   end function critical_courant_number
end module grid_group
