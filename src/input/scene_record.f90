!> The resolved scene as namelist text: every variable of every group, with the values the run uses
!> (after the overrides of the command line and the defaults resolved by resolve_scene). Checkpoints
!> store it, so that a restart can tell which variables of the scene were changed (scene_comparison).
!>
!> Reals are written in the shortest form that reads back exactly (real_text), strings quoted, every
!> array whole; the text reads back as a scene file giving the same scene. The same text is the
!> output folder's scene.nml and the `scene` attribute of every HDF5 file (provenance).
!> `&run overwrite` is left out: it is an action on the output folder, not part of the scene, and a run
!> started again from the text must not replace results silently. `&run flip_fraction` is left out with
!> `transfer = 'apic'`, which refuses it.
module scene_record
   use kinds, only: rp
   use scene_description, only: scene_t, motion_spec_t
   use shape_geometry, only: no_vertex
   use scene_reader, only: known_groups, group_variables, entry_count
   use gauge_group, only: gauge_value
   use run_group, only: run_value
   use material_group, only: material_value
   use inlet_group, only: inlet_value
   use contact_group, only: contact_value
   use input_text, only: int_text, real_text, real_list_text, quoted, logical_text
   implicit none
   private

   public :: scene_namelist_groups, scene_namelist_text

   !> The text of one namelist group, `&name` to `/`, one variable per line.
   type, public :: namelist_text_t
      character(len=:), allocatable :: text
   end type namelist_text_t

   !> The 2 sides of each axis as `&box_walls` names them: x_min is side 1 of axis 1.
   character(len=*), parameter :: axis_letters = 'xyz'

