!> Reads a scene file of Fortran namelists (docs/input.md): rank 0 reads and checks it, then every
!> rank receives the same scene and the same status (style.md, lesson 9).
!>
!> The file is read in layers that could later be repeated for an override file: a text pre-scan
!> (`namelist_scan`) that knows every group and its lines, the namelist reads of the singleton groups
!> (which start from the scene's current values), the repeated groups, the checks that the base file
!> gives every required variable, and finally `validate_scene` / `resolve_scene` on the whole scene.
module scene_reader
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size
   use memory_budget, only: memory_budget_t, measure_memory_budget
   use kinds, only: path_len
   use error_status, only: status_t
   use scene_description, only: scene_t, material_spec_t, body_spec_t, wall_spec_t, inlet_spec_t, gauge_spec_t, &
                                panel_spec_t, structure_spec_t, contact_spec_t, model_newtonian_fluid, model_linear_elastic, &
                                model_rigid
   use shape_geometry, only: max_vertices
   use namelist_scan, only: namelist_file_t, namelist_group_t, scan_namelist_file
   use scene_validation, only: validate_scene
   use scene_defaults, only: resolve_scene, default_name
   use scene_memory, only: check_scene_memory
   use scene_variables, only: variable_info_t, value_too_long
   use gauge_group, only: gauge_variables, read_gauge_group
   use panel_group, only: panel_variables, read_panel_group
   use damping_zone_group, only: damping_zone_variables, read_damping_zone_group, damping_zone_spec_t
   use body_group, only: body_variables, read_body_group
   use structure_group, only: structure_variables, read_structure_group
   use wall_group, only: wall_variables, read_wall_group
   use gravity_group, only: gravity_variables, read_gravity_group
   use grid_group, only: grid_variables, read_grid_group, box_walls_variables, read_box_walls_group
   use run_group, only: run_variables, read_run_group
   use material_group, only: material_variables, read_material_group
   use inlet_group, only: inlet_variables, read_inlet_group
   use contact_group, only: contact_variables, read_contact_group
   use input_checks, only: name_detail
   use scene_broadcast, only: broadcast_scene
   use status_broadcast, only: broadcast_status
   use input_text, only: int_text, ordinal, group_context
   use point_file, only: load_body_points
   use inlet_table, only: load_inlet_tables
   use wall_motion, only: load_motion_tables
   implicit none
   private

   public :: read_scene, group_variables, entry_count

   !> A layer applied on top of the scene file: another namelist file, or namelist text from the command
   !> line (`--set '&grid rotation = 45 /'`). Singleton groups change the variables they assign; a
   !> repeated group changes the entries it selects: `&material name = 'water' ... /` the material named
   !> water, `&body material = 'water' ... /` (and &inlet) the bodies of water, `&wall name = 'left' ... /`
   !> (and &gauge) the wall so named (an unnamed wall by its default name `wall_<k>`); without the
   !> selecting variable, every entry of the group. An override changes entries; it does not add them.
   type, public :: scene_override_t
      character(len=:), allocatable :: source    !< file path, or namelist text
      logical :: is_text = .false.
   end type scene_override_t

   !> The rank of `comm` that reads the file.
   integer, parameter :: root = 0

   !> The namelist groups of a scene file, in the order a resolved scene is written (scene_record).
   character(len=*), parameter, public :: known_groups(*) = &
      [character(len=12) :: 'run', 'grid', 'box_walls', 'gravity', 'material', 'body', 'wall', 'inlet', 'gauge', &
                            'panel', 'structure', 'contact', 'damping_zone']
   !> Groups that may appear at most once.
   character(len=*), parameter :: singleton_groups(*) = [character(len=12) :: 'run', 'grid', 'box_walls', 'gravity']
   !> Groups that may appear any number of times, one scene entry each.
   character(len=*), parameter, public :: repeated_groups(*) = &
      [character(len=12) :: 'material', 'body', 'wall', 'inlet', 'gauge', 'panel', 'structure', 'contact', &
                            'damping_zone']
   !> Groups a scene file must contain.
   character(len=*), parameter :: required_groups(*) = [character(len=8) :: 'run', 'grid', 'material']

   !> The variables of every group, each group's rows from its module (src/input/groups/): their kind names
   !> the expected value in messages.
   type(variable_info_t), parameter :: variables(*) = [ &
      run_variables, &
      grid_variables, &
      box_walls_variables, &
      gravity_variables, &
      material_variables, &
      body_variables, &
      wall_variables, &
      inlet_variables, &
      gauge_variables, &
      panel_variables, &
      damping_zone_variables, &
      contact_variables, &
      structure_variables]

contains

   !> Read the scene file `path`. Collective over `comm`: rank 0 reads and checks the file, then the
   !> status and (if it is ok) the scene are broadcast, so that every rank returns the same status and
   !> the same scene. On failure the scene is the default scene_t on every rank.
   !> With `overrides`, each is applied in turn on top of the file, and the whole scene is checked after
   !> the last (messages then name the file "with" its overrides).
   subroutine read_scene(path, comm, scene, status, overrides)
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(out) :: scene
      type(status_t), intent(out) :: status
      type(scene_override_t), intent(in), optional :: overrides(:)
      type(scene_t) :: empty_scene
      type(memory_budget_t) :: budget
      character(len=:), allocatable :: label
      integer :: rank, ranks, i

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, ranks)
      budget = measure_memory_budget(comm)
      if (rank == root) then
         call load_scene_file(path, scene, status)
         label = trim(path)
         if (present(overrides)) then
            do i = 1, size(overrides)
               if (.not. status%ok) exit
               call apply_override(overrides(i), i, scene, status)
               if (i == 1) then
                  label = label//' with '//override_label(overrides(i), i)
               else
                  label = label//', '//override_label(overrides(i), i)
               end if
            end do
         end if
         if (status%ok) call validate_scene(scene, label, status)
         ! the points of `&body points_file` (checked like the scene's values, before any output)
         if (status%ok) call load_body_points(scene, label, status)
         if (status%ok) call load_inlet_tables(scene, label, status)
         ! the tables of `&wall` and `&structure motion = 'table'` (the whole motion checked against the scene box)
         if (status%ok) call load_motion_tables(scene, label, status)
         if (status%ok) call resolve_scene(scene)
         ! before any particle is made: a scene too large for the machine is refused, not run out of memory
         if (status%ok) call check_scene_memory(scene, label, ranks, budget, status)
      end if
      call broadcast_status(status, comm, root)
      if (status%ok) then
         call broadcast_scene(scene, comm, root)
      else
         scene = empty_scene
      end if
   end subroutine read_scene

   !> How messages name an override: its file, or `--set <i>`.
   function override_label(override, i) result(label)
      type(scene_override_t), intent(in) :: override
      integer, intent(in) :: i
      character(len=:), allocatable :: label
      if (override%is_text) then
         label = '--set '//int_text(i)
      else
         label = override%source
      end if
   end function override_label

   !> Apply one override (serial, rank 0): text goes through a scratch file, so both kinds share the
   !> scan and the reads of the scene file.
   subroutine apply_override(override, i, scene, status)
      type(scene_override_t), intent(in) :: override
      integer, intent(in) :: i
      type(scene_t), intent(inout) :: scene
      type(status_t), intent(inout) :: status
      character(len=512) :: message
      integer :: unit, ios
      logical :: exists

      if (override%is_text) then
         open (newunit=unit, status='scratch', action='readwrite', form='formatted', iostat=ios, iomsg=message)
         if (ios == 0) write (unit, '(a)', iostat=ios, iomsg=message) override%source
         if (ios == 0) rewind (unit)
      else
         inquire (file=override%source, exist=exists)
         if (.not. exists) then
            call status%fail(override%source//': override file not found')
            return
         end if
         open (newunit=unit, file=override%source, status='old', action='read', form='formatted', iostat=ios, &
               iomsg=message)
      end if
      if (ios /= 0) then
         call status%fail(override_label(override, i)//': cannot read the override: '//trim(message))
         return
      end if
      if (.not. override%is_text) then
         if (is_whole_scene(unit, override%source)) then
            call status%fail(override%source//' is a whole scene, not an override file: flotsam runs one scene '// &
                             '(usage: flotsam <scene.nml> [override.nml ...] [--set <text> ...]; see flotsam --help)')
            close (unit)
            return
         end if
      end if
      call read_override(unit, override_label(override, i), scene, status)
      close (unit)
   end subroutine apply_override

   !> True if the file open on `unit` would be accepted as a scene file by itself (every required
   !> group and variable): `flotsam a.nml b.nml` with two scenes would otherwise run b.nml's changes to
   !> a.nml. An override that changes many entries still lacks required variables (&grid dim, ...).
   logical function is_whole_scene(unit, path) result(whole)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: path
      type(scene_t) :: probe
      type(status_t) :: probe_status
      rewind (unit)
      call read_base_file(unit, path, probe, probe_status)
      whole = probe_status%ok
      rewind (unit)
   end function is_whole_scene

   !> The groups of an override open on `unit` change the scene in place.
   subroutine read_override(unit, label, scene, status)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: label
      type(scene_t), intent(inout) :: scene
      type(status_t), intent(inout) :: status
      type(namelist_file_t) :: file
      type(scene_t) :: probe
      character(len=512) :: message
      character(len=:), allocatable :: group, text, selector, chosen
      integer :: g, k, j, ios, selected

      call scan_namelist_file(unit, label, known_groups, file, status)
      if (.not. status%ok) return
      call check_group_counts(file, status)
      if (.not. status%ok) return
      call read_singleton_groups(file, scene, status)
      if (.not. status%ok) return
      allocate (probe%materials(1), probe%bodies(1), probe%walls(1), probe%inlets(1), probe%gauges(1), probe%panels(1), &
                probe%structures(1), probe%contacts(1), probe%damping_zones(1))
      do g = 1, size(file%groups)
         group = file%groups(g)%name
         if (.not. any(repeated_groups == group)) cycle
         k = count_before(file, g) + 1
         ! the group as text, so that it can be read into each entry it selects
         text = file%groups(g)%text()
         message = ''
         call read_group(group, probe, 1, ios, message, text)
         if (ios /= 0) then
            call report_read_error(file, group, k, message, status)
            return
         end if
         selector = selecting_variable(group)
         chosen = ''
         if (len(selector) > 0) then
            if (file%groups(g)%assigns(selector)) chosen = selected_value(group, probe)
         end if
         selected = 0
         do j = 1, entry_count(scene, group)
            if (len(chosen) > 0) then
               if (selected_value(group, scene, j) /= chosen) cycle
            end if
            call read_group(group, scene, j, ios, message, text)
            selected = selected + 1
         end do
         if (selected == 0) then
            if (len(chosen) > 0) then
               call status%fail(group_context(label, group, k)//': the scene has no &'//group//' with '//selector// &
                                " = '"//chosen//"' (an override changes entries of the scene, it does not add them)")
            else
               call status%fail(group_context(label, group, k)//': the scene has no &'//group// &
                                ' to change (an override changes entries of the scene, it does not add them)')
            end if
            return
         end if
      end do
   end subroutine read_override

   !> The variable that selects the entries of a repeated group an override changes ('' : all).
   pure function selecting_variable(group) result(name)
      character(len=*), intent(in) :: group
      character(len=:), allocatable :: name
      select case (group)
      case ('material', 'wall', 'gauge', 'panel', 'structure', 'damping_zone')
         name = 'name'
      case ('body', 'inlet')
         name = 'material'
      case default
         name = ''
      end select
   end function selecting_variable

   !> The selecting value of entry k (default 1) of a repeated group.
   function selected_value(group, scene, k) result(value)
      character(len=*), intent(in) :: group
      type(scene_t), intent(in) :: scene
      integer, intent(in), optional :: k
      character(len=:), allocatable :: value
      integer :: i
      i = 1
      if (present(k)) i = k
      select case (group)
      case ('material')
         value = trim(scene%materials(i)%name)
      case ('body')
         value = trim(scene%bodies(i)%material)
      case ('inlet')
         value = trim(scene%inlets(i)%material)
      case ('wall')
         ! an unnamed wall is selected by its default name (wall_<k>)
         value = trim(scene%walls(i)%name)
         if (len(value) == 0) value = default_name('wall', i)
      case ('gauge')
         value = trim(scene%gauges(i)%name)
      case ('panel')
         value = trim(scene%panels(i)%name)
      case ('damping_zone')
         value = trim(scene%damping_zones(i)%name)
      case ('structure')
         ! an unnamed structure is selected by its default name (structure_<k>)
         value = trim(scene%structures(i)%name)
         if (len(value) == 0) value = default_name('structure', i)
      case default
         value = ''
      end select
   end function selected_value

   !> Entries of `group` in the scene: 1 for a singleton group.
   pure integer function entry_count(scene, group) result(n)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: group
      n = 1
      if (.not. any(repeated_groups == group)) return
      n = 0
      select case (group)
      case ('material')
         if (allocated(scene%materials)) n = size(scene%materials)
      case ('body')
         if (allocated(scene%bodies)) n = size(scene%bodies)
      case ('wall')
         if (allocated(scene%walls)) n = size(scene%walls)
      case ('inlet')
         if (allocated(scene%inlets)) n = size(scene%inlets)
      case ('gauge')
         if (allocated(scene%gauges)) n = size(scene%gauges)
      case ('panel')
         if (allocated(scene%panels)) n = size(scene%panels)
      case ('damping_zone')
         if (allocated(scene%damping_zones)) n = size(scene%damping_zones)
      case ('contact')
         if (allocated(scene%contacts)) n = size(scene%contacts)
      case ('structure')
         if (allocated(scene%structures)) n = size(scene%structures)
      end select
   end function entry_count

   !> Serial part of `read_scene`: open `path` and read every group into `scene`.
   subroutine load_scene_file(path, scene, status)
      character(len=*), intent(in) :: path
      type(scene_t), intent(inout) :: scene
      type(status_t), intent(inout) :: status
      character(len=512) :: message
      logical :: exists, is_directory
      integer :: unit, ios

      if (len_trim(path) == 0) then
         call status%fail('no scene file given')
         return
      else if (len_trim(path) > path_len) then
         call status%fail(trim(path)//': the path of the scene file is longer than '//int_text(path_len)//' characters')
         return
      end if
      inquire (file=trim(path), exist=exists)
      if (.not. exists) then
         call status%fail(trim(path)//': scene file not found')
         return
      end if
      inquire (file=trim(path)//'/.', exist=is_directory)
      if (is_directory) then
         call status%fail(trim(path)//': is a directory, not a scene file')
         return
      end if
      open (newunit=unit, file=trim(path), status='old', action='read', form='formatted', access='sequential', &
            iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail(trim(path)//': cannot open the scene file: '//trim(message))
         return
      end if
      scene%source_file = path
      call read_base_file(unit, trim(path), scene, status)
      close (unit)
   end subroutine load_scene_file

   !> Read the scene file open on `unit`: every required group and variable must be there.
   subroutine read_base_file(unit, path, scene, status)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: path
      type(scene_t), intent(inout) :: scene
      type(status_t), intent(inout) :: status
      type(namelist_file_t) :: file
      integer :: g

      call scan_namelist_file(unit, path, known_groups, file, status)
      if (.not. status%ok) return
      call check_group_counts(file, status)
      if (.not. status%ok) return
      do g = 1, size(required_groups)
         if (file%count(required_groups(g)) == 0) then
            call status%fail(path//': group &'//trim(required_groups(g))//' is required but missing')
            return
         end if
      end do
      call read_singleton_groups(file, scene, status)
      if (.not. status%ok) return
      call read_repeated_groups(file, scene, status)
      if (.not. status%ok) return
      call check_required_variables(file, scene, status)
   end subroutine read_base_file

   !> A singleton group may appear at most once.
   subroutine check_group_counts(file, status)
      type(namelist_file_t), intent(in) :: file
      type(status_t), intent(inout) :: status
      integer :: g, n
      do g = 1, size(singleton_groups)
         n = file%count(singleton_groups(g))
         if (n > 1) then
            call status%fail(file%path//': group &'//trim(singleton_groups(g))//' appears '//int_text(n)// &
                             ' times (lines '//int_text(file%groups(file%find(singleton_groups(g), 1))%first_line)// &
                             ' and '//int_text(file%groups(file%find(singleton_groups(g), 2))%first_line)// &
                             '); it may appear only once')
            return
         end if
      end do
   end subroutine check_group_counts

   !> Read every singleton group present in the file. Each read starts from the values the scene
   !> already holds, so a second file could override some of them.
   subroutine read_singleton_groups(file, scene, status)
      type(namelist_file_t), intent(in) :: file
      type(scene_t), intent(inout) :: scene
      type(status_t), intent(inout) :: status
      character(len=512) :: message
      integer :: g, found, ios

      do g = 1, size(singleton_groups)
         found = file%find(trim(singleton_groups(g)), 1)
         if (found == 0) cycle
         message = ''
         call read_group(trim(singleton_groups(g)), scene, 1, ios, message, file%groups(found)%text())
         if (ios /= 0) then
            call report_read_error(file, trim(singleton_groups(g)), 1, message, status)
            return
         end if
      end do
   end subroutine read_singleton_groups

   !> Read every occurrence of the repeated groups, in file order, each from the defaults.
   subroutine read_repeated_groups(file, scene, status)
      type(namelist_file_t), intent(in) :: file
      type(scene_t), intent(inout) :: scene
      type(status_t), intent(inout) :: status
      type(scene_t) :: one
      type(material_spec_t) :: default_material
      type(body_spec_t) :: default_body
      type(wall_spec_t) :: default_wall
      type(inlet_spec_t) :: default_inlet
      type(gauge_spec_t) :: default_gauge
      type(panel_spec_t) :: default_panel
      type(damping_zone_spec_t) :: default_damping_zone
      type(contact_spec_t) :: default_contact
      type(structure_spec_t) :: default_structure
      character(len=512) :: message
      character(len=:), allocatable :: group
      integer :: g, k, ios

      allocate (scene%materials(file%count('material')), scene%bodies(file%count('body')), &
                scene%walls(file%count('wall')), scene%inlets(file%count('inlet')), scene%gauges(file%count('gauge')), &
                scene%panels(file%count('panel')), scene%structures(file%count('structure')), &
                scene%contacts(file%count('contact')), scene%damping_zones(file%count('damping_zone')))
      allocate (one%materials(1), one%bodies(1), one%walls(1), one%inlets(1), one%gauges(1), one%panels(1), one%structures(1), &
                one%contacts(1), one%damping_zones(1))
      do g = 1, size(repeated_groups)
         group = trim(repeated_groups(g))
         do k = 1, file%count(group)
            one%materials(1) = default_material
            one%bodies(1) = default_body
            one%walls(1) = default_wall
            one%inlets(1) = default_inlet
            one%gauges(1) = default_gauge
            one%panels(1) = default_panel
            one%damping_zones(1) = default_damping_zone
            one%contacts(1) = default_contact
            one%structures(1) = default_structure
            message = ''
            call read_group(group, one, 1, ios, message, file%groups(file%find(group, k))%text())
            if (ios /= 0) then
               call report_read_error(file, group, k, message, status)
               return
            end if
            select case (group)
            case ('material')
               scene%materials(k) = one%materials(1)
            case ('body')
               scene%bodies(k) = one%bodies(1)
            case ('wall')
               scene%walls(k) = one%walls(1)
            case ('inlet')
               scene%inlets(k) = one%inlets(1)
            case ('gauge')
               scene%gauges(k) = one%gauges(1)
            case ('panel')
               scene%panels(k) = one%panels(1)
            case ('damping_zone')
               scene%damping_zones(k) = one%damping_zones(1)
            case ('contact')
               scene%contacts(k) = one%contacts(1)
            case ('structure')
               scene%structures(k) = one%structures(1)
            end select
         end do
      end do
   end subroutine read_repeated_groups

   !> The base file must give every required variable (and the parameters its material model needs).
   subroutine check_required_variables(file, scene, status)
      type(namelist_file_t), intent(in) :: file
      type(scene_t), intent(in) :: scene
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: group, where
      integer :: v, g, k

      do g = 1, size(file%groups)
         group = file%groups(g)%name
         k = count_before(file, g) + 1
         select case (group)
         case ('material')
            where = group_context(file%path, group, k, name_detail(scene%materials(k)%name))
         case ('body')
            where = group_context(file%path, group, k, material_detail(scene%bodies(k)%material))
         case ('wall')
            where = group_context(file%path, group, k, name_detail(scene%walls(k)%name))
         case ('inlet')
            where = group_context(file%path, group, k, material_detail(scene%inlets(k)%material))
         case ('gauge')
            where = group_context(file%path, group, k, name_detail(scene%gauges(k)%name))
         case ('panel')
            where = group_context(file%path, group, k, name_detail(scene%panels(k)%name))
         case ('damping_zone')
            where = group_context(file%path, group, k, name_detail(scene%damping_zones(k)%name))
         case ('contact')
            where = group_context(file%path, group, k)
         case ('structure')
            where = group_context(file%path, group, k, name_detail(scene%structures(k)%name))
         case default
            where = group_context(file%path, group, 0)
         end select
         do v = 1, size(variables)
            if (variables(v)%group /= group .or. .not. variables(v)%required) cycle
            if (.not. file%groups(g)%assigns(variables(v)%name)) then
               call status%fail(where//': variable '//trim(variables(v)%name)//' is required')
               return
            end if
         end do
         if (group == 'material') then
            associate (material => scene%materials(k))
               if (material%model == model_newtonian_fluid .and. .not. file%groups(g)%assigns('bulk_modulus')) then
                  call status%fail(where//": variable bulk_modulus is required for model '"//model_newtonian_fluid//"'")
               else if (material%model == model_linear_elastic .and. &
                        .not. file%groups(g)%assigns('youngs_modulus')) then
                  call status%fail(where//": variable youngs_modulus is required for model '"//model_linear_elastic//"'")
               else if (material%model == model_rigid) then
                  call refuse_constants(file%groups(g), where)
               end if
               if (.not. status%ok) return
            end associate
         end if
      end do

   contains

      !> A rigid material has no stiffness or viscosity: a constant given for it would be silently unused.
      subroutine refuse_constants(group_text, where)
         type(namelist_group_t), intent(in) :: group_text
         character(len=*), intent(in) :: where
         character(len=*), parameter :: constants(4) = [character(len=14) :: 'bulk_modulus', 'viscosity', &
                                                        'youngs_modulus', 'poisson_ratio']
         integer :: c
         do c = 1, size(constants)
            if (.not. group_text%assigns(trim(constants(c)))) cycle
            call status%fail(where//': variable '//trim(constants(c))//" is not used by model '"//model_rigid// &
                             "' (a rigid body has no elastic constants: remove it, or use model '"// &
                             model_linear_elastic//"')")
            return
         end do
      end subroutine refuse_constants
   end subroutine check_required_variables

   !> How many groups of the same name come before group `g`.
   pure integer function count_before(file, g) result(n)
      type(namelist_file_t), intent(in) :: file
      integer, intent(in) :: g
      integer :: i
      n = 0
      do i = 1, g - 1
         if (file%groups(i)%name == file%groups(g)%name) n = n + 1
      end do
   end function count_before

   pure function material_detail(material) result(detail)
      character(len=*), intent(in) :: material
      character(len=:), allocatable :: detail
      detail = ''
      if (len_trim(material) > 0) detail = "material '"//trim(material)//"'"
   end function material_detail

   !> A group read failed: find the item responsible by reading the group's items one at a time, and
   !> report it by name. gfortran's own message names the value rather than the variable for a value
   !> of the wrong type (`cfl = 'abc'` gives "Cannot match namelist object name 'abc'").
   subroutine report_read_error(file, group, occurrence, message, status)
      type(namelist_file_t), intent(in) :: file
      character(len=*), intent(in) :: group
      integer, intent(in) :: occurrence
      character(len=*), intent(in) :: message
      type(status_t), intent(inout) :: status
      type(scene_t) :: one
      character(len=512) :: item_message
      character(len=:), allocatable :: label, prefix
      integer :: g, i, v, ios

      label = ''
      if (any(repeated_groups == group)) label = ' ('//ordinal(occurrence)//')'
      g = file%find(group, occurrence)
      if (g == 0) then
         call status%fail(file%path//': group &'//group//label//': '//trim(message))
         return
      end if
      allocate (one%materials(1), one%bodies(1), one%walls(1), one%inlets(1), one%gauges(1), one%panels(1), one%structures(1), &
                one%contacts(1), one%damping_zones(1))
      associate (items => file%groups(g)%items)
         do i = 1, size(items)
            prefix = file%path//': line '//int_text(items(i)%line)//': group &'//group//label
            if (len(items(i)%designator) == 0) then
               call status%fail(prefix//": expected 'variable = value', got '"//items(i)%value//"'")
               return
            end if
            item_message = ''
            call read_group(group, one, 1, ios, item_message, '&'//group//' '//items(i)%text()//' /')
            if (ios == 0) cycle
            v = find_variable(group, items(i)%name)
            if (ios == value_too_long) then
               call status%fail(prefix//': '//trim(item_message))
            else if (v == 0 .or. item_message == 'Cannot match namelist object name '//items(i)%name) then
               call status%fail(prefix//': unknown variable '//items(i)%name//unknown_hint(group, items(i)%name))
            else if (scan(items(i)%designator, '(%') > 0) then
               call status%fail(prefix//': variable '//items(i)%designator//' = '//items(i)%value//' cannot be read: '// &
                                trim(item_message))
            else
               call status%fail(prefix//': variable '//items(i)%name//' must be '//expected_value(variables(v)%kind)// &
                                ', got '//items(i)%value)
            end if
            return
         end do
      end associate
      ! Every item reads on its own: report the reader's message for the whole group.
      call status%fail(file%path//': line '//int_text(file%groups(g)%first_line)//': group &'//group//label//': '// &
                       trim(message))
   end subroutine report_read_error

   !> The variables of namelist group `group`, in the order of the table above (docs/input.md).
   pure function group_variables(group) result(names)
      character(len=*), intent(in) :: group
      character(len=len(variables%name)), allocatable :: names(:)
      names = pack(variables%name, variables%group == group)
   end function group_variables

   !> Position of variable `name` of `group` in `variables`; 0 if the group has no such variable.
   pure integer function find_variable(group, name) result(found)
      character(len=*), intent(in) :: group, name
      integer :: v
      found = 0
      do v = 1, size(variables)
         if (variables(v)%group == group .and. variables(v)%name == name) then
            found = v
            return
         end if
      end do
   end function find_variable

   !> " (dim belongs to group &grid)" or " (variables of &run: end_time, cfl, ...)".
   pure function unknown_hint(group, name) result(hint)
      character(len=*), intent(in) :: group, name
      character(len=:), allocatable :: hint
      integer :: v
      do v = 1, size(variables)
         if (variables(v)%name == name .and. variables(v)%group /= group) then
            hint = ' ('//name//' belongs to group &'//trim(variables(v)%group)//')'
            return
         end if
      end do
      hint = ''
      do v = 1, size(variables)
         if (variables(v)%group /= group) cycle
         if (len(hint) > 0) hint = hint//', '
         hint = hint//trim(variables(v)%name)
      end do
      hint = ' (variables of &'//group//': '//hint//')'
   end function unknown_hint

   pure function expected_value(kind) result(text)
      character(len=*), intent(in) :: kind
      character(len=:), allocatable :: text
      select case (kind)
      case ('real')
         text = 'a real number'
      case ('real3')
         text = 'up to 3 real numbers'
      case ('reals')
         text = 'a list of real numbers (vertices: x1, y1, x2, y2, ..., at most '//int_text(max_vertices)// &
                ' vertices; z_range: 2 numbers)'
      case ('integer')
         text = 'an integer (no decimal point or exponent)'
      case ('logical')
         text = 'a logical (.true. or .false.)'
      case ('string2')
         text = "two quoted strings ('a', 'b')"
      case default
         text = 'a quoted string'
      end select
   end function expected_value

   !> Read group `group` into `scene` (into entry `k` of a repeated group) from `text`, the group as
   !> `&group ... /` (namelist_group_t%text: the scan's items, so that a file, an override and a single
   !> item for an error report are read the same way).
   !> Each reader below copies the current values into local variables named like the namelist's
   !> variables (a namelist group can only name variables), reads, and copies them back: that shape
   !> repeats because the language asks for it, the checks and conversions are shared (take_text).
   subroutine read_group(group, scene, k, ios, message, text)
      character(len=*), intent(in) :: group
      type(scene_t), intent(inout) :: scene
      integer, intent(in) :: k
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      select case (group)
      case ('run')
         call read_run_group(scene%run, ios, message, text)
      case ('grid')
         call read_grid_group(scene%grid, ios, message, text)
      case ('box_walls')
         call read_box_walls_group(scene%grid, ios, message, text)
      case ('gravity')
         call read_gravity_group(scene%gravity, ios, message, text)
      case ('material')
         call read_material_group(scene%materials(k), ios, message, text)
      case ('body')
         call read_body_group(scene%bodies(k), ios, message, text)
      case ('wall')
         call read_wall_group(scene%walls(k), ios, message, text)
      case ('inlet')
         call read_inlet_group(scene%inlets(k), ios, message, text)
      case ('gauge')
         call read_gauge_group(scene%gauges(k), ios, message, text)
      case ('panel')
         call read_panel_group(scene%panels(k), ios, message, text)
      case ('damping_zone')
         call read_damping_zone_group(scene%damping_zones(k), ios, message, text)
      case ('contact')
         call read_contact_group(scene%contacts(k), ios, message, text)
      case ('structure')
         call read_structure_group(scene%structures(k), ios, message, text)
      case default
         ios = value_too_long
         message = 'no namelist group &'//group
      end select
   end subroutine read_group

end module scene_reader
