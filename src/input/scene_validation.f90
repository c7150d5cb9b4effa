!> Checks of a scene's values against the allowed ranges of docs/input.md, group by group: `validate_scene`
!> runs them in the order of the file (run, grid, box walls, gravity, materials, bodies, walls, structures,
!> inlets, gauges, load names, contacts) and stops at the first violation. The groups' own checks live
!> next to this module by job: body_validation, boundary_validation, sensor_validation; the shared checks
!> in input_checks, the keyword lists in scene_keywords, the derived defaults in scene_defaults and the
!> memory estimate in scene_memory.
module scene_validation
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, run_control_t, grid_spec_t, material_spec_t, contact_spec_t, &
                                structure_spec_t, model_newtonian_fluid, model_linear_elastic, model_rigid, &
                                particle_field_names, field_precision_keywords
   use input_text, only: int_text, real_text, quoted_list, group_context, ordinal
   use input_checks, only: check_real, pair_text
   use scene_keywords, only: stabilization_keywords, oscillation_rule_keywords, smoothed_variables_keywords, &
                             volume_correction_keywords, shape_function_keywords, update_scheme_keywords, &
                             transfer_keywords, model_keywords
   use scene_memory, only: body_count, inlet_count
   use scene_defaults, only: find_material, find_structure, structure_name
   use body_validation, only: validate_body, check_body_has_particles
   use boundary_validation, only: validate_box_walls, validate_wall, validate_structure, validate_inlet
   use sensor_validation, only: validate_gauge_walls, validate_load_names
   use gauge_group, only: validate_gauge
   implicit none
   private

   public :: validate_scene

   !> Above this shifting coefficient the explicit occupancy diffusion is no longer stable (2-D bilinear
   !> grid Laplacian, docs/volume-conservation.md).
   real(rp), parameter :: max_shifting_coefficient = 0.25_rp
   !> Relative tolerance of "extent is a whole multiple of cell_size".
   real(rp), parameter :: multiple_tolerance = 1.0e-9_rp
   !> Largest number of cells along one axis and in the whole grid (default integers index them).
   real(rp), parameter :: max_cells = real(huge(1), rp)

