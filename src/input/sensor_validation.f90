!> Checks of what a run measures that read other groups: the wall of a wall_pressure gauge or a panel (their
!> own values: gauge_group, panel_group) and the load namespace (the names of loads.csv: box sides that are walls, &wall,
!> &inlet, &body, &structure, unique and resolved).
module sensor_validation
   use kinds, only: name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, wall_none, motion_none, gauge_wall_pressure, panel_load_cell
   use input_text, only: quoted_list, group_context, ordinal
   use input_checks, only: given_or, name_detail
   use scene_memory, only: body_count, wall_count, structure_count, inlet_count
   use scene_defaults, only: default_name
   use grid_group, only: side_name
   implicit none
   private

   public :: validate_gauge_walls, validate_panel_walls, validate_load_names

   !> One name of the load namespace (box sides that are walls, &wall, &inlet, &body), for the
   !> uniqueness check: the resolved name, whether the scene gave it, and how messages name its place.
   type :: load_name_t
      character(len=name_len) :: name = ''
      logical :: given = .false.
      character(len=:), allocatable :: owner      !< "the 2nd &wall", "the &box_walls side x_max"
      character(len=:), allocatable :: where      !< group context of the variable that sets it
      character(len=:), allocatable :: variable   !< "name", "x_max_name"
   end type load_name_t

