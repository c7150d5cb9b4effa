!> The fluid volume corrections of docs/volume-conservation.md, on 1, 2 and 4 ranks:
!>  - shifting does nothing to a tank whose particles fill space as their volumes say (a uniform lattice
!>    on an aligned grid has occupancy exactly 1: the hat functions' lattice sums are exact), and the run
!>    equals the uncorrected one;
!>  - shifting undoes crowding: two overlapping bodies (occupancy 2 where they overlap, yet J = 1, no
!>    pressure, nothing else moves them) spread until no node is crowded by more than 5 %, with the
!>    mass kept and no particle outside the box; without the correction the overlap stays;
!>  - under gravity the occupancy knows where the free surface is: no shift either when the surface lies
!>    inside a cell; the top particle layer of a tank at rest, pressed together by 10 % (positions only;
!>    volumes, J and stress unchanged), rises back by more than half the drop, and stays pressed without
!>    the correction; 2-D and 3-D;
!>  - the sub-cell fraction under a surface plane is exact (box cut by a plane: known areas and volumes);
!>  - the corrector's shortcuts (height lookups and minima per column, rows above the surface skipped, walls
!>    far from a node left out, cube roots per run, P2G's stencils read, the surface's cut of open supports
!>    in closed form) give the general way's open volumes bit for bit and its fluid volumes and shifts to
!>    round-off, under a free surface that is not flat and beside an inclined wall (2-D and 3-D); P2G's
!>    kept stencils give the gradient of located ones; the gradients (closed form) are the hat functions'
!>    sum over the corners, and scale with a factor, to round-off;
!>  - the lowest height over a rectangle of bins (the height function's block skip and the cut's shortcut
!>    share it, so comparing them cannot see it) is minval's, on every rectangle of a random field;
!>  - eos_relaxation starts a hydrostatic fluid in its EOS state p = K ln(rho/rho_0) and, at rate 1,
!>    puts every particle's pressure back on it after each step.
module test_volume_correction
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_MAX, MPI_INTEGER
   use assertions, only: assertTrue, assertEqual, assertRelativelyEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, wall_spec_t
   use mpm_solver, only: solver_t
   use particle_set, only: particle_set_t
   use particle_sorting, only: set_material_ranges
   use volume_correction, only: volume_corrector_t, part_below, lowest_height
   use run_diagnostics, only: diagnostics_t
   use test_scenes, only: water_scene, add_body
   use input_text, only: real_text, int_text
   use grid_transfer, only: gradient_at_particles, particles_to_grid, volume_to_grid
   use background_grid, only: grid_t
   use stencil_cache, only: holds_stencils
   use reproducible_numbers, only: hash01, mirror_swaps
   implicit none

   !> A solver's volume correction (one of its step components).
   type :: corrector_ref_t
      type(volume_corrector_t), pointer :: corrector => null()
   end type corrector_ref_t
   private

   public :: test_shifting_leaves_a_filled_tank_alone, test_shifting_spreads_crowded_particles, &
             test_eos_relaxation_keeps_the_eos_state, test_shift_takes_the_hydrostatic_pressure, &
             test_eos_relaxation_per_unit_time, &
             test_shifting_lifts_a_crowded_surface_layer, test_fraction_below_a_plane, &
             test_shortcuts_are_the_general_way, test_height_function_skips_exactly, &
             test_lowest_height_is_minval