contains

   !> Every group of the scene in the order of known_groups, a repeated group once per entry.
   function scene_namelist_groups(scene) result(groups)
      type(scene_t), intent(in) :: scene
      type(namelist_text_t), allocatable :: groups(:)
      integer :: g, k, n
      n = 0
      do g = 1, size(known_groups)
         n = n + entry_count(scene, trim(known_groups(g)))
      end do
      allocate (groups(n))
      n = 0
      do g = 1, size(known_groups)
         do k = 1, entry_count(scene, trim(known_groups(g)))
            n = n + 1
            groups(n)%text = group_text(scene, trim(known_groups(g)), k)
         end do
      end do
   end function scene_namelist_groups

   !> The whole scene as one namelist text (groups on lines of their own).
   function scene_namelist_text(scene) result(text)
      type(scene_t), intent(in) :: scene
      character(len=:), allocatable :: text
      type(namelist_text_t), allocatable :: groups(:)
      integer :: g
      groups = scene_namelist_groups(scene)
      text = ''
      do g = 1, size(groups)
         text = text//groups(g)%text//new_line('a')
      end do
   end function scene_namelist_text

   !> Entry k of `group`: every variable the reader knows for it, in its order.
   function group_text(scene, group, k) result(text)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: group
      integer, intent(in) :: k
      character(len=:), allocatable :: text
      character(len=:), allocatable :: names(:)
      integer :: v
      names = group_variables(group)
      text = '&'//group
      do v = 1, size(names)
         if (group == 'run' .and. names(v) == 'overwrite') cycle
         ! APIC has no blend: a flip_fraction in the text would make it a scene that is refused
         if (group == 'run' .and. names(v) == 'flip_fraction' .and. scene%run%transfer == 'apic') cycle
         text = text//new_line('a')//'   '//trim(names(v))//' = '//value_text(scene, group, k, trim(names(v)))
      end do
      text = text//new_line('a')//'/'
   end function group_text

   !> The value of variable `name` of entry k of `group` as namelist text; '' for a variable this module
   !> does not know (the unit test checks that there is none).
   function value_text(scene, group, k, name) result(text)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: group, name
      integer, intent(in) :: k
      character(len=:), allocatable :: text
      select case (group)
      case ('run')
         text = run_value(scene%run, name)
      case ('grid')
         text = grid_value(scene, name)
      case ('box_walls')
         text = box_walls_value(scene, name)
      case ('gravity')
         text = ''
         if (name == 'acceleration') text = real_list_text(scene%gravity)
      case ('material')
         text = material_value(scene%materials(k), name)
      case ('body')
         text = body_value(scene, k, name)
      case ('wall')
         text = wall_value(scene, k, name)
      case ('inlet')
         text = inlet_value(scene%inlets(k), name)
      case ('gauge')
         text = gauge_value(scene%gauges(k), name)
      case ('contact')
         text = contact_value(scene%contacts(k), name)
      case ('structure')
         text = structure_value(scene, k, name)
      case default
         text = ''
      end select
   end function value_text

   function grid_value(scene, name) result(text)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      associate (grid => scene%grid)
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
      end associate
   end function grid_value

   !> `x_min` ... `z_max`: the side's condition; `x_min_name` ...: its name; `friction`: the sides' mu.
   function box_walls_value(scene, name) result(text)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      integer :: axis, side
      text = ''
      if (name == 'friction') then
         text = real_text(scene%grid%wall_friction)
         return
      end if
      if (len(name) < 5) return
      axis = index(axis_letters, name(1:1))
      side = 0
      if (name(2:5) == '_min') side = 1
      if (name(2:5) == '_max') side = 2
      if (axis == 0 .or. side == 0) return
      if (name(6:) == '') then
         text = quoted(scene%grid%wall(side, axis))
      else if (name(6:) == '_name') then
         text = quoted(scene%grid%wall_name(side, axis))
      end if
   end function box_walls_value

   function body_value(scene, k, name) result(text)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      associate (body => scene%bodies(k))
         select case (name)
         case ('name')
            text = quoted(body%name)
         case ('material')
            text = quoted(body%material)
         case ('shape')
            text = quoted(body%shape%kind)
         case ('lower')
            text = real_list_text(body%lower)
         case ('upper')
            text = real_list_text(body%upper)
         case ('centre')
            text = real_list_text(body%shape%centre)
         case ('size')
            text = real_list_text(body%shape%size)
         case ('rotation')
            text = real_text(body%shape%rotation)
         case ('rotation_axis')
            text = real_list_text(body%shape%rotation_axis)
         case ('radius')
            text = real_text(body%shape%radius)
         case ('axis')
            text = real_list_text(body%shape%axis)
         case ('length')
            text = real_text(body%shape%length)
         case ('vertices')
            text = vertex_list(body%shape%vertices)
         case ('z_range')
            text = real_list_text(body%shape%z_range)
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
            text = ''
         end select
      end associate
   end function body_value

   function wall_value(scene, k, name) result(text)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      associate (wall => scene%walls(k))
         select case (name)
         case ('point')
            text = real_list_text(wall%point)
         case ('normal')
            text = real_list_text(wall%normal)
         case ('lower')
            text = real_list_text(wall%lower)
         case ('upper')
            text = real_list_text(wall%upper)
         case ('condition')
            text = quoted(wall%condition)
         case ('friction')
            text = real_text(wall%friction)
         case ('name')
            text = quoted(wall%name)
         case ('moment_point')
            text = real_list_text(wall%moment_point)
         case default
            text = motion_value(wall%motion, name)
         end select
      end associate
   end function wall_value

   !> A variable of the prescribed motion of a `&wall` or a `&structure`; '' for another variable.
   function motion_value(motion, name) result(text)
      type(motion_spec_t), intent(in) :: motion
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('motion')
         text = quoted(motion%kind)
      case ('motion_start')
         text = real_text(motion%start)
      case ('wave_height')
         text = real_text(motion%wave_height)
      case ('water_depth')
         text = real_text(motion%water_depth)
      case ('motion_direction')
         text = real_list_text(motion%direction)
      case ('motion_file')
         text = quoted(motion%file)
      case ('motion_checksum')
         text = quoted(motion%checksum)
      case default
         text = ''
      end select
   end function motion_value

   function structure_value(scene, k, name) result(text)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      associate (structure => scene%structures(k), shape => scene%structures(k)%shape)
         select case (name)
         case ('name')
            text = quoted(structure%name)
         case ('shape')
            text = quoted(shape%kind)
         case ('centre')
            text = real_list_text(shape%centre)
         case ('size')
            text = real_list_text(shape%size)
         case ('rotation')
            text = real_text(shape%rotation)
         case ('rotation_axis')
            text = real_list_text(shape%rotation_axis)
         case ('radius')
            text = real_text(shape%radius)
         case ('axis')
            text = real_list_text(shape%axis)
         case ('length')
            text = real_text(shape%length)
         case ('vertices')
            text = vertex_list(shape%vertices)
         case ('z_range')
            text = real_list_text(shape%z_range)
         case ('lower')
            text = real_list_text(structure%lower)
         case ('upper')
            text = real_list_text(structure%upper)
         case ('condition')
            text = quoted(structure%condition)
         case ('friction')
            text = real_text(structure%friction)
         case ('moment_point')
            text = real_list_text(structure%moment_point)
         case default
            text = motion_value(structure%motion, name)
         end select
      end associate
   end function structure_value

   !> The vertices as given, "x1, y1, x2, y2, ..." up to the first empty slot; none: a namelist null
   !> value "," (the variable keeps its default, no vertex).
   function vertex_list(vertices) result(text)
      real(rp), intent(in) :: vertices(:, :)
      character(len=:), allocatable :: text
      real(rp), allocatable :: flat(:)
      integer :: n
      flat = reshape(vertices, [size(vertices)])
      n = 0
      do while (n < size(flat))
         if (flat(n + 1) >= no_vertex) exit
         n = n + 1
      end do
      if (n == 0) then
         text = ','
      else
         text = real_list_text(flat(1:n))
      end if
   end function vertex_list
end module scene_record
