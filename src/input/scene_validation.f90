!> Checks of a scene's values (the allowed ranges of docs/input.md) and resolution of the values that
!> default to something derived (`output_interval = 0`, `floor_size = 0`, grid cell counts, material
!> indices of bodies). Both work on a whole scene, whatever file(s) its values came from.
module scene_validation
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, run_control_t, grid_spec_t, material_spec_t, body_spec_t, wall_spec_t, &
                                inlet_spec_t, opening_far_end, wall_none, wall_slip, wall_no_slip, model_newtonian_fluid, &
                                model_linear_elastic
   use input_text, only: int_text, real_text, quoted_list, group_context, ordinal
   implicit none
   private

   public :: validate_scene, resolve_scene, find_material

   !> Accepted `&material stabilization=` keywords in their canonical spelling (compared without case).
   character(len=*), parameter, public :: stabilization_keywords(*) = [character(len=5) :: 'none', 'C0', 'NB', 'FOAL1']
   !> Accepted `&material oscillation_rule=` and `smoothed_variables=` keywords (FOAL1 options).
   character(len=*), parameter, public :: oscillation_rule_keywords(*) = [character(len=3) :: 'OR', 'AND']
   character(len=*), parameter, public :: smoothed_variables_keywords(*) = [character(len=8) :: 'stress', 'pressure']
   !> Accepted `&material volume_correction=` keywords (docs/volume-conservation.md).
   character(len=*), parameter, public :: volume_correction_keywords(*) = &
      [character(len=23) :: 'none', 'shifting', 'eos_relaxation', 'shifting+eos_relaxation']
   !> Above this shifting coefficient the explicit occupancy diffusion is no longer stable (2-D bilinear
   !> grid Laplacian, docs/volume-conservation.md).
   real(rp), parameter :: max_shifting_coefficient = 0.25_rp
   !> Accepted `&run update_scheme=` keywords (stored upper case).
   character(len=*), parameter, public :: update_scheme_keywords(*) = [character(len=4) :: 'USL', 'MUSL']
   !> Accepted `&box_walls` keywords (stored lower case).
   character(len=*), parameter, public :: wall_keywords(*) = [character(len=7) :: wall_none, wall_slip, wall_no_slip]
   !> Accepted `&wall condition=` keywords (stored lower case).
   character(len=*), parameter, public :: wall_condition_keywords(*) = [character(len=7) :: wall_slip, wall_no_slip]
   !> Accepted `&material model=` keywords (stored lower case).
   character(len=*), parameter, public :: model_keywords(*) = &
      [character(len=15) :: model_newtonian_fluid, model_linear_elastic]

   !> Relative tolerance of "extent is a whole multiple of cell_size".
   real(rp), parameter :: multiple_tolerance = 1.0e-9_rp
   !> Tolerance of "body inside the grid", in cell sizes.
   real(rp), parameter :: inside_tolerance = 1.0e-9_rp
   !> Largest number of cells along one axis and in the whole grid (default integers index them).
   real(rp), parameter :: max_cells = real(huge(1), rp)

   character(len=1), parameter :: axis_letter(3) = ['x', 'y', 'z']

