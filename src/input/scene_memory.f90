!> The memory a scene will need, estimated before any particle is made: the particles each body and inlet
!> creates over the run, the grid nodes, and the bytes per rank against the memory budget (issue 14;
!> docs/input.md, "Memory"). Refuses a scene that will not fit, naming the group that makes most particles.
module scene_memory
   use kinds, only: rp, i8
   use error_status, only: status_t
   use scene_description, only: scene_t, has_velocity_file, model_newtonian_fluid, model_linear_elastic
   use input_text, only: int_text, group_context
   use memory_budget, only: memory_budget_t, byte_text
   use body_lattice, only: has_points_file, body_bounds, count_particles
   use input_checks, only: count_text
   implicit none
   private

   !> An elastic body's impact peak converges from about this many cells across its smallest extent
   !> (docs/contact.md, "The debris peak against resolution": 8, 10 and 20 cells agree within 5 %)
   real(rp), parameter :: resolved_body_cells = 8.0_rp

   public :: check_scene_memory, scene_particle_count, memory_estimate_per_rank, scene_advice
   public :: body_count, wall_count, structure_count, inlet_count, gauge_count, panel_count

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

contains

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

   !> Advice on a valid scene that is likely to fail, or whose answer the grid bounds, '' when there is none:
   !> the run prints it as warnings after its banner (one line each, `separator` between them). APIC on the
   !> multilinear grid with a fluid: its small-mass node where a free surface rises through a row of nodes
   !> blows up at any step (docs/theory.md, "APIC" and section 3.6). An elastic body fewer than
   !> resolved_body_cells cells across: the peak of its impact on a structure grows with refinement until
   !> it has about that many (docs/contact.md, "The debris peak against resolution").
   function scene_advice(scene, separator) result(text)
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: separator
      character(len=:), allocatable :: text
      real(rp) :: lo(3), hi(3), cells
      character(len=24) :: across
      integer :: b, dim
      text = ''
      if (scene%run%transfer == 'apic' .and. scene%grid%shape_function == 'linear' .and. &
          any(scene%materials%model == model_newtonian_fluid)) &
         text = "&run transfer = 'apic' with &grid shape_function = 'linear' and a fluid: APIC blows up where a free "// &
                "surface rises through a row of nodes (waves, bores, moving walls); shape_function = 'bspline2' runs "// &
                "them (docs/theory.md, APIC)"
      dim = scene%grid%dim
      do b = 1, body_count(scene)
         if (scene%materials(scene%bodies(b)%material_index)%model /= model_linear_elastic) cycle
         call body_bounds(scene, b, lo, hi)
         cells = minval(hi(1:dim) - lo(1:dim)) / scene%grid%cell_size
         if (cells >= resolved_body_cells) cycle
         write (across, '(f0.1)') cells
         if (len(text) > 0) text = text//separator
         text = text//"&body '"//trim(scene%bodies(b)%name)//"' (material '"//trim(scene%bodies(b)%material)// &
                "') is "//trim(across)//' cells across: the peak of its impact on a structure is '// &
                'resolution-bound below about '//int_text(nint(resolved_body_cells))//' cells across (its impulse is not; '// &
                'docs/contact.md, "The debris peak against resolution")'
      end do
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

   pure integer function gauge_count(scene)
      type(scene_t), intent(in) :: scene
      gauge_count = 0
      if (allocated(scene%gauges)) gauge_count = size(scene%gauges)
   end function gauge_count

   pure integer function panel_count(scene)
      type(scene_t), intent(in) :: scene
      panel_count = 0
      if (allocated(scene%panels)) panel_count = size(scene%panels)
   end function panel_count
end module scene_memory
