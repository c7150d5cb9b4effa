!> Checks of a scene's values (the allowed ranges of docs/input.md) and resolution of the values that
!> default to something derived (`output_interval = 0`, `floor_size = 0`, grid cell counts, material
!> indices of bodies, default names, gauge radii, moment points). Both work on a whole scene, whatever
!> file(s) its values came from.
module scene_validation
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, run_control_t, grid_spec_t, material_spec_t, body_spec_t, wall_spec_t, &
                                inlet_spec_t, gauge_spec_t, contact_spec_t, structure_spec_t, opening_far_end, wall_none, &
                                has_velocity_file, motion_spec_t, structure_shape, &
                                wall_slip, wall_no_slip, wall_friction, motion_none, motion_solitary_wave, motion_table, &
                                model_newtonian_fluid, model_linear_elastic, model_rigid, gauge_pressure, gauge_level, &
                                gauge_connected_level, gauge_velocity, gauge_wall_pressure, &
                                particle_field_names, field_precision_keywords
   use input_text, only: int_text, real_text, quoted_list, group_context, ordinal
   use memory_budget, only: memory_budget_t, byte_text
   use shape_geometry, only: shape_t, shape_problem, shape_bounds, box_corners, polygon_vertices, polygon_area, &
                             max_vertices, no_vertex, shape_box, shape_circle, shape_sphere, shape_cylinder, &
                             shape_polygon, shape_extruded_polygon
   use body_lattice, only: has_points_file, box_corners_given, body_shape, body_bounds, count_particles, particle_spacing
   use wall_motion, only: wall_motion_t, prescribed_motion, box_excursion
   implicit none
   private

   public :: validate_scene, resolve_scene, find_material, find_structure, default_name, side_name
   public :: check_scene_memory, scene_particle_count, memory_estimate_per_rank, scene_advice

   !> Peak resident memory per particle a run grows by [bytes]: particle arrays, sort buffers and the
   !> fields file's buffers, measured as the slope of run_summary.csv's peak_memory_bytes over the
   !> particle count (dam break at 6/12/24 particles per cell: 300 to 344; 3-D column at 1/2/3: 320).
   integer(i8), parameter :: bytes_per_particle(2:3) = [300_i8, 320_i8]
   !> Grid memory per node [bytes]: mass, momentum, force, velocity and its increment, MUSL's remapped
   !> momentum (1 + 5 dim reals), doubled for halos, stabilization and grid output. [R]
   integer(i8), parameter :: bytes_per_node(2:3) = [2_i8 * 8_i8 * 11_i8, 2_i8 * 8_i8 * 16_i8]
   !> Grid memory per node of each body with a velocity field of its own (&contact, body_contact): its
   !> mass, momentum, force and mass gradient in the accumulated rows, velocity, increment and MUSL's
   !> remapped momentum (1 + 6 dim reals), doubled for halos. [R]
   integer(i8), parameter :: bytes_per_field_node(2:3) = [2_i8 * 8_i8 * 13_i8, 2_i8 * 8_i8 * 19_i8]

   !> Accepted `&material stabilization=` keywords in their canonical spelling (compared without case).
   character(len=*), parameter, public :: stabilization_keywords(*) = [character(len=5) :: 'none', 'C0', 'NB', 'FOAL1']
   !> Accepted `&material oscillation_rule=` and `smoothed_variables=` keywords (FOAL1 options).
   character(len=*), parameter, public :: oscillation_rule_keywords(*) = [character(len=3) :: 'OR', 'AND']
   character(len=*), parameter, public :: smoothed_variables_keywords(*) = [character(len=8) :: 'stress', 'pressure']
   !> Accepted `&material volume_correction=` keywords (docs/volume-conservation.md).
   character(len=*), parameter, public :: volume_correction_keywords(*) = &
      [character(len=23) :: 'none', 'shifting', 'eos_relaxation', 'shifting+eos_relaxation']
   !> Above this shifting coefficient the explicit occupancy diffusion is no longer stable (2-D bilinear
   !> grid Laplacian, docs/volume-conservation.md).
   real(rp), parameter :: max_shifting_coefficient = 0.25_rp
   !> Accepted `&grid shape_function=` keywords (stored lower case; docs/theory.md section 1.1).
   character(len=*), parameter, public :: shape_function_keywords(*) = [character(len=8) :: 'linear', 'bspline2']
   !> Accepted `&run update_scheme=` keywords (stored upper case).
   character(len=*), parameter, public :: update_scheme_keywords(*) = [character(len=4) :: 'USL', 'MUSL']
   !> Accepted `&run transfer=` keywords (stored lower case).
   character(len=*), parameter, public :: transfer_keywords(*) = [character(len=8) :: 'flip_pic', 'apic']
   !> Accepted `&wall motion=` keywords (stored lower case).
   character(len=*), parameter, public :: motion_keywords(*) = [character(len=13) :: motion_none, &
                                                                motion_solitary_wave, motion_table]
   !> Largest solitary wave height over depth a wall may make (solitary waves break near A/h = 0.78;
   !> Goring's first-order stroke is poor beyond about 0.6).
   real(rp), parameter :: max_wave_ratio = 0.6_rp

   !> Accepted `&box_walls` keywords (stored lower case).
   character(len=*), parameter, public :: wall_keywords(*) = [character(len=8) :: wall_none, wall_slip, wall_no_slip, &
                                                              wall_friction]
   !> Accepted `&structure condition=` keywords (stored lower case).
   character(len=*), parameter, public :: wall_condition_keywords(*) = [character(len=8) :: wall_slip, wall_no_slip, &
                                                                        wall_friction]
   !> `&wall condition = 'free'`: a wall that constrains nothing and reports a zero load (free_condition).
   character(len=*), parameter, public :: wall_free = 'free'
   !> Accepted `&wall condition=` keywords.
   character(len=*), parameter, public :: wall_group_condition_keywords(*) = [character(len=8) :: &
                                                                              wall_condition_keywords, wall_free]
   !> Accepted `&material model=` keywords (stored lower case).
   character(len=*), parameter, public :: model_keywords(*) = &
      [character(len=15) :: model_newtonian_fluid, model_linear_elastic, model_rigid]
   !> Accepted `&gauge kind=` keywords (stored lower case).
   character(len=*), parameter, public :: gauge_kind_keywords(*) = &
      [character(len=15) :: gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, gauge_wall_pressure]

   !> Relative tolerance of "extent is a whole multiple of cell_size".
   real(rp), parameter :: multiple_tolerance = 1.0e-9_rp
   !> Tolerance of "body inside the grid", in cell sizes.
   real(rp), parameter :: inside_tolerance = 1.0e-9_rp
   !> Largest number of cells along one axis and in the whole grid (default integers index them).
   real(rp), parameter :: max_cells = real(huge(1), rp)

   character(len=1), parameter :: axis_letter(3) = ['x', 'y', 'z']

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
      if (status%ok) call validate_walls(scene%grid, path, status)
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
      if (allocated(scene%contacts)) then
         do i = 1, size(scene%contacts)
            call validate_contact(scene%contacts, i, scene%materials, scene%structures, path, status)
            if (.not. status%ok) return
         end do
      end if
   end subroutine validate_scene

   !> Particles body b (b > 0) or inlet -b (b < 0) of the scene creates over the run (a real: a bad
   !> scene may ask for more than any integer holds). Bodies: the particles inside their shapes
   !> (body_lattice's count_particles) or the points of their files; inlets: the layers that exist at
   !> end_time times the particles across the opening (fluid_inflow).
   real(rp) function source_particle_count(scene, b) result(n)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: b
      real(rp) :: spacing, length
      real(rp), allocatable :: area(:)
      integer :: dim
      logical :: exact
      dim = scene%grid%dim
      n = 1.0_rp
      if (b > 0) then
         call count_particles(scene, b, n, exact)
      else
         associate (inlet => scene%inlets(-b))
            spacing = scene%grid%cell_size / inlet%particles_per_cell
            length = inlet%velocity * max(0.0_rp, min(scene%run%end_time, inlet%end_time) - inlet%start_time)
            if (has_velocity_file(inlet) .and. allocated(scene%inlet_tables)) then
               ! the table's L(t) = integral of v dt (its first column)
               if (allocated(scene%inlet_tables(-b)%time)) then
                  area = scene%inlet_tables(-b)%integral(inlet%start_time, &
                                                         max(inlet%start_time, min(scene%run%end_time, inlet%end_time)))
                  length = area(1)
               end if
            end if
            n = aint(length / spacing) * max(1.0_rp, anint(inlet%height / spacing))
            if (dim == 3) n = n * max(1.0_rp, anint(inlet%width / spacing))
         end associate
      end if
   end function source_particle_count

   !> Particles all bodies and inlets create over the run.
   real(rp) function scene_particle_count(scene) result(n)
      type(scene_t), intent(in) :: scene
      integer :: b
      n = 0.0_rp
      do b = 1, body_count(scene)
         n = n + source_particle_count(scene, b)
      end do
      do b = 1, inlet_count(scene)
         n = n + source_particle_count(scene, -b)
      end do
   end function scene_particle_count

   !> Memory one of `ranks` ranks needs at least for the scene [bytes, as a real]: its share of the
   !> particles at bytes_per_particle, and its share of the nodes of the grid around the bodies (the
   !> active region the run starts with; it grows as the material spreads) at bytes_per_node.
   real(rp) function memory_estimate_per_rank(scene, ranks, particles) result(bytes)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: ranks
      real(rp), intent(in), optional :: particles   !< scene_particle_count, if known (counting walks shapes)
      real(rp) :: nodes, box, lo(3), hi(3), total
      integer :: b, k, dim
      dim = scene%grid%dim
      nodes = 0.0_rp
      do b = 1, body_count(scene)
         call body_bounds(scene, b, lo, hi)
         box = 1.0_rp
         do k = 1, dim
            box = box * (aint((hi(k) - lo(k)) / scene%grid%cell_size) + 3.0_rp)
         end do
         nodes = nodes + box
      end do
      if (present(particles)) then
         total = particles
      else
         total = scene_particle_count(scene)
      end if
      bytes = (real(bytes_per_particle(dim), rp) * total + &
               real(bytes_per_node(dim) + contact_field_count(scene) * bytes_per_field_node(dim), rp) * nodes) / ranks
   end function memory_estimate_per_rank

   !> Advice on a valid scene that is likely to fail, '' when there is none: the run prints it as a warning
   !> after its banner. APIC on the multilinear grid with a fluid: its small-mass node where a free surface
   !> rises through a row of nodes blows up at any step (docs/theory.md, "APIC" and section 3.6).
   function scene_advice(scene) result(text)
      type(scene_t), intent(in) :: scene
      character(len=:), allocatable :: text
      text = ''
      if (scene%run%transfer /= 'apic' .or. scene%grid%shape_function /= 'linear') return
      if (.not. any(scene%materials%model == model_newtonian_fluid)) return
      text = "&run transfer = 'apic' with &grid shape_function = 'linear' and a fluid: APIC blows up where a free "// &
             "surface rises through a row of nodes (waves, bores, moving walls); shape_function = 'bspline2' runs "// &
             "them (docs/theory.md, APIC)"
   end function scene_advice

   !> Bodies that get a velocity field of their own: those of a material some `&contact` names.
   pure integer function contact_field_count(scene) result(fields)
      type(scene_t), intent(in) :: scene
      integer :: b, c
      fields = 0
      if (.not. allocated(scene%contacts) .or. .not. allocated(scene%bodies)) return
      do b = 1, size(scene%bodies)
         do c = 1, size(scene%contacts)
            if (any(scene%contacts(c)%material_index == scene%bodies(b)%material_index)) then
               fields = fields + 1
               exit
            end if
         end do
      end do
   end function contact_field_count

   !> Refuse a scene whose particles cannot fit: more than a rank can count (default integers), or an
   !> estimate per rank (memory_estimate_per_rank, an even share) above what every rank has
   !> (`budget`, memory_budget; not checked when unknown). The message names the body or inlet that
   !> makes the most particles, e.g. `dam.nml: group &body (1st, material 'water'): variable
   !> particles_per_cell = 100 makes 25000000 particles (25000000 in the scene), about 3.8 GB per rank
   !> on 2 ranks, more than the 1.2 GB per rank available (...)`. Call on a validated scene.
   subroutine check_scene_memory(scene, path, ranks, budget, status)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      integer, intent(in) :: ranks
      type(memory_budget_t), intent(in) :: budget
      type(status_t), intent(inout) :: status
      real(rp) :: total, estimate, largest, counts(-inlet_count(scene):body_count(scene))
      integer :: b, biggest
      character(len=:), allocatable :: where, made, cause

      ! each source counted once: counting the particles of a shape walks its lattice
      counts = 0.0_rp
      do b = -inlet_count(scene), body_count(scene)
         if (b /= 0) counts(b) = source_particle_count(scene, b)
      end do
      total = sum(counts)
      estimate = memory_estimate_per_rank(scene, ranks, total)
      if (total / ranks <= real(huge(1), rp) .and. &
          (budget%per_rank < 0 .or. estimate <= real(budget%per_rank, rp))) return
      largest = -1.0_rp
      biggest = 0
      do b = -inlet_count(scene), body_count(scene)
         if (b == 0) cycle
         if (counts(b) > largest) then
            largest = counts(b)
            biggest = b
         end if
      end do
      if (biggest > 0) then
         where = group_context(path, 'body', biggest, "material '"//trim(scene%bodies(biggest)%material)//"'")
         cause = 'particles_per_cell = '//int_text(scene%bodies(biggest)%particles_per_cell)
         if (has_points_file(scene%bodies(biggest))) cause = "points_file = '"//trim(scene%bodies(biggest)%points_file)//"'"
      else
         where = group_context(path, 'inlet', -biggest, "material '"//trim(scene%inlets(-biggest)%material)//"'")
         cause = 'particles_per_cell = '//int_text(scene%inlets(-biggest)%particles_per_cell)
      end if
      made = where//': variable '//cause//' makes '//count_text(largest)//' particles'
      if (total > largest) made = made//' ('//count_text(total)//' in the scene)'
      made = made//', about '//byte_text(estimate)//' per rank on '//int_text(ranks)//' rank'//trim(merge('s', ' ', ranks > 1))
      if (budget%per_rank >= 0 .and. estimate > real(budget%per_rank, rp)) then
         call status%fail(made//', more than the '//budget%describe()//' available')
      else
         call status%fail(made//', more particles than one rank can hold ('//int_text(huge(1))//')')
      end if
   end subroutine check_scene_memory

   !> A particle count: the integer below 1e18, else in exponent form.
   function count_text(n) result(text)
      real(rp), intent(in) :: n
      character(len=:), allocatable :: text
      character(len=16) :: buffer
      if (n < 1.0e18_rp) then
         text = int_text(int(n, i8))
      else
         write (buffer, '(es10.3)') n
         text = trim(adjustl(buffer))
      end if
   end function count_text

   pure integer function body_count(scene)
      type(scene_t), intent(in) :: scene
      body_count = 0
      if (allocated(scene%bodies)) body_count = size(scene%bodies)
   end function body_count

   pure integer function wall_count(scene)
      type(scene_t), intent(in) :: scene
      wall_count = 0
      if (allocated(scene%walls)) wall_count = size(scene%walls)
   end function wall_count

   pure integer function structure_count(scene)
      type(scene_t), intent(in) :: scene
      structure_count = 0
      if (allocated(scene%structures)) structure_count = size(scene%structures)
   end function structure_count

   pure integer function inlet_count(scene)
      type(scene_t), intent(in) :: scene
      inlet_count = 0
      if (allocated(scene%inlets)) inlet_count = size(scene%inlets)
   end function inlet_count

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

   !> Name of a side of the scene box, and its `&box_walls` variable: `x_min` (side 1, axis 1) ... `z_max`.
   pure function side_name(side, axis) result(name)
      integer, intent(in) :: side, axis
      character(len=5) :: name
      name = axis_letter(axis)//merge('_min', '_max', side == 1)
   end function side_name

   !> A name is a plain identifier: a letter, then letters, digits or underscores (no blanks), so that
   !> it can prefix csv columns and be used in plots and scripts as is.
   pure logical function is_identifier(name)
      character(len=*), intent(in) :: name
      integer :: i
      character :: c
      is_identifier = .false.
      if (len_trim(name) == 0) return
      do i = 1, len_trim(name)
         c = name(i:i)
         if (is_letter(c)) cycle
         if (i > 1 .and. (c == '_' .or. (c >= '0' .and. c <= '9'))) cycle
         return
      end do
      is_identifier = .true.
   end function is_identifier

   pure logical function is_letter(c)
      character, intent(in) :: c
      is_letter = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z')
   end function is_letter

   !> Fail unless the name a scene gives (empty: the default name) is a plain identifier.
   subroutine check_name(where, variable, name, status)
      character(len=*), intent(in) :: where, variable, name
      type(status_t), intent(inout) :: status
      if (.not. status%ok .or. len_trim(name) == 0) return
      if (.not. is_identifier(name)) then
         call status%fail(where//': variable '//variable//" must be a plain identifier (a letter, then letters, "// &
                          "digits or '_'), got '"//trim(name)//"'")
      end if
   end subroutine check_name

   !> Index of the material called `name` (exact match); 0 if there is none.
   pure integer function find_material(materials, name) result(found)
      type(material_spec_t), intent(in) :: materials(:)
      character(len=*), intent(in) :: name
      integer :: m
      found = 0
      do m = 1, size(materials)
         if (materials(m)%name == name) then
            found = m
            return
         end if
      end do
   end function find_material

   subroutine validate_run(run, path, status)
      type(run_control_t), intent(in) :: run
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where

      where = group_context(path, 'run', 0)
      call check_real(where, 'end_time', run%end_time, status, greater_than=0.0_rp)
      call check_real(where, 'cfl', run%cfl, status, greater_than=0.0_rp, at_most=1.0_rp)
      call check_real(where, 'dt', run%fixed_dt, status, at_least=0.0_rp)
      call check_real(where, 'output_interval', run%output_interval, status, at_least=0.0_rp)
      if (len_trim(run%output_dir) == 0) call status%fail(where//': variable output_dir must not be empty')
      if (all(run%update_scheme /= update_scheme_keywords)) then
         call status%fail(where//': variable update_scheme must be one of '//quoted_list(update_scheme_keywords)// &
                          ", got '"//trim(run%update_scheme)//"'")
      end if
      if (all(run%transfer /= transfer_keywords)) then
         call status%fail(where//': variable transfer must be one of '//quoted_list(transfer_keywords)// &
                          ", got '"//trim(run%transfer)//"'")
      else if (run%transfer == 'apic' .and. run%flip_fraction_given) then
         ! a blend the user asked for must not be dropped without a word
         call status%fail(where//": variable flip_fraction has no effect with transfer = 'apic' (APIC has no FLIP/PIC "// &
                          "blend); remove it")
      end if
      call check_real(where, 'flip_fraction', run%flip_fraction, status, at_least=0.0_rp, at_most=1.0_rp)
      call check_real(where, 'theta', run%theta, status, greater_than=0.0_rp, at_most=1.0_rp)
      if (run%max_steps <= 0_i8) then
         call status%fail(where//': variable max_steps must be > 0, got '//int_text(run%max_steps))
      end if
      call check_real(where, 'progress_interval', run%progress_interval, status)
      call check_real(where, 'floor_size', run%floor_size, status, at_least=0.0_rp)
      if (run%checkpoint_interval_steps < 0_i8) then
         call status%fail(where//': variable checkpoint_interval_steps must be >= 0, got '// &
                          int_text(run%checkpoint_interval_steps))
      end if
      call check_real(where, 'checkpoint_interval_wall', run%checkpoint_interval_wall, status, at_least=0.0_rp)
      if (run%checkpoints_kept < 1) then
         call status%fail(where//': variable checkpoints_kept must be >= 1, got '//int_text(run%checkpoints_kept))
      end if
      call check_real(where, 'speed_limit', run%speed_limit, status, at_least=0.0_rp)
      ! below 1 even a perfect balance would exceed the threshold (NaN fails the finiteness test first)
      if (.not. ieee_is_finite(run%rebalance_threshold)) then
         call check_real(where, 'rebalance_threshold', run%rebalance_threshold, status)
      else if (run%rebalance_threshold < 0.0_rp .or. &
               (run%rebalance_threshold > 0.0_rp .and. run%rebalance_threshold < 1.0_rp)) then
         call status%fail(where//': variable rebalance_threshold must be 0 (off) or >= 1, got '// &
                          real_text(run%rebalance_threshold))
      end if
      if (run%rebalance_interval < 1) then
         call status%fail(where//': variable rebalance_interval must be >= 1, got '//int_text(run%rebalance_interval))
      end if
      call check_real(where, 'load_interval', run%load_interval, status, at_least=0.0_rp)
      if (status%ok .and. all(run%field_precision /= field_precision_keywords)) then
         call status%fail(where//': variable field_precision must be one of '//quoted_list(field_precision_keywords)// &
                          ", got '"//trim(run%field_precision)//"'")
      end if
      if (status%ok) call check_particle_fields(where, run%particle_fields, status)
   end subroutine validate_run

   !> `&run particle_fields` is a comma-separated list of particle datasets (or 'all'; 'position' is
   !> always written and may be named).
   subroutine check_particle_fields(where, fields, status)
      character(len=*), intent(in) :: where, fields
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: item
      integer :: start, comma
      start = 1
      do
         comma = index(fields(start:), ',')
         if (comma == 0) then
            item = trim(fields(start:))
         else
            item = fields(start:start + comma - 2)
         end if
         if (item /= 'all' .and. item /= 'position' .and. all(particle_field_names /= item)) then
            if (len(item) == 0) then
               call status%fail(where//": variable particle_fields has an empty name in '"//trim(fields)// &
                                "' (a comma-separated list of "//quoted_list(particle_field_names)//", or 'all')")
            else
               call status%fail(where//": variable particle_fields: unknown field '"//item//"' (fields: "// &
                                quoted_list(particle_field_names)//", or 'all'; position is always written)")
            end if
            return
         end if
         if (comma == 0) return
         start = start + comma
      end do
   end subroutine check_particle_fields

   subroutine validate_grid(grid, path, status)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: cells, total_cells
      integer :: k

      where = group_context(path, 'grid', 0)
      if (grid%dim /= 2 .and. grid%dim /= 3) then
         call status%fail(where//': variable dim must be 2 or 3, got '//int_text(grid%dim))
         return
      end if
      call check_real(where, 'cell_size', grid%cell_size, status, greater_than=0.0_rp)
      do k = 1, grid%dim
         call check_real(where, 'origin('//int_text(k)//')', grid%origin(k), status)
      end do
      do k = 1, grid%dim
         call check_real(where, 'extent('//int_text(k)//')', grid%extent(k), status, greater_than=0.0_rp)
      end do
      call check_real(where, 'rotation', grid%rotation, status, at_least=-360.0_rp, at_most=360.0_rp)
      if (all(grid%shape_function /= shape_function_keywords)) then
         call status%fail(where//': variable shape_function must be one of '//quoted_list(shape_function_keywords)// &
                          ", got '"//trim(grid%shape_function)//"'")
      end if
      if (.not. status%ok) return

      total_cells = 1.0_rp
      do k = 1, grid%dim
         cells = grid%extent(k) / grid%cell_size
         if (cells > max_cells) then
            call status%fail(where//': variable extent('//int_text(k)//') gives '//real_text(cells)// &
                             ' cells of size cell_size = '//real_text(grid%cell_size)//', more than '// &
                             int_text(huge(1)))
            return
         end if
         if (abs(real(nint(cells), rp) * grid%cell_size - grid%extent(k)) > multiple_tolerance * grid%extent(k)) then
            call status%fail(where//': variable extent('//int_text(k)//') must be a whole multiple of cell_size = '// &
                             real_text(grid%cell_size)//', got '//real_text(grid%extent(k)))
            return
         end if
         total_cells = total_cells * real(nint(cells), rp)
      end do
      if (total_cells > max_cells) then
         call status%fail(where//': variables extent and cell_size give '//real_text(total_cells)// &
                          ' cells, more than '//int_text(huge(1)))
      end if
   end subroutine validate_grid

   subroutine validate_walls(grid, path, status)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, variable
      integer :: k, side

      where = group_context(path, 'box_walls', 0)
      do k = 1, 3
         do side = 1, 2
            variable = axis_letter(k)//merge('_min', '_max', side == 1)
            if (all(grid%wall(side, k) /= wall_keywords)) then
               call status%fail(where//': variable '//variable//' must be one of '//quoted_list(wall_keywords)// &
                                ", got '"//trim(grid%wall(side, k))//"'")
               return
            end if
            if (k > grid%dim .and. grid%wall(side, k) /= wall_none) then
               call status%fail(where//': variable '//variable//" must be '"//wall_none//"' in 2-D (dim = 2), got '"// &
                                trim(grid%wall(side, k))//"'")
               return
            end if
         end do
      end do
      call check_real(where, 'friction', grid%wall_friction, status, at_least=0.0_rp)
      if (status%ok .and. grid%wall_friction > 0.0_rp .and. all(grid%wall /= wall_friction)) &
         call status%fail(where//': variable friction is the Coulomb coefficient of the sides whose condition is '''// &
                          wall_friction//"', and no side is: give a side 'friction' or leave friction out")
      if (.not. status%ok) return
      ! a name labels the loads of a wall: an open side has none
      do k = 1, 3
         do side = 1, 2
            variable = side_name(side, k)
            if (len_trim(grid%wall_name(side, k)) == 0) cycle
            if (grid%wall(side, k) == wall_none) then
               call status%fail(where//': variable '//variable//"_name names side "//variable//", which is not a wall ("// &
                                variable//" = '"//wall_none//"')")
               return
            end if
            call check_name(where, variable//'_name', grid%wall_name(side, k), status)
            if (.not. status%ok) return
         end do
      end do
   end subroutine validate_walls

   subroutine validate_gravity(gravity, dim, path, status)
      real(rp), intent(in) :: gravity(3)
      integer, intent(in) :: dim
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      integer :: k
      do k = 1, dim
         call check_real(group_context(path, 'gravity', 0), 'acceleration('//int_text(k)//')', gravity(k), status)
      end do
   end subroutine validate_gravity

   !> The schemes of a material that a shape function does not combine with (docs/theory.md section 1.1):
   !> the volume correction's occupancy and open volumes integrate the multilinear hat of a node over its
   !> two cells, which bspline2 replaces by a wider support [R].
   subroutine check_shape_function_combination(material, m, grid, path, status)
      type(material_spec_t), intent(in) :: material
      integer, intent(in) :: m
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      if (grid%shape_function == 'linear') return
      if (material%volume_correction /= 'none') &
         call status%fail(group_context(path, 'material', m, "name '"//trim(material%name)//"'")// &
                          ": variable volume_correction = '"//trim(material%volume_correction)// &
                          "' needs &grid shape_function = 'linear', got '"//trim(grid%shape_function)//"'")
   end subroutine check_shape_function_combination

   subroutine validate_material(materials, m, path, status)
      type(material_spec_t), intent(in) :: materials(:)
      integer, intent(in) :: m
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: other
      logical :: incompressible

      associate (material => materials(m))
         if (len_trim(material%name) == 0) then
            call status%fail(group_context(path, 'material', m)//': variable name is required')
            return
         end if
         where = group_context(path, 'material', m, "name '"//trim(material%name)//"'")
         other = find_material(materials(1:m - 1), material%name)
         if (other > 0) then
            call status%fail(where//": variable name '"//trim(material%name)//"' is already used by the "// &
                             ordinal(other)//' &material')
            return
         end if
         if (all(material%model /= model_keywords)) then
            call status%fail(where//': variable model must be one of '//quoted_list(model_keywords)//", got '"// &
                             trim(material%model)//"'")
            return
         end if
         call check_real(where, 'density', material%density, status, greater_than=0.0_rp)
         select case (trim(material%model))
         case (model_newtonian_fluid)
            call check_real(where, 'bulk_modulus', material%bulk_modulus, status, greater_than=0.0_rp)
            call check_real(where, 'viscosity', material%viscosity, status, at_least=0.0_rp)
         case (model_linear_elastic)
            call check_real(where, 'youngs_modulus', material%youngs_modulus, status, greater_than=0.0_rp)
            incompressible = .false.
            if (ieee_is_finite(material%poisson_ratio)) incompressible = material%poisson_ratio >= 0.5_rp
            if (.not. incompressible) then
               call check_real(where, 'poisson_ratio', material%poisson_ratio, status, greater_than=-1.0_rp, &
                               less_than=0.5_rp)
            else
               ! nu = 0.5 is incompressible: the bulk modulus E / (3 (1 - 2 nu)) would be infinite.
               call status%fail(where//': variable poisson_ratio must be < 0.5 (0.5 is incompressible: use a '// &
                                'smaller ratio or a newtonian_fluid), got '//real_text(material%poisson_ratio))
            end if
         end select
         if (all(material%stabilization /= stabilization_keywords)) then
            call status%fail(where//': variable stabilization must be one of '//quoted_list(stabilization_keywords)// &
                             ", got '"//trim(material%stabilization)//"'")
         else if (material%model == model_rigid .and. material%stabilization /= 'none') then
            call status%fail(where//": variable stabilization must be 'none' for model '"//model_rigid// &
                             "' (a rigid body has no strain to filter), got '"//trim(material%stabilization)//"'")
         end if
         if (all(material%oscillation_rule /= oscillation_rule_keywords)) then
            call status%fail(where//': variable oscillation_rule must be one of '// &
                             quoted_list(oscillation_rule_keywords)//", got '"//trim(material%oscillation_rule)//"'")
         end if
         if (all(material%smoothed_variables /= smoothed_variables_keywords)) then
            call status%fail(where//': variable smoothed_variables must be one of '// &
                             quoted_list(smoothed_variables_keywords)//", got '"//trim(material%smoothed_variables)//"'")
         end if
         call check_real(where, 'gamma_max', material%gamma_max, status, at_least=0.0_rp, at_most=1.0_rp)
         if (all(material%volume_correction /= volume_correction_keywords)) then
            call status%fail(where//': variable volume_correction must be one of '// &
                             quoted_list(volume_correction_keywords)//", got '"//trim(material%volume_correction)//"'")
         else if (material%volume_correction /= 'none' .and. material%model /= model_newtonian_fluid) then
            call status%fail(where//": variable volume_correction = '"//trim(material%volume_correction)// &
                             "' is for fluids (model = '"//model_newtonian_fluid//"'), got model = '"// &
                             trim(material%model)//"'")
         end if
         call check_real(where, 'shifting_coefficient', material%shifting_coefficient, status, greater_than=0.0_rp, &
                         at_most=max_shifting_coefficient)
         call check_real(where, 'eos_relaxation_rate', material%eos_relaxation_rate, status, greater_than=0.0_rp, &
                         at_most=1.0_rp)
      end associate
   end subroutine validate_material

   subroutine validate_body(body, b, materials, grid, path, status)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: b
      type(material_spec_t), intent(in) :: materials(:)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, given
      integer :: k, m
      character(len=name_len) :: declared(size(materials))

      if (len_trim(body%material) == 0) then
         call status%fail(group_context(path, 'body', b)//': variable material is required')
         return
      end if
      where = group_context(path, 'body', b, body_detail(body))
      call check_name(where, 'name', body%name, status)
      if (.not. status%ok) return
      if (find_material(materials, body%material) == 0) then
         do m = 1, size(materials)
            declared(m) = materials(m)%name
         end do
         call status%fail(where//': variable material must name a declared &material ('// &
                          quoted_list(declared)//"), got '"//trim(body%material)//"'")
         return
      end if
      if (body%particles_per_cell < 1) then
         call status%fail(where//': variable particles_per_cell must be >= 1, got '//int_text(body%particles_per_cell))
         return
      end if
      do k = 1, grid%dim
         call check_real(where, 'lower('//int_text(k)//')', body%lower(k), status)
         call check_real(where, 'upper('//int_text(k)//')', body%upper(k), status)
         call check_real(where, 'velocity('//int_text(k)//')', body%velocity(k), status)
      end do
      do k = 1, 3
         call check_real(where, 'angular_velocity('//int_text(k)//')', body%angular_velocity(k), status)
      end do
      if (status%ok .and. grid%dim == 2 .and. any(body%angular_velocity(1:2) /= 0.0_rp)) then
         call status%fail(where//': variable angular_velocity turns a 2-D body about z only: give 0.0, 0.0, '// &
                          'omega_z, got '//real_text(body%angular_velocity(1))//', '//real_text(body%angular_velocity(2)))
         return
      end if
      call check_real(where, 'free_surface_level', body%free_surface_level, status)
      call check_shape_reals(where, body%shape, status)
      if (.not. status%ok) return

      given = given_shape_variables(body, grid%dim)
      if (has_points_file(body)) then
         ! the file gives the particles: a shape as well would be ignored
         if (len(given) > 0) call status%fail(where//': variable points_file gives the particles of the body; '// &
                                              'remove the shape variables ('//given//')')
         return
      end if
      if (len_trim(body%points_checksum) > 0) then
         call status%fail(where//': variable points_checksum belongs to points_file, which is not given')
         return
      end if
      if (body%shape%kind == shape_box) then
         call validate_box(body, where, grid, status)
      else
         call validate_shape(body, where, grid, status)
      end if
   end subroutine validate_body

   !> A box: by lower/upper (the usual way) or by centre/size, either turned by rotation about its centre.
   subroutine validate_box(body, where, grid, status)
      type(body_spec_t), intent(in) :: body
      character(len=*), intent(in) :: where
      type(grid_spec_t), intent(in) :: grid
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: lower_k, upper_k, unused
      real(rp) :: grid_lower, grid_upper, tolerance, spacing
      integer :: k

      unused = not_used(body, grid%dim, [character(len=8) :: 'radius', 'axis', 'length', 'vertices', 'z_range'])
      if (len(unused) > 0) then
         call status%fail(where//": variable "//unused//" is not used by shape 'box'")
         return
      end if
      if (box_corners_given(body, grid%dim)) then
         if (any(differs(body%shape%size(1:grid%dim), 0.0_rp)) .or. any(differs(body%shape%centre(1:grid%dim), 0.0_rp))) then
            call status%fail(where//': variables lower/upper and centre/size both give the box; give one pair')
            return
         end if
      else if (.not. any(differs(body%shape%size(1:grid%dim), 0.0_rp))) then
         call status%fail(where//': variables lower and upper are required (or centre and size) for a box')
         return
      end if
      if (abs(body%shape%rotation) > 0.0_rp .or. .not. box_corners_given(body, grid%dim)) then
         ! a turned box, or one given by centre/size: as the other shapes
         if (box_corners_given(body, grid%dim)) then
            do k = 1, grid%dim
               if (.not. (body%upper(k) > body%lower(k))) then
                  call status%fail(where//': variable upper('//int_text(k)//') must be > lower('//int_text(k)// &
                                   ') = '//real_text(body%lower(k))//', got '//real_text(body%upper(k)))
                  return
               end if
            end do
         end if
         call validate_shape(body, where, grid, status)
         return
      end if

      tolerance = inside_tolerance * grid%cell_size
      spacing = grid%cell_size / real(body%particles_per_cell, rp)
      do k = 1, grid%dim
         lower_k = 'lower('//int_text(k)//')'
         upper_k = 'upper('//int_text(k)//')'
         grid_lower = grid%origin(k)
         grid_upper = grid%origin(k) + grid%extent(k)
         if (.not. (body%upper(k) > body%lower(k))) then
            call status%fail(where//': variable '//upper_k//' must be > '//lower_k//' = '//real_text(body%lower(k))// &
                             ', got '//real_text(body%upper(k)))
         else if (body%lower(k) < grid_lower - tolerance) then
            call status%fail(where//': variable '//lower_k//' must be >= '//real_text(grid_lower)// &
                             ' (the lower edge of the grid along '//axis_letter(k)//'), got '//real_text(body%lower(k)))
         else if (body%upper(k) > grid_upper + tolerance) then
            call status%fail(where//': variable '//upper_k//' must be <= '//real_text(grid_upper)// &
                             ' (the upper edge of the grid along '//axis_letter(k)//'), got '//real_text(body%upper(k)))
         else if (nint((body%upper(k) - body%lower(k)) / spacing, i8) == 0_i8) then
            call status%fail(where//': variable '//upper_k//' gives 0 particles along '//axis_letter(k)// &
                             ': the body spans '//real_text(body%lower(k))//' .. '//real_text(body%upper(k))// &
                             ', less than half the particle spacing cell_size/particles_per_cell = '//real_text(spacing))
         end if
         if (.not. status%ok) return
      end do
   end subroutine validate_box

   !> A shape other than an unrotated box given by lower/upper: its keyword and parameters
   !> (shape_problem), no variable of another shape, and inside the scene box.
   subroutine validate_shape(body, where, grid, status)
      type(body_spec_t), intent(in) :: body
      character(len=*), intent(in) :: where
      type(grid_spec_t), intent(in) :: grid
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: problem, unused
      real(rp) :: lo(3), hi(3), tolerance
      integer :: k
      type(shape_t) :: shape

      shape = body_shape(body, grid%dim)
      problem = shape_problem(shape, grid%dim)
      if (len(problem) > 0) then
         call status%fail(where//': variable '//problem)
         return
      end if
      select case (shape%kind)
      case (shape_circle, shape_sphere)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'size', 'rotation', &
                                            'rotation_axis', 'axis', 'length', 'vertices', 'z_range'])
      case (shape_cylinder)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'size', 'rotation', &
                                            'rotation_axis', 'vertices', 'z_range'])
      case (shape_polygon)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'centre', 'size', 'rotation', &
                                            'rotation_axis', 'radius', 'axis', 'length', 'z_range'])
      case (shape_extruded_polygon)
         unused = not_used(body, grid%dim, [character(len=13) :: 'lower', 'upper', 'centre', 'size', 'rotation', &
                                            'rotation_axis', 'radius', 'axis', 'length'])
      case default
         unused = ''
      end select
      if (len(unused) > 0) then
         call status%fail(where//': variable '//unused//" is not used by shape '"//trim(shape%kind)//"'")
         return
      end if
      call shape_bounds(shape, grid%dim, lo, hi)
      tolerance = inside_tolerance * grid%cell_size
      do k = 1, grid%dim
         if (lo(k) < grid%origin(k) - tolerance .or. hi(k) > grid%origin(k) + grid%extent(k) + tolerance) then
            call status%fail(where//": the shape '"//trim(shape%kind)//"' reaches outside the scene box of &grid "// &
                             'along '//axis_letter(k)//': it spans '//real_text(lo(k))//' .. '//real_text(hi(k))// &
                             ', the box '//real_text(grid%origin(k))//' .. '//real_text(grid%origin(k) + grid%extent(k)))
            return
         end if
      end do
   end subroutine validate_shape

   !> A body of a shape must hold at least one lattice point (docs/input.md: a lattice cell counts if its
   !> centre is inside).
   subroutine check_body_has_particles(scene, b, path, status)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: b
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      real(rp) :: n
      logical :: exact
      associate (body => scene%bodies(b))
         if (has_points_file(body)) return
         if (body%shape%kind == shape_box .and. box_corners_given(body, scene%grid%dim) .and. &
             .not. abs(body%shape%rotation) > 0.0_rp) return     ! validate_box counted per axis
         call count_particles(scene, b, n, exact)
         if (n < 1.0_rp) then
            call status%fail(group_context(path, 'body', b, body_detail(body))//": the shape '"// &
                             trim(body%shape%kind)//"' holds no particle: no point of the particle lattice "// &
                             '(spacing cell_size/particles_per_cell = '//real_text(particle_spacing(body, scene%grid))// &
                             ') lies inside it; make it larger or raise particles_per_cell')
         end if
      end associate
   end subroutine check_body_has_particles

   !> The shape variables a body gives (differ from their defaults), as "radius, vertices"; lower/upper as
   !> one pair.
   function given_shape_variables(body, dim) result(names)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      character(len=:), allocatable :: names
      names = not_used(body, dim, [character(len=13) :: 'shape', 'lower', 'upper', 'centre', 'size', 'rotation', &
                                   'rotation_axis', 'radius', 'axis', 'length', 'vertices', 'z_range'])
   end function given_shape_variables

   !> Those of the shape variables `names` that the body gives (differ from their defaults), comma-separated.
   function not_used(body, dim, names) result(list)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      character(len=*), intent(in) :: names(:)
      character(len=:), allocatable :: list
      type(shape_t) :: default
      logical :: given
      integer :: i
      list = ''
      do i = 1, size(names)
         select case (trim(names(i)))
         case ('shape')
            given = body%shape%kind /= default%kind
         case ('lower')
            given = any(differs(body%lower(1:dim), 0.0_rp))
         case ('upper')
            given = any(differs(body%upper(1:dim), 0.0_rp))
         case ('centre')
            given = any(differs(body%shape%centre(1:dim), default%centre(1:dim)))
         case ('size')
            given = any(differs(body%shape%size(1:dim), default%size(1:dim)))
         case ('rotation')
            given = differs(body%shape%rotation, default%rotation)
         case ('rotation_axis')
            given = any(differs(body%shape%rotation_axis, default%rotation_axis))
         case ('radius')
            given = differs(body%shape%radius, default%radius)
         case ('axis')
            given = any(differs(body%shape%axis, default%axis))
         case ('length')
            given = differs(body%shape%length, default%length)
         case ('vertices')
            given = any(differs(body%shape%vertices, no_vertex))
         case ('z_range')
            given = any(differs(body%shape%z_range, default%z_range))
         case default
            given = .false.
         end select
         if (.not. given) cycle
         if (len(list) > 0) list = list//', '
         list = list//trim(names(i))
      end do
   end function not_used

   !> Every real of the shape is finite; vertices come in x, y pairs.
   subroutine check_shape_reals(where, shape, status)
      character(len=*), intent(in) :: where
      type(shape_t), intent(in) :: shape
      type(status_t), intent(inout) :: status
      integer :: k, values
      do k = 1, 3
         call check_real(where, 'centre('//int_text(k)//')', shape%centre(k), status)
         call check_real(where, 'size('//int_text(k)//')', shape%size(k), status, at_least=0.0_rp)
         call check_real(where, 'rotation_axis('//int_text(k)//')', shape%rotation_axis(k), status)
         call check_real(where, 'axis('//int_text(k)//')', shape%axis(k), status)
      end do
      call check_real(where, 'rotation', shape%rotation, status)
      call check_real(where, 'radius', shape%radius, status, at_least=0.0_rp)
      call check_real(where, 'length', shape%length, status, at_least=0.0_rp)
      call check_real(where, 'z_range(1)', shape%z_range(1), status)
      call check_real(where, 'z_range(2)', shape%z_range(2), status)
      if (.not. status%ok) return
      values = 0
      do k = 1, 2 * max_vertices
         associate (v => shape%vertices(modulo(k - 1, 2) + 1, (k - 1) / 2 + 1))
            call check_real(where, 'vertices('//int_text(k)//')', v, status)
            if (.not. status%ok) return
            if (v < no_vertex) values = k
         end associate
      end do
      if (modulo(values, 2) /= 0) then
         call status%fail(where//': variable vertices must list x, y pairs (x1, y1, x2, y2, ...), got '// &
                          int_text(values)//' values')
      end if
   end subroutine check_shape_reals

   !> a and b differ (a comparison of given values with their defaults, not of computed ones).
   elemental logical function differs(a, b)
      real(rp), intent(in) :: a, b
      differs = a > b .or. a < b
   end function differs

   !> "name 'log', material 'wood'" (the name when given) for a body's group context.
   pure function body_detail(body) result(detail)
      type(body_spec_t), intent(in) :: body
      character(len=:), allocatable :: detail
      detail = "material '"//trim(body%material)//"'"
      if (len_trim(body%name) > 0) detail = "name '"//trim(body%name)//"', "//detail
   end function body_detail

   subroutine validate_wall(wall, w, scene, path, status)
      type(wall_spec_t), intent(in) :: wall
      integer, intent(in) :: w
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: k, dim

      dim = scene%grid%dim
      where = group_context(path, 'wall', w, name_detail(wall%name))
      call check_name(where, 'name', wall%name, status)
      do k = 1, dim
         call check_real(where, 'point('//int_text(k)//')', wall%point(k), status)
         call check_real(where, 'normal('//int_text(k)//')', wall%normal(k), status)
         call check_real(where, 'lower('//int_text(k)//')', wall%lower(k), status)
         call check_real(where, 'upper('//int_text(k)//')', wall%upper(k), status)
         ! huge: not given (the component of point)
         call check_real(where, 'moment_point('//int_text(k)//')', wall%moment_point(k), status)
      end do
      if (.not. status%ok) return
      if (norm2(wall%normal(1:dim)) < tiny(1.0_rp)**0.25_rp) then
         call status%fail(where//': variable normal must not be zero: it points from the wall into the fluid')
         return
      end if
      do k = 1, dim
         if (wall%upper(k) < wall%lower(k)) then
            call status%fail(where//': variable upper('//int_text(k)//') must be >= lower('//int_text(k)//') = '// &
                             real_text(wall%lower(k))//', got '//real_text(wall%upper(k)))
         else if (wall%point(k) < wall%lower(k) .or. wall%point(k) > wall%upper(k)) then
            call status%fail(where//': variable point('//int_text(k)//') must lie in the extent of the wall, lower('// &
                             int_text(k)//') .. upper('//int_text(k)//') = '//real_text(wall%lower(k))//' .. '// &
                             real_text(wall%upper(k))//', got '//real_text(wall%point(k)))
         end if
         if (.not. status%ok) return
      end do
      if (all(wall%condition /= wall_group_condition_keywords)) then
         call status%fail(where//': variable condition must be one of '//quoted_list(wall_group_condition_keywords)// &
                          ", got '"//trim(wall%condition)//"'")
      end if
      call check_friction(where, wall%condition, wall%friction, status)
      call validate_motion(wall%motion, where, 'wall', wall%point, wall%point, wall%normal, scene, status)
   end subroutine validate_wall

   !> `&wall motion`, `&structure motion`: a known keyword; its variables given only with it; the solitary
   !> wave's height and depth in range (A/h in (0, max_wave_ratio], gravity not zero) and its direction
   !> (a wall's `normal`; a structure's motion_direction, required and not zero); the whole stroke keeps
   !> the wall's point (`what` = 'wall', lower = upper) or the structure's box lower..upper (world, at
   !> rest) in the scene box. A table is checked against the scene box when it is read (load_motion_tables).
   subroutine validate_motion(spec, where, what, lower, upper, direction, scene, status)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(in) :: where, what
      real(rp), intent(in) :: lower(3), upper(3), direction(3)
      type(scene_t), intent(in) :: scene
      type(status_t), intent(inout) :: status
      type(wall_motion_t) :: motion
      real(rp) :: g
      integer :: k, dim
      character(len=:), allocatable :: excursion
      if (.not. status%ok) return
      dim = scene%grid%dim
      if (all(spec%kind /= motion_keywords)) then
         call status%fail(where//': variable motion must be one of '//quoted_list(motion_keywords)//", got '"// &
                          trim(spec%kind)//"'")
         return
      end if
      if (spec%kind /= motion_solitary_wave) then
         if (spec%wave_height /= 0.0_rp) call refuse('wave_height')
         if (spec%water_depth /= 0.0_rp) call refuse('water_depth')
         if (any(spec%direction /= 0.0_rp)) call refuse('motion_direction')
      end if
      if (spec%kind == motion_none .and. spec%start /= 0.0_rp) call refuse('motion_start')
      if (spec%kind /= motion_table) then
         if (len_trim(spec%file) > 0) call refuse('motion_file')
         if (len_trim(spec%checksum) > 0) call refuse('motion_checksum')
      else if (len_trim(spec%file) == 0) then
         call status%fail(where//": variable motion_file is required with motion = '"//motion_table// &
                          "' (a CSV of t, x, y[, z]: the "//what//"'s displacement)")
      end if
      if (spec%kind == motion_table .and. spec%start /= 0.0_rp) then
         call status%fail(where//": variable motion_start belongs to motion = '"//motion_solitary_wave// &
                          "' (a table gives its own times)")
      end if
      if (.not. status%ok .or. spec%kind /= motion_solitary_wave) return
      call check_real(where, 'motion_start', spec%start, status, at_least=0.0_rp)
      call check_real(where, 'water_depth', spec%water_depth, status, greater_than=0.0_rp)
      call check_real(where, 'wave_height', spec%wave_height, status, greater_than=0.0_rp, &
                      at_most=max_wave_ratio * spec%water_depth)
      g = norm2(scene%gravity(1:dim))
      if (status%ok .and. g <= 0.0_rp) call status%fail(where//": variable motion = '"//motion_solitary_wave// &
                                                        "' needs gravity (&gravity acceleration is zero)")
      if (what == 'structure') then
         do k = 1, dim
            call check_real(where, 'motion_direction('//int_text(k)//')', spec%direction(k), status)
         end do
         if (status%ok .and. .not. norm2(spec%direction(1:dim)) > 0.0_rp) &
            call status%fail(where//": variable motion_direction is required with motion = '"//motion_solitary_wave// &
                             "' (the direction of the stroke, not zero)")
      end if
      if (.not. status%ok) return
      motion = prescribed_motion(spec, direction, scene%gravity, dim)
      ! the stroke is monotonic along its direction: its end is the farthest place
      excursion = box_excursion(scene%grid, what, lower, upper, motion%stroke() * motion%direction(1:dim))
      if (len(excursion) > 0) call status%fail(where//": variable motion = '"//trim(spec%kind)//"' drives the "// &
                                               what//' out of the scene box of &grid: '//excursion)

   contains

      subroutine refuse(variable)
         character(len=*), intent(in) :: variable
         character(len=:), allocatable :: owner
         if (.not. status%ok) return
         ! motion_start belongs to every motion, motion_file and motion_checksum to the table, the others
         ! to the solitary wave
         owner = "motion = '"//motion_solitary_wave//"'"
         if (variable == 'motion_start') owner = 'a motion'
         if (variable == 'motion_file' .or. variable == 'motion_checksum') owner = "motion = '"//motion_table//"'"
         call status%fail(where//': variable '//variable//' belongs to '//owner//", which is not given (motion = '"// &
                          trim(spec%kind)//"')")
      end subroutine refuse
   end subroutine validate_motion

   !> mu >= 0, and given only with condition 'friction' (elsewhere it would be silently unused).
   subroutine check_friction(where, condition, friction, status)
      character(len=*), intent(in) :: where, condition
      real(rp), intent(in) :: friction
      type(status_t), intent(inout) :: status
      if (.not. status%ok) return
      call check_real(where, 'friction', friction, status, at_least=0.0_rp)
      if (status%ok .and. friction > 0.0_rp .and. condition /= wall_friction) &
         call status%fail(where//': variable friction = '//real_text(friction)//" is used only with condition = '"// &
                          wall_friction//"', got condition = '"//trim(condition)//"'")
   end subroutine check_friction

   !> A structure: its name, condition and friction, the shape's parameters (shape_problem), a box by its
   !> corners or by centre and size (not both), the whole shape inside the scene box, and its motion.
   subroutine validate_structure(structure, s, scene, path, status)
      type(structure_spec_t), intent(in) :: structure
      integer, intent(in) :: s
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, problem
      type(shape_t) :: shape
      real(rp) :: lower(3), upper(3), tolerance, top
      integer :: k, dim, v
      logical :: corners

      dim = scene%grid%dim
      where = group_context(path, 'structure', s, name_detail(structure%name))
      call check_name(where, 'name', structure%name, status)
      if (.not. status%ok) return
      if (all(structure%condition /= wall_condition_keywords)) then
         call status%fail(where//': variable condition must be one of '//quoted_list(wall_condition_keywords)// &
                          ", got '"//trim(structure%condition)//"'")
         return
      end if
      call check_friction(where, structure%condition, structure%friction, status)
      shape = structure%shape
      do k = 1, dim
         call check_real(where, 'centre('//int_text(k)//')', shape%centre(k), status)
         call check_real(where, 'size('//int_text(k)//')', shape%size(k), status)
         call check_real(where, 'axis('//int_text(k)//')', shape%axis(k), status)
         call check_real(where, 'rotation_axis('//int_text(k)//')', shape%rotation_axis(k), status)
      end do
      call check_real(where, 'rotation', shape%rotation, status)
      call check_real(where, 'radius', shape%radius, status)
      call check_real(where, 'length', shape%length, status)
      call check_real(where, 'z_range(1)', shape%z_range(1), status)
      call check_real(where, 'z_range(2)', shape%z_range(2), status)
      if (.not. status%ok) return
      do v = 1, max_vertices
         ! the slots hold x, y pairs; 'none' (no_vertex) marks the end of the list
         if (all(is_none(shape%vertices(:, v)))) exit
         do k = 1, 2
            if (is_none(shape%vertices(k, v))) then
               call status%fail(where//': variable vertices has an odd number of values ('//int_text(2 * v - 1)// &
                                '): give x1, y1, x2, y2, ... in pairs')
               return
            end if
            call check_real(where, 'vertices('//int_text(2 * (v - 1) + k)//')', shape%vertices(k, v), status)
         end do
         if (.not. status%ok) return
      end do

      ! a box by its corners: both, and instead of centre and size
      corners = any(structure%lower(1:dim) < huge(1.0_rp)) .or. any(structure%upper(1:dim) < huge(1.0_rp))
      if (corners) then
         if (shape%kind /= shape_box) then
            call status%fail(where//": variables lower and upper give a box's corners, but shape = '"// &
                             trim(shape%kind)//"' (use them with shape = 'box')")
            return
         end if
         if (any(abs(shape%size(1:dim)) > 0.0_rp) .or. any(abs(shape%centre(1:dim)) > 0.0_rp)) then
            call status%fail(where//': variables lower and upper give the box, and so do centre and size: '// &
                             'give one pair only')
            return
         end if
         do k = 1, dim
            call check_real(where, 'lower('//int_text(k)//')', structure%lower(k), status, less_than=huge(1.0_rp))
            call check_real(where, 'upper('//int_text(k)//')', structure%upper(k), status, less_than=huge(1.0_rp))
            if (status%ok .and. .not. structure%upper(k) > structure%lower(k)) &
               call status%fail(where//': variable upper('//int_text(k)//') must be > lower('//int_text(k)//') = '// &
                                real_text(structure%lower(k))//', got '//real_text(structure%upper(k)))
            if (.not. status%ok) return
         end do
         shape = box_corners(shape, structure%lower, structure%upper, dim)
      end if

      problem = shape_problem(shape, dim)
      if (len(problem) > 0) then
         call status%fail(where//': variable '//problem)
         return
      end if
      do k = 1, dim
         ! huge: not given (the shape's centre)
         call check_real(where, 'moment_point('//int_text(k)//')', structure%moment_point(k), status)
      end do
      if (.not. status%ok) return

      ! the scene box is axis-aligned in the world frame, whatever the grid's rotation (as for &gauge)
      call shape_bounds(shape, dim, lower, upper)
      tolerance = inside_tolerance * scene%grid%cell_size
      do k = 1, dim
         top = scene%grid%origin(k) + scene%grid%extent(k)
         if (lower(k) < scene%grid%origin(k) - tolerance .or. upper(k) > top + tolerance) then
            call status%fail(where//': variables '//shape_variables(shape%kind, corners)//' put the structure '// &
                             'outside the scene box of &grid: it spans '//axis_letter(k)//' = '//real_text(lower(k))// &
                             ' .. '//real_text(upper(k))//', the box '//real_text(scene%grid%origin(k))//' .. '//real_text(top))
            return
         end if
      end do
      call validate_motion(structure%motion, where, 'structure', lower, upper, structure%motion%direction, scene, status)
   end subroutine validate_structure

   !> The value that marks the end of a vertex list (a NaN is a value given, and reported as such).
   elemental logical function is_none(value)
      real(rp), intent(in) :: value
      is_none = .false.
      if (ieee_is_finite(value)) is_none = value >= no_vertex
   end function is_none

   !> The variables that place a shape of kind `kind`, for messages.
   pure function shape_variables(kind, corners) result(names)
      character(len=*), intent(in) :: kind
      logical, intent(in) :: corners
      character(len=:), allocatable :: names
      select case (kind)
      case (shape_box)
         names = 'centre, size and rotation'
         if (corners) names = 'lower, upper and rotation'
      case (shape_circle, shape_sphere)
         names = 'centre and radius'
      case (shape_cylinder)
         names = 'centre, axis, length and radius'
      case (shape_polygon)
         names = 'vertices'
      case (shape_extruded_polygon)
         names = 'vertices and z_range'
      case default
         names = 'shape'
      end select
   end function shape_variables

   subroutine validate_inlet(inlet, i, materials, grid, path, status)
      type(inlet_spec_t), intent(in) :: inlet
      integer, intent(in) :: i
      type(material_spec_t), intent(in) :: materials(:)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: far_end(3), tolerance
      integer :: k, m, dim

      dim = grid%dim
      where = group_context(path, 'inlet', i, "material '"//trim(inlet%material)//"'")
      call check_name(where, 'name', inlet%name, status)
      if (.not. status%ok) return
      m = find_material(materials, inlet%material)
      if (m == 0) then
         call status%fail(where//': variable material must name a declared &material, got '''//trim(inlet%material)//"'")
         return
      else if (materials(m)%model /= model_newtonian_fluid) then
         call status%fail(where//": variable material must name a '"//model_newtonian_fluid//"' material, got '"// &
                          trim(inlet%material)//"' (model '"//trim(materials(m)%model)//"')")
         return
      end if
      do k = 1, dim
         call check_real(where, 'point('//int_text(k)//')', inlet%point(k), status)
         call check_real(where, 'direction('//int_text(k)//')', inlet%direction(k), status)
      end do
      call check_real(where, 'height', inlet%height, status, greater_than=0.0_rp)
      if (dim == 3) call check_real(where, 'width', inlet%width, status, greater_than=0.0_rp)
      if (has_velocity_file(inlet)) then
         ! velocity = 0 is the default: a scene record writes it beside the file
         if (abs(inlet%velocity) > 0.0_rp) then
            call status%fail(where//': variables velocity and velocity_file exclude each other: give a constant '// &
                             'speed or a time table of it, not both')
            return
         end if
      else
         if (len_trim(inlet%velocity_checksum) > 0) then
            call status%fail(where//': variable velocity_checksum belongs to velocity_file, which is not given')
            return
         else if (inlet%height_from_file) then
            call status%fail(where//': variable height_from_file needs velocity_file (a time table with a column '// &
                             'height)')
            return
         else if (abs(inlet%velocity) == 0.0_rp) then
            call status%fail(where//': give variable velocity (a constant inflow speed > 0) or velocity_file (a '// &
                             'time table of t and velocity)')
            return
         end if
         call check_real(where, 'velocity', inlet%velocity, status, greater_than=0.0_rp)
      end if
      call check_real(where, 'start_time', inlet%start_time, status, at_least=0.0_rp)
      call check_real(where, 'end_time', inlet%end_time, status, greater_than=inlet%start_time)
      if (.not. status%ok) return
      if (inlet%particles_per_cell < 1) then
         call status%fail(where//': variable particles_per_cell must be >= 1, got '//int_text(inlet%particles_per_cell))
         return
      end if
      if (norm2(inlet%direction(1:dim)) < tiny(1.0_rp)**0.25_rp) then
         call status%fail(where//': variable direction must not be zero: it is the direction of the inflow')
         return
      end if
      if (dim == 3 .and. abs(inlet%direction(3)) > 0.0_rp) then
         call status%fail(where//': variable direction(3) must be 0 (the opening spans height in the x-y plane and '// &
                          'width along z), got '//real_text(inlet%direction(3)))
         return
      end if
      ! both ends of the opening must lie in the scene box
      far_end = opening_far_end(inlet, dim)
      tolerance = inside_tolerance * grid%cell_size
      do k = 1, dim
         if (inlet%point(k) < grid%origin(k) - tolerance .or. &
             inlet%point(k) > grid%origin(k) + grid%extent(k) + tolerance) then
            call status%fail(where//': variable point('//int_text(k)//') must lie in the scene box of &grid, '// &
                             real_text(grid%origin(k))//' .. '//real_text(grid%origin(k) + grid%extent(k))//', got '// &
                             real_text(inlet%point(k)))
         else if (far_end(k) < grid%origin(k) - tolerance .or. &
                  far_end(k) > grid%origin(k) + grid%extent(k) + tolerance) then
            call status%fail(where//': variables point, direction, height and width put the far end of the opening '// &
                             'outside the scene box of &grid ('//axis_letter(k)//' = '//real_text(far_end(k))//')')
         end if
         if (.not. status%ok) return
      end do
   end subroutine validate_inlet

   subroutine validate_gauge(gauges, g, grid, path, status)
      type(gauge_spec_t), intent(in) :: gauges(:)
      integer, intent(in) :: g
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      real(rp) :: tolerance
      integer :: k, other

      associate (gauge => gauges(g))
         if (len_trim(gauge%name) == 0) then
            call status%fail(group_context(path, 'gauge', g)//': variable name is required')
            return
         end if
         where = group_context(path, 'gauge', g, name_detail(gauge%name))
         call check_name(where, 'name', gauge%name, status)
         if (.not. status%ok) return
         ! gauges.csv is a file of its own: gauge names need only differ from each other
         do other = 1, g - 1
            if (gauges(other)%name == gauge%name) then
               call status%fail(where//": variable name '"//trim(gauge%name)//"' is already used by the "// &
                                ordinal(other)//' &gauge')
               return
            end if
         end do
         if (all(gauge%kind /= gauge_kind_keywords)) then
            call status%fail(where//': variable kind must be one of '//quoted_list(gauge_kind_keywords)//", got '"// &
                             trim(gauge%kind)//"'")
            return
         end if
         do k = 1, grid%dim
            call check_real(where, 'point('//int_text(k)//')', gauge%point(k), status)
         end do
         call check_real(where, 'radius', gauge%radius, status, at_least=0.0_rp)
         if (.not. status%ok) return
         ! the scene box is axis-aligned in the world frame, whatever the grid's rotation (as for &inlet)
         tolerance = inside_tolerance * grid%cell_size
         do k = 1, grid%dim
            if (gauge%point(k) < grid%origin(k) - tolerance .or. &
                gauge%point(k) > grid%origin(k) + grid%extent(k) + tolerance) then
               call status%fail(where//': variable point('//int_text(k)//') must lie in the scene box of &grid, '// &
                                real_text(grid%origin(k))//' .. '//real_text(grid%origin(k) + grid%extent(k))// &
                                ', got '//real_text(gauge%point(k)))
               return
            end if
         end do
      end associate
   end subroutine validate_gauge

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
            if (any(moving_surfaces(scene) == gauge%wall)) then
               call status%fail(where//": variable wall names '"//trim(gauge%wall)//"', which moves (its "// &
                                'motion): a wall_pressure gauge reads a fixed wall or structure')
               return
            end if
            if (all(surfaces /= gauge%wall)) then
               if (size(surfaces) == 0) then
                  call status%fail(where//": variable wall names '"//trim(gauge%wall)//"', but the scene has no "// &
                                   'wall, box side wall or structure')
               else
                  call status%fail(where//": variable wall must be the name of a wall, box side or structure, "// &
                                   quoted_list(surfaces)//", got '"//trim(gauge%wall)//"'")
               end if
               return
            end if
         end associate
      end do
   end subroutine validate_gauge_walls

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

   !> `given` if the scene gave it, else `default` (a name of loads.csv).
   pure function given_or(given, default) result(name)
      character(len=*), intent(in) :: given, default
      character(len=name_len) :: name
      name = default
      if (len_trim(given) > 0) name = given
   end function given_or

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

   !> The name structure s has in loads.csv: its `name`, or the default `structure_<s>`.
   pure function structure_name(structures, s) result(name)
      type(structure_spec_t), intent(in) :: structures(:)
      integer, intent(in) :: s
      character(len=name_len) :: name
      name = structures(s)%name
      if (len_trim(name) == 0) name = default_name('structure', s)
   end function structure_name

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

   !> "'steel', 'wood'" for messages.
   pure function pair_text(names) result(text)
      character(len=*), intent(in) :: names(2)
      character(len=:), allocatable :: text
      text = "'"//trim(names(1))//"', '"//trim(names(2))//"'"
   end function pair_text

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

   !> "name 'left'" for a message's group context; '' when no name is given.
   pure function name_detail(name) result(detail)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: detail
      detail = ''
      if (len_trim(name) > 0) detail = "name '"//trim(name)//"'"
   end function name_detail

   !> Fail with "<where>: variable <variable> must be <range>, got <value>" unless `value` is finite and
   !> inside the range given by the optional bounds.
   subroutine check_real(where, variable, value, status, greater_than, at_least, less_than, at_most)
      character(len=*), intent(in) :: where, variable
      real(rp), intent(in) :: value
      type(status_t), intent(inout) :: status
      real(rp), intent(in), optional :: greater_than, at_least, less_than, at_most
      character(len=:), allocatable :: range
      logical :: ok

      ! Comparisons only after the finiteness test: NaN must not reach them (-ffpe-trap=invalid).
      ok = ieee_is_finite(value)
      if (ok .and. present(greater_than)) ok = value > greater_than
      if (ok .and. present(at_least)) ok = value >= at_least
      if (ok .and. present(less_than)) ok = value < less_than
      if (ok .and. present(at_most)) ok = value <= at_most
      if (ok) return

      if (present(greater_than) .and. present(at_most)) then
         range = 'in ('//bound_text(greater_than)//', '//bound_text(at_most)//']'
      else if (present(greater_than) .and. present(less_than)) then
         range = 'in ('//bound_text(greater_than)//', '//bound_text(less_than)//')'
      else if (present(at_least) .and. present(at_most)) then
         range = 'in ['//bound_text(at_least)//', '//bound_text(at_most)//']'
      else if (present(greater_than)) then
         range = '> '//bound_text(greater_than)
      else if (present(at_least)) then
         range = '>= '//bound_text(at_least)
      else
         range = 'a finite number'
      end if
      call status%fail(where//': variable '//variable//' must be '//range//', got '//real_text(value))
   end subroutine check_real

   !> A bound in a message: 0 rather than 0.0, so that ranges read "> 0".
   function bound_text(bound) result(text)
      real(rp), intent(in) :: bound
      character(len=:), allocatable :: text
      if (abs(bound - anint(bound)) < tiny(bound) .and. abs(bound) < 1.0e9_rp) then
         text = int_text(nint(bound))
      else
         text = real_text(bound)
      end if
   end function bound_text
end module scene_validation
