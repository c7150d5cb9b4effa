!> The entries of loads.csv, in their order: the one place that order is decided (docs/output.md,
!> "Loads, gauges and bodies"). Each surface that takes load from the material is one entry, named as the scene names
!> it: the `&wall` groups, the `&box_walls` sides that are walls (x_min, x_max, y_min, ... in that order),
!> the `&inlet` groups (an inlet's feeder and its closing walls are one entry), the `&structure` groups.
!> The constraints built from the scene (constraint_factory) take their entry from
!> here, and wall_loads names its columns from here. The box sides as `&wall` entries (box_side_walls) are
!> here too: the walls built from them and their entries come from the one enumeration.
module load_entries
   use kinds, only: rp, name_len
   use scene_description, only: scene_t, wall_spec_t, grid_spec_t, wall_none
   implicit none
   private

   !> What an entry is: which scene group it comes from.
   integer, parameter, public :: entry_wall = 1, entry_box_side = 2, entry_inlet = 3, entry_structure = 4

   type, public :: load_entry_t
      character(len=name_len) :: name = ''
      integer :: group = 0         !< entry_wall ... entry_structure
      integer :: index = 0         !< its place in that group: the k-th &wall, box side, &inlet or &structure
   end type load_entry_t

   public :: scene_load_entries, entry_of, entries_before, box_side_walls

contains

   !> The scene's loads.csv entries in order (the scene's names are resolved: defaults filled in).
   function scene_load_entries(scene) result(entries)
      type(scene_t), intent(in) :: scene
      type(load_entry_t), allocatable :: entries(:)
      type(wall_spec_t), allocatable :: sides(:)
      integer :: i
      allocate (entries(0))
      if (allocated(scene%walls)) then
         entries = [entries, (load_entry_t(scene%walls(i)%name, entry_wall, i), i = 1, size(scene%walls))]
      end if
      sides = box_side_walls(scene%grid)
      entries = [entries, (load_entry_t(sides(i)%name, entry_box_side, i), i = 1, size(sides))]
      if (allocated(scene%inlets)) then
         entries = [entries, (load_entry_t(scene%inlets(i)%name, entry_inlet, i), i = 1, size(scene%inlets))]
      end if
      if (allocated(scene%structures)) then
         entries = [entries, (load_entry_t(scene%structures(i)%name, entry_structure, i), &
                              i = 1, size(scene%structures))]
      end if
   end function scene_load_entries

   !> The entry (its index in `entries`) of the index-th member of `group`; 0 if there is none.
   pure integer function entry_of(entries, group, index) result(found)
      type(load_entry_t), intent(in) :: entries(:)
      integer, intent(in) :: group, index
      integer :: e
      found = 0
      do e = 1, size(entries)
         if (entries(e)%group == group .and. entries(e)%index == index) then
            found = e
            return
         end if
      end do
   end function entry_of

   !> How many entries come before the first of `group` (all of them if the group has none).
   pure integer function entries_before(entries, group) result(before)
      type(load_entry_t), intent(in) :: entries(:)
      integer, intent(in) :: group
      before = findloc(entries%group, group, 1) - 1
      if (before < 0) before = size(entries)
   end function entries_before

   !> The sides of the scene box that `&box_walls` makes walls, as `&wall` entries: each is the face of
   !> the box lower..lower + ncells h (world frame), with the normal pointing into the box.
   pure function box_side_walls(grid) result(walls)
      type(grid_spec_t), intent(in) :: grid
      type(wall_spec_t), allocatable :: walls(:)
      type(wall_spec_t) :: wall
      real(rp) :: upper(3)
      integer :: k, side
      allocate (walls(0))
      upper = grid%origin + grid%ncells * grid%cell_size
      do k = 1, grid%dim
         do side = 1, 2
            if (grid%wall(side, k) == wall_none) cycle
            wall%condition = grid%wall(side, k)
            wall%friction = grid%wall_friction
            wall%name = grid%wall_name(side, k)
            wall%normal = 0.0_rp
            wall%normal(k) = merge(1.0_rp, -1.0_rp, side == 1)
            wall%lower = grid%origin
            wall%upper = upper
            wall%point = grid%origin
            if (side == 2) wall%point(k) = upper(k)
            wall%lower(k) = wall%point(k)
            wall%upper(k) = wall%point(k)
            ! the moment of a box side is taken about its lower corner
            wall%moment_point = wall%point
            walls = [walls, wall]
         end do
      end do
   end function box_side_walls
end module load_entries
