!> The values of a scene that default to something derived (`output_interval = 0`, `floor_size = 0`, grid
!> cell counts, material indices of bodies, default names, gauge radii, moment points), resolved once the
!> whole scene is read, and the look-ups of a group by name.
module scene_defaults
   use kinds, only: rp, name_len
   use scene_description, only: scene_t, structure_spec_t, wall_none, structure_shape, gauge_level, &
                                gauge_wall_pressure
   use input_text, only: int_text
   use shape_geometry, only: shape_t, polygon_vertices, polygon_area, shape_polygon, shape_extruded_polygon
   use grid_group, only: side_name
   use motion_spec, only: motion_spec_t, motion_regular_wave, motion_irregular_wave
   use material_group, only: find_material
   implicit none
   private

   public :: resolve_scene, default_name, find_structure, structure_name

contains

   !> Replace the "0 = derived" defaults by their values and fill the derived fields. Call once, on a
   !> scene that `validate_scene` accepted.
   subroutine resolve_scene(scene)
      type(scene_t), intent(inout) :: scene
      integer :: k, b, i, w, g, side

      associate (run => scene%run, grid => scene%grid)
         ! Validated >= 0, so not > 0 means 0.
         if (.not. run%output_interval > 0.0_rp) run%output_interval = run%end_time / 100.0_rp
         if (.not. run%floor_size > 0.0_rp) run%floor_size = product(grid%extent(1:grid%dim - 1))
         grid%ncells = 1
         do k = 1, grid%dim
            grid%ncells(k) = nint(grid%extent(k) / grid%cell_size)
         end do
         ! sides without a wall keep the empty name: they carry no load
         do k = 1, 3
            do side = 1, 2
               if (grid%wall(side, k) /= wall_none .and. len_trim(grid%wall_name(side, k)) == 0) then
                  grid%wall_name(side, k) = side_name(side, k)
               end if
            end do
         end do
      end associate
      if (.not. allocated(scene%bodies)) allocate (scene%bodies(0))
      do b = 1, size(scene%bodies)
         scene%bodies(b)%material_index = find_material(scene%materials, scene%bodies(b)%material)
         if (len_trim(scene%bodies(b)%name) == 0) scene%bodies(b)%name = default_name('body', b)
      end do
      if (.not. allocated(scene%walls)) allocate (scene%walls(0))     ! (wall normals are made unit where walls are built)
      do w = 1, size(scene%walls)
         associate (wall => scene%walls(w))
            if (len_trim(wall%name) == 0) wall%name = default_name('wall', w)
            ! each component not given is the wall point's
            where (wall%moment_point >= huge(1.0_rp)) wall%moment_point = wall%point
            call resolve_wave_defaults(wall%motion)
         end associate
      end do
      if (.not. allocated(scene%inlets)) allocate (scene%inlets(0))
      do i = 1, size(scene%inlets)
         associate (inlet => scene%inlets(i))
            inlet%material_index = find_material(scene%materials, inlet%material)
            inlet%direction(1:scene%grid%dim) = inlet%direction(1:scene%grid%dim) / norm2(inlet%direction(1:scene%grid%dim))
            if (len_trim(inlet%name) == 0) inlet%name = default_name('inlet', i)
         end associate
      end do
      if (.not. allocated(scene%contacts)) allocate (scene%contacts(0))
      do i = 1, size(scene%contacts)
         do k = 1, 2
            scene%contacts(i)%material_index(k) = find_material(scene%materials, scene%contacts(i)%between(k))
         end do
      end do
      if (.not. allocated(scene%structures)) allocate (scene%structures(0))
      do i = 1, size(scene%contacts)
         do k = 1, 2
            scene%contacts(i)%structure_index(k) = find_structure(scene%structures, scene%contacts(i)%between(k))
         end do
      end do
      do i = 1, size(scene%structures)
         associate (structure => scene%structures(i))
            if (len_trim(structure%name) == 0) structure%name = default_name('structure', i)
            call resolve_wave_defaults(structure%motion)
            ! a box given by its corners becomes centre and size (validated: both corners, no centre/size)
            if (structure%lower(1) < huge(1.0_rp)) then
               structure%shape = structure_shape(structure, scene%grid%dim)
               structure%lower = huge(1.0_rp)
               structure%upper = huge(1.0_rp)
            end if
            ! each component not given is the shape's centre's
            where (structure%moment_point >= huge(1.0_rp)) structure%moment_point = shape_centre(structure%shape, &
                                                                                                 scene%grid%dim)
         end associate
      end do
      if (.not. allocated(scene%panels)) allocate (scene%panels(0))
      if (.not. allocated(scene%damping_zones)) allocate (scene%damping_zones(0))
      if (.not. allocated(scene%gauges)) allocate (scene%gauges(0))
      do g = 1, size(scene%gauges)
         associate (gauge => scene%gauges(g))
            ! Validated >= 0, so not > 0 means 0: one cell, a level gauge's column half a cell either side
            ! (a connected level's one cell: a narrower column can miss the particles of a whole layer as
            ! they stream past, a gap it would not bridge).
            if (.not. gauge%radius > 0.0_rp) then
               if (gauge%kind == gauge_level .or. gauge%kind == gauge_wall_pressure) then
                  gauge%radius = 0.5_rp * scene%grid%cell_size
               else
                  gauge%radius = scene%grid%cell_size
               end if
            end if
         end associate
      end do
   end subroutine resolve_scene

   !> A piston's waves: the ramp not given (< 0) two periods (peak periods) long, the irregular record not
   !> given (0) 200 peak periods long (docs/input.md).
   pure subroutine resolve_wave_defaults(motion)
      type(motion_spec_t), intent(inout) :: motion
      if (motion%kind == motion_regular_wave .and. motion%ramp_time < 0.0_rp) motion%ramp_time = 2.0_rp * motion%wave_period
      if (motion%kind /= motion_irregular_wave) return
      if (motion%ramp_time < 0.0_rp) motion%ramp_time = 2.0_rp * motion%peak_period
      if (.not. motion%wave_duration > 0.0_rp) motion%wave_duration = 200.0_rp * motion%peak_period
   end subroutine resolve_wave_defaults

   !> The point a structure's moment is taken about by default: the centre of a box, circle, sphere or
   !> cylinder, the centroid of a polygon's area (of an extruded polygon: at mid z_range), so that the
   !> buoyancy of a submerged structure has no moment about it.
   pure function shape_centre(shape, dim) result(centre)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      real(rp) :: centre(3)
      real(rp), allocatable :: v(:, :)
      real(rp) :: area, cross
      integer :: k, n
      centre = shape%centre
      if (shape%kind /= shape_polygon .and. shape%kind /= shape_extruded_polygon) return
      v = polygon_vertices(shape)
      n = size(v, 2)
      area = polygon_area(v)
      centre = 0.0_rp
      do k = 1, n
         associate (a => v(:, k), b => v(:, modulo(k, n) + 1))
            cross = a(1) * b(2) - b(1) * a(2)
            centre(1:2) = centre(1:2) + (a + b) * cross
         end associate
      end do
      centre(1:2) = centre(1:2) / (6.0_rp * area)
      if (dim == 3) centre(3) = 0.5_rp * (shape%z_range(1) + shape%z_range(2))
   end function shape_centre

   !> Default name of the k-th entry of a repeated group that carries loads: `wall_<k>`, `inlet_<k>`,
   !> `body_<k>`, `structure_<k>`.
   pure function default_name(group, k) result(name)
      character(len=*), intent(in) :: group
      integer, intent(in) :: k
      character(len=:), allocatable :: name
      name = trim(group)//'_'//int_text(k)
   end function default_name

   !> Index of the structure called `name` (its name or default name); 0 if there is none.
   pure integer function find_structure(structures, name) result(found)
      type(structure_spec_t), intent(in) :: structures(:)
      character(len=*), intent(in) :: name
      integer :: s
      found = 0
      do s = 1, size(structures)
         if (structure_name(structures, s) == name) then
            found = s
            return
         end if
      end do
   end function find_structure

   !> The name structure s has in loads.csv: its `name`, or the default `structure_<s>`.
   pure function structure_name(structures, s) result(name)
      type(structure_spec_t), intent(in) :: structures(:)
      integer, intent(in) :: s
      character(len=name_len) :: name
      name = structures(s)%name
      if (len_trim(name) == 0) name = default_name('structure', s)
   end function structure_name
end module scene_defaults
