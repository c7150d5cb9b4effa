!> The explicit MPM solver on a rank's part of the domain decomposition (algorithms.md section 1.2).
!>
!> One step t_n -> t_n+1:
!>   1. particles -> grid (mass, momentum, internal and external force), ghost-node sums
!>   2. nodal update v^{n+1} = v^n + dt f / m, wall constraints (eq. 14), dv and v^{n+theta}; with &contact
!>      per velocity field, the bodies' fields meeting at a node by contact (body_contact)
!>   3. stabilization schemes bin their cells at x^n
!>   4. grid -> particles: L_p, FLIP/PIC or APIC velocity, positions (MUSL: re-map before L)
!>   5. filter part A (d -> d~), constitutive update per material, filter part B (sbar -> sbar~)
!>   6. wall safeguard, inflow, migration to owning ranks, sort by (material, cell), next dt.
!>   7. the active region follows the particles (active_region): a new layout when they near its edge.
!> Everything runs in the grid's frame; the scene (world frame) is mapped into it once, in init.
!> The step calls its parts through their interfaces: steps 1, 2 and 4 through the velocity fields
!> (velocity_fields: one field, or one per body with &contact; USL or MUSL), 3 and 5 through the
!> stabilizers, the walls and structures through the constraint list, and the features a scene may
!> declare (inflow, volume correction) through the step components (step_component), stage by stage.
module mpm_solver
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_Allgather, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_MIN, &
                      MPI_INTEGER8
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use error_status, only: status_t
   use communication_counters, only: count_collective, comm_time_step, comm_balance, comm_other, real_bytes, int8_bytes
   use scene_description, only: scene_t, run_control_t, model_newtonian_fluid
   use sensor_setup, only: attach_scene_sensors, check_sensors_on_surfaces
   use domain_decomposition, only: domain_t, layout_dims, fit_box, min_slab_width
   use shape_functions, only: shape_function_kind, ghost_node_layers, shape_linear
   use load_balance, only: balanced_layout
   use particle_redistribution, only: redistribute_particles
   use background_grid, only: grid_t
   use node_halo, only: sum_shared_nodes
   use particle_set, only: particle_set_t
   use tensor_layout, only: n_spin
   use particle_seeding, only: seed_bodies
   use body_lattice, only: scene_id_count
   use particle_sorting, only: sort_by_material_and_cell, update_cells, set_material_ranges, in_material_order
   use particle_migration, only: migrate_particles
   use material_model, only: material_slot_t
   use material_factory, only: build_materials
   use newtonian_fluid, only: newtonian_fluid_t
   use stabilizer, only: stabilizer_slot_t, stage_context_t
   use stabilizer_factory, only: build_stabilizers
   use c0_anti_locking, only: c0_anti_locking_t
   use constraint_list, only: constraint_list_t
   use constraint_factory, only: build_constraints
   use step_component, only: component_slot_t, step_state_t
   use step_component_factory, only: build_step_components
   use wall_loads, only: wall_loads_t
   use fluid_gauges, only: fluid_gauges_t
   use body_motion, only: body_motion_t
   use body_contact, only: contact_field_rows
   use velocity_fields, only: velocity_fields_t, transfer_state_t
   use velocity_fields_factory, only: build_velocity_fields
   use rigid_bodies, only: rigid_set_t
   use world_frame, only: frame_t, place_grid
   use stencil_cache, only: stencil_cache_t, forget_stencils
   use run_diagnostics, only: diagnostics_t, compute_diagnostics
   use active_region, only: scene_extent, particle_extent, cells_of_extent, guard_cells, box_needs_change, target_box, &
                            slack_cells
   use status_broadcast, only: agree_on_status
   use health_check, only: particles_healthy, motion_scan_t, scan_motion, merge_motion_scans
   use input_text, only: int_text, real_text, real_list_text, group_context
   use phase_timers, only: phase_timers_t, phase_particles_to_grid, phase_grid_update, phase_walls, &
                           phase_stabilization, phase_grid_to_particles, phase_constitutive, &
                           phase_halo, phase_migration, phase_sort, phase_time_step, &
                           phase_loads, phase_health, phase_other
   implicit none
   private

   !> Steps between full re-sorts of the particles when none arrived from another rank.
   integer, parameter :: sort_interval = 20
   !> &run flip_fraction is the FLIP share of a step of the automatic length at this CFL number (the default
   !> cfl; blend_per_step) [R]: the blend of every scene run at the default step is as it was.
   real(rp), parameter :: blend_reference_cfl = 0.5_rp
   !> The default automatic step (&run cfl = 0) per material [R] (docs/theory.md section 5.1). A weakly
   !> compressible fluid on multilinear functions steps at 0.75 h / c (CFL 1.06 in 2-D, 1.30 in 3-D; the
   !> bench dam break's kinetic energy 0.57 % from half that step in 2.6 times fewer steps): its sound speed
   !> is chosen for the step, and the smoothing of FOAL1 and NB, in passes per reference step
   !> (smoothing_passes), keeps its rate per unit time. Everything else at CFL 0.5: a fluid with C0, whose
   !> cell averages leave a checkerboard pressure that grows at long steps (the filling tank at 3 s, [Y17]
   !> Fig. 1: RMS 0.31 / 0.30 / 0.56 rho g 1 m at CFL 0.5 / 0.75 / 1.06), a solid, whose waves carry the
   !> loads of an impact and whose front overshoots more at larger steps (an elastic block on a wall: the
   !> peak +4..6 % of rho c_P A v at 0.5, +6..13 % at 1.06), a rigid body, whose rotation is explicit, and
   !> quadratic B-splines, with which a tank's start-up transient stays in its loads longer (the 3-D
   !> hydrostatic floor force over 0.02 s: -0.44 % at 0.5, -0.6 % at 1.0 and 1.30).
   real(rp), parameter :: other_default_cfl = 0.5_rp
   !> a fluid's default step as a fraction of h / c (its CFL number is this times sqrt(dim))
   real(rp), parameter :: fluid_default_step = 0.75_rp

   !> The stages of the step at which the components act (step_component), in the order the step reaches them.
   integer, parameter :: stage_before_walls_move = 1, stage_walls_placed = 2, stage_grid_summed = 3, &
                         stage_particles_moved = 4, stage_stress_updated = 5, stage_end_step = 6

   !> The time loop's flags that advance sets itself (solver_t%loop_flags): a particle is unhealthy
   !> (health_check), the particle arrays could not grow. The caller's own flags follow them.
   integer, parameter, public :: flag_unhealthy = 1, flag_no_memory = 2

   type, public :: solver_t
      type(scene_t) :: scene                    !< what the constraints are rebuilt from (a new layout)
      type(run_control_t) :: run
      real(rp) :: gravity(3) = 0.0_rp           !< grid frame
      type(domain_t) :: domain
      type(grid_t) :: grid
      type(particle_set_t) :: particles
      type(material_slot_t), allocatable :: materials(:)
      type(stabilizer_slot_t), allocatable :: schemes(:)
      type(constraint_list_t) :: constraints   !< walls, box sides, inlets' walls, structures (loads.csv order)
      !> the features of the step the scene declares (step_component): inflow, volume correction
      type(component_slot_t), allocatable :: components(:)
      type(wall_loads_t) :: loads               !< impulse of every wall since the last row of loads.csv
      !> per sensor on a wall (sensor_setup), how far it lies from the surface of its wall [m] and the part of a
      !> panel's area off the wettable surface (checked at the start)
      real(rp), allocatable :: sensor_offset(:), sensor_outside(:)
      type(fluid_gauges_t) :: gauges            !< the &gauge sensors (gauges.csv)
      type(body_motion_t) :: bodies             !< the solid bodies (bodies.csv)
      !> the grid's velocity field(s) and the transfers through them: one field, or with &contact one per body
      class(velocity_fields_t), allocatable :: fields
      type(rigid_set_t) :: rigid                !< the rigid bodies (&material model = 'rigid')
      real(rp) :: time = 0.0_rp, dt = 0.0_rp
      !> the automatic step found with dt over the one at the FLIP/PIC blend's reference CFL number
      !> (blend_reference_cfl); 1 with a fixed dt (blend_per_step)
      real(rp) :: reference_steps = 1.0_rp
      !> per material: the CFL number of its automatic step (&run cfl, or its default: material_courant_numbers)
      real(rp), allocatable :: courant(:)
      integer(i8) :: step = 0
      integer :: lost_particles = 0             !< local count of particles that left the grid
      integer :: wall_corrections = 0           !< local count of safeguard corrections
      real(rp) :: mass_tolerance = 0.0_rp       !< nodes lighter than this carry no velocity
      !> per material: its scheme forms the filtered rate of deformation from the nodal velocities, and G2P
      !> forms no particle rates (see materials_taking_rate_from_grid)
      logical, allocatable :: rate_from_grid(:)
      type(stencil_cache_t) :: stencils        !< the particles' stencils at x^n, from P2G to G2P of a step (3-D)
      real(rp) :: extent(3, 2) = 0.0_rp         !< lowest and highest particle position after the last move
      integer :: relayouts = 0                  !< layouts made because the particles outgrew the active region
      !> the largest rank's particle count when the last layout search found no better layout (0: none since
      !> the layout last changed); kept in checkpoints, so a restart searches when the run it continues would
      integer(i8) :: unimproved_largest = 0
      integer :: layout_searches = 0            !< layout searches of the load balancing (this run)
      !> the time loop's flags, carried by the step's one reduction (follow_particles) instead of a reduction
      !> of their own: the caller sets its flags (from index 3) before advance, advance sets flag_unhealthy
      !> (with the limits below) and flag_no_memory and leaves the maxima over the ranks. Unallocated: none.
      integer, allocatable :: loop_flags(:)
      real(rp) :: speed_limit = 0.0_rp          !< blow-up limits of flag_unhealthy (particles_healthy)
      real(rp) :: density_limits(2) = 0.0_rp
      type(phase_timers_t) :: timers            !< wall time per phase (the time loop adds its own phases)
   contains
      procedure :: init => solver_init
      procedure :: advance => solver_advance
      procedure :: stable_time_step => solver_stable_time_step
      procedure :: diagnostics => solver_diagnostics
      procedure :: balance_load => solver_balance_load
      procedure :: set_layout => solver_set_layout
      procedure :: cover_particles => solver_cover_particles
      procedure :: check_particle_memory => solver_check_particle_memory
      procedure :: free => solver_free
   end type solver_t

