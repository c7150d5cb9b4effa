!> The `&body` group (docs/input.md): a solid shape of one material filled with particles, or the points
!> of a file. Here: the type and defaults of its variables (body_spec_t), the reader's rows
!> (body_variables), the namelist read and the scene.nml text (body_value); its shape's variables are
!> shape_input's. Its checks stay with the scene's validation (body_validation).
module body_group
   use kinds, only: rp, name_len, path_len
   use shape_geometry, only: shape_t, max_vertices
   use input_text, only: int_text, real_text, real_list_text, quoted, logical_text
   use scene_variables, only: variable_info_t, text_len, take_text
   use shape_input, only: shape_to_locals, locals_to_shape, shape_value
   implicit none
   private

   public :: read_body_group, body_value

   !> `&body`: a solid shape of one material filled with particles (docs/input.md): a box (`lower`/`upper`,
   !> or `centre`/`size` in `shape`), a circle, polygon, sphere, cylinder or extruded polygon (`shape`), or
   !> the particles of a file of points (`points_file`). Every value is kept as the scene gives it (the
   !> scene record writes it back); body_lattice derives the lattice and bounds.
   type, public :: body_spec_t
      character(len=name_len) :: name = ''    !< name in bodies.csv; resolved default 'body_<k>'
      character(len=name_len) :: material = ''
      integer :: material_index = 0           !< derived: position in scene%materials
      real(rp) :: lower(3) = 0.0_rp           !< box: lower corner [m] (lower = upper: not given)
      real(rp) :: upper(3) = 0.0_rp           !< box: upper corner [m]
      !> shape%kind and, except lower/upper, the shape's variables as given (shape_geometry)
      type(shape_t) :: shape
      !> file of points (CSV or HDF5) the body's particles are read from; resolved to an absolute path
      character(len=path_len) :: points_file = ''
      !> checksum of the points read from points_file (16 hex digits); given: must match the file
      character(len=16) :: points_checksum = ''
      integer :: particles_per_cell = 2       !< particles per cell per direction
      real(rp) :: velocity(3) = 0.0_rp        !< initial velocity [m/s]
      !> initial angular velocity [rad/s] about the centre of the body's bounding box (2-D: component 3)
      real(rp) :: angular_velocity(3) = 0.0_rp
      logical :: hydrostatic = .false.        !< start from the hydrostatic stress of a fluid at rest
      real(rp) :: free_surface_level = 0.0_rp !< height of the free surface along -gravity [m]
   end type body_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: body_variables(*) = [ &
      variable_info_t('body', 'name', 'string', .false.), &
      variable_info_t('body', 'material', 'string', .true.), &
      variable_info_t('body', 'shape', 'string', .false.), &
      variable_info_t('body', 'lower', 'real3', .false.), &
      variable_info_t('body', 'upper', 'real3', .false.), &
      variable_info_t('body', 'centre', 'real3', .false.), &
      variable_info_t('body', 'size', 'real3', .false.), &
      variable_info_t('body', 'rotation', 'real', .false.), &
      variable_info_t('body', 'rotation_axis', 'real3', .false.), &
      variable_info_t('body', 'radius', 'real', .false.), &
      variable_info_t('body', 'axis', 'real3', .false.), &
      variable_info_t('body', 'length', 'real', .false.), &
      variable_info_t('body', 'vertices', 'reals', .false.), &
      variable_info_t('body', 'z_range', 'reals', .false.), &
      variable_info_t('body', 'points_file', 'string', .false.), &
      variable_info_t('body', 'points_checksum', 'string', .false.), &
      variable_info_t('body', 'particles_per_cell', 'integer', .false.), &
      variable_info_t('body', 'velocity', 'real3', .false.), &
      variable_info_t('body', 'angular_velocity', 'real3', .false.), &
      variable_info_t('body', 'hydrostatic', 'logical', .false.), &
      variable_info_t('body', 'free_surface_level', 'real', .false.)]

contains

   !> Read one `&body ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_body_group(spec, ios, message, text)
      type(body_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, material, shape, points_file, points_checksum
      real(rp) :: lower(3), upper(3), velocity(3), angular_velocity(3), free_surface_level, centre(3), size(3), &
                  rotation, rotation_axis(3), radius, axis(3), length, vertices(2 * max_vertices), z_range(2)
      integer :: particles_per_cell
      logical :: hydrostatic
      namelist /body/ name, material, shape, lower, upper, centre, size, rotation, rotation_axis, radius, axis, &
         length, vertices, z_range, points_file, points_checksum, particles_per_cell, velocity, angular_velocity, &
         hydrostatic, free_surface_level

      name = spec%name
      material = spec%material
      shape = spec%shape%kind
      lower = spec%lower
      upper = spec%upper
      call shape_to_locals(spec%shape, centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range)
      points_file = spec%points_file
      points_checksum = spec%points_checksum
      particles_per_cell = spec%particles_per_cell
      velocity = spec%velocity
      angular_velocity = spec%angular_velocity
      hydrostatic = spec%hydrostatic
      free_surface_level = spec%free_surface_level
      read (text, nml=body, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('material', material, spec%material, ios, message)
      call take_text('shape', shape, spec%shape%kind, ios, message, fold='lower')
      call take_text('points_file', points_file, spec%points_file, ios, message)
      call take_text('points_checksum', points_checksum, spec%points_checksum, ios, message, fold='lower')
      if (ios /= 0) return
      spec%lower = lower
      spec%upper = upper
      call locals_to_shape(centre, size, rotation, rotation_axis, radius, axis, length, vertices, z_range, spec%shape)
      spec%particles_per_cell = particles_per_cell
      spec%velocity = velocity
      spec%angular_velocity = angular_velocity
      spec%hydrostatic = hydrostatic
      spec%free_surface_level = free_surface_level
   end subroutine read_body_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function body_value(body, name) result(text)
      type(body_spec_t), intent(in) :: body
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(body%name)
      case ('material')
         text = quoted(body%material)
      case ('lower')
         text = real_list_text(body%lower)
      case ('upper')
         text = real_list_text(body%upper)
      case ('points_file')
         text = quoted(body%points_file)
      case ('points_checksum')
         text = quoted(body%points_checksum)
      case ('particles_per_cell')
         text = int_text(body%particles_per_cell)
      case ('velocity')
         text = real_list_text(body%velocity)
      case ('angular_velocity')
         text = real_list_text(body%angular_velocity)
      case ('hydrostatic')
         text = logical_text(body%hydrostatic)
      case ('free_surface_level')
         text = real_text(body%free_surface_level)
      case default
         text = shape_value(body%shape, name)
      end select
   end function body_value
end module body_group
