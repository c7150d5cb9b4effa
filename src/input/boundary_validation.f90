!> Checks of the walls and structures that read other groups: `&wall` (plane, condition, motion against
!> the grid and gravity) and `&structure` (shape, condition, motion); `&box_walls` and `&inlet` check
!> themselves (grid_group, inlet_group).
module boundary_validation
   use kinds, only: rp
   use error_status, only: status_t
   use scene_description, only: scene_t, wall_spec_t, structure_spec_t, motion_spec_t, wall_friction, motion_none, &
                                motion_solitary_wave, motion_table
   use wave_validation, only: validate_wave_motion, stray_wave_variable
   use input_text, only: int_text, real_text, quoted_list, group_context
   use shape_geometry, only: shape_t, shape_problem, shape_bounds, box_corners, max_vertices, shape_box, &
                             shape_circle, shape_sphere, shape_cylinder, shape_polygon, shape_extruded_polygon
   use wall_motion, only: wall_motion_t, prescribed_motion, box_excursion
   use input_checks, only: check_real, check_name, is_none, name_detail, inside_tolerance, axis_letter
   use grid_group, only: wall_condition_keywords
   use wall_group, only: wall_group_condition_keywords
   use motion_spec, only: motion_keywords, motion_regular_wave, motion_irregular_wave
   implicit none
   private

   public :: validate_wall, validate_structure

   !> Largest solitary wave height over depth a wall may make (solitary waves break near A/h = 0.78;
   !> Goring's first-order stroke is poor beyond about 0.6).
   real(rp), parameter :: max_wave_ratio = 0.6_rp

contains

   subroutine validate_wall(wall, w, scene, path, status)
      type(wall_spec_t), intent(in) :: wall
      integer, intent(in) :: w
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: k, dim

      dim = scene%grid%dim
      where = group_context(path, 'wall', w, name_detail(wall%name))
      call check_name(where, 'name', wall%name, status)
      do k = 1, dim
         call check_real(where, 'point('//int_text(k)//')', wall%point(k), status)
         call check_real(where, 'normal('//int_text(k)//')', wall%normal(k), status)
         call check_real(where, 'lower('//int_text(k)//')', wall%lower(k), status)
         call check_real(where, 'upper('//int_text(k)//')', wall%upper(k), status)
         ! huge: not given (the component of point)
         call check_real(where, 'moment_point('//int_text(k)//')', wall%moment_point(k), status)
      end do
      if (.not. status%ok) return
      if (norm2(wall%normal(1:dim)) < tiny(1.0_rp)**0.25_rp) then
         call status%fail(where//': variable normal must not be zero: it points from the wall into the fluid')
         return
      end if
      do k = 1, dim
         if (wall%upper(k) < wall%lower(k)) then
            call status%fail(where//': variable upper('//int_text(k)//') must be >= lower('//int_text(k)//') = '// &
                             real_text(wall%lower(k))//', got '//real_text(wall%upper(k)))
         else if (wall%point(k) < wall%lower(k) .or. wall%point(k) > wall%upper(k)) then
            call status%fail(where//': variable point('//int_text(k)//') must lie in the extent of the wall, lower('// &
                             int_text(k)//') .. upper('//int_text(k)//') = '//real_text(wall%lower(k))//' .. '// &
                             real_text(wall%upper(k))//', got '//real_text(wall%point(k)))
         end if
         if (.not. status%ok) return
      end do
      if (all(wall%condition /= wall_group_condition_keywords)) then
         call status%fail(where//': variable condition must be one of '//quoted_list(wall_group_condition_keywords)// &
                          ", got '"//trim(wall%condition)//"'")
      end if
      call check_friction(where, wall%condition, wall%friction, status)
      call validate_motion(wall%motion, where, 'wall', wall%point, wall%point, wall%normal, scene, status)
   end subroutine validate_wall

   !> `&wall motion`, `&structure motion`: a known keyword; its variables given only with it; the solitary
   !> wave's height and depth in range (A/h in (0, max_wave_ratio], gravity not zero), a piston's waves
   !> as wave_validation says, and the direction of either (a wall's `normal`; a structure's
   !> motion_direction, required and not zero); the whole stroke keeps the wall's point (`what` = 'wall',
   !> lower = upper) or the structure's box lower..upper (world, at rest) in the scene box (a piston's waves:
   !> either way). A table is checked against the scene box when it is read (load_motion_tables).
   subroutine validate_motion(spec, where, what, lower, upper, direction, scene, status)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(in) :: where, what
      real(rp), intent(in) :: lower(3), upper(3), direction(3)
      type(scene_t), intent(in) :: scene
      type(status_t), intent(inout) :: status
      character(len=*), parameter :: wave_motions = "the wave motions ('"//motion_solitary_wave//"', '"// &
                                                    motion_regular_wave//"', '"//motion_irregular_wave//"')"
      type(wall_motion_t) :: motion
      real(rp) :: g
      integer :: k, dim
      logical :: waves, stroke
      character(len=:), allocatable :: excursion, variable, owner
      if (.not. status%ok) return
      dim = scene%grid%dim
      if (all(spec%kind /= motion_keywords)) then
         call status%fail(where//': variable motion must be one of '//quoted_list(motion_keywords)//", got '"// &
                          trim(spec%kind)//"'")
         return
      end if
      waves = spec%kind == motion_regular_wave .or. spec%kind == motion_irregular_wave
      ! the motions along a direction: a stroke of a solitary wave or a piston's waves
      stroke = waves .or. spec%kind == motion_solitary_wave
      if (spec%kind /= motion_solitary_wave .and. spec%kind /= motion_regular_wave .and. spec%wave_height /= 0.0_rp) &
         call refuse('wave_height', "motion = '"//motion_solitary_wave//"' or '"//motion_regular_wave//"'")
      if (.not. stroke .and. spec%water_depth /= 0.0_rp) call refuse('water_depth', wave_motions)
      if (.not. stroke .and. any(spec%direction /= 0.0_rp)) call refuse('motion_direction', wave_motions)
      if (spec%kind == motion_none .and. spec%start /= 0.0_rp) call refuse('motion_start', 'a motion')
      call stray_wave_variable(spec, variable, owner)
      if (len(variable) > 0) call refuse(variable, owner)
      if (spec%kind /= motion_table) then
         if (len_trim(spec%file) > 0) call refuse('motion_file', "motion = '"//motion_table//"'")
         if (len_trim(spec%checksum) > 0) call refuse('motion_checksum', "motion = '"//motion_table//"'")
      else if (len_trim(spec%file) == 0) then
         call status%fail(where//": variable motion_file is required with motion = '"//motion_table// &
                          "' (a CSV of t, x, y[, z]: the "//what//"'s displacement)")
      end if
      if (spec%kind == motion_table .and. spec%start /= 0.0_rp) then
         call status%fail(where//": variable motion_start belongs to "//wave_motions// &
                          " (a table gives its own times)")
      end if
      if (.not. status%ok .or. .not. stroke) return
      ! what every wave motion needs: its start, the depth and gravity
      call check_real(where, 'motion_start', spec%start, status, at_least=0.0_rp)
      call check_real(where, 'water_depth', spec%water_depth, status, greater_than=0.0_rp)
      g = norm2(scene%gravity(1:dim))
      if (status%ok .and. .not. g > 0.0_rp) call status%fail(where//": variable motion = '"//trim(spec%kind)// &
                                                             "' needs gravity (&gravity acceleration is zero)")
      if (.not. status%ok) return
      if (waves) then
         call validate_wave_motion(spec, where, g, scene%grid%cell_size, status)
      else
         call check_real(where, 'wave_height', spec%wave_height, status, greater_than=0.0_rp, &
                         at_most=max_wave_ratio * spec%water_depth)
      end if
      if (what == 'structure') then
         do k = 1, dim
            call check_real(where, 'motion_direction('//int_text(k)//')', spec%direction(k), status)
         end do
         if (status%ok .and. .not. norm2(spec%direction(1:dim)) > 0.0_rp) &
            call status%fail(where//": variable motion_direction is required with motion = '"//trim(spec%kind)// &
                             "' (the direction of the stroke, not zero)")
      end if
      if (.not. status%ok) return
      motion = prescribed_motion(spec, direction, scene%gravity, dim)
      ! a solitary stroke is monotonic along its direction: its end is the farthest place; a piston's waves
      ! reach the stroke either way
      excursion = box_excursion(scene%grid, what, lower, upper, motion%stroke() * motion%direction(1:dim))
      if (len(excursion) == 0 .and. motion%oscillates()) &
         excursion = box_excursion(scene%grid, what, lower, upper, -motion%stroke() * motion%direction(1:dim))
      if (len(excursion) > 0) call status%fail(where//": variable motion = '"//trim(spec%kind)//"' drives the "// &
                                               what//' out of the scene box of &grid: '//excursion)

   contains

      subroutine refuse(variable, owner)
         character(len=*), intent(in) :: variable, owner
         if (.not. status%ok) return
         call status%fail(where//': variable '//variable//' belongs to '//owner//", which is not given (motion = '"// &
                          trim(spec%kind)//"')")
      end subroutine refuse
   end subroutine validate_motion

   !> mu >= 0, and given only with condition 'friction' (elsewhere it would be silently unused).
   subroutine check_friction(where, condition, friction, status)
      character(len=*), intent(in) :: where, condition
      real(rp), intent(in) :: friction
      type(status_t), intent(inout) :: status
      if (.not. status%ok) return
      call check_real(where, 'friction', friction, status, at_least=0.0_rp)
      if (status%ok .and. friction > 0.0_rp .and. condition /= wall_friction) &
         call status%fail(where//': variable friction = '//real_text(friction)//" is used only with condition = '"// &
                          wall_friction//"', got condition = '"//trim(condition)//"'")
   end subroutine check_friction

   !> A structure: its name, condition and friction, the shape's parameters (shape_problem), a box by its
   !> corners or by centre and size (not both), the whole shape inside the scene box, and its motion.
   subroutine validate_structure(structure, s, scene, path, status)
      type(structure_spec_t), intent(in) :: structure
      integer, intent(in) :: s
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, problem
      type(shape_t) :: shape
      real(rp) :: lower(3), upper(3), tolerance, top
      integer :: k, dim, v
      logical :: corners

      dim = scene%grid%dim
      where = group_context(path, 'structure', s, name_detail(structure%name))
      call check_name(where, 'name', structure%name, status)
      if (.not. status%ok) return
      if (all(structure%condition /= wall_condition_keywords)) then
         call status%fail(where//': variable condition must be one of '//quoted_list(wall_condition_keywords)// &
                          ", got '"//trim(structure%condition)//"'")
         return
      end if
      call check_friction(where, structure%condition, structure%friction, status)
      shape = structure%shape
      do k = 1, dim
         call check_real(where, 'centre('//int_text(k)//')', shape%centre(k), status)
         call check_real(where, 'size('//int_text(k)//')', shape%size(k), status)
         call check_real(where, 'axis('//int_text(k)//')', shape%axis(k), status)
         call check_real(where, 'rotation_axis('//int_text(k)//')', shape%rotation_axis(k), status)
      end do
      call check_real(where, 'rotation', shape%rotation, status)
      call check_real(where, 'radius', shape%radius, status)
      call check_real(where, 'length', shape%length, status)
      call check_real(where, 'z_range(1)', shape%z_range(1), status)
      call check_real(where, 'z_range(2)', shape%z_range(2), status)
      if (.not. status%ok) return
      do v = 1, max_vertices
         ! the slots hold x, y pairs; 'none' (no_vertex) marks the end of the list
         if (all(is_none(shape%vertices(:, v)))) exit
         do k = 1, 2
            if (is_none(shape%vertices(k, v))) then
               call status%fail(where//': variable vertices has an odd number of values ('//int_text(2 * v - 1)// &
                                '): give x1, y1, x2, y2, ... in pairs')
               return
            end if
            call check_real(where, 'vertices('//int_text(2 * (v - 1) + k)//')', shape%vertices(k, v), status)
         end do
         if (.not. status%ok) return
      end do

      ! a box by its corners: both, and instead of centre and size
      corners = any(structure%lower(1:dim) < huge(1.0_rp)) .or. any(structure%upper(1:dim) < huge(1.0_rp))
      if (corners) then
         if (shape%kind /= shape_box) then
            call status%fail(where//": variables lower and upper give a box's corners, but shape = '"// &
                             trim(shape%kind)//"' (use them with shape = 'box')")
            return
         end if
         if (any(abs(shape%size(1:dim)) > 0.0_rp) .or. any(abs(shape%centre(1:dim)) > 0.0_rp)) then
            call status%fail(where//': variables lower and upper give the box, and so do centre and size: '// &
                             'give one pair only')
            return
         end if
         do k = 1, dim
            call check_real(where, 'lower('//int_text(k)//')', structure%lower(k), status, less_than=huge(1.0_rp))
            call check_real(where, 'upper('//int_text(k)//')', structure%upper(k), status, less_than=huge(1.0_rp))
            if (status%ok .and. .not. structure%upper(k) > structure%lower(k)) &
               call status%fail(where//': variable upper('//int_text(k)//') must be > lower('//int_text(k)//') = '// &
                                real_text(structure%lower(k))//', got '//real_text(structure%upper(k)))
            if (.not. status%ok) return
         end do
         shape = box_corners(shape, structure%lower, structure%upper, dim)
      end if

      problem = shape_problem(shape, dim)
      if (len(problem) > 0) then
         call status%fail(where//': variable '//problem)
         return
      end if
      do k = 1, dim
         ! huge: not given (the shape's centre)
         call check_real(where, 'moment_point('//int_text(k)//')', structure%moment_point(k), status)
      end do
      if (.not. status%ok) return

      ! the scene box is axis-aligned in the world frame, whatever the grid's rotation (as for &gauge)
      call shape_bounds(shape, dim, lower, upper)
      tolerance = inside_tolerance * scene%grid%cell_size
      do k = 1, dim
         top = scene%grid%origin(k) + scene%grid%extent(k)
         if (lower(k) < scene%grid%origin(k) - tolerance .or. upper(k) > top + tolerance) then
            call status%fail(where//': variables '//shape_variables(shape%kind, corners)//' put the structure '// &
                             'outside the scene box of &grid: it spans '//axis_letter(k)//' = '//real_text(lower(k))// &
                             ' .. '//real_text(upper(k))//', the box '//real_text(scene%grid%origin(k))//' .. '//real_text(top))
            return
         end if
      end do
      call validate_motion(structure%motion, where, 'structure', lower, upper, structure%motion%direction, scene, status)
   end subroutine validate_structure

   !> The variables that place a shape of kind `kind`, for messages.
   pure function shape_variables(kind, corners) result(names)
      character(len=*), intent(in) :: kind
      logical, intent(in) :: corners
      character(len=:), allocatable :: names
      select case (kind)
      case (shape_box)
         names = 'centre, size and rotation'
         if (corners) names = 'lower, upper and rotation'
      case (shape_circle, shape_sphere)
         names = 'centre and radius'
      case (shape_cylinder)
         names = 'centre, axis, length and radius'
      case (shape_polygon)
         names = 'vertices'
      case (shape_extruded_polygon)
         names = 'vertices and z_range'
      case default
         names = 'shape'
      end select
   end function shape_variables

end module boundary_validation