contains

   !> Decompose, build the grid, materials, schemes and walls, seed the particles. Collective.
   !> With seed_particles = .false. the particle set stays empty: a restart fills it from a checkpoint,
   !> together with time, step, dt, the counters and mass_tolerance.
   subroutine solver_init(self, scene, comm, status, seed_particles)
      class(solver_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      type(MPI_Comm), intent(in) :: comm
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: seed_particles
      real(rp) :: min_mass
      type(frame_t) :: frame
      logical :: seed
      logical, allocatable :: filtered(:)
      integer :: dim, grid_cells(3), i, need_lo(3), need_hi(3), box_lo(3), box_hi(3)
      real(rp) :: grid_origin(3), x_lo(3), x_hi(3)

      dim = scene%grid%dim
      self%scene = scene
      self%run = scene%run
      call place_grid(scene%grid, frame, grid_origin, grid_cells)
      self%gravity = 0.0_rp
      self%gravity(1:dim) = frame%grid_vector(scene%gravity(1:dim))
      ! the active region starts at the bodies and inlets: the empty rest of the grid is never allocated
      call scene_extent(scene, frame, scene%grid%cell_size, 0.0_rp, .true., x_lo, x_hi)
      call cells_of_extent(grid_origin, 1.0_rp / scene%grid%cell_size, grid_cells, dim, x_lo, x_hi, need_lo, need_hi)
      if (any(need_lo(1:dim) > need_hi(1:dim))) then
         need_lo = 0
         need_hi = 0
      end if
      call target_box(need_lo, need_hi, guard_cells(1.0_rp) + slack_cells, grid_cells, dim, box_lo, box_hi)
      self%grid%shape = shape_function_kind(scene%grid%shape_function)
      self%domain%min_width = max(min_slab_width, 1 + 2 * ghost_node_layers(self%grid%shape))
      call self%domain%init(comm, dim, grid_cells, status, box_lo, box_hi)
      if (.not. status%ok) return
      self%grid%field_rows = contact_field_rows(scene)
      call self%grid%init(self%domain, grid_origin, scene%grid%cell_size, frame, status)
      call build_materials(scene%materials, self%materials, status)
      self%courant = material_courant_numbers(scene)
      if (status%ok) call build_stabilizers(scene%materials, self%schemes, status)
      call agree_on_status(status, self%domain%comm)
      if (.not. status%ok) return
      call self%loads%init(scene)
      call build_boundaries(self)
      ! inlet ids start after every id of the bodies (their whole lattices, not just the particles kept)
      call build_step_components(self%scene, scene_id_count(self%scene), self%gravity, &
                                 maxval(self%courant) / blend_reference_cfl, self%constraints, &
                                 self%components)
      call check_sensors_on_surfaces(self%scene, self%grid%h, self%sensor_offset, self%sensor_outside, status)
      if (.not. status%ok) return
      call self%gauges%init(scene, frame, self%gravity)
      call self%bodies%init(scene, self%materials, frame, self%gravity)
      call build_velocity_fields(scene, self%bodies, size(self%materials), self%fields)
      self%rate_from_grid = materials_taking_rate_from_grid(self)

      ! the rate of deformation and the spin are held per particle only for a material with a scheme, which
      ! filters the rate between G2P and the stress update (the spin only if such a model reads it: the
      ! solids' Jaumann rate), and the rate only if the scheme does not take it from the grid; the others'
      ! stay in move_particles' block buffer
      filtered = [(allocated(self%schemes(i)%scheme), i = 1, size(self%materials))]
      call self%particles%init(scene%grid%dim, size(scene%materials), 1024, affine=scene%run%transfer == 'apic', &
                               spin=any([(self%materials(i)%model%uses_spin .and. filtered(i), &
                                          i = 1, size(self%materials))]), &
                               strain_rate=any(filtered .and. .not. self%rate_from_grid))
      seed = .true.
      if (present(seed_particles)) seed = seed_particles
      if (seed) call seed_bodies(scene, self%grid, self%domain, self%particles)
      call self%check_particle_memory(status)
      if (.not. status%ok) return
      if (seed) call displace_fluid(self)
      call self%particles%fit()
      if (seed) call check_structures_clear(self, status)
      if (.not. status%ok) return
      call update_cells(self%grid, self%particles)
      call sort_by_material_and_cell(self%grid, self%particles)
      call self%fields%size_nodes(self%grid)
      ! the rigid bodies' mass, inertia and motion from their particles (a restart reads them)
      call self%rigid%init(scene, self%bodies, self%grid, self%particles, self%domain%comm, measure=seed)

      ! a node is "empty" below a millionth of a millionth of the lightest particle
      ! (of the particles the bodies and the inlets make: a scene may start empty and fill through an inlet)
      min_mass = huge(1.0_rp)
      if (self%particles%count > 0) min_mass = minval(self%particles%mass(1:self%particles%count))
      do i = 1, size(self%components)
         min_mass = min(min_mass, self%components(i)%component%lightest_particle())
      end do
      call MPI_Allreduce(MPI_IN_PLACE, min_mass, 1, MPI_DOUBLE_PRECISION, MPI_MIN, self%domain%comm)
      call count_collective(comm_other, 1, real_bytes)
      self%mass_tolerance = 1.0e-12_rp * min_mass
      self%time = 0.0_rp
      self%step = 0
      self%dt = self%stable_time_step()
      ! the bodies' momentum at t = 0 starts their force series (a restart reads it from the checkpoint)
      if (seed) call self%bodies%start(self%bodies%measure(self%particles, self%grid%frame, self%domain%comm))
   end subroutine solver_init

   !> Fail on every rank if the particle arrays of some rank could not grow (seeding, inflow, migration):
   !> the message of the lowest such rank. Collective.
   subroutine solver_check_particle_memory(self, status)
      class(solver_t), intent(in) :: self
      type(status_t), intent(inout) :: status
      if (.not. self%particles%allocation%ok) &
         call status%fail('rank '//int_text(self%domain%rank)//': '//trim(self%particles%allocation%message))
      call agree_on_status(status, self%domain%comm)
   end subroutine solver_check_particle_memory

   !> The boundary constraints (walls, box sides, inlets' walls, structures, with their local nodes, in the
   !> order of the entries of loads.csv) and the sensors on them (gauges, panels, load cells).
   subroutine build_boundaries(self)
      type(solver_t), intent(inout) :: self
      call build_constraints(self%scene, self%grid, self%time, self%constraints)
      call attach_scene_sensors(self%scene, self%loads%names, self%grid, self%constraints, self%sensor_offset, &
                                self%sensor_outside)
   end subroutine build_boundaries


   !> A structure displaces the fluid: the particles of fluid bodies seeded inside it (phi < 0) are not
   !> kept, so that a structure can stand in water at rest [R]. Solid bodies are not cut (check_structures_clear
   !> refuses them). Local: a particle's fate depends on its position only.
   subroutine displace_fluid(self)
      type(solver_t), intent(inout) :: self
      integer :: w, p, kept
      logical :: inside
      if (.not. allocated(self%scene%structures)) return
      kept = 0
      do p = 1, self%particles%count
         inside = .false.
         if (self%scene%materials(self%particles%material(p))%model == model_newtonian_fluid) then
            do w = 1, self%constraints%count()
               if (self%constraints%structure(w) == 0) cycle
               if (self%constraints%items(w)%item%distance(self%grid, self%particles%x(:, p)) < 0.0_rp) inside = .true.
            end do
         end if
         if (inside) cycle
         kept = kept + 1
         if (kept < p) call self%particles%copy_particle(p, kept)
      end do
      self%particles%count = kept
   end subroutine displace_fluid

   !> Refuse a scene whose solid bodies start inside a structure: a seeded particle with phi < 0 (whatever the
   !> body's shape). The message names the structure and the place of the lowest rank's first such
   !> particle. Collective.
   subroutine check_structures_clear(self, status)
      type(solver_t), intent(in) :: self
      type(status_t), intent(inout) :: status
      integer :: s, p
      real(rp) :: depth, x(3)
      if (.not. allocated(self%scene%structures)) return
      do s = 1, size(self%scene%structures)
         associate (structure => self%constraints%items(self%constraints%of_structure(s))%item)
            p = structure%first_particle_inside(self%grid, self%particles, depth)
         end associate
         if (p == 0) cycle
         x = 0.0_rp
         x(1:self%grid%dim) = self%grid%frame%world_point(self%particles%x(:, p))
         call status%fail(group_context(self%scene%source_file, 'structure', s, "name '"// &
                                        trim(self%scene%structures(s)%name)//"'")// &
                          ": the structure overlaps a body at the start: a particle of material '"// &
                          trim(self%scene%materials(self%particles%material(p))%name)//"' at "// &
                          '('//real_list_text(x(1:self%grid%dim))//') lies '//real_text(depth)// &
                          ' m inside it (move the body or the structure)')
         exit
      end do
      call agree_on_status(status, self%domain%comm)
   end subroutine check_structures_clear

   !> Rebalance if the largest rank holds more than rebalance_threshold times the mean number of
   !> particles per rank and another layout lowers that largest count (docs/theory.md section 6).
   !> A search that found no better layout is repeated only once the largest count has grown by the
   !> unbalance the threshold allows ((threshold - 1) times the mean) or the layout changed: in a scene
   !> no layout balances better (particles in fewer layers than the ranks need) the search, a pass over
   !> the particles per rank grid, would else run at every check. Between steps only. Collective: one
   !> gather of the counts; the layout search only when unbalanced.
   subroutine solver_balance_load(self, status)
      class(solver_t), intent(inout) :: self
      type(status_t), intent(inout) :: status
      integer(i8) :: counts(self%domain%nranks), largest, now_largest
      integer :: cuts(0:self%domain%nranks, 3)
      real(rp) :: total, allowed
      if (self%domain%nranks == 1 .or. self%run%rebalance_threshold <= 0.0_rp) return
      call MPI_Allgather(int(self%particles%count, i8), 1, MPI_INTEGER8, counts, 1, MPI_INTEGER8, self%domain%comm)
      call count_collective(comm_balance, self%domain%nranks, int8_bytes)
      ! compared as counts times the number of ranks: the largest count against threshold x total
      now_largest = maxval(counts)
      total = real(sum(counts), rp)
      allowed = self%run%rebalance_threshold * total
      if (real(now_largest, rp) * self%domain%nranks <= allowed) return
      if (self%unimproved_largest > 0) then
         if (real(now_largest - self%unimproved_largest, rp) * self%domain%nranks <= allowed - total) return
      end if
      self%layout_searches = self%layout_searches + 1
      call balanced_layout(self%domain, self%grid, self%particles, cuts, largest)
      if (largest < now_largest) then
         call self%set_layout(cuts, status)
      else
         self%unimproved_largest = now_largest     ! no better layout: keep this one
      end if
   end subroutine solver_balance_load

   !> Adopt the decomposition `cuts` (as domain%cuts; the rank grid and the active region may change): the
   !> particles go to their new owners, the grid, the walls' node lists and the node arrays are made for
   !> the new box. When only the outer ends of the slabs move (the active region follows the particles) no
   !> particle changes rank and the particles keep their order. With `moved` (particles read from a
   !> checkpoint of another rank count) every particle is sent to its owner. The stabilizers size their
   !> cell arrays to the grid when they next run. Collective.
   subroutine solver_set_layout(self, cuts, status, moved)
      class(solver_t), intent(inout) :: self
      integer, intent(in) :: cuts(0:, :)
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: moved
      logical :: same_owners
      integer :: k, d
      same_owners = all(layout_dims(cuts) == self%domain%dims)
      do k = 1, 3
         d = self%domain%dims(k)
         if (same_owners) same_owners = all(cuts(1:d - 1, k) == self%domain%cuts(1:d - 1, k))
      end do
      if (present(moved)) same_owners = same_owners .and. .not. moved
      call self%domain%set_layout(cuts)
      self%unimproved_largest = 0      ! a new layout: the balance check may search again
      if (.not. same_owners) then
         call redistribute_particles(self%domain, self%grid, self%particles, status)
         if (.not. status%ok) return
      end if
      call self%grid%init(self%domain, self%grid%origin, self%grid%h, self%grid%frame, status)
      call agree_on_status(status, self%domain%comm)
      if (.not. status%ok) return
      call build_boundaries(self)
      do k = 1, size(self%components)
         call self%components(k)%component%layout_changed()
      end do
      call update_cells(self%grid, self%particles)
      if (.not. same_owners) call sort_by_material_and_cell(self%grid, self%particles)
      call self%fields%size_nodes(self%grid)
   end subroutine solver_set_layout

   !> Lay the active region out around the particles wherever they are (all inside the grid), on this rank
   !> grid, and send every particle to its owner: the particles read from a checkpoint written on another
   !> number of ranks. Collective.
   subroutine solver_cover_particles(self, status)
      class(solver_t), intent(inout) :: self
      type(status_t), intent(inout) :: status
      real(rp) :: extent(6)
      integer :: dim, need_lo(3), need_hi(3), box_lo(3), box_hi(3), cuts(0:self%domain%nranks, 3)
      logical :: kept
      dim = self%grid%dim
      call particle_extent(self%particles, extent(1:3), extent(4:6))
      extent(4:6) = -extent(4:6)
      call MPI_Allreduce(MPI_IN_PLACE, extent, 6, MPI_DOUBLE_PRECISION, MPI_MIN, self%domain%comm)
      call count_collective(comm_balance, 6, real_bytes)
      call needed_cells(self, extent(1:3), -extent(4:6), need_lo, need_hi)
      call target_box(need_lo, need_hi, guard_cells(1.0_rp) + slack_cells, self%grid%global_cells, dim, box_lo, box_hi)
      call fit_box(self%domain%dims, self%grid%global_cells, box_lo, box_hi, self%domain%min_width)
      call self%domain%box_cuts(box_lo, box_hi, cuts, kept)
      call self%set_layout(cuts, status, moved=.true.)
   end subroutine solver_cover_particles

   !> The cells lo..hi the active region must hold: those of the particles' extent x_lo..x_hi (all ranks)
   !> and of the inlets still to inject. The cell 0 if there is nothing (an empty box is not a layout).
   subroutine needed_cells(self, x_lo, x_hi, lo, hi)
      type(solver_t), intent(in) :: self
      real(rp), intent(in) :: x_lo(3), x_hi(3)
      integer, intent(out) :: lo(3), hi(3)
      real(rp) :: inlet_lo(3), inlet_hi(3)
      integer :: dim
      dim = self%grid%dim
      ! inlets opening within the next two steps (self%dt is the next step's): see scene_extent
      call scene_extent(self%scene, self%grid%frame, self%grid%h, self%time, .false., inlet_lo, inlet_hi, &
                        lead=2.0_rp * self%dt)
      call cells_of_extent(self%grid%origin, self%grid%inv_h, self%grid%global_cells, dim, &
                           min(x_lo, inlet_lo), max(x_hi, inlet_hi), lo, hi)
      if (any(lo(1:dim) > hi(1:dim))) then
         lo = 0
         hi = 0
      end if
   end subroutine needed_cells

   !> One explicit step of length self%dt; afterwards self%dt holds the next stable step.
   subroutine solver_advance(self)
      class(solver_t), intent(inout), target :: self
      integer :: m, first, last, arrived, created
      real(rp) :: dt
      type(stage_context_t) :: context
      type(transfer_state_t) :: transfer
      logical :: smoothed(size(self%schemes))

      dt = self%dt
      ! the step's state: what the components' stages read (its parent) and what the transfers read
      transfer = transfer_state_t(domain=self%domain, grid=self%grid, particles=self%particles, &
                                  constraints=self%constraints, stencils=self%stencils, time=self%time, dt=dt, &
                                  reference_steps=self%reference_steps, step=self%step, loads=self%loads, &
                                  rigid=self%rigid, timers=self%timers, &
                                  gravity=self%gravity, mass_tolerance=self%mass_tolerance, &
                                  flip_fraction=blend_per_step(self%run%flip_fraction, self%reference_steps), &
                                  theta=self%run%theta)
      call self%timers%switch_to(phase_walls)
      call self%constraints%set_activity(self%time)
      call run_stage(self, stage_before_walls_move, transfer%step_state_t)
      ! moving walls and structures: placed at t_n (node lists rebuilt), their velocity the mean over the step
      call self%constraints%move(self%grid, self%time, self%time + dt)
      call self%loads%begin_step(self%constraints%count())
      call run_stage(self, stage_walls_placed, transfer%step_state_t)
      context%domain => self%domain
      context%grid => self%grid
      context%stencils => self%stencils
      context%dt = dt
      context%reference_steps = self%reference_steps
      ! the rate's nodal velocities (MUSL; rows 1:dim: with contact fields the common field's)
      context%strain_velocity => self%fields%strain_velocity()
      ! a scheme of a material no body or opened inlet supplies has no particles on any rank: skip it (its
      ! halo exchange and cell scans); a supplied one runs on every rank, with or without particles there
      do m = 1, size(self%schemes)
         smoothed(m) = allocated(self%schemes(m)%scheme)
         if (smoothed(m)) smoothed(m) = material_supplied(self, m)
      end do
      ! only one material supplied: all particles are its particles, on every rank
      context%sole_material = count([(material_supplied(self, m), m = 1, size(self%materials))]) == 1
      call self%timers%switch_to(phase_particles_to_grid)
      call self%fields%to_grid(transfer)
      call self%timers%switch_to(phase_halo)
      call sum_shared_nodes(self%domain, self%grid, self%grid%accumulated)
      call run_stage(self, stage_grid_summed, transfer%step_state_t)
      call self%timers%switch_to(phase_grid_update)
      call self%fields%update_nodes(transfer, dt)

      call self%timers%switch_to(phase_stabilization)
      do m = 1, size(self%schemes)
         if (.not. smoothed(m)) cycle
         call set_slice(m)
         call self%schemes(m)%scheme%prepare(context, self%particles)
      end do

      call self%timers%switch_to(phase_grid_to_particles)
      call self%fields%remap(transfer)
      call move_particles(self, transfer, dt)
      call self%rigid%finish()
      call run_stage(self, stage_particles_moved, transfer%step_state_t)

      call self%timers%switch_to(phase_stabilization)
      do m = 1, size(self%schemes)
         if (.not. smoothed(m)) cycle
         call set_slice(m)
         call self%schemes(m)%scheme%filter_strain_rate(context, self%particles)
      end do
      ! the stress update of the filtered materials (the others had theirs in move_particles)
      call self%timers%switch_to(phase_constitutive)
      do m = 1, size(self%materials)
         first = self%particles%material_first(m)
         last = self%particles%material_last(m)
         if (last < first .or. .not. allocated(self%schemes(m)%scheme)) cycle
         if (self%rate_from_grid(m)) then
            call update_stress_from_cell_rates(self, m, dt)
         else
            call self%materials(m)%model%update_stress(self%grid%dim, dt, self%particles%strain_rate(:, first:last), &
                                                      self%particles%spin(:, first:last), &
                                                      self%particles%density(first:last), &
                                                      self%particles%sbar(:, first:last))
         end if
      end do
      call self%timers%switch_to(phase_stabilization)
      do m = 1, size(self%schemes)
         if (.not. smoothed(m)) cycle
         call set_slice(m)
         call self%schemes(m)%scheme%filter_stress(context, self%particles)
      end do
      call run_stage(self, stage_stress_updated, transfer%step_state_t)

      call self%timers%switch_to(phase_walls)
      ! the safeguard against the moving walls and structures where they are at the step's end
      call self%constraints%place(self%grid, self%time + dt)
      call self%fields%keep_particles_inside(transfer, self%extent(:, 1), self%extent(:, 2), self%wall_corrections)
      call self%timers%switch_to(phase_loads)
      call self%loads%end_step(self%constraints%loads)
      created = 0
      call run_stage(self, stage_end_step, transfer%step_state_t, created)
      call self%timers%switch_to(phase_migration)
      call migrate_particles(self%domain, self%grid, self%particles, self%lost_particles, arrived)
      call self%timers%switch_to(phase_sort)
      ! arrivals and new particles are appended at the end: re-sort where that would split a material's
      ! particles (or any particle was created); otherwise re-sort now and then for memory locality
      ! (removals keep the grouping of the rest). Arrivals that keep the materials in order (one material)
      ! wait for that periodic sort: out of cell order meanwhile, they change only the order of sums (the
      ! receiving rank sorted its whole set at every step in which a particle crossed)
      if (created > 0 .or. mod(self%step + 1, int(sort_interval, i8)) == 0 .or. &
          .not. in_material_order(self%particles, self%particles%count - arrived)) then
         call sort_by_material_and_cell(self%grid, self%particles)
      else
         call set_material_ranges(self%particles)
      end if

      self%time = self%time + dt
      self%step = self%step + 1
      call self%timers%switch_to(phase_time_step)
      call follow_particles(self)
      call self%timers%switch_to(phase_other)

   contains

      !> Stage `stage` of every component, in list order, each timed as its phase; the step's phase resumes.
      subroutine run_stage(self, stage, state, created)
         type(solver_t), intent(inout) :: self
         integer, intent(in) :: stage
         type(step_state_t), intent(inout) :: state
         integer, intent(inout), optional :: created
         integer :: c, resume
         resume = self%timers%current
         do c = 1, size(self%components)
            associate (component => self%components(c)%component)
               call self%timers%switch_to(component%phase)
               select case (stage)
               case (stage_before_walls_move)
                  call component%before_walls_move(state)
               case (stage_walls_placed)
                  call component%walls_placed(state)
               case (stage_grid_summed)
                  call component%grid_summed(state)
               case (stage_particles_moved)
                  call component%particles_moved(state, self%extent)
               case (stage_stress_updated)
                  call component%stress_updated(state)
               case (stage_end_step)
                  created = created + component%end_step(state)
               end select
            end associate
         end do
         if (size(self%components) > 0) call self%timers%switch_to(resume)
      end subroutine run_stage

      subroutine set_slice(material)
         integer, intent(in) :: material
         context%first = self%particles%material_first(material)
         context%last = self%particles%material_last(material)
         context%rate_from_grid = self%rate_from_grid(material)
      end subroutine set_slice
   end subroutine solver_advance

   !> The stress update of material m, whose scheme keeps the filtered rates per cell (rate_from_grid): block
   !> by block, each block's rates gathered into a buffer that stays in L1 (as move_particles does for the
   !> unfiltered materials), so that no particle array is written and read again.
   subroutine update_stress_from_cell_rates(self, m, dt)
      type(solver_t), intent(inout) :: self
      integer, intent(in) :: m
      real(rp), intent(in) :: dt
      integer, parameter :: block_size = 256
      real(rp) :: rate(self%particles%n_sigma, block_size)
      integer :: b, e
      select type (scheme => self%schemes(m)%scheme)
      class is (c0_anti_locking_t)
         do b = self%particles%material_first(m), self%particles%material_last(m), block_size
            e = min(self%particles%material_last(m), b + block_size - 1)
            call scheme%rates_of_particles(self%particles, b, e, rate)
            call self%materials(m)%model%update_stress(self%grid%dim, dt, rate(:, 1:e - b + 1), &
                                                      self%particles%spin(:, b:e), self%particles%density(b:e), &
                                                      self%particles%sbar(:, b:e))
         end do
      end select
   end subroutine update_stress_from_cell_rates

   !> Per material: whether its scheme takes the filtered rate of deformation from the grid (C0 and FOAL1 with
   !> full tensors: cell_strain_rate). It needs all the material's particles to read their rate's nodal
   !> velocities from one field (MUSL's re-mapped ones; with contact fields the common field, which holds
   !> every particle of a material in no &contact), multilinear shape functions (the cell's particles share
   !> the cell's nodes), and a model that reads no spin (the only other use of the particle's velocity
   !> gradient).
   function materials_taking_rate_from_grid(self) result(from_grid)
      type(solver_t), intent(in) :: self
      logical :: from_grid(size(self%materials))
      integer :: m
      from_grid = .false.
      do m = 1, size(self%materials)
         if (.not. allocated(self%schemes(m)%scheme)) cycle
         select type (scheme => self%schemes(m)%scheme)
         class is (c0_anti_locking_t)    ! and FOAL1, which extends it
            from_grid(m) = scheme%takes_rate_from_grid() .and. self%fields%musl .and. &
                           self%grid%shape == shape_linear .and. .not. self%materials(m)%model%uses_spin .and. &
                           .not. self%fields%has_fields_of(m)
         end select
      end do
   end function materials_taking_rate_from_grid

   !> True if material m may have particles on some rank now: a body of it, or an inlet of it that has
   !> opened. The same on every rank (scene and time only), so collective stages can be skipped by it.
   !> A material whose particles all left through open sides still counts (the scheme then just idles).
   logical function material_supplied(self, m) result(supplied)
      type(solver_t), intent(in) :: self
      integer, intent(in) :: m
      integer :: i
      supplied = .false.
      if (allocated(self%scene%bodies)) supplied = any(self%scene%bodies%material_index == m)
      do i = 1, size(self%components)
         if (self%components(i)%component%supplies(m, self%time)) supplied = .true.
      end do
   end function material_supplied

   !> Step 7 (G2P: rate of deformation, velocities with USL, positions), the volume correction's shifts,
   !> and step 5's stress update for the materials no scheme filters, material by material. The stress
   !> update of an unfiltered material follows G2P block by block, so that the block's rate of
   !> deformation is still in cache and no particle array holds it (docs/performance.md, "Memory per
   !> particle"); each particle still gets G2P, its shift and its stress update in this order, so the
   !> results are those of three passes bit for bit. A filtered material's rate goes to
   !> particles%strain_rate for its scheme, and its stress update comes after the filter. self%extent
   !> gets the extent of the new positions.
   subroutine move_particles(self, transfer, dt)
      class(solver_t), intent(inout), target :: self
      type(transfer_state_t), intent(inout) :: transfer
      real(rp), intent(in) :: dt
      integer, parameter :: block_size = 256    ! 8 (2-D) to 12 kB (3-D) of rate: stays in L1
      real(rp) :: rate(self%particles%n_sigma, block_size), extent(3, 2)
      real(rp), allocatable :: spin(:, :)
      integer :: m, first, last, b, e, dim, c
      logical :: uses_spin, with_rate, shifting

      dim = self%grid%dim
      ! a component that shifts particles this step (the volume correction on its steps): asked once here
      shifting = .false.
      do c = 1, size(self%components)
         if (self%components(c)%component%shifts_now()) shifting = .true.
      end do
      self%extent(:, 1) = 0.0_rp
      self%extent(:, 2) = 0.0_rp
      self%extent(1:dim, 1) = huge(1.0_rp)
      self%extent(1:dim, 2) = -huge(1.0_rp)
      ! the material slices are contiguous and cover the set (sorted by material after every arrival)
      do m = 1, size(self%materials)
         first = self%particles%material_first(m)
         last = self%particles%material_last(m)
         if (last < first) cycle
         uses_spin = self%materials(m)%model%uses_spin
         with_rate = .not. self%rate_from_grid(m)
         if (self%rigid%moves_material(m)) then
            ! rigid bodies move as wholes (rigid_bodies): no G2P, no stress
            call self%rigid%move(self%bodies, self%grid, self%particles, first, last, self%extent(1:dim, 1), &
                                 self%extent(1:dim, 2))
            cycle
         end if
         if (allocated(self%schemes(m)%scheme)) then
            call particle_kinematics(first, last, self%particles%strain_rate(:, first:last), &
                                     self%particles%spin(:, first:last))
            if (shifting) call apply_shifts(first, last)
         else
            allocate (spin(merge(n_spin(dim), 0, uses_spin), block_size))
            do b = first, last, block_size
               e = min(last, b + block_size - 1)
               call particle_kinematics(b, e, rate(:, 1:e - b + 1), spin(:, 1:e - b + 1))
               if (shifting) call apply_shifts(b, e)
               call self%materials(m)%model%update_stress(dim, dt, rate(:, 1:e - b + 1), spin(:, 1:e - b + 1), &
                                                         self%particles%density(b:e), self%particles%sbar(:, b:e))
            end do
            deallocate (spin)
         end if
      end do
      call forget_stencils(self%stencils)     ! the particles moved

   contains

      !> The components' shifts of particles first:last (the volume correction's), each timed as its phase (a
      !> clock read per call: per material with a scheme, per block without; called on the steps that shift).
      subroutine apply_shifts(first, last)
         integer, intent(in) :: first, last
         integer :: c
         do c = 1, size(self%components)
            associate (component => self%components(c)%component)
               if (.not. component%shifts_now()) cycle
               call self%timers%switch_to(component%phase)
               call component%shift_particles(self%particles, first, last)
               call self%timers%switch_to(phase_grid_to_particles)
            end associate
         end do
      end subroutine apply_shifts

      !> G2P of particles first:last, their rate and spin into d and w.
      subroutine particle_kinematics(first, last, d, w)
         integer, intent(in) :: first, last
         real(rp), intent(inout), contiguous :: d(:, :), w(:, :)
         call self%fields%kinematics(transfer, dt, first, last, with_rate, uses_spin, d, w, extent)
         self%extent(1:dim, 1) = min(self%extent(1:dim, 1), extent(1:dim, 1))
         self%extent(1:dim, 2) = max(self%extent(1:dim, 2), extent(1:dim, 2))
      end subroutine particle_kinematics
   end subroutine move_particles

   !> dt = CFL h / (sqrt(dim) max_p (c_p + |v_p|)), limited by the viscous step CFL rho h^2 / (2 dim mu)
   !> (algorithms.md section 5.4), or the fixed dt of &run. Collective (global maxima of the speeds).
   real(rp) function solver_stable_time_step(self) result(dt)
      class(solver_t), intent(inout) :: self
      real(rp) :: speeds(2 * size(self%materials)), speed
      call local_speeds(self, speeds)
      speeds = -speeds
      call MPI_Allreduce(MPI_IN_PLACE, speeds, size(speeds), MPI_DOUBLE_PRECISION, MPI_MIN, self%domain%comm)
      call count_collective(comm_time_step, size(speeds), real_bytes)
      call time_step_of_speeds(self, -speeds, wall_speed_ahead(self), dt, speed, self%reference_steps)
   end function solver_stable_time_step

   !> This rank's part of the step's bound, per material m: speeds(2 m - 1) the wave speed at the lowest
   !> density of its particles here, speeds(2 m) their largest |v| (with a fixed step: sqrt(dim) max |v_k|,
   !> no squares that could overflow in a blowing-up state); 0 without particles. Every model's wave speed
   !> falls with density, so c(rho_min) + max |v| bounds c_p + |v_p| at one model call. The two are reduced
   !> apart (a maximum each over the ranks): c(rho_min) + max |v| of the whole material is then the same
   !> number on any rank count, which the largest per-rank sum c + |v| is not (the slowest density and the
   !> fastest particle may lie on different ranks).
   !> `motion`: the materials' scans merged, for the health check (made with a fixed step too, for it).
   subroutine local_speeds(self, speeds, motion)
      type(solver_t), intent(in) :: self
      real(rp), intent(out) :: speeds(:)
      type(motion_scan_t), intent(out), optional :: motion
      integer :: m, first, last
      type(motion_scan_t) :: scan
      speeds = 0.0_rp
      do m = 1, size(self%materials)
         first = self%particles%material_first(m)
         last = self%particles%material_last(m)
         if (last < first) cycle
         if (self%run%fixed_dt <= 0.0_rp .or. present(motion)) &
            call scan_motion(self%particles%v(:, first:last), self%particles%density(first:last), scan)
         if (present(motion)) call merge_motion_scans(motion, scan)
         if (self%run%fixed_dt > 0.0_rp) then
            speeds(2 * m) = sqrt(real(self%grid%dim, rp)) * maxval(abs(self%particles%v(:, first:last)))
         else
            speeds(2 * m - 1) = self%materials(m)%model%wave_speed(scan%lightest)
            speeds(2 * m) = sqrt(scan%speed2)
         end if
      end do
   end subroutine local_speeds

   !> The stable step `dt` from the speeds of all ranks (local_speeds, reduced), and a bound `speed`
   !> [m/s] on how fast the particles move: the largest signal speed c + |v| of the materials and open
   !> inlets, or with a fixed step a bound on the largest |v| (the sound speed is not needed then, and a
   !> blowing-up state may have no valid one). An inlet that is not closed yet counts as a particle of its
   !> fluid at rho0 moving at v0 (a hydrograph: its largest speed until it closes): the step must resolve
   !> the fluid it is about to create (and an empty tank must not take a huge step).
   subroutine time_step_of_speeds(self, speeds, wall_speed, dt, speed, reference_steps)
      type(solver_t), intent(in) :: self
      real(rp), intent(in) :: speeds(:), wall_speed
      real(rp), intent(out) :: dt, speed, reference_steps
      integer :: m, i
      real(rp) :: material_speed(size(self%materials)), created
      ! the particles a component is about to create (an open inlet's fluid), at the smallest CFL number
      created = 0.0_rp
      do i = 1, size(self%components)
         created = max(created, self%components(i)%component%signal_speed(self%time, self%materials, self%grid%dim, &
                                                                           self%run%fixed_dt > 0.0_rp))
      end do
      speed = created
      do m = 1, size(self%materials)
         material_speed(m) = speeds(2 * m - 1) + speeds(2 * m)
         ! a moving wall counts as a particle of every material moving at its speed (it drives the material
         ! next to it at that speed); none: speed unchanged, bit for bit
         if (wall_speed > 0.0_rp) material_speed(m) = max(material_speed(m), speeds(2 * m - 1) + wall_speed)
         speed = max(speed, material_speed(m))
      end do
      if (self%run%fixed_dt > 0.0_rp) then
         dt = self%run%fixed_dt
         reference_steps = 1.0_rp
         return
      end if
      ! each material's step at its CFL number; with one number for all (&run cfl given) the step of the
      ! largest speed, bit for bit (the step falls with the speed)
      dt = huge(1.0_rp)
      if (created > 0.0_rp) dt = automatic_step(self, created, minval(self%courant))
      do m = 1, size(self%materials)
         dt = min(dt, automatic_step(self, material_speed(m), self%courant(m)))
      end do
      reference_steps = 1.0_rp
      if (any(self%courant /= blend_reference_cfl)) reference_steps = dt / automatic_step(self, speed, blend_reference_cfl)
   end subroutine time_step_of_speeds

   !> Per material of the scene, the CFL number of its automatic step: &run cfl when the scene gives it (one
   !> number for all), else the material's default (fluid_default_step h / c for a fluid on multilinear
   !> functions but with C0, else other_default_cfl).
   pure function material_courant_numbers(scene) result(courant)
      type(scene_t), intent(in) :: scene
      real(rp), allocatable :: courant(:)
      integer :: m
      allocate (courant(size(scene%materials)))
      do m = 1, size(scene%materials)
         if (scene%run%cfl > 0.0_rp) then
            courant(m) = scene%run%cfl
         else if (scene%materials(m)%model == model_newtonian_fluid .and. scene%grid%shape_function == 'linear' .and. &
                  scene%materials(m)%stabilization /= 'C0') then
            courant(m) = fluid_default_step * sqrt(real(scene%grid%dim, rp))
         else
            courant(m) = other_default_cfl
         end if
      end do
   end function material_courant_numbers

   !> The step at CFL number cfl for the signal speed `speed`: cfl h / (sqrt(dim) speed), limited by the
   !> fall from rest and the viscous step.
   real(rp) function automatic_step(self, speed, cfl) result(dt)
      type(solver_t), intent(in) :: self
      real(rp), intent(in) :: speed, cfl
      dt = huge(1.0_rp)
      if (speed > 0.0_rp) dt = cfl * self%grid%h / (sqrt(real(self%grid%dim, rp)) * speed)
      ! a body without waves (rigid) at rest: falling from rest it moves g dt^2 / 2 <= cfl h in the step
      if (any(self%gravity /= 0.0_rp)) dt = min(dt, sqrt(2.0_rp * cfl * self%grid%h / norm2(self%gravity)))
      dt = min(dt, viscous_time_step(self, cfl))
   end function automatic_step

   !> The FLIP share of a step, so that the PIC share damps at one rate per unit time: the blend alpha =
   !> &run flip_fraction holds for a step of the automatic length at CFL number blend_reference_cfl, and an
   !> automatic step `reference_steps` times as long takes that many times its PIC share 1 - alpha (at most
   !> all of it). Linear, not alpha**reference_steps: the deviation of the particles' velocities from the
   !> grid's that the PIC share removes is made anew by every transfer, so the energy it takes per unit time
   !> is the share per step over the step (docs/theory.md, "The FLIP/PIC blend as a rate"). At the default
   !> CFL number and with a fixed dt alpha itself, bit for bit.
   pure real(rp) function blend_per_step(alpha, reference_steps) result(share)
      real(rp), intent(in) :: alpha, reference_steps
      share = alpha
      if (reference_steps /= 1.0_rp .and. alpha > 0.0_rp .and. alpha < 1.0_rp) &
         share = max(0.0_rp, 1.0_rp - (1.0_rp - alpha) * reference_steps)
   end function blend_per_step

   !> The next time step, and a new layout if the particles outgrew the active region or it became too big
   !> for them (active_region). One reduction for both: the step, the largest signal speed and the
   !> particles' extent travel together (there is no other reduction per step for the box), and with them
   !> the time loop's flags (loop_flags). Collective.
   subroutine follow_particles(self)
      type(solver_t), intent(inout) :: self
      real(rp), allocatable :: values(:)
      real(rp) :: speed, wall_speed
      integer :: dim, need_lo(3), need_hi(3), box_lo(3), box_hi(3), target_lo(3), target_hi(3), guard, margin, n, flags
      integer :: cuts(0:self%domain%nranks, 3)
      integer(i8) :: largest
      logical :: kept
      type(status_t) :: status
      type(motion_scan_t) :: motion

      dim = self%grid%dim
      ! all as minima: [lo(1:3), -hi(1:3), -speeds(:)] (local_speeds). The extent is that of the positions
      ! the step computed (no pass of its own): the safeguard then moves particles only back behind walls,
      ! by less than the step's travel, and inlets inject into their openings, which the region covers.
      n = 6 + 2 * size(self%materials)
      flags = 0
      if (allocated(self%loop_flags)) flags = size(self%loop_flags)
      allocate (values(n + flags))
      values(1:3) = self%extent(:, 1)
      values(4:6) = -self%extent(:, 2)
      call local_speeds(self, values(7:n), motion)
      values(7:n) = -values(7:n)
      if (flags > 0) then
         call self%timers%switch_to(phase_health)
         ! the velocities and densities as the step's scan found them: the check reads only the stresses
         self%loop_flags(flag_unhealthy) = merge(0, 1, particles_healthy(self%particles, self%speed_limit, &
                                                                         self%density_limits, motion))
         self%loop_flags(flag_no_memory) = merge(0, 1, self%particles%allocation%ok)
         ! maxima as minima of the negated (small integers: exact)
         values(n + 1:) = -real(self%loop_flags, rp)
         call self%timers%switch_to(phase_time_step)
      end if
      call MPI_Allreduce(MPI_IN_PLACE, values, size(values), MPI_DOUBLE_PRECISION, MPI_MIN, self%domain%comm)
      call count_collective(comm_time_step, size(values), real_bytes)
      if (flags > 0) self%loop_flags = nint(-values(n + 1:))
      wall_speed = wall_speed_ahead(self)
      call time_step_of_speeds(self, -values(7:n), wall_speed, self%dt, speed, self%reference_steps)

      ! a state that is no longer finite is the health check's business, not the layout's
      if (.not. all(ieee_is_finite(values(1:n)))) return
      call needed_cells(self, values(1:3), -values(4:6), need_lo, need_hi)
      guard = guard_cells(self%dt * speed * self%grid%inv_h)
      margin = guard + slack_cells
      call target_box(need_lo, need_hi, margin, self%grid%global_cells, dim, target_lo, target_hi)
      call fit_box(self%domain%dims, self%grid%global_cells, target_lo, target_hi, self%domain%min_width)
      call self%domain%region(box_lo, box_hi)
      if (.not. box_needs_change(box_lo, box_hi, need_lo, need_hi, guard, margin, target_lo, target_hi, &
                                 self%grid%global_cells, dim)) return

      call self%domain%box_cuts(target_lo, target_hi, cuts, kept)
      ! an axis that had to be split anew is split by particle count, as load balancing would
      if (.not. kept .and. self%domain%nranks > 1 .and. self%run%rebalance_threshold > 0.0_rp) &
         call balanced_layout(self%domain, self%grid, self%particles, cuts, largest, target_lo, target_hi)
      ! every particle lies in the grid after migration, so the redistribution cannot fail
      call self%set_layout(cuts, status)
      self%relayouts = self%relayouts + 1
   end subroutine follow_particles

   !> The largest speed of the moving walls over the next two steps (two of the last step's length: the
   !> next one is not known yet), for the time step and the active region's guard. 0 without moving walls.
   real(rp) function wall_speed_ahead(self) result(speed)
      type(solver_t), intent(in) :: self
      speed = self%constraints%moving_speed(self%time, self%time + 2.0_rp * self%dt)
   end function wall_speed_ahead

   !> CFL rho0 h^2 / (2 dim mu) over the viscous fluids present.
   real(rp) function viscous_time_step(self, cfl) result(dt)
      type(solver_t), intent(in) :: self
      real(rp), intent(in) :: cfl
      integer :: m
      dt = huge(1.0_rp)
      do m = 1, size(self%materials)
         select type (model => self%materials(m)%model)
         type is (newtonian_fluid_t)
            if (model%viscosity > 0.0_rp) dt = min(dt, cfl * model%reference_density * self%grid%h**2 / &
                                                       (2.0_rp * self%grid%dim * model%viscosity))
         end select
      end do
   end function viscous_time_step

   !> Global diagnostics at the current time. Collective.
   function solver_diagnostics(self) result(diag)
      class(solver_t), intent(in) :: self
      type(diagnostics_t) :: diag
      diag%time = self%time
      diag%step = self%step
      diag%dt = self%dt
      call compute_diagnostics(self%domain%comm, self%particles, self%materials, self%run%floor_size, &
                               int(self%lost_particles, i8), int(self%wall_corrections, i8), diag)
   end function solver_diagnostics

   subroutine solver_free(self)
      class(solver_t), intent(inout) :: self
      call self%domain%free()
   end subroutine solver_free
end module mpm_solver