contains

   !> Check every value of `scene` against its allowed range. `path` names the file in messages.
   !> The first violation is reported, e.g.
   !> `x.nml: group &material (2nd, name 'water'): variable bulk_modulus must be > 0, got -1.0`.
   subroutine validate_scene(scene, path, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      integer :: m, b, w, i

      call validate_run(scene%run, path, status)
      if (status%ok) call validate_grid(scene%grid, path, status)
      if (status%ok) call validate_walls(scene%grid, path, status)
      if (status%ok) call validate_gravity(scene%gravity, scene%grid%dim, path, status)
      if (.not. status%ok) return

      if (.not. allocated(scene%materials)) then
         call status%fail(trim(path)//': at least one group &material is required')
      else if (size(scene%materials) == 0) then
         call status%fail(trim(path)//': at least one group &material is required')
      end if
      if (.not. status%ok) return
      do m = 1, size(scene%materials)
         call validate_material(scene%materials, m, path, status)
         if (.not. status%ok) return
      end do

      ! something must bring material into the scene
      if (body_count(scene) == 0 .and. inlet_count(scene) == 0) then
         call status%fail(trim(path)//': at least one group &body or &inlet is required')
         return
      end if
      do b = 1, body_count(scene)
         call validate_body(scene%bodies(b), b, scene%materials, scene%grid, path, status)
         if (.not. status%ok) return
      end do
      if (allocated(scene%walls)) then
         do w = 1, size(scene%walls)
            call validate_wall(scene%walls(w), w, scene%grid%dim, path, status)
            if (.not. status%ok) return
         end do
      end if
      if (allocated(scene%inlets)) then
         do i = 1, size(scene%inlets)
            call validate_inlet(scene%inlets(i), i, scene%materials, scene%grid, path, status)
            if (.not. status%ok) return
         end do
      end if
   end subroutine validate_scene

   pure integer function body_count(scene)
      type(scene_t), intent(in) :: scene
      body_count = 0
      if (allocated(scene%bodies)) body_count = size(scene%bodies)
   end function body_count

   pure integer function inlet_count(scene)
      type(scene_t), intent(in) :: scene
      inlet_count = 0
      if (allocated(scene%inlets)) inlet_count = size(scene%inlets)
   end function inlet_count

   !> Replace the "0 = derived" defaults by their values and fill the derived fields. Call once, on a
   !> scene that `validate_scene` accepted.
   subroutine resolve_scene(scene)
      type(scene_t), intent(inout) :: scene
      integer :: k, b, i

      associate (run => scene%run, grid => scene%grid)
         ! Validated >= 0, so not > 0 means 0.
         if (.not. run%output_interval > 0.0_rp) run%output_interval = run%end_time / 100.0_rp
         if (.not. run%floor_size > 0.0_rp) run%floor_size = product(grid%extent(1:grid%dim - 1))
         grid%ncells = 1
         do k = 1, grid%dim
            grid%ncells(k) = nint(grid%extent(k) / grid%cell_size)
         end do
      end associate
      if (.not. allocated(scene%bodies)) allocate (scene%bodies(0))
      do b = 1, size(scene%bodies)
         scene%bodies(b)%material_index = find_material(scene%materials, scene%bodies(b)%material)
      end do
      if (.not. allocated(scene%walls)) allocate (scene%walls(0))     ! (wall normals are made unit where walls are built)
      if (.not. allocated(scene%inlets)) allocate (scene%inlets(0))
      do i = 1, size(scene%inlets)
         associate (inlet => scene%inlets(i))
            inlet%material_index = find_material(scene%materials, inlet%material)
            inlet%direction(1:scene%grid%dim) = inlet%direction(1:scene%grid%dim) / norm2(inlet%direction(1:scene%grid%dim))
         end associate
      end do
   end subroutine resolve_scene

   !> Index of the material called `name` (exact match); 0 if there is none.
   pure integer function find_material(materials, name) result(found)
      type(material_spec_t), intent(in) :: materials(:)
      character(len=*), intent(in) :: name
      integer :: m
      found = 0
      do m = 1, size(materials)
         if (materials(m)%name == name) then
            found = m
            return
         end if
      end do
   end function find_material

   subroutine validate_run(run, path, status)
      type(run_control_t), intent(in) :: run
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where

      where = group_context(path, 'run', 0)
      call check_real(where, 'end_time', run%end_time, status, greater_than=0.0_rp)
      call check_real(where, 'cfl', run%cfl, status, greater_than=0.0_rp, at_most=1.0_rp)
      call check_real(where, 'dt', run%fixed_dt, status, at_least=0.0_rp)
      call check_real(where, 'output_interval', run%output_interval, status, at_least=0.0_rp)
      if (len_trim(run%output_dir) == 0) call status%fail(where//': variable output_dir must not be empty')
      if (all(run%update_scheme /= update_scheme_keywords)) then
         call status%fail(where//': variable update_scheme must be one of '//quoted_list(update_scheme_keywords)// &
                          ", got '"//trim(run%update_scheme)//"'")
      end if
      call check_real(where, 'flip_fraction', run%flip_fraction, status, at_least=0.0_rp, at_most=1.0_rp)
      call check_real(where, 'theta', run%theta, status, greater_than=0.0_rp, at_most=1.0_rp)
      if (run%max_steps <= 0_i8) then
         call status%fail(where//': variable max_steps must be > 0, got '//int_text(run%max_steps))
      end if
      call check_real(where, 'progress_interval', run%progress_interval, status)
      call check_real(where, 'floor_size', run%floor_size, status, at_least=0.0_rp)
      if (run%checkpoint_interval_steps < 0_i8) then
         call status%fail(where//': variable checkpoint_interval_steps must be >= 0, got '// &
                          int_text(run%checkpoint_interval_steps))
      end if
      call check_real(where, 'checkpoint_interval_wall', run%checkpoint_interval_wall, status, at_least=0.0_rp)
      if (run%checkpoints_kept < 1) then
         call status%fail(where//': variable checkpoints_kept must be >= 1, got '//int_text(run%checkpoints_kept))
      end if
      call check_real(where, 'speed_limit', run%speed_limit, status, at_least=0.0_rp)
      ! below 1 even a perfect balance would exceed the threshold (NaN fails the finiteness test first)
      if (.not. ieee_is_finite(run%rebalance_threshold)) then
         call check_real(where, 'rebalance_threshold', run%rebalance_threshold, status)
      else if (run%rebalance_threshold < 0.0_rp .or. &
               (run%rebalance_threshold > 0.0_rp .and. run%rebalance_threshold < 1.0_rp)) then
         call status%fail(where//': variable rebalance_threshold must be 0 (off) or >= 1, got '// &
                          real_text(run%rebalance_threshold))
      end if
      if (run%rebalance_interval < 1) then
         call status%fail(where//': variable rebalance_interval must be >= 1, got '//int_text(run%rebalance_interval))
      end if
   end subroutine validate_run

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

   subroutine validate_walls(grid, path, status)
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
   end subroutine validate_walls

   subroutine validate_gravity(gravity, dim, path, status)
      real(rp), intent(in) :: gravity(3)
      integer, intent(in) :: dim
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      integer :: k
      do k = 1, dim
         call check_real(group_context(path, 'gravity', 0), 'acceleration('//int_text(k)//')', gravity(k), status)
      end do
   end subroutine validate_gravity

   subroutine validate_material(materials, m, path, status)
      type(material_spec_t), intent(in) :: materials(:)
      integer, intent(in) :: m
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: other
      logical :: incompressible

      associate (material => materials(m))
         if (len_trim(material%name) == 0) then
            call status%fail(group_context(path, 'material', m)//': variable name is required')
            return
         end if
         where = group_context(path, 'material', m, "name '"//trim(material%name)//"'")
         other = find_material(materials(1:m - 1), material%name)
         if (other > 0) then
            call status%fail(where//": variable name '"//trim(material%name)//"' is already used by the "// &
                             ordinal(other)//' &material')
            return
         end if
         if (all(material%model /= model_keywords)) then
            call status%fail(where//': variable model must be one of '//quoted_list(model_keywords)//", got '"// &
                             trim(material%model)//"'")
            return
         end if
         call check_real(where, 'density', material%density, status, greater_than=0.0_rp)
         select case (trim(material%model))
         case (model_newtonian_fluid)
            call check_real(where, 'bulk_modulus', material%bulk_modulus, status, greater_than=0.0_rp)
            call check_real(where, 'viscosity', material%viscosity, status, at_least=0.0_rp)
         case (model_linear_elastic)
            call check_real(where, 'youngs_modulus', material%youngs_modulus, status, greater_than=0.0_rp)
            incompressible = .false.
            if (ieee_is_finite(material%poisson_ratio)) incompressible = material%poisson_ratio >= 0.5_rp
            if (.not. incompressible) then
               call check_real(where, 'poisson_ratio', material%poisson_ratio, status, greater_than=-1.0_rp, &
                               less_than=0.5_rp)
            else
               ! nu = 0.5 is incompressible: the bulk modulus E / (3 (1 - 2 nu)) would be infinite.
               call status%fail(where//': variable poisson_ratio must be < 0.5 (0.5 is incompressible: use a '// &
                                'smaller ratio or a newtonian_fluid), got '//real_text(material%poisson_ratio))
            end if
         end select
         if (all(material%stabilization /= stabilization_keywords)) then
            call status%fail(where//': variable stabilization must be one of '//quoted_list(stabilization_keywords)// &
                             ", got '"//trim(material%stabilization)//"'")
         end if
         if (all(material%oscillation_rule /= oscillation_rule_keywords)) then
            call status%fail(where//': variable oscillation_rule must be one of '// &
                             quoted_list(oscillation_rule_keywords)//", got '"//trim(material%oscillation_rule)//"'")
         end if
         if (all(material%smoothed_variables /= smoothed_variables_keywords)) then
            call status%fail(where//': variable smoothed_variables must be one of '// &
                             quoted_list(smoothed_variables_keywords)//", got '"//trim(material%smoothed_variables)//"'")
         end if
         call check_real(where, 'gamma_max', material%gamma_max, status, at_least=0.0_rp, at_most=1.0_rp)
         if (all(material%volume_correction /= volume_correction_keywords)) then
            call status%fail(where//': variable volume_correction must be one of '// &
                             quoted_list(volume_correction_keywords)//", got '"//trim(material%volume_correction)//"'")
         else if (material%volume_correction /= 'none' .and. material%model /= model_newtonian_fluid) then
            call status%fail(where//": variable volume_correction = '"//trim(material%volume_correction)// &
                             "' is for fluids (model = '"//model_newtonian_fluid//"'), got model = '"// &
                             trim(material%model)//"'")
         end if
         call check_real(where, 'shifting_coefficient', material%shifting_coefficient, status, greater_than=0.0_rp, &
                         at_most=max_shifting_coefficient)
         call check_real(where, 'eos_relaxation_rate', material%eos_relaxation_rate, status, greater_than=0.0_rp, &
                         at_most=1.0_rp)
      end associate
   end subroutine validate_material

   subroutine validate_body(body, b, materials, grid, path, status)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: b
      type(material_spec_t), intent(in) :: materials(:)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, lower_k, upper_k
      real(rp) :: grid_lower, grid_upper, tolerance, spacing
      integer :: k, m
      character(len=name_len) :: declared(size(materials))

      if (len_trim(body%material) == 0) then
         call status%fail(group_context(path, 'body', b)//': variable material is required')
         return
      end if
      where = group_context(path, 'body', b, "material '"//trim(body%material)//"'")
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
      call check_real(where, 'free_surface_level', body%free_surface_level, status)
      if (.not. status%ok) return

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
   end subroutine validate_body

   subroutine validate_wall(wall, w, dim, path, status)
      type(wall_spec_t), intent(in) :: wall
      integer, intent(in) :: w, dim
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: k

      where = group_context(path, 'wall', w)
      do k = 1, dim
         call check_real(where, 'point('//int_text(k)//')', wall%point(k), status)
         call check_real(where, 'normal('//int_text(k)//')', wall%normal(k), status)
         call check_real(where, 'lower('//int_text(k)//')', wall%lower(k), status)
         call check_real(where, 'upper('//int_text(k)//')', wall%upper(k), status)
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
      if (all(wall%condition /= wall_condition_keywords)) then
         call status%fail(where//': variable condition must be one of '//quoted_list(wall_condition_keywords)// &
                          ", got '"//trim(wall%condition)//"'")
      end if
   end subroutine validate_wall

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
      call check_real(where, 'velocity', inlet%velocity, status, greater_than=0.0_rp)
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

   !> Fail with "<where>: variable <variable> must be <range>, got <value>" unless `value` is finite and
   !> inside the range given by the optional bounds.
   subroutine check_real(where, variable, value, status, greater_than, at_least, less_than, at_most)
      character(len=*), intent(in) :: where, variable
      real(rp), intent(in) :: value
      type(status_t), intent(inout) :: status
      real(rp), intent(in), optional :: greater_than, at_least, less_than, at_most
      character(len=:), allocatable :: range
      logical :: ok

      ! Comparisons only after the finiteness test: NaN must not reach them (-ffpe-trap=invalid).
      ok = ieee_is_finite(value)
      if (ok .and. present(greater_than)) ok = value > greater_than
      if (ok .and. present(at_least)) ok = value >= at_least
      if (ok .and. present(less_than)) ok = value < less_than
      if (ok .and. present(at_most)) ok = value <= at_most
      if (ok) return

      if (present(greater_than) .and. present(at_most)) then
         range = 'in ('//bound_text(greater_than)//', '//bound_text(at_most)//']'
      else if (present(greater_than) .and. present(less_than)) then
         range = 'in ('//bound_text(greater_than)//', '//bound_text(less_than)//')'
      else if (present(at_least) .and. present(at_most)) then
         range = 'in ['//bound_text(at_least)//', '//bound_text(at_most)//']'
      else if (present(greater_than)) then
         range = '> '//bound_text(greater_than)
      else if (present(at_least)) then
         range = '>= '//bound_text(at_least)
      else
         range = 'a finite number'
      end if
      call status%fail(where//': variable '//variable//' must be '//range//', got '//real_text(value))
   end subroutine check_real

   !> A bound in a message: 0 rather than 0.0, so that ranges read "> 0".
   function bound_text(bound) result(text)
      real(rp), intent(in) :: bound
      character(len=:), allocatable :: text
      if (abs(bound - anint(bound)) < tiny(bound) .and. abs(bound) < 1.0e9_rp) then
         text = int_text(nint(bound))
      else
         text = real_text(bound)
      end if
   end function bound_text
end module scene_validation