contains

   !> Check every value of `scene` against its allowed range. `path` names the file in messages.
   !> The first violation is reported, e.g.
   !> `x.nml: group &material (2nd, name 'water'): variable bulk_modulus must be > 0, got -1.0`.
   subroutine validate_scene(scene, path, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      integer :: m, b, w, i, g

      call validate_run(scene%run, path, status)
      if (status%ok) call validate_grid(scene%grid, path, status)
      if (status%ok) call validate_box_walls(scene%grid, path, status)
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
         call check_shape_function_combination(scene%materials(m), m, scene%grid, path, status)
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
         call check_body_has_particles(scene, b, path, status)
         if (.not. status%ok) return
      end do
      if (allocated(scene%walls)) then
         do w = 1, size(scene%walls)
            call validate_wall(scene%walls(w), w, scene, path, status)
            if (.not. status%ok) return
         end do
      end if
      if (allocated(scene%structures)) then
         do i = 1, size(scene%structures)
            call validate_structure(scene%structures(i), i, scene, path, status)
            if (.not. status%ok) return
         end do
      end if
      if (allocated(scene%inlets)) then
         do i = 1, size(scene%inlets)
            call validate_inlet(scene%inlets(i), i, scene%materials, scene%grid, path, status)
            if (.not. status%ok) return
         end do
      end if
      if (allocated(scene%gauges)) then
         do g = 1, size(scene%gauges)
            call validate_gauge(scene%gauges, g, scene%grid%dim, scene%grid%origin, scene%grid%extent, &
                                scene%grid%cell_size, path, status)
            if (.not. status%ok) return
         end do
      end if
      call validate_load_names(scene, path, status)
      if (.not. status%ok) return
      call validate_gauge_walls(scene, path, status)
      if (.not. status%ok) return
      if (allocated(scene%contacts)) then
         do i = 1, size(scene%contacts)
            call validate_contact(scene%contacts, i, scene%materials, scene%structures, path, status)
            if (.not. status%ok) return
         end do
      end if
   end subroutine validate_scene

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
      if (all(run%transfer /= transfer_keywords)) then
         call status%fail(where//': variable transfer must be one of '//quoted_list(transfer_keywords)// &
                          ", got '"//trim(run%transfer)//"'")
      else if (run%transfer == 'apic' .and. run%flip_fraction_given) then
         ! a blend the user asked for must not be dropped without a word
         call status%fail(where//": variable flip_fraction has no effect with transfer = 'apic' (APIC has no FLIP/PIC "// &
                          "blend); remove it")
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
      call check_real(where, 'load_interval', run%load_interval, status, at_least=0.0_rp)
      if (status%ok .and. all(run%field_precision /= field_precision_keywords)) then
         call status%fail(where//': variable field_precision must be one of '//quoted_list(field_precision_keywords)// &
                          ", got '"//trim(run%field_precision)//"'")
      end if
      if (status%ok) call check_particle_fields(where, run%particle_fields, status)
   end subroutine validate_run

   !> `&run particle_fields` is a comma-separated list of particle datasets (or 'all'; 'position' is
   !> always written and may be named).
   subroutine check_particle_fields(where, fields, status)
      character(len=*), intent(in) :: where, fields
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: item
      integer :: start, comma
      start = 1
      do
         comma = index(fields(start:), ',')
         if (comma == 0) then
            item = trim(fields(start:))
         else
            item = fields(start:start + comma - 2)
         end if
         if (item /= 'all' .and. item /= 'position' .and. all(particle_field_names /= item)) then
            if (len(item) == 0) then
               call status%fail(where//": variable particle_fields has an empty name in '"//trim(fields)// &
                                "' (a comma-separated list of "//quoted_list(particle_field_names)//", or 'all')")
            else
               call status%fail(where//": variable particle_fields: unknown field '"//item//"' (fields: "// &
                                quoted_list(particle_field_names)//", or 'all'; position is always written)")
            end if
            return
         end if
         if (comma == 0) return
         start = start + comma
      end do
   end subroutine check_particle_fields

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

   !> The schemes of a material that a shape function does not combine with (docs/theory.md section 1.1):
   !> the volume correction's occupancy and open volumes integrate the multilinear hat of a node over its
   !> two cells, which bspline2 replaces by a wider support [R].
   subroutine check_shape_function_combination(material, m, grid, path, status)
      type(material_spec_t), intent(in) :: material
      integer, intent(in) :: m
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      if (grid%shape_function == 'linear') return
      if (material%volume_correction /= 'none') &
         call status%fail(group_context(path, 'material', m, "name '"//trim(material%name)//"'")// &
                          ": variable volume_correction = '"//trim(material%volume_correction)// &
                          "' needs &grid shape_function = 'linear', got '"//trim(grid%shape_function)//"'")
   end subroutine check_shape_function_combination

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
         else if (material%model == model_rigid .and. material%stabilization /= 'none') then
            call status%fail(where//": variable stabilization must be 'none' for model '"//model_rigid// &
                             "' (a rigid body has no strain to filter), got '"//trim(material%stabilization)//"'")
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

   !> `&contact`: two declared solid materials (fluid-solid contact is not implemented: a fluid shares the
   !> common velocity field, docs/contact.md), or a solid material and a `&structure` (by its name, default
   !> `structure_<k>`; a name that is both a material and a structure is refused as ambiguous), a pair no
   !> earlier &contact gives (in either order), mu >= 0.
   subroutine validate_contact(contacts, c, materials, structures, path, status)
      type(contact_spec_t), intent(in) :: contacts(:)
      integer, intent(in) :: c
      type(material_spec_t), intent(in) :: materials(:)
      type(structure_spec_t), intent(in), allocatable :: structures(:)
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      character(len=name_len), allocatable :: declared(:)
      integer :: k, m, s, other, n_structures, found_structures

      n_structures = 0
      if (allocated(structures)) n_structures = size(structures)
      associate (contact => contacts(c))
         where = group_context(path, 'contact', c)
         if (any(len_trim(contact%between) == 0)) then
            call status%fail(where//": variable between must name two materials ('a', 'b'; the same name twice for "// &
                             "bodies of one material), got "//pair_text(contact%between))
            return
         end if
         where = group_context(path, 'contact', c, 'between '//pair_text(contact%between))
         found_structures = 0
         do k = 1, 2
            m = find_material(materials, contact%between(k))
            s = 0
            if (n_structures > 0) s = find_structure(structures, contact%between(k))
            if (m > 0 .and. s > 0) then
               call status%fail(where//": variable between names '"//trim(contact%between(k))// &
                                "', which is both a &material and a &structure; rename one of them")
               return
            end if
            if (s > 0) then
               found_structures = found_structures + 1
               cycle
            end if
            if (m == 0) then
               allocate (declared(size(materials) + n_structures))
               do m = 1, size(materials)
                  declared(m) = materials(m)%name
               end do
               do s = 1, n_structures
                  declared(size(materials) + s) = structure_name(structures, s)
               end do
               call status%fail(where//': variable between must name declared &material or &structure groups ('// &
                                quoted_list(declared)//"), got '"//trim(contact%between(k))//"'")
               return
            end if
            if (materials(m)%model == model_newtonian_fluid) then
               call status%fail(where//": variable between names the fluid '"//trim(contact%between(k))// &
                                "': contact of a fluid is not implemented (fluids share the common velocity "// &
                                'field with the solids, docs/contact.md); name solid materials only')
               return
            end if
         end do
         if (found_structures == 2) then
            call status%fail(where//': variable between names two structures; name a material and a structure '// &
                             '(structures do not act on each other: each is fixed or moves as prescribed)')
            return
         end if
         do other = 1, c - 1
            if ((contacts(other)%between(1) == contact%between(1) .and. &
                 contacts(other)%between(2) == contact%between(2)) .or. &
                (contacts(other)%between(1) == contact%between(2) .and. &
                 contacts(other)%between(2) == contact%between(1))) then
               call status%fail(where//': variable between names the same pair as the '//ordinal(other)// &
                                ' &contact; give each pair once')
               return
            end if
         end do
         call check_real(where, 'friction', contact%friction, status, at_least=0.0_rp)
      end associate
   end subroutine validate_contact
end module scene_validation
