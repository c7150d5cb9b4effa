!> The boundary constraints of a scene, built in one place and listed in the order of loads.csv's entries
!> (load_entries): the `&wall` groups, the `&box_walls` sides, each `&inlet`'s feeder and closing walls,
!> the `&structure` groups. Which type a group becomes and which condition its keyword names is decided
!> here (and in wall_conditions' condition_of) only.
module constraint_factory
   use kinds, only: rp
   use scene_description, only: scene_t, wall_spec_t, opening_far_end
   use background_grid, only: grid_t
   use wall_motion, only: prescribed_motion
   use load_entries, only: load_entry_t, scene_load_entries, entry_of, entry_wall, entry_box_side, entry_inlet, &
                           entry_structure, box_side_walls
   use wall_conditions, only: condition_of, slip_condition_t, prescribed_condition_t
   use planar_wall, only: planar_wall_t, make_planar_wall
   use structure_surface, only: structure_surface_t, make_structure_surface
   use constraint_list, only: constraint_list_t
   implicit none
   private

   !> Extent tolerance of an inlet's walls, in cells: only nodes on the opening itself are fed.
   real(rp), parameter :: opening_margin = 1.0e-6_rp

   public :: build_constraints

contains

   !> The constraints of `scene` on `grid` (with their local nodes), each placed where its motion has it
   !> at `time`.
   subroutine build_constraints(scene, grid, time, list)
      type(scene_t), intent(in) :: scene
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: time
      type(constraint_list_t), intent(out) :: list
      type(load_entry_t), allocatable :: entries(:)
      entries = scene_load_entries(scene)
      allocate (list%items(0), list%structure(0), list%loads(0), list%blocks_flow(0), list%feeder(0))
      call add_walls()
      call add_inlets()
      call add_structures()

   contains

      !> The `&wall` groups (moving ones with their motion) and the `&box_walls` sides.
      subroutine add_walls()
         type(wall_spec_t), allocatable :: specs(:)
         type(planar_wall_t) :: wall
         integer :: w, n_walls, load
         n_walls = 0
         if (allocated(scene%walls)) n_walls = size(scene%walls)
         if (n_walls > 0) then
            specs = [scene%walls, box_side_walls(scene%grid)]
         else
            specs = box_side_walls(scene%grid)
         end if
         do w = 1, size(specs)
            if (w <= n_walls) then
               load = entry_of(entries, entry_wall, w)
            else
               load = entry_of(entries, entry_box_side, w - n_walls)
            end if
            wall = make_planar_wall(grid, specs(w)%point, specs(w)%normal, specs(w)%lower, specs(w)%upper, grid%h, &
                                    condition_of(specs(w)%condition, specs(w)%friction), load=load, &
                                    moment_point=specs(w)%moment_point)
            if (w <= n_walls) then
               if (allocated(scene%wall_tables)) then
                  wall%motion = prescribed_motion(specs(w)%motion, specs(w)%normal, scene%gravity, grid%dim, &
                                                  scene%wall_tables(w))
               else
                  wall%motion = prescribed_motion(specs(w)%motion, specs(w)%normal, scene%gravity, grid%dim)
               end if
               if (wall%motion%moving()) then
                  wall%moving = .true.
                  wall%rest_point = specs(w)%point
                  wall%rest_lower = specs(w)%lower
                  wall%rest_upper = specs(w)%upper
                  call wall%place(grid, time)
                  call wall%refresh(grid)
               end if
            end if
            call list%append(wall, 0)
         end do
      end subroutine add_walls

      !> Each inlet's feeder (v0 while it is open, algorithms.md section 4.3) and the slip walls that close its
      !> opening after it (and before it, if it opens later), one loads.csv entry for all three.
      subroutine add_inlets()
         type(prescribed_condition_t) :: feeding
         real(rp) :: far_end(3), lower(3), upper(3), margin
         integer :: i, dim, load, feeder
         if (.not. allocated(scene%inlets)) return
         dim = scene%grid%dim
         margin = opening_margin * scene%grid%cell_size
         do i = 1, size(scene%inlets)
            associate (spec => scene%inlets(i))
               far_end = opening_far_end(spec, dim)
               lower = min(spec%point, far_end)
               upper = max(spec%point, far_end)
               load = entry_of(entries, entry_inlet, i)
               call feeding%prescribe(grid%frame%grid_vector(spec%velocity * spec%direction(1:dim)))
               call list%append(make_planar_wall(grid, spec%point, spec%direction, lower, upper, margin, feeding, &
                                                 active_from=spec%start_time, active_until=spec%end_time, load=load), &
                                0, feeder)
               list%feeder = [list%feeder, feeder]
               call list%append(make_planar_wall(grid, spec%point, spec%direction, lower, upper, margin, &
                                                 slip_condition_t(), active_from=spec%end_time, load=load), 0)
               if (spec%start_time > 0.0_rp) &
                  call list%append(make_planar_wall(grid, spec%point, spec%direction, lower, upper, margin, &
                                                    slip_condition_t(), active_until=spec%start_time, load=load), 0)
            end associate
         end do
      end subroutine add_inlets

      !> The `&structure` groups (moving ones with their motion).
      subroutine add_structures()
         type(structure_surface_t) :: structure
         integer :: s
         if (.not. allocated(scene%structures)) return
         do s = 1, size(scene%structures)
            associate (spec => scene%structures(s))
               structure = make_structure_surface(grid, spec%shape, condition_of(spec%condition, spec%friction), &
                                                  entry_of(entries, entry_structure, s), spec%moment_point)
               if (allocated(scene%structure_tables)) then
                  structure%motion = prescribed_motion(spec%motion, spec%motion%direction, scene%gravity, grid%dim, &
                                                       scene%structure_tables(s))
               else
                  structure%motion = prescribed_motion(spec%motion, spec%motion%direction, scene%gravity, grid%dim)
               end if
               structure%moving = structure%motion%moving()
               structure%rest_shape = spec%shape
               call structure%place(grid, time)
               call structure%refresh(grid)
               call list%append(structure, s)
            end associate
         end do
      end subroutine add_structures
   end subroutine build_constraints
end module constraint_factory
