!> The scene's sensors on the boundary constraints (surface_sensors): its wall_pressure gauges (slots
!> 1 .. G, in gauges.csv order), then its panels and load cells (slots G + 1 .., in panels.csv order), put
!> on the constraints of the loads.csv entries they name; and the check that each lies on its surface.
module sensor_setup
   use kinds, only: rp
   use error_status, only: status_t
   use scene_description, only: scene_t, gauge_wall_pressure, panel_load_cell
   use surface_sensors, only: surface_sensor_t, sensor_gauge, sensor_panel, sensor_load_cell
   use background_grid, only: grid_t
   use constraint_list, only: constraint_list_t
   use input_text, only: real_text, group_context
   use scene_memory, only: gauge_count, panel_count
   implicit none
   private

   public :: attach_scene_sensors, check_sensors_on_surfaces

   !> A panel may reach this fraction of its area beyond the wettable part of its face (round-off of its corners).
   real(rp), parameter :: outside_tolerance = 1.0e-9_rp

contains

   !> Build the sensors of `scene` and put them on `constraints`; `names` are loads.csv's entries. `offset`
   !> (per sensor): how far it lies from its surface [m]; `outside`: the part of a panel's area off the
   !> wettable surface.
   subroutine attach_scene_sensors(scene, names, grid, constraints, offset, outside)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: names(:)
      type(grid_t), intent(in) :: grid
      type(constraint_list_t), intent(inout) :: constraints
      real(rp), allocatable, intent(out) :: offset(:), outside(:)
      type(surface_sensor_t), allocatable :: sensors(:)
      type(surface_sensor_t) :: sensor
      integer, allocatable :: entries(:)
      integer :: g, p
      allocate (sensors(0), entries(0))
      do g = 1, gauge_count(scene)
         associate (gauge => scene%gauges(g))
            if (gauge%kind /= gauge_wall_pressure) cycle
            sensors = [sensors, surface_sensor_t(slot=size(sensors) + 1, kind=sensor_gauge, point=gauge%point, &
                                                 radius=gauge%radius)]
            entries = [entries, findloc(names, gauge%wall, 1)]
         end associate
      end do
      do p = 1, panel_count(scene)
         associate (panel => scene%panels(p))
            sensor = surface_sensor_t(slot=size(sensors) + 1, lower=panel%lower, upper=panel%upper)
            sensor%kind = merge(sensor_load_cell, sensor_panel, panel%kind == panel_load_cell)
            sensors = [sensors, sensor]
            ! a load cell without a wall: every constraint in its box (entry 0)
            entries = [entries, merge(0, findloc(names, panel%wall, 1), len_trim(panel%wall) == 0)]
         end associate
      end do
      allocate (offset(size(sensors)), outside(size(sensors)))
      if (size(sensors) > 0) call constraints%attach_sensors(grid, sensors, entries, offset, outside)
   end subroutine attach_scene_sensors

   !> A wall_pressure gauge's point, and a surface panel's box, must lie on its wall's surface (within half a
   !> cell, on the rank that has the wall: every rank builds all walls); a panel must lie inside the part of
   !> the surface that can be wetted (the face, cut by the scene box and the walls across it).
   subroutine check_sensors_on_surfaces(scene, h, offset, outside, status)
      type(scene_t), intent(in) :: scene
      real(rp), intent(in) :: h, offset(:), outside(:)
      type(status_t), intent(inout) :: status
      integer :: g, p, slot
      slot = 0
      do g = 1, gauge_count(scene)
         associate (gauge => scene%gauges(g))
            if (gauge%kind /= gauge_wall_pressure) cycle
            slot = slot + 1
            if (offset(slot) <= 0.5_rp * h) cycle
            call status%fail(group_context(scene%source_file, 'gauge', g, "name '"//trim(gauge%name)//"'")// &
                             ': variable point lies '//trim(real_text(offset(slot)))// &
                             " m from the surface of wall '"//trim(gauge%wall)// &
                             "' (a wall_pressure gauge must lie on it, within half a cell)")
            return
         end associate
      end do
      do p = 1, panel_count(scene)
         slot = slot + 1
         associate (panel => scene%panels(p))
            if (panel%kind == panel_load_cell) cycle
            if (offset(slot) > 0.5_rp * h) then
               call status%fail(group_context(scene%source_file, 'panel', p, "name '"//trim(panel%name)//"'")// &
                                ': variables lower, upper lie '//trim(real_text(offset(slot)))// &
                                " m from the surface of wall '"//trim(panel%wall)// &
                                "' (a panel must lie on it, within half a cell)")
               return
            end if
            if (outside(slot) > outside_tolerance) then
               call status%fail(group_context(scene%source_file, 'panel', p, "name '"//trim(panel%name)//"'")// &
                                ': variables lower, upper reach beyond the face of wall '''//trim(panel%wall)// &
                                "': "//trim(real_text(100.0_rp * outside(slot)))//' % of the panel lies outside '// &
                                'the part of the surface the fluid can wet (the scene box, cut by the walls across it)')
               return
            end if
         end associate
      end do
   end subroutine check_sensors_on_surfaces
end module sensor_setup