contains

   !> A wall_pressure gauge names the wall, box side or structure it lies on (its name in loads.csv, given or
   !> default; that it lies on the surface is checked when the walls are built); the other kinds take no `wall`.
   subroutine validate_gauge_walls(scene, path, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=name_len), allocatable :: surfaces(:)
      character(len=:), allocatable :: where
      integer :: g
      if (.not. allocated(scene%gauges)) return
      surfaces = surface_names(scene)
      do g = 1, size(scene%gauges)
         associate (gauge => scene%gauges(g))
            where = group_context(path, 'gauge', g, name_detail(gauge%name))
            if (gauge%kind /= gauge_wall_pressure) then
               if (len_trim(gauge%wall) > 0) then
                  call status%fail(where//": variable wall is used by kind 'wall_pressure' only, got kind '"// &
                                   trim(gauge%kind)//"'")
                  return
               end if
               cycle
            end if
            if (len_trim(gauge%wall) == 0) then
               call status%fail(where//": variable wall is required for kind 'wall_pressure' (the name of the "// &
                                'wall, box side or structure the gauge lies on, as in loads.csv)')
               return
            end if
            call check_surface_name(scene, surfaces, where, gauge%wall, 'a wall_pressure gauge', .false., status)
            if (.not. status%ok) return
         end associate
      end do
   end subroutine validate_gauge_walls

   !> A surface panel names the wall, box side or structure it lies on (fixed, as a wall_pressure gauge's);
   !> a load cell may name one (moving or not) or none (every constraint in its box). That a surface panel
   !> lies on its surface is checked when the walls are built.
   subroutine validate_panel_walls(scene, path, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=name_len), allocatable :: surfaces(:)
      character(len=:), allocatable :: where
      integer :: p
      if (.not. allocated(scene%panels)) return
      surfaces = surface_names(scene)
      do p = 1, size(scene%panels)
         associate (panel => scene%panels(p))
            where = group_context(path, 'panel', p, name_detail(panel%name))
            if (panel%kind == panel_load_cell) then
               if (len_trim(panel%wall) > 0) &
                  call check_surface_name(scene, surfaces, where, panel%wall, 'a load_cell', .true., status)
            else if (len_trim(panel%wall) == 0) then
               call status%fail(where//": variable wall is required for kind 'surface' (the name of the wall, box "// &
                                'side or structure the panel lies on, as in loads.csv)')
            else
               call check_surface_name(scene, surfaces, where, panel%wall, 'a surface panel', .false., status)
            end if
            if (.not. status%ok) return
         end associate
      end do
   end subroutine validate_panel_walls

   !> `wall` (variable wall of the group at `where`) must be one of the scene's `surfaces`, and (unless
   !> `may_move`) not a moving one: `who` reads a fixed surface.
   subroutine check_surface_name(scene, surfaces, where, wall, who, may_move, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: surfaces(:), where, wall, who
      logical, intent(in) :: may_move
      type(status_t), intent(inout) :: status
      if (.not. may_move .and. any(moving_surfaces(scene) == wall)) then
         call status%fail(where//": variable wall names '"//trim(wall)//"', which moves (its "// &
                          'motion): '//who//' reads a fixed wall or structure')
      else if (all(surfaces /= wall)) then
         if (size(surfaces) == 0) then
            call status%fail(where//": variable wall names '"//trim(wall)//"', but the scene has no "// &
                             'wall, box side wall or structure')
         else
            call status%fail(where//": variable wall must be the name of a wall, box side or structure, "// &
                             quoted_list(surfaces)//", got '"//trim(wall)//"'")
         end if
      end if
   end subroutine check_surface_name

   !> The names of the scene's constraining surfaces, as loads.csv names them: box sides that are walls,
   !> &wall groups, &structure groups (given names or the defaults).
   function surface_names(scene) result(names)
      type(scene_t), intent(in) :: scene
      character(len=name_len), allocatable :: names(:)
      integer :: k, side, i
      allocate (names(0))
      do k = 1, 3
         do side = 1, 2
            if (scene%grid%wall(side, k) == wall_none) cycle
            names = [names, given_or(scene%grid%wall_name(side, k), side_name(side, k))]
         end do
      end do
      names = [names, (given_or(scene%walls(i)%name, default_name('wall', i)), i = 1, wall_count(scene))]
      names = [names, (given_or(scene%structures(i)%name, default_name('structure', i)), i = 1, structure_count(scene))]
   end function surface_names

   !> The names of the &wall and &structure groups that move (a `motion` other than 'none').
   function moving_surfaces(scene) result(names)
      type(scene_t), intent(in) :: scene
      character(len=name_len), allocatable :: names(:)
      integer :: i
      allocate (names(0))
      do i = 1, wall_count(scene)
         if (scene%walls(i)%motion%kind /= motion_none) names = [names, given_or(scene%walls(i)%name, default_name('wall', i))]
      end do
      do i = 1, structure_count(scene)
         if (scene%structures(i)%motion%kind /= motion_none) &
            names = [names, given_or(scene%structures(i)%name, default_name('structure', i))]
      end do
   end function moving_surfaces

   !> The names of the walls (box sides that are walls, &wall), inlets and bodies are one namespace: the
   !> columns of loads.csv and bodies.csv, and the labels of their plots. A name the scene gives must
   !> differ from every other name, given or default (`wall_<k>`, `x_min`, `inlet_<k>`, `body_<k>`); the
   !> message names the variable the scene wrote, so it is always a name the user can change.
   subroutine validate_load_names(scene, path, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      type(load_name_t), allocatable :: names(:)
      character(len=:), allocatable :: owner
      integer :: n, k, side, i, j

      allocate (names(6 + wall_count(scene) + inlet_count(scene) + body_count(scene) + structure_count(scene)))
      n = 0
      do k = 1, 3
         do side = 1, 2
            if (scene%grid%wall(side, k) == wall_none) cycle
            n = n + 1
            call set_name(names(n), scene%grid%wall_name(side, k), side_name(side, k), &
                          'the &box_walls side '//side_name(side, k), group_context(path, 'box_walls', 0), &
                          side_name(side, k)//'_name')
         end do
      end do
      do i = 1, wall_count(scene)
         n = n + 1
         call set_name(names(n), scene%walls(i)%name, default_name('wall', i), 'the '//ordinal(i)//' &wall', &
                       group_context(path, 'wall', i, name_detail(scene%walls(i)%name)), 'name')
      end do
      do i = 1, inlet_count(scene)
         n = n + 1
         call set_name(names(n), scene%inlets(i)%name, default_name('inlet', i), 'the '//ordinal(i)//' &inlet', &
                       group_context(path, 'inlet', i, "material '"//trim(scene%inlets(i)%material)//"'"), 'name')
      end do
      do i = 1, body_count(scene)
         n = n + 1
         call set_name(names(n), scene%bodies(i)%name, default_name('body', i), 'the '//ordinal(i)//' &body', &
                       group_context(path, 'body', i, "material '"//trim(scene%bodies(i)%material)//"'"), 'name')
      end do
      do i = 1, structure_count(scene)
         n = n + 1
         call set_name(names(n), scene%structures(i)%name, default_name('structure', i), &
                       'the '//ordinal(i)//' &structure', &
                       group_context(path, 'structure', i, name_detail(scene%structures(i)%name)), 'name')
      end do

      ! Two default names never clash, so every clash involves a given name: report it there (the later
      ! of two given names).
      do j = 1, n
         if (.not. names(j)%given) cycle
         do i = 1, n
            if (i == j .or. names(i)%name /= names(j)%name) cycle
            if (names(i)%given .and. i > j) cycle
            owner = names(i)%owner
            if (.not. names(i)%given) owner = owner//' (its default name)'
            call status%fail(names(j)%where//': variable '//names(j)%variable//" '"//trim(names(j)%name)// &
                             "' is already used by "//owner)
            return
         end do
      end do
   end subroutine validate_load_names

   !> One entry of the load namespace: `given` if not empty, else `default`.
   subroutine set_name(entry, given, default, owner, where, variable)
      type(load_name_t), intent(out) :: entry
      character(len=*), intent(in) :: given, default, owner, where, variable
      entry%given = len_trim(given) > 0
      if (entry%given) then
         entry%name = given
      else
         entry%name = default
      end if
      entry%owner = owner
      entry%where = where
      entry%variable = variable
   end subroutine set_name
end module sensor_validation