contains

   !> The volume correction among the solver's step components (the scenes here all select one).
   function corrector_of(solver) result(corrector)
      type(solver_t), intent(in), target :: solver
      type(volume_corrector_t), pointer :: corrector
      integer :: c
      corrector => null()
      do c = 1, size(solver%components)
         select type (component => solver%components(c)%component)
         type is (volume_corrector_t)
            corrector => component
         end select
      end do
      call assertTrue(associated(corrector), 'the scene has a volume correction')
   end function corrector_of

   !> The paper's tank (3.2 m x 6.4 m, half full, h = 0.4 m, 3 x 3 particles per cell), FOAL1, at rest;
   !> in 3-D a 1.6 m x 1.6 m x 3.2 m tank, half full, 2 x 2 x 2 particles per cell. `depth` (default: half
   !> full) moves the free surface off the node row, into a cell.
   function tank_scene(correction, dim, depth) result(scene)
      character(len=*), intent(in) :: correction
      integer, intent(in) :: dim
      real(rp), intent(in), optional :: depth
      type(scene_t) :: scene
      real(rp) :: d
      if (dim == 3) then
         d = 1.6_rp
         if (present(depth)) d = depth
         scene = water_scene(3, 0.4_rp, [1.6_rp, 1.6_rp, 3.2_rp], 2.2e9_rp, 10.0_rp)
         call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [1.6_rp, 1.6_rp, d], 2, .true., d)
      else
         d = 3.2_rp
         if (present(depth)) d = depth
         scene = water_scene(2, 0.4_rp, [3.2_rp, 6.4_rp, 0.0_rp], 2.2e9_rp, 10.0_rp)
         call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [3.2_rp, d, 0.0_rp], 3, .true., d)
      end if
      scene%materials(1)%stabilization = 'FOAL1'
      scene%materials(1)%volume_correction = correction
   end function tank_scene

   !> Also with the free surface inside a cell (22 rows of 3 per cell: 2.933 m, a third into the top cell;
   !> 3-D 1.4 m, half-way): the surface's cut of the nodes' supports is exact there too.
   subroutine test_shifting_leaves_a_filled_tank_alone(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_filled_tank(comm, 2, 3.2_rp)
      call check_filled_tank(comm, 3, 1.6_rp)
      call check_filled_tank(comm, 2, 22 * 0.4_rp / 3)
      call check_filled_tank(comm, 3, 1.4_rp)
   end subroutine test_shifting_leaves_a_filled_tank_alone

   subroutine check_filled_tank(comm, dim, depth)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      real(rp), intent(in) :: depth
      type(solver_t), target :: plain, shifted
      type(volume_corrector_t), pointer :: volume
      type(status_t) :: status
      type(diagnostics_t) :: dp, ds
      integer :: step, n
      real(rp) :: longest

      call plain%init(tank_scene('none', dim, depth), comm, status)
      call assertTrue(status%ok, 'plain: '//trim(status%message))
      call shifted%init(tank_scene('shifting', dim, depth), comm, status)
      call assertTrue(status%ok, 'shifting: '//trim(status%message))
      volume => corrector_of(shifted)
      longest = 0.0_rp
      do step = 1, merge(100, 30, dim == 2)
         call plain%advance()
         call shifted%advance()
         n = shifted%particles%count
         if (n > 0) longest = max(longest, maxval(norm2(volume%shift(:, 1:n), dim=1)))
      end do
      call MPI_Allreduce(MPI_IN_PLACE, longest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertTrue(longest <= 1.0e-12_rp * 0.4_rp, 'no shift in a tank filled to '//real_text(depth)//' m, got '// &
                      real_text(longest)//' m')
      call assertTrue(longest >= 0.0_rp .and. volume%shifting, 'the shifting ran')
      dp = plain%diagnostics()
      ds = shifted%diagnostics()
      ! at rest to round-off: the kinetic energies are ~1e-30 J, compare them against the tank's rho g H^2 W / 2
      call assertTrue(abs(dp%kinetic_energy - ds%kinetic_energy) <= 1.0e-20_rp * 1000 * 10 * 3.2_rp**3 / 2, &
                      'the same kinetic energy: '//real_text(dp%kinetic_energy)//' and '//real_text(ds%kinetic_energy)//' J')
      call assertRelativelyEqual(dp%h_eq, ds%h_eq, 1.0e-12_rp, 'the same h_eq')
      call plain%free()
      call shifted%free()
   end subroutine check_filled_tank

   !> A 2 m x 2 m box without gravity: a body filling the lower half and a second one overlapping its
   !> middle. The particles carry no stress and no velocity, so only the shifting moves them.
   function crowded_scene(correction) result(scene)
      character(len=*), intent(in) :: correction
      type(scene_t) :: scene
      scene = water_scene(2, 0.1_rp, [2.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 0.0_rp)
      scene%materials(1)%stabilization = 'FOAL1'
      scene%materials(1)%volume_correction = correction
      scene%materials(1)%shifting_coefficient = 0.2_rp
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [2.0_rp, 1.0_rp, 0.0_rp], 2, .false., 0.0_rp)
      call add_body(scene, 1, [0.5_rp, 0.2_rp, 0.0_rp], [1.5_rp, 0.8_rp, 0.0_rp], 2, .false., 0.0_rp)
   end function crowded_scene

   !> A dam break (a water column beside a lower layer, so the surface has a step and then slopes) with an
   !> inclined wall beyond the layer (a beach: it cuts supports at angles to the grid), run a few steps by two
   !> identical solvers; then one application each, with the corrector's shortcuts and the general way
   !> (volume_corrector_t%shortcuts): the same open volumes and surface heights bit for bit, the same fluid
   !> volumes and shifts to round-off (the supports no wall cuts take a closed form), and shifts not zero;
   !> and with the stencils its transfer kept, the gradient of a field varying along every axis is that with
   !> the stencils located again.
   subroutine test_shortcuts_are_the_general_way(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_shortcuts(comm, 2)
      call compare_shortcuts(comm, 3)
   end subroutine test_shortcuts_are_the_general_way

   subroutine compare_shortcuts(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(solver_t), target :: solver(2)
      type(corrector_ref_t) :: volumes(2)
      type(scene_t) :: scene
      type(status_t) :: status
      real(rp) :: largest, difference(8), cut_counts(2), steepest, reference(dim), fullest
      real(rp), allocatable :: field(:), kept(:, :), located(:, :), scaled(:, :), occupancy(:), summed(:)
      logical, allocatable :: known(:)
      integer :: i, step, n, node
      character(len=2) :: label
      label = merge('2D', '3D', dim == 2)
      if (dim == 2) then
         scene = water_scene(2, 0.1_rp, [2.0_rp, 1.2_rp, 0.0_rp], 2.0e6_rp, 10.0_rp)
         ! 4 x 4 particles per cell: the surface heights' blocks of 256 particles below the top rows raise no
         ! bin, which the shortcuts skip
         call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [0.6_rp, 0.8_rp, 0.0_rp], 4, .true., 0.8_rp)
         call add_body(scene, 1, [0.6_rp, 0.0_rp, 0.0_rp], [1.4_rp, 0.25_rp, 0.0_rp], 4, .true., 0.25_rp)
         scene%walls = [beach([1.53_rp, 0.0_rp, 0.0_rp], [-1.0_rp, 0.7_rp, 0.0_rp])]
      else
         scene = water_scene(3, 0.1_rp, [1.2_rp, 0.4_rp, 0.8_rp], 2.0e6_rp, 10.0_rp)
         call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [0.4_rp, 0.4_rp, 0.6_rp], 2, .true., 0.6_rp)
         call add_body(scene, 1, [0.4_rp, 0.0_rp, 0.0_rp], [0.9_rp, 0.4_rp, 0.15_rp], 2, .true., 0.15_rp)
         scene%walls = [beach([0.97_rp, 0.0_rp, 0.0_rp], [-1.0_rp, 0.3_rp, 0.8_rp])]
      end if
      scene%materials(1)%stabilization = 'FOAL1'
      scene%materials(1)%volume_correction = 'shifting'
      do i = 1, 2
         call solver(i)%init(scene, comm, status)
         call assertTrue(status%ok, label//': '//trim(status%message))
         do step = 1, 15
            call solver(i)%advance()
         end do
      end do
      volumes = [corrector_ref_t(corrector_of(solver(1))), corrector_ref_t(corrector_of(solver(2)))]
      volumes(2)%corrector%shortcuts = .false.
      do i = 1, 2
         associate (s => solver(i))
            call volumes(i)%corrector%reset_grid()       ! the open volumes measured again, each way
            ! an application as the step makes it: prepare, the transfer (its stencils kept in 3-D), the rest
            call volumes(i)%corrector%prepare(s%domain, s%grid, s%constraints, s%particles, &
                                              int(volumes(i)%corrector%interval, i8))
            call particles_to_grid(s%grid, s%particles, s%gravity, stencils=s%stencils)
            call volumes(i)%corrector%measure_excess(s%domain, s%grid, s%constraints, s%particles, s%stencils)
         end associate
      end do
      call assertTrue(volumes(1)%corrector%shifting_now .and. volumes(1)%corrector%surface_model, label//': an application')
      n = solver(1)%particles%count
      largest = 0.0_rp
      difference = 0.0_rp
      if (n > 0) then
         largest = maxval(abs(volumes(1)%corrector%shift(:, 1:n)))
         difference(1) = maxval(abs(volumes(1)%corrector%shift(:, 1:n) - volumes(2)%corrector%shift(:, 1:n)))
      end if
      difference(2) = maxval(abs(volumes(1)%corrector%open_volume - volumes(2)%corrector%open_volume))
      difference(3) = maxval(abs(volumes(1)%corrector%fluid_volume - volumes(2)%corrector%fluid_volume))
      difference(7) = maxval(abs(volumes(1)%corrector%surface_height - volumes(2)%corrector%surface_height))
      ! supports cut by walls, and open supports the surface cuts (the closed form's)
      associate (v => volumes(1)%corrector)
         cut_counts = [count(.not. v%fully_open), &
                       count(v%fully_open .and. v%fluid_volume > 0.0_rp .and. v%fluid_volume < v%open_volume)]
      end associate
      call MPI_Allreduce(MPI_IN_PLACE, cut_counts, 2, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      ! the stencils kept by the transfer (3-D), which the occupancy and the gradients read, against located
      ! ones, for a nodal field that varies along every axis (the excess of this scene hardly varies across
      ! its layers)
      call assertTrue(holds_stencils(solver(1)%stencils, n) .eqv. dim == 3, label//': stencils kept in 3-D only')
      associate (grid => solver(1)%grid)
         allocate (field(grid%node_count), known(grid%node_count), kept(dim, n), located(dim, n))
         do node = 1, grid%node_count
            field(node) = hash01(node)
            known(node) = hash01(node + grid%node_count) > 0.2_rp
         end do
         call gradient_at_particles(grid, solver(1)%particles, 1, n, field, known, kept, solver(1)%stencils)
         call gradient_at_particles(grid, solver(1)%particles, 1, n, field, known, located)
         ! the gradient of a multiple of the field (the shifts' factor -D h^2 goes in so)
         allocate (scaled(dim, n))
         call gradient_at_particles(grid, solver(1)%particles, 1, n, field, known, scaled, solver(1)%stencils, &
                                    factor=-2.5_rp)
         ! and the gradient of the multilinear functions' formula, particle by particle
         steepest = 0.0_rp
         difference(5) = 0.0_rp
         difference(8) = 0.0_rp
         do i = 1, n
            reference = multilinear_gradient(grid, solver(1)%particles%x(1:dim, i), field, known)
            steepest = max(steepest, maxval(abs(reference)))
            difference(5) = max(difference(5), maxval(abs(kept(:, i) - reference)))
            difference(8) = max(difference(8), maxval(abs(scaled(:, i) + 2.5_rp * reference)))
         end do
      end associate
      difference(4) = 0.0_rp
      if (n > 0) difference(4) = maxval(abs(kept - located))
      ! the occupancy's transfer (its sums kept along runs of particles with one stencil) against the
      ! multilinear functions' formula summed particle by particle, on this rank's nodes
      associate (grid => solver(1)%grid, particles => solver(1)%particles)
         allocate (occupancy(grid%node_count), summed(grid%node_count))
         occupancy = 0.0_rp
         call volume_to_grid(grid, particles, occupancy, solver(1)%stencils)
         summed = 0.0_rp
         do i = 1, n
            call add_multilinear_volume(grid, particles%x(1:dim, i), particles%mass(i) / particles%density(i), summed)
         end do
         fullest = maxval(summed)
         difference(6) = maxval(abs(occupancy - summed))
      end associate
      call MPI_Allreduce(MPI_IN_PLACE, largest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(MPI_IN_PLACE, steepest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(MPI_IN_PLACE, fullest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(MPI_IN_PLACE, difference, 8, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertTrue(difference(5) <= 1.0e-12_rp * steepest, label//': the gradients are the formula''s to '// &
                      'round-off, largest difference '//real_text(difference(5))//' of '//real_text(steepest))
      call assertTrue(difference(8) <= 2.5e-12_rp * steepest, label//': the gradients of -2.5 times the field '// &
                      'are -2.5 times the formula''s, largest difference '//real_text(difference(8)))
      call assertTrue(fullest > 0.0_rp .and. difference(6) <= 1.0e-12_rp * fullest, label//': the occupancy is '// &
                      'the formula''s to round-off, largest difference '//real_text(difference(6))//' of '// &
                      real_text(fullest))
      call assertTrue(largest > 0.0_rp, label//': particles shift')
      call assertTrue(cut_counts(1) > 0.0_rp, label//': walls cut some supports')
      call assertTrue(difference(1) <= 1.0e-10_rp * largest, label//': the same shifts to round-off, largest '// &
                      'difference '//real_text(difference(1))//' m of '//real_text(largest)//' m')
      call assertTrue(difference(2) <= 0.0_rp, label//': the same open volumes bit for bit, largest difference '// &
                      real_text(difference(2))//' m^dim')
      call assertTrue(difference(3) <= 1.0e-13_rp * solver(1)%grid%h**dim, label//': the same fluid volumes to round-off '// &
                      '(the closed form of open supports), largest difference '//real_text(difference(3))//' m^dim')
      call assertTrue(cut_counts(2) > 0.0_rp, label//': the surface cuts supports no wall cuts (the closed form)')
      call assertTrue(difference(7) <= 0.0_rp, label//': the same surface heights bit for bit, largest difference '// &
                      real_text(difference(7))//' m')
      call assertTrue(difference(4) <= 0.0_rp, label//': kept stencils give the located gradient bit for bit, '// &
                      'largest difference '//real_text(difference(4)))
      do i = 1, 2
         call solver(i)%free()
      end do
   contains
      !> sum_a grad N_a(x) f_a over the 2^dim nodes of x's cell (multilinear hat functions), where a node that
      !> is not known takes the N-weighted mean of the known ones (0 if none is).
      function multilinear_gradient(grid, x, field, known) result(gradient)
         type(grid_t), intent(in) :: grid
         real(rp), intent(in) :: x(:), field(:)
         logical, intent(in) :: known(:)
         real(rp) :: gradient(size(x)), xi(size(x)), f(2**size(x)), n(2**size(x)), weight, mean
         integer :: cell(size(x)), corner(size(x), 2**size(x)), a, k, j, node(2**size(x))
         xi = (x - grid%origin(1:size(x))) * grid%inv_h
         cell = floor(xi)
         xi = xi - cell
         weight = 0.0_rp
         mean = 0.0_rp
         do a = 1, 2**size(x)
            corner(:, a) = [(ibits(a - 1, k - 1, 1), k = 1, size(x))]
            node(a) = grid%local_node(cell + corner(:, a))
            n(a) = product(merge(xi, 1.0_rp - xi, corner(:, a) == 1))
            f(a) = field(node(a))
            if (known(node(a))) then
               weight = weight + n(a)
               mean = mean + n(a) * f(a)
            end if
         end do
         if (weight > 0.0_rp) mean = mean / weight
         where (.not. known(node)) f = mean
         gradient = 0.0_rp
         do a = 1, 2**size(x)
            do k = 1, size(x)
               ! d N_a / d x_k: the other axes' factors times +-1/h along k
               gradient(k) = gradient(k) + f(a) * merge(1.0_rp, -1.0_rp, corner(k, a) == 1) * grid%inv_h * &
                             product(merge(xi, 1.0_rp - xi, corner(:, a) == 1), mask=[(j /= k, j = 1, size(x))])
            end do
         end do
      end function multilinear_gradient

      !> summed(i) += N_i(x) volume over the 2^dim nodes of x's cell (multilinear hat functions).
      subroutine add_multilinear_volume(grid, x, volume, summed)
         type(grid_t), intent(in) :: grid
         real(rp), intent(in) :: x(:), volume
         real(rp), intent(inout) :: summed(:)
         real(rp) :: xi(size(x))
         integer :: cell(size(x)), corner(size(x)), a, k, node
         xi = (x - grid%origin(1:size(x))) * grid%inv_h
         cell = floor(xi)
         xi = xi - cell
         do a = 1, 2**size(x)
            corner = [(ibits(a - 1, k - 1, 1), k = 1, size(x))]
            node = grid%local_node(cell + corner)
            summed(node) = summed(node) + product(merge(xi, 1.0_rp - xi, corner == 1)) * volume
         end do
      end subroutine add_multilinear_volume

      !> An unbounded slip wall through `point` with inward normal `normal` (world frame).
      type(wall_spec_t) function beach(point, normal)
         real(rp), intent(in) :: point(3), normal(3)
         beach%point = point
         beach%normal = normal
         beach%moment_point = point
         beach%name = 'beach'
      end function beach
   end subroutine compare_shortcuts

   !> The height function's shortcut skips a block of particles none of which rises above the bins the block
   !> spans. A wide flat layer (4 x 4 particles per cell, 480 per row of cells: blocks of 256 within a row or
   !> two), with a few particles of its top row swapped into the bottom rows: their bins then stand a row
   !> lower until the block that holds them, which must not be skipped. Against the general way, bit for bit,
   !> and against the layer's top.
   subroutine test_height_function_skips_exactly(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t), target :: solver(2)
      type(corrector_ref_t) :: volumes(2)
      type(scene_t) :: scene
      type(status_t) :: status
      integer, allocatable :: dest(:)
      integer :: i, n
      real(rp) :: difference, error
      scene = water_scene(2, 0.1_rp, [3.0_rp, 1.0_rp, 0.0_rp], 2.0e6_rp, 10.0_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [3.0_rp, 0.4_rp, 0.0_rp], 4, .true., 0.4_rp)
      scene%materials(1)%stabilization = 'FOAL1'
      scene%materials(1)%volume_correction = 'shifting'
      do i = 1, 2
         call solver(i)%init(scene, comm, status)
         call assertTrue(status%ok, trim(status%message))
         call solver(i)%advance()             ! sorted by cell: the rows of cells bottom up
      end do
      volumes = [corrector_ref_t(corrector_of(solver(1))), corrector_ref_t(corrector_of(solver(2)))]
      volumes(2)%corrector%shortcuts = .false.
      n = solver(1)%particles%count
      dest = mirror_swaps(n, 37, 100)
      do i = 1, 2
         call solver(i)%particles%permute(dest)
         associate (s => solver(i))
            ! an application as the step makes it (the heights come after the transfer)
            call volumes(i)%corrector%prepare(s%domain, s%grid, s%constraints, s%particles, &
                                              int(volumes(i)%corrector%interval, i8))
            call particles_to_grid(s%grid, s%particles, s%gravity, stencils=s%stencils)
            call volumes(i)%corrector%measure_excess(s%domain, s%grid, s%constraints, s%particles, s%stencils)
         end associate
      end do
      associate (height => volumes(1)%corrector%surface_height)
         difference = maxval(abs(height - volumes(2)%corrector%surface_height))
         ! the bins over the layer (3.0 m of the grid's 3.0 m: all of them) at its top, 0.4 m
         error = maxval(abs(height - 0.4_rp))
      end associate
      call MPI_Allreduce(MPI_IN_PLACE, difference, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertTrue(difference <= 0.0_rp, 'the same heights with the shortcut, largest difference '// &
                      real_text(difference)//' m')
      call assertTrue(error <= 1.0e-6_rp, 'the heights are the layer''s top, 0.4 m, to '//real_text(error)//' m')
      do i = 1, 2
         call solver(i)%free()
      end do
   end subroutine test_height_function_skips_exactly

   subroutine test_shifting_spreads_crowded_particles(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_crowding(comm, 'shifting', 1500, spread=.true.)
      call check_crowding(comm, 'none', 300, spread=.false.)
   end subroutine test_shifting_spreads_crowded_particles

   subroutine check_crowding(comm, correction, steps, spread)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), intent(in) :: correction
      integer, intent(in) :: steps
      logical, intent(in) :: spread
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: before, after
      real(rp) :: crowding, outside
      integer :: step, n

      call solver%init(crowded_scene(correction), comm, status)
      call assertTrue(status%ok, correction//': '//trim(status%message))
      before = solver%diagnostics()
      crowding = largest_crowding(solver, comm)
      call assertTrue(crowding > 0.9_rp, correction//': the overlap crowds the nodes by ~100 %, got '// &
                      real_text(100 * crowding)//' %')
      do step = 1, steps
         call solver%advance()
      end do
      after = solver%diagnostics()
      crowding = largest_crowding(solver, comm)
      if (spread) then
         call assertTrue(crowding < 0.05_rp, correction//': largest crowding after '//real_text(real(steps, rp))// &
                         ' steps below 5 %, got '//real_text(100 * crowding)//' %')
      else
         call assertTrue(crowding > 0.9_rp, correction//': the overlap stays, got '//real_text(100 * crowding)//' %')
      end if
      call assertRelativelyEqual(before%total_mass, after%total_mass, 1.0e-14_rp, correction//': mass kept')
      n = solver%particles%count
      outside = 0.0_rp
      if (n > 0) outside = max(0.0_rp, -minval(solver%particles%x(:, 1:n)), maxval(solver%particles%x(:, 1:n)) - 2.0_rp)
      call MPI_Allreduce(MPI_IN_PLACE, outside, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertTrue(outside <= 0.0_rp, correction//': no particle outside the box')
      call solver%free()
   end subroutine check_crowding

   !> max_i (phi_i - 1) over the nodes, the occupancy measured with the corrector's own open volumes but
   !> here from the particles directly: sum_p N_ip V_p / V_i (V_i = h^2, h^2/2, h^2/4 in the box).
   real(rp) function largest_crowding(solver, comm) result(largest)
      type(solver_t), intent(inout) :: solver
      type(MPI_Comm), intent(in) :: comm
      real(rp), allocatable :: occupancy(:)
      real(rp) :: xi(2), n(4), open_volume
      integer :: p, c(2), a, k, node, corner(2), g(2)
      associate (grid => solver%grid, particles => solver%particles)
         allocate (occupancy(grid%node_count))
         occupancy = 0.0_rp
         do p = 1, particles%count
            do k = 1, 2
               xi(k) = particles%x(k, p) * grid%inv_h
               c(k) = min(floor(xi(k)), grid%global_cells(k) - 1)
               xi(k) = xi(k) - c(k)
            end do
            do a = 1, 4
               corner = [mod(a - 1, 2), (a - 1) / 2]
               n(a) = product(merge(xi, 1.0_rp - xi, corner == 1))
               node = grid%local_node(c + corner)
               occupancy(node) = occupancy(node) + n(a) * particles%mass(p) / particles%density(p)
            end do
         end do
         ! nodes on a rank boundary: only their own particles' share here, so look at interior nodes of the
         ! rank and the box walls (a crowded spot several cells wide is seen by either rank)
         largest = 0.0_rp
         do node = 1, grid%node_count
            g = [grid%node_lo(1) + mod(node - 1, grid%n_nodes(1)), grid%node_lo(2) + (node - 1) / grid%n_nodes(1)]
            if (any((g == grid%node_lo(1:2) .or. g == grid%node_hi(1:2)) .and. &
                    g /= 0 .and. g /= grid%global_cells(1:2))) cycle
            open_volume = grid%h**2
            do k = 1, 2
               if (g(k) == 0 .or. g(k) == grid%global_cells(k)) open_volume = open_volume / 2
            end do
            largest = max(largest, occupancy(node) / open_volume - 1.0_rp)
         end do
      end associate
      call MPI_Allreduce(MPI_IN_PLACE, largest, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
   end function largest_crowding

   subroutine test_shifting_lifts_a_crowded_surface_layer(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_surface_layer(comm, 2)
      call check_surface_layer(comm, 3)
   end subroutine test_shifting_lifts_a_crowded_surface_layer

   !> The tank at rest with the particles of its top cell layer moved down toward the layer's floor by 10 %
   !> of their height above it: the surface (highest particle + half a spacing) drops by 3.3 cm (2-D), 3 cm
   !> (3-D). With shifting it rises back by more than half of that; without, it stays down. (Not all of it:
   !> the shift is the gradient of a multilinear field, constant along the vertical within a cell, so a layer
   !> that is exactly one aligned cell moves up as a whole, and its own crowding stays: measured 62 % and
   !> 70 % of the drop recovered, the rest hidden at the node under it by the gap the layer leaves.)
   subroutine check_surface_layer(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      call pressed_surface_run(comm, dim, 'shifting')
      call pressed_surface_run(comm, dim, 'none')
   end subroutine check_surface_layer

   subroutine pressed_surface_run(comm, dim, correction)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      character(len=*), intent(in) :: correction
      type(solver_t) :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      real(rp) :: depth, spacing, floor_of_layer, surface, pressed
      integer :: step
      character(len=16) :: label

      depth = merge(3.2_rp, 1.6_rp, dim == 2)
      spacing = 0.4_rp / merge(3, 2, dim == 2)
      floor_of_layer = depth - 0.4_rp
      pressed = floor_of_layer + 0.9_rp * (depth - spacing / 2 - floor_of_layer) + spacing / 2
      write (label, '(a, " ", i0, "-D")') correction, dim
      scene = tank_scene(correction, dim)
      scene%materials(1)%shifting_coefficient = 0.2_rp      ! every step: the test needs no patience
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, trim(label)//': '//trim(status%message))
      associate (y => solver%particles%x(dim, 1:solver%particles%count))
         where (y > floor_of_layer) y = floor_of_layer + 0.9_rp * (y - floor_of_layer)
      end associate
      surface = surface_height(solver, comm, dim, spacing)
      call assertRelativelyEqual(pressed, surface, 1.0e-12_rp, trim(label)//': the pressed surface')
      do step = 1, 1000
         call solver%advance()
      end do
      surface = surface_height(solver, comm, dim, spacing)
      if (correction == 'shifting') then
         call assertTrue(surface - pressed >= 0.5_rp * (depth - pressed), trim(label)//': the surface rises from '// &
                         real_text(pressed)//' m by half the drop at least, got '//real_text(surface)//' m')
      else
         call assertTrue(surface - pressed <= 0.1_rp * (depth - pressed), trim(label)//': the surface stays down at '// &
                         real_text(pressed)//' m, got '//real_text(surface)//' m')
      end if
      call solver%free()
   end subroutine pressed_surface_run

   !> Highest particle + half a spacing, over all ranks.
   real(rp) function surface_height(solver, comm, dim, spacing) result(top)
      type(solver_t), intent(in) :: solver
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      real(rp), intent(in) :: spacing
      top = -huge(1.0_rp)
      if (solver%particles%count > 0) top = maxval(solver%particles%x(dim, 1:solver%particles%count)) + spacing / 2
      call MPI_Allreduce(MPI_IN_PLACE, top, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
   end function surface_height

   !> A box cut by a plane: the fraction below it and that part's centroid height against areas and volumes
   !> worked by hand (triangles; the unit cube's s = x + y + z is Irwin-Hall distributed: E[s | s <= 3/2]
   !> = 1.09375, E[s | s <= 1] = 3/4), on every rank.
   subroutine test_fraction_below_a_plane(comm)
      type(MPI_Comm), intent(in) :: comm
      real(rp), parameter :: a = 0.1_rp, r2 = sqrt(2.0_rp), r3 = sqrt(3.0_rp)
      real(rp) :: worst
      worst = 0.0_rp
      ! aligned: a plane on the faces gives 0 or 1 exactly, and inside it the linear share
      call compare('aligned square, plane on the top face', 1.0_rp, 0.5_rp * a, a * [0.0_rp, 1.0_rp], 0.0_rp)
      call compare('aligned square, plane on the bottom face', 0.0_rp, -0.5_rp * a, a * [0.0_rp, 1.0_rp], 0.0_rp)
      call compare('aligned square, a quarter up', 0.75_rp, 0.25_rp * a, a * [0.0_rp, 1.0_rp], -0.125_rp * a)
      ! a square turned 45 degrees: the corner triangle below a plane a/(2 r2) under the centre is 1/8,
      ! its centroid two thirds up from the corner
      call compare('45 degrees, through the centre', 0.5_rp, 0.0_rp, a * [1.0_rp, 1.0_rp] / r2, -r2 * a / 6)
      call compare('45 degrees, the corner', 0.125_rp, -0.5_rp * a / r2, a * [1.0_rp, 1.0_rp] / r2, -r2 * a / 3)
      call compare('45 degrees, all but a corner', 0.875_rp, 0.5_rp * a / r2, a * [1.0_rp, 1.0_rp] / r2, -r2 * a / 21)
      ! a cube on its diagonal: through the centre half; the corner tetrahedron up to its three neighbours 1/6
      call compare('cube diagonal, through the centre', 0.5_rp, 0.0_rp, a * [1.0_rp, 1.0_rp, 1.0_rp] / r3, &
                   -0.40625_rp * a / r3)
      call compare('cube diagonal, the corner tetrahedron', 1.0_rp / 6.0_rp, -0.5_rp * a / r3, &
                   a * [1.0_rp, 1.0_rp, 1.0_rp] / r3, -0.75_rp * a / r3)
      ! a cube with up along a face diagonal: the 2-D answer
      call compare('cube, face diagonal', 0.125_rp, -0.5_rp * a / r2, a * [1.0_rp, 0.0_rp, 1.0_rp] / r2, -r2 * a / 3)
      call MPI_Allreduce(MPI_IN_PLACE, worst, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertTrue(worst <= 1.0e-13_rp, 'every rank: largest error '//real_text(worst))
   contains
      subroutine compare(case, expected, distance, depths, expected_centroid)
         character(len=*), intent(in) :: case
         real(rp), intent(in) :: expected, distance, depths(:), expected_centroid
         real(rp) :: got, centroid
         call part_below(distance, depths, got, centroid)
         call assertTrue(abs(got - expected) <= 1.0e-13_rp, case//': expected '//real_text(expected)//', got '// &
                         real_text(got))
         call assertTrue(abs(centroid - expected_centroid) <= 1.0e-13_rp, case//': centroid expected '// &
                         real_text(expected_centroid)//', got '//real_text(centroid))
         worst = max(worst, abs(got - expected), abs(centroid - expected_centroid))
      end subroutine compare
   end subroutine test_fraction_below_a_plane

   subroutine test_eos_relaxation_keeps_the_eos_state(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: solver
      type(status_t) :: status
      type(scene_t) :: scene
      real(rp) :: worst
      integer :: step

      scene = tank_scene('eos_relaxation', 2)
      scene%materials(1)%stabilization = 'FOAL1'
      scene%materials(1)%eos_relaxation_rate = 1.0_rp
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, trim(status%message))
      worst = eos_mismatch(solver, comm)
      call assertTrue(worst <= 1.0e-5_rp, 'seeded in the EOS state: largest |p - K ln(rho/rho0)| = '// &
                      real_text(worst)//' Pa')
      do step = 1, 20
         call solver%advance()
      end do
      worst = eos_mismatch(solver, comm)
      call assertTrue(worst <= 1.0e-5_rp, 'on the EOS after each step at rate 1: largest mismatch '// &
                      real_text(worst)//' Pa')
      call solver%free()
   end subroutine test_eos_relaxation_keeps_the_eos_state

   !> The relaxation acts at one rate per unit time: a step of 2.5 reference steps leaves a particle's pressure
   !> where 2.5 steps of rate r would, p_EOS + (1 - r)^2.5 (p - p_EOS) (checked against two steps of 1 and one
   !> of 0.5: (1 - r)^2 (1 - r)^0.5), the deviatoric stress untouched.
   subroutine test_eos_relaxation_per_unit_time(comm)
      type(MPI_Comm), intent(in) :: comm
      type(volume_corrector_t) :: corrector
      type(particle_set_t) :: one_step, steps
      type(scene_t) :: scene
      real(rp), parameter :: rate = 0.2_rp, sbar(4) = [-2.0_rp, -2.5_rp, -3.0_rp, 0.5_rp]   ! p = 2502.5 Pa
      real(rp) :: eos, expected, long, short
      scene = tank_scene('eos_relaxation', 2)
      scene%materials(1)%eos_relaxation_rate = rate
      call corrector%init(scene, [0.0_rp, -10.0_rp, 0.0_rp], 1.0_rp)
      call one_step%init(2, 1, 4)
      call one_step%add([1.0_rp, 1.0_rp], [0.0_rp, 0.0_rp], 1.0_rp, 1001.0_rp, sbar, 1, 1_i8)
      call set_material_ranges(one_step)
      steps = one_step
      call corrector%relax_pressure(one_step, 2.5_rp)
      call corrector%relax_pressure(steps, 1.0_rp)
      call corrector%relax_pressure(steps, 1.0_rp)
      call corrector%relax_pressure(steps, 0.5_rp)
      eos = scene%materials(1)%bulk_modulus * log(1001.0_rp / scene%materials(1)%density)
      expected = eos + (1.0_rp - rate)**2.5_rp * (2502.5_rp - eos)
      long = -1001.0_rp * sum(one_step%sbar(1:3, 1)) / 3.0_rp
      short = -1001.0_rp * sum(steps%sbar(1:3, 1)) / 3.0_rp
      call assertTrue(abs(eos - 2502.5_rp) > 100.0_rp, 'the particle starts off the EOS')
      call assertRelativelyEqual(expected, long, 1.0e-12_rp, 'one step of 2.5 reference steps')
      call assertRelativelyEqual(expected, short, 1.0e-12_rp, 'steps of 1, 1 and 0.5 reference steps')
      call assertRelativelyEqual(0.5_rp, one_step%sbar(4, 1), 1.0e-15_rp, 'shear kept')
      call assertEqual(0.5_rp, one_step%sbar(1, 1) - one_step%sbar(2, 1), 1.0e-9_rp, 'deviator kept')
   end subroutine test_eos_relaxation_per_unit_time

   !> A particle shifted by dx in a fluid at rest takes the pressure of its new place: p + rho g . dx
   !> (down by 1 cm under g = 10: +100 Pa at rho = 1000), the deviatoric stress and shear untouched.
   subroutine test_shift_takes_the_hydrostatic_pressure(comm)
      type(MPI_Comm), intent(in) :: comm
      type(volume_corrector_t) :: corrector
      type(particle_set_t) :: particles
      real(rp) :: sbar(4), pressure
      call corrector%init(tank_scene('shifting', 2), [0.0_rp, -10.0_rp, 0.0_rp], 1.0_rp)
      call particles%init(2, 1, 4)
      sbar = [-2.0_rp, -2.0_rp, -2.0_rp, 0.5_rp]            ! p = 2000 Pa at rho = 1000, a shear of 500 Pa
      call particles%add([1.0_rp, 1.0_rp], [0.0_rp, 0.0_rp], 1.0_rp, 1000.0_rp, sbar, 1, 1_i8)
      call set_material_ranges(particles)
      allocate (corrector%shift(2, 1))
      corrector%shift(:, 1) = [0.003_rp, -0.01_rp]
      corrector%shifting_now = .true.      ! as prepare sets it on the steps that shift
      call corrector%apply_shifts(particles, 1, particles%count)
      pressure = -1000.0_rp * sum(particles%sbar(1:3, 1)) / 3.0_rp
      ! every rank does the same: the largest pressure over the ranks is the one to check
      call MPI_Allreduce(MPI_IN_PLACE, pressure, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call assertRelativelyEqual(2100.0_rp, pressure, 1.0e-12_rp, 'pressure 1 cm deeper')
      call assertRelativelyEqual(0.5_rp, particles%sbar(4, 1), 1.0e-15_rp, 'shear kept')
      call assertRelativelyEqual(1.003_rp, particles%x(1, 1), 1.0e-15_rp, 'moved along x')
      call assertRelativelyEqual(0.99_rp, particles%x(2, 1), 1.0e-15_rp, 'moved along y')
   end subroutine test_shift_takes_the_hydrostatic_pressure

   real(rp) function eos_mismatch(solver, comm) result(worst)
      type(solver_t), intent(in) :: solver
      type(MPI_Comm), intent(in) :: comm
      integer :: p
      real(rp) :: pressure
      worst = 0.0_rp
      associate (particles => solver%particles)
         do p = 1, particles%count
            pressure = -particles%density(p) * sum(particles%sbar(1:3, p)) / 3.0_rp
            worst = max(worst, abs(pressure - 2.2e9_rp * log(particles%density(p) / 1000.0_rp)))
         end do
      end associate
      call MPI_Allreduce(MPI_IN_PLACE, worst, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
   end function eos_mismatch

   !> lowest_height against minval over every rectangle of bins of a 7 x 5 field of distinct random heights (an
   !> empty range gives huge); the block skip and the cut's shortcut both use it, so their comparisons with the
   !> general way cannot see an error shared by both (a bin left out at a row's end went unnoticed).
   subroutine test_lowest_height_is_minval(comm)
      type(MPI_Comm), intent(in) :: comm
      real(rp) :: height(7, 5), expected, got
      integer :: i1, i2, j1, j2, wrong, rectangles
      do j1 = 1, 5
         do i1 = 1, 7
            height(i1, j1) = hash01(i1 + 7 * j1)
         end do
      end do
      wrong = 0
      rectangles = 0
      do j1 = 1, 5
         do j2 = j1 - 1, 5
            do i1 = 1, 7
               do i2 = i1 - 1, 7
                  expected = huge(1.0_rp)
                  if (i2 >= i1 .and. j2 >= j1) expected = minval(height(i1:i2, j1:j2))
                  got = lowest_height(height, [i1, j1], [i2, j2])
                  rectangles = rectangles + 1
                  if (abs(got - expected) > 0.0_rp) then   ! exactly minval (no -Wcompare-reals)
                     wrong = wrong + 1
                     if (wrong <= 3) call assertTrue(.false., 'bins '//int_text(i1)//':'//int_text(i2)//' x '// &
                                                     int_text(j1)//':'//int_text(j2)//': expected '// &
                                                     real_text(expected)//', got '//real_text(got))
                  end if
               end do
            end do
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, wrong, 1, MPI_INTEGER, MPI_MAX, comm)
      call assertTrue(wrong == 0 .and. rectangles == 700, 'every rank: '//int_text(wrong)//' of '// &
                      int_text(rectangles)//' rectangles wrong')
   end subroutine test_lowest_height_is_minval
end module test_volume_correction
