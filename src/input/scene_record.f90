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
   use scene_description, only: scene_t
   use scene_reader, only: known_groups, group_variables, entry_count
   use run_group, only: run_value
   use grid_group, only: grid_value, box_walls_value
   use gravity_group, only: gravity_value
   use material_group, only: material_value
   use body_group, only: body_value
   use wall_group, only: wall_value
   use structure_group, only: structure_value
   use inlet_group, only: inlet_value
   use gauge_group, only: gauge_value
   use panel_group, only: panel_value
   use damping_zone_group, only: damping_zone_value
   use contact_group, only: contact_value
   implicit none
   private

   public :: scene_namelist_groups, scene_namelist_text

   !> The text of one namelist group, `&name` to `/`, one variable per line.
   type, public :: namelist_text_t
      character(len=:), allocatable :: text
   end type namelist_text_t

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
         text = grid_value(scene%grid, name)
      case ('box_walls')
         text = box_walls_value(scene%grid, name)
      case ('gravity')
         text = gravity_value(scene%gravity, name)
      case ('material')
         text = material_value(scene%materials(k), name)
      case ('body')
         text = body_value(scene%bodies(k), name)
      case ('wall')
         text = wall_value(scene%walls(k), name)
      case ('inlet')
         text = inlet_value(scene%inlets(k), name)
      case ('gauge')
         text = gauge_value(scene%gauges(k), name)
      case ('panel')
         text = panel_value(scene%panels(k), name)
      case ('damping_zone')
         text = damping_zone_value(scene%damping_zones(k), name)
      case ('contact')
         text = contact_value(scene%contacts(k), name)
      case ('structure')
         text = structure_value(scene%structures(k), name)
      case default
         text = ''
      end select
   end function value_text
end module scene_record
