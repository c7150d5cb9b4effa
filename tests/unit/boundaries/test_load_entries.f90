!> Unit tests of src/boundaries/load_entries.f90 (issue 51): the order of the entries of loads.csv, decided
!> in one place, and the look-ups the walls, inlets and structures take their entry from.
module test_load_entries
   use assertions, only: assertEqual, assertTrue
   use scene_description, only: scene_t
   use load_entries, only: load_entry_t, scene_load_entries, entry_of, entries_before, entry_wall, entry_box_side, &
                           entry_inlet, entry_structure
   implicit none
   private

   public :: test_entries_in_loads_csv_order, test_entry_look_ups, test_scene_without_surfaces

contains

   !> Two &wall groups, the box sides x_min and y_max, one &inlet and two &structure groups (2-D).
   function scene_with_every_surface() result(scene)
      type(scene_t) :: scene
      scene%grid%dim = 2
      allocate (scene%walls(2), scene%inlets(1), scene%structures(2))
      scene%walls(1)%name = 'baffle'
      scene%walls(2)%name = 'ramp'
      scene%grid%wall(1, 1) = 'slip'
      scene%grid%wall_name(1, 1) = 'back_wall'
      scene%grid%wall(2, 2) = 'no_slip'
      scene%grid%wall_name(2, 2) = 'lid'
      scene%inlets(1)%name = 'feed'
      scene%structures(1)%name = 'pier'
      scene%structures(2)%name = 'deck'
   end function scene_with_every_surface

   !> The &wall groups, the box sides (x_min before y_max), the inlets, the structures: loads.csv's order.
   subroutine test_entries_in_loads_csv_order()
      type(load_entry_t), allocatable :: entries(:)
      character(len=9), parameter :: expected(7) = [character(len=9) :: 'baffle', 'ramp', 'back_wall', 'lid', 'feed', &
                                                     'pier', 'deck']
      integer, allocatable :: groups(:), indices(:)
      integer :: e
      entries = scene_load_entries(scene_with_every_surface())
      call assertEqual(7, size(entries), 'one entry per surface')
      do e = 1, size(expected)
         call assertTrue(entries(e)%name == expected(e), 'entry '//expected(e)//' in its place')
      end do
      groups = entries%group      ! contiguous copies (a component section passed on would be a temporary)
      indices = entries%index
      call assertEqual([entry_wall, entry_wall, entry_box_side, entry_box_side, entry_inlet, entry_structure, &
                        entry_structure], groups, 'groups')
      call assertEqual([1, 2, 1, 2, 1, 1, 2], indices, 'index within the group')
   end subroutine test_entries_in_loads_csv_order

   !> entry_of finds the k-th member of a group (0 when there is none); entries_before counts the entries
   !> ahead of a group (the structures' body-field entries follow from it).
   subroutine test_entry_look_ups()
      type(load_entry_t), allocatable :: entries(:)
      entries = scene_load_entries(scene_with_every_surface())
      call assertEqual(2, entry_of(entries, entry_wall, 2), 'second &wall')
      call assertEqual(4, entry_of(entries, entry_box_side, 2), 'second box side (y_max)')
      call assertEqual(5, entry_of(entries, entry_inlet, 1), 'the inlet')
      call assertEqual(7, entry_of(entries, entry_structure, 2), 'second structure')
      call assertEqual(0, entry_of(entries, entry_inlet, 2), 'no second inlet')
      call assertEqual(5, entries_before(entries, entry_structure), 'five entries before the structures')
      call assertEqual(2, entries_before(entries, entry_box_side), 'two before the box sides')
   end subroutine test_entry_look_ups

   !> A scene without walls, sides, inlets or structures has no entries; a group it lacks has all entries
   !> before it.
   subroutine test_scene_without_surfaces()
      type(scene_t) :: scene
      type(load_entry_t), allocatable :: entries(:)
      scene%grid%dim = 3
      entries = scene_load_entries(scene)
      call assertEqual(0, size(entries), 'no entries')
      scene%grid%wall(1, 3) = 'slip'
      scene%grid%wall_name(1, 3) = 'floor'
      entries = scene_load_entries(scene)
      call assertEqual(1, size(entries), 'the floor only')
      call assertEqual(1, entries_before(entries, entry_structure), 'no structures: every entry before them')
   end subroutine test_scene_without_surfaces
end module test_load_entries
