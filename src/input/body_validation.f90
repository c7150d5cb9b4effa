!> Checks of the `&body` groups: material, shape (box, circle/sphere, cylinder, polygon, point file) and its
!> variables, the lattice inside the grid, and that every body makes at least one particle.
module body_validation
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, grid_spec_t, material_spec_t, body_spec_t
   use input_text, only: int_text, real_text, quoted_list, group_context
   use shape_geometry, only: shape_t, shape_problem, shape_bounds, max_vertices, no_vertex, shape_box, shape_circle, &
                             shape_sphere, shape_cylinder, shape_polygon, shape_extruded_polygon
   use body_lattice, only: has_points_file, box_corners_given, body_shape, count_particles, particle_spacing
   use input_checks, only: check_real, check_upper_above_lower, check_name, differs, inside_tolerance, axis_letter
   use material_group, only: find_material
   implicit none
   private

   public :: validate_body, check_body_has_particles

contains

   subroutine validate_body(body, b, materials, grid, path, status)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: b
      type(material_spec_t), intent(in) :: materials(:)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, given
      integer :: k, m
      character(len=name_len) :: declared(size(materials))

      if (len_trim(body%material) == 0) then
         call status%fail(group_context(path, 'body', b)//': variable material is required')
         return
      end if
      where = group_context(path, 'body', b, body_detail(body))
      call check_name(where, 'name', body%name, status)
      if (.not. status%ok) return
      if (find_material(materials, body%material) == 0) then
         do m = 1, size(materials)
            declared(m) = materials(m)%name
         end do
         call status%fail(where//': variable material must name a declared &material ('// &
                          quoted_list(declared)//"), got '"//trim(body%material)//"'")
         return
      end if
      if (body%particles_per_cell < 1) then
         call status%fail(where//': variable particles_per_cell must be >= 1, got '//int_text(body%particles_per_cell))
         return
      end if
      do k = 1, grid%dim
         call check_real(where, 'lower('//int_text(k)//')', body%lower(k), status)
         call check_real(where, 'upper('//int_text(k)//')', body%upper(k), status)
         call check_real(where, 'velocity('//int_text(k)//')', body%velocity(k), status)
      end do
      do k = 1, 3
         call check_real(where, 'angular_velocity('//int_text(k)//')', body%angular_velocity(k), status)
      end do
      if (status%ok .and. grid%dim == 2 .and. any(body%angular_velocity(1:2) /= 0.0_rp)) then
         call status%fail(where//': variable angular_velocity turns a 2-D body about z only: give 0.0, 0.0, '// &
                          'omega_z, got '//real_text(body%angular_velocity(1))//', '//real_text(body%angular_velocity(2)))
         return
      end if
      call check_real(where, 'free_surface_level', body%free_surface_level, status)
      call check_shape_reals(where, body%shape, status)
      if (.not. status%ok) return

      given = given_shape_variables(body, grid%dim)
      if (has_points_file(body)) then
         ! the file gives the particles: a shape as well would be ignored
         if (len(given) > 0) call status%fail(where//': variable points_file gives the particles of the body; '// &
                                              'remove the shape variables ('//given//')')
         return
      end if
      if (len_trim(body%points_checksum) > 0) then
         call status%fail(where//': variable points_checksum belongs to points_file, which is not given')
         return
      end if
      if (body%shape%kind == shape_box) then
         call validate_box(body, where, grid, status)
      else
         call validate_shape(body, where, grid, status)
      end if
   end subroutine validate_body

   !> A box: by lower/upper (the usual way) or by centre/size, either turned by rotation about its centre.
   subroutine validate_box(body, where, grid, status)
      type(body_spec_t), intent(in) :: body
      character(len=*), intent(in) :: where
      type(grid_spec_t), intent(in) :: grid
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: lower_k, upper_k, unused
      real(rp) :: grid_lower, grid_upper, tolerance, spacing
      integer :: k

      unused = not_used(body, grid%dim, [character(len=8) :: 'radius', 'axis', 'length', 'vertices', 'z_range'])
      if (len(unused) > 0) then
         call status%fail(where//": variable "//unused//" is not used by shape 'box'")
         return
      end if
      if (box_corners_given(body, grid%dim)) then
         if (any(differs(body%shape%size(1:grid%dim), 0.0_rp)) .or. any(differs(body%shape%centre(1:grid%dim), 0.0_rp))) then
            call status%fail(where//': variables lower/upper and centre/size both give the box; give one pair')
            return
         end if
      else if (.not. any(differs(body%shape%size(1:grid%dim), 0.0_rp))) then
         call status%fail(where//': variables lower and upper are required (or centre and size) for a box')
         return
      end if
      if (abs(body%shape%rotation) > 0.0_rp .or. .not. box_corners_given(body, grid%dim)) then
         ! a turned box, or one given by centre/size: as the other shapes
         if (box_corners_given(body, grid%dim)) then
            call check_upper_above_lower(where, body%lower, body%upper, grid%dim, status)
            if (.not. status%ok) return
         end if
         call validate_shape(body, where, grid, status)
         return
      end if

      tolerance = inside_tolerance * grid%cell_size
      spacing = grid%cell_size / real(body%particles_per_cell, rp)
      do k = 1, grid%dim
         lower_k = 'lower('//int_text(k)//')'
         upper_k = 'upper('//int_text(k)//')'
         grid_lower = grid%origin(k)
         grid_upper = grid%origin(k) + grid%extent(k)
         if (.not. (body%upper(k) > body%lower(k))) then
            call status%fail(where//': variable '//upper_k//' must be > '//lower_k//' = '//real_text(body%lower(k))// &
                             ', got '//real_text(body%upper(k)))
         else if (body%lower(k) < grid_lower - tolerance) then
            call status%fail(where//': variable '//lower_k//' must be >= '//real_text(grid_lower)// &
                             ' (the lower edge of the grid along '//axis_letter(k)//'), got '//real_text(body%lower(k)))
         else if (body%upper(k) > grid_upper + tolerance) then
            call status%fail(where//': variable '//upper_k//' must be <= '//real_text(grid_upper)// &
                             ' (the upper edge of the grid along '//axis_letter(k)//'), got '//real_text(body%upper(k)))
         else if (nint((body%upper(k) - body%lower(k)) / spacing, i8) == 0_i8) then
            call status%fail(where//': variable '//upper_k//' gives 0 particles along '//axis_letter(k)// &
                             ': the body spans '//real_text(body%lower(k))//' .. '//real_text(body%upper(k))// &
                             ', less than half the particle spacing cell_size/particles_per_cell = '//real_text(spacing))
         end if
         if (.not. status%ok) return
      end do
   end subroutine validate_box

   !> A shape other than an unrotated box given by lower/upper: its keyword and parameters
   !> (shape_problem), no variable of another shape, and inside the scene box.
   subroutine validate_shape(body, where, grid, status)
      type(body_spec_t), intent(in) :: body
      character(len=*), intent(in) :: where
      type(grid_spec_t), intent(in) :: grid
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: problem, unused
      real(rp) :: lo(3), hi(3), tolerance
      integer :: k
      type(shape_t) :: shape

      shape = body_shape(body, grid%dim)
      problem = shape_problem(shape, grid%dim)
      if (len(problem) > 0) then
         call status%fail(where//': variable '//problem)
         return
      end if
      select case (shape%kind)
      case (shape_circle, shape_sphere)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'size', 'rotation', &
                                            'rotation_axis', 'axis', 'length', 'vertices', 'z_range'])
      case (shape_cylinder)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'size', 'rotation', &
                                            'rotation_axis', 'vertices', 'z_range'])
      case (shape_polygon)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'centre', 'size', 'rotation', &
                                            'rotation_axis', 'radius', 'axis', 'length', 'z_range'])
      case (shape_extruded_polygon)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'centre', 'size', 'rotation', &
                                            'rotation_axis', 'radius', 'axis', 'length'])
      case default
         unused = ''
      end select
      if (len(unused) > 0) then
         call status%fail(where//': variable '//unused//" is not used by shape '"//trim(shape%kind)//"'")
         return
      end if
      call shape_bounds(shape, grid%dim, lo, hi)
      tolerance = inside_tolerance * grid%cell_size
      do k = 1, grid%dim
         if (lo(k) < grid%origin(k) - tolerance .or. hi(k) > grid%origin(k) + grid%extent(k) + tolerance) then
            call status%fail(where//": the shape '"//trim(shape%kind)//"' reaches outside the scene box of &grid "// &
                             'along '//axis_letter(k)//': it spans '//real_text(lo(k))//' .. '//real_text(hi(k))// &
                             ', the box '//real_text(grid%origin(k))//' .. '//real_text(grid%origin(k) + grid%extent(k)))
            return
         end if
      end do
   end subroutine validate_shape

   !> A body of a shape must hold at least one lattice point (docs/input.md: a lattice cell counts if its
   !> centre is inside).
   subroutine check_body_has_particles(scene, b, path, status)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: b
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      real(rp) :: n
      logical :: exact
      associate (body => scene%bodies(b))
         if (has_points_file(body)) return
         if (body%shape%kind == shape_box .and. box_corners_given(body, scene%grid%dim) .and. &
             .not. abs(body%shape%rotation) > 0.0_rp) return     ! validate_box counted per axis
         call count_particles(scene, b, n, exact)
         if (n < 1.0_rp) then
            call status%fail(group_context(path, 'body', b, body_detail(body))//": the shape '"// &
                             trim(body%shape%kind)//"' holds no particle: no point of the particle lattice "// &
                             '(spacing cell_size/particles_per_cell = '//real_text(particle_spacing(body, scene%grid))// &
                             ') lies inside it; make it larger or raise particles_per_cell')
         end if
      end associate
   end subroutine check_body_has_particles

   !> The shape variables a body gives (differ from their defaults), as "radius, vertices"; lower/upper as
   !> one pair.
   function given_shape_variables(body, dim) result(names)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      character(len=:), allocatable :: names
      names = not_used(body, dim, [character(len=13) :: 'shape', 'lower', 'upper', 'centre', 'size', 'rotation', &
                                   'rotation_axis', 'radius', 'axis', 'length', 'vertices', 'z_range'])
   end function given_shape_variables

   !> Those of the shape variables `names` that the body gives (differ from their defaults), comma-separated.
   function not_used(body, dim, names) result(list)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      character(len=*), intent(in) :: names(:)
      character(len=:), allocatable :: list
      type(shape_t) :: default
      logical :: given
      integer :: i
      list = ''
      do i = 1, size(names)
         select case (trim(names(i)))
         case ('shape')
            given = body%shape%kind /= default%kind
         case ('lower')
            given = any(differs(body%lower(1:dim), 0.0_rp))
         case ('upper')
            given = any(differs(body%upper(1:dim), 0.0_rp))
         case ('centre')
            given = any(differs(body%shape%centre(1:dim), default%centre(1:dim)))
         case ('size')
            given = any(differs(body%shape%size(1:dim), default%size(1:dim)))
         case ('rotation')
            given = differs(body%shape%rotation, default%rotation)
         case ('rotation_axis')
            given = any(differs(body%shape%rotation_axis, default%rotation_axis))
         case ('radius')
            given = differs(body%shape%radius, default%radius)
         case ('axis')
            given = any(differs(body%shape%axis, default%axis))
         case ('length')
            given = differs(body%shape%length, default%length)
         case ('vertices')
            given = any(differs(body%shape%vertices, no_vertex))
         case ('z_range')
            given = any(differs(body%shape%z_range, default%z_range))
         case default
            given = .false.
         end select
         if (.not. given) cycle
         if (len(list) > 0) list = list//', '
         list = list//trim(names(i))
      end do
   end function not_used

   !> Every real of the shape is finite; vertices come in x, y pairs.
   subroutine check_shape_reals(where, shape, status)
      character(len=*), intent(in) :: where
      type(shape_t), intent(in) :: shape
      type(status_t), intent(inout) :: status
      integer :: k, values
      do k = 1, 3
         call check_real(where, 'centre('//int_text(k)//')', shape%centre(k), status)
         call check_real(where, 'size('//int_text(k)//')', shape%size(k), status, at_least=0.0_rp)
         call check_real(where, 'rotation_axis('//int_text(k)//')', shape%rotation_axis(k), status)
         call check_real(where, 'axis('//int_text(k)//')', shape%axis(k), status)
      end do
      call check_real(where, 'rotation', shape%rotation, status)
      call check_real(where, 'radius', shape%radius, status, at_least=0.0_rp)
      call check_real(where, 'length', shape%length, status, at_least=0.0_rp)
      call check_real(where, 'z_range(1)', shape%z_range(1), status)
      call check_real(where, 'z_range(2)', shape%z_range(2), status)
      if (.not. status%ok) return
      values = 0
      do k = 1, 2 * max_vertices
         associate (v => shape%vertices(modulo(k - 1, 2) + 1, (k - 1) / 2 + 1))
            call check_real(where, 'vertices('//int_text(k)//')', v, status)
            if (.not. status%ok) return
            if (v < no_vertex) values = k
         end associate
      end do
      if (modulo(values, 2) /= 0) then
         call status%fail(where//': variable vertices must list x, y pairs (x1, y1, x2, y2, ...), got '// &
                          int_text(values)//' values')
      end if
   end subroutine check_shape_reals

   !> "name 'log', material 'wood'" (the name when given) for a body's group context.
   pure function body_detail(body) result(detail)
      type(body_spec_t), intent(in) :: body
      character(len=:), allocatable :: detail
      detail = "material '"//trim(body%material)//"'"
      if (len_trim(body%name) > 0) detail = "name '"//trim(body%name)//"', "//detail
   end function body_detail
end module body_validation
