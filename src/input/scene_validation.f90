!> Checks of a scene's values against the allowed ranges of docs/input.md, group by group: `validate_scene`
!> runs them in the order of the file (run, grid, box walls, gravity, materials, bodies, walls, structures,
!> inlets, gauges, load names, contacts) and stops at the first violation. A group's checks of its own
!> values live in its module (src/input/groups/: run, grid and box walls, gravity, material, inlet,
!> gauge); the checks that read other groups next to this one by job (body_validation: a body's material,
!> shape and lattice; boundary_validation: walls and structures with their motion; sensor_validation:
!> gauge walls and the load names) and here (contacts); the shared checks in input_checks, the derived
!> defaults in scene_defaults and the memory estimate in scene_memory.
module scene_validation
   use kinds, only: rp, name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, material_spec_t, contact_spec_t, structure_spec_t, model_newtonian_fluid
   use input_text, only: quoted_list, group_context, ordinal, real_text
   use input_checks, only: check_real, pair_text
   use scene_memory, only: body_count, inlet_count
   use scene_defaults, only: find_structure, structure_name
   use material_group, only: find_material, validate_material, check_shape_function_combination
   use run_group, only: validate_run
   use grid_group, only: validate_grid, validate_box_walls, critical_courant_number
   use gravity_group, only: validate_gravity
   use inlet_group, only: validate_inlet
   use body_validation, only: validate_body, check_body_has_particles
   use boundary_validation, only: validate_wall, validate_structure
   use sensor_validation, only: validate_gauge_walls, validate_panel_walls, validate_load_names
   use gauge_group, only: validate_gauge
   use panel_group, only: validate_panel
   use damping_zone_group, only: validate_damping_zone
   implicit none
   private

   public :: validate_scene

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
      if (status%ok) call check_courant_limit(scene, path, status)
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
            call validate_gauge(scene%gauges, g, scene%grid, path, status)
            if (.not. status%ok) return
         end do
      end if
      call validate_load_names(scene, path, status)
      if (.not. status%ok) return
      call validate_gauge_walls(scene, path, status)
      if (.not. status%ok) return
      if (allocated(scene%panels)) then
         do i = 1, size(scene%panels)
            call validate_panel(scene%panels, i, scene%grid, path, status)
            if (.not. status%ok) return
         end do
      end if
      call validate_panel_walls(scene, path, status)
      if (.not. status%ok) return
      if (allocated(scene%damping_zones)) then
         do i = 1, size(scene%damping_zones)
            call validate_damping_zone(scene%damping_zones, i, scene%grid, path, status)
            if (.not. status%ok) return
         end do
      end if
      if (allocated(scene%contacts)) then
         do i = 1, size(scene%contacts)
            call validate_contact(scene%contacts, i, scene%materials, scene%structures, path, status)
            if (.not. status%ok) return
         end do
      end if
   end subroutine validate_scene

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

   !> The automatic step's CFL number must not exceed the critical step of the grid's shape functions
   !> (critical_courant_number). A fixed dt has its own guard (the run stops when it exceeds the CFL step);
   !> cfl = 0 (each material's default, the solver's material_courant_numbers) is below every limit.
   subroutine check_courant_limit(scene, path, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      real(rp) :: limit
      character(len=8) :: limit_text
      limit = critical_courant_number(scene%grid)
      if (scene%run%cfl <= limit * (1.0_rp + 1.0e-12_rp)) return
      write (limit_text, '(f8.2)') limit
      call status%fail(trim(path)//': group &run: variable cfl = '//real_text(scene%run%cfl)//' exceeds the critical '// &
                       'step of '//trim(scene%grid%shape_function)//' shape functions in '// &
                       achar(iachar('0') + scene%grid%dim)//'-D (at most '//trim(adjustl(limit_text))// &
                       '; docs/theory.md section 5.1)')
   end subroutine check_courant_limit
end module scene_validation
