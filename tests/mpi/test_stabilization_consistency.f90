!> The stabilization schemes inside the solver, on any number of ranks:
!>  - FOAL1 smoothing of a random field and of a checkerboard gives the same particle values on one
!>    rank and on all ranks of `comm` (<= 1e-13 relative): the cell halo carries what the fluxes need;
!>  - FOAL1 with gamma_max = 0 is C0, bit for bit;
!>  - C0 in 2-D is one-point quadrature at the cell mass centre (algorithms.md section 2.2);
!>  - C0's and FOAL1's rate from the grid (cell_strain_rate) is the cell average of the particles' rates, in
!>    2-D and 3-D (<= 1e-12 relative), with particles off the lattice;
!>  - NB of the only material takes the grid's mass row of P2G for its own nodal masses, bit for bit;
!>  - FOAL1 and NB of two materials keep each material's sum m_p s_p;
!>  - FOAL1's stress stage sets every particle to q_c + dq_c of its cell, with q_c, m_c and x_o^c summed
!>    here particle by particle and dq_c from limited_flux_increments on those cell data (2-D and 3-D; the
!>    particles out of cell order); in a step of 2.5 reference steps to three passes of 5/6 of the fluxes,
!>    each from the cell values the last left;
!>  - those passes give the same particle values on one rank and on all ranks (the halo exchanged anew per
!>    pass), and FOAL1's and NB's passes keep each material's sum m_p s_p.
module test_stabilization_consistency
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_split, MPI_Comm_free, MPI_Allreduce, MPI_Bcast, &
                      MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_UNDEFINED, MPI_COMM_NULL, operator(/=)
   use assertions, only: assertTrue, assertEqual
   use reproducible_numbers, only: hash01, mirror_swaps
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use stabilizer, only: stage_context_t
   use c0_anti_locking, only: c0_anti_locking_t
   use grid_transfer, only: grid_to_particles, particles_to_grid
   use node_halo, only: sum_shared_nodes
   use shape_functions, only: n_corners, corner_offset, shape_values_and_gradients
   use test_scenes, only: water_scene, add_body
   use foal1_smoothing, only: foal1_smoothing_t
   use input_text, only: real_text, int_text
   use cell_halo, only: padded_cells_t
   use limited_flux_smoothing, only: flux_options_t, flux_workspace_t, limited_flux_increments
   implicit none
   private

   public :: test_c0_volumetric_only, &
             test_conservation_per_material, test_random_field_rank_invariance, test_checkerboard_rank_invariance, &
             test_random_field_3d_rank_invariance, &
             test_gamma_zero_is_c0, test_c0_is_one_point_quadrature_2d, test_nb_sole_material_grid_mass, &
             test_c0_rate_from_grid_2d, test_c0_rate_from_grid_3d, test_foal1_rate_from_grid_2d, &
             test_foal1_rate_from_grid_3d, test_foal1_particles_take_the_cell_smoothing, test_passes_rank_invariance

   integer, parameter :: random_field = 1, checkerboard = 2

contains

   !> A water block of 20 x 12 cells (2-D) filling part of a tank, 2 x 2 particles per cell, one body:
   !> particle ids run 0 .. n - 1.
   function block_scene(dim, scheme) result(scene)
      integer, intent(in) :: dim
      character(len=*), intent(in) :: scheme
      type(scene_t) :: scene
      scene = water_scene(dim, 0.1_rp, [3.0_rp, 2.0_rp, 0.8_rp], 2.0e6_rp, 10.0_rp)
      call add_body(scene, 1, [0.3_rp, 0.0_rp, 0.0_rp], [2.3_rp, 1.2_rp, 0.6_rp], 2, .true., 1.2_rp)
      scene%materials(1)%stabilization = scheme
   end function block_scene

   subroutine test_random_field_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_smoothing(comm, 2, random_field)
   end subroutine test_random_field_rank_invariance

   subroutine test_checkerboard_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_smoothing(comm, 2, checkerboard)
   end subroutine test_checkerboard_rank_invariance

   subroutine test_random_field_3d_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_smoothing(comm, 3, random_field)
   end subroutine test_random_field_3d_rank_invariance

   !> FOAL1 in a step of 2.5 reference steps (three passes), 2-D and 3-D.
   subroutine test_passes_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_smoothing(comm, 2, random_field, 2.5_rp)
      call compare_smoothing(comm, 3, random_field, 2.5_rp)
   end subroutine test_passes_rank_invariance

   !> Smooth the same field on one rank and on all ranks; compare particle by particle (by id).
   subroutine compare_smoothing(comm, dim, pattern, reference_steps)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim, pattern
      real(rp), intent(in), optional :: reference_steps
      type(MPI_Comm) :: serial
      real(rp), allocatable :: one(:, :), all(:, :)
      integer :: rank, n
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_split(comm, merge(0, MPI_UNDEFINED, rank == 0), 0, serial)
      call smoothed_field(comm, dim, pattern, all, reference_steps)
      n = size(all)
      allocate (one(size(all, 1), size(all, 2)))
      one = 0.0_rp
      if (serial /= MPI_COMM_NULL) then
         call smoothed_field(serial, dim, pattern, one, reference_steps)
         call MPI_Comm_free(serial)
      end if
      call MPI_Bcast(one, n, MPI_DOUBLE_PRECISION, 0, comm)
      call assertTrue(maxval(abs(all)) > 0.0_rp, 'field present')
      call assertEqual(0.0_rp, maxval(abs(all - one)) / maxval(abs(one)), 1.0e-13_rp, 'same smoothing on 1 and N ranks')
      call assertTrue(maxval(abs(all - initial_field(dim, pattern, size(all, 2)))) > 0.0_rp, 'the field was smoothed')
   end subroutine compare_smoothing

   !> The field before smoothing, by particle id (as set in smoothed_field).
   function initial_field(dim, pattern, n) result(field)
      integer, intent(in) :: dim, pattern, n
      real(rp), allocatable :: field(:, :)
      integer :: i
      allocate (field(merge(4, 6, dim == 2), n))
      do i = 1, n
         field(:, i) = value_of(int(i - 1, i8), [0, 0, 0], pattern, size(field, 1))
      end do
   end function initial_field

   !> sbar of a particle: pseudo-random from its id, or +-1 by the parity of its cell.
   pure function value_of(id, cell, pattern, n_sigma) result(v)
      integer(i8), intent(in) :: id
      integer, intent(in) :: cell(3), pattern, n_sigma
      real(rp) :: v(n_sigma)
      integer :: j
      do j = 1, n_sigma
         if (pattern == random_field) then
            v(j) = 1.0e3_rp * (hash01(id * 7 + j) - 0.5_rp)
         else
            v(j) = real((-1)**(sum(cell)), rp)
         end if
      end do
   end function value_of

   !> Build the solver with FOAL1 on `comm`, set the field, run FOAL1's stress stage once, return the
   !> particle values (n_sigma, n_particles) indexed by id + 1, summed over ranks.
   subroutine smoothed_field(comm, dim, pattern, field, reference_steps)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim, pattern
      real(rp), allocatable, intent(inout) :: field(:, :)
      real(rp), intent(in), optional :: reference_steps
      type(solver_t), target :: solver
      type(status_t) :: status
      integer :: p, n_total
      real(rp) :: count_real

      call solver%init(block_scene(dim, 'FOAL1'), comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do p = 1, solver%particles%count
         solver%particles%sbar(:, p) = value_of(solver%particles%id(p), &
                                                solver%grid%cell_of_position(solver%particles%x(:, p)), pattern, &
                                                solver%particles%n_sigma)
      end do
      call smooth_stress(solver, 1, reference_steps)

      count_real = real(solver%particles%count, rp)
      call MPI_Allreduce(MPI_IN_PLACE, count_real, 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      n_total = nint(count_real)
      if (.not. allocated(field)) allocate (field(solver%particles%n_sigma, n_total))
      field = 0.0_rp
      do p = 1, solver%particles%count
         field(:, solver%particles%id(p) + 1) = solver%particles%sbar(:, p)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, field, size(field), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call solver%free()
   end subroutine smoothed_field

   !> Two fluids side by side and mixed in some cells, each smoothed by its own FOAL1, then by its own NB:
   !> the sum of m_p s_p of each material is unchanged by the stress stage (cell averaging and fluxes;
   !> NB's projection with the material's own nodal masses), to round-off.
   subroutine test_conservation_per_material(comm)
      type(MPI_Comm), intent(in) :: comm
      call conservation_per_material(comm, 'FOAL1', 1.0_rp)
      call conservation_per_material(comm, 'NB', 1.0_rp)
      call conservation_per_material(comm, 'FOAL1', 2.5_rp)
      call conservation_per_material(comm, 'NB', 2.5_rp)
   end subroutine test_conservation_per_material

   subroutine conservation_per_material(comm, scheme, reference_steps)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), intent(in) :: scheme
      real(rp), intent(in) :: reference_steps
      type(solver_t), target :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      real(rp) :: before(6, 2), after(6, 2), scale(2)
      integer :: m, p
      scene = block_scene(2, scheme)
      scene%materials = [scene%materials(1), scene%materials(1)]
      scene%materials(2)%name = 'oil'
      scene%materials(2)%density = 800.0_rp
      scene%bodies(1)%upper(1) = 1.3_rp
      call add_body(scene, 2, [1.25_rp, 0.0_rp, 0.0_rp], [2.3_rp, 1.2_rp, 0.0_rp], 3, .true., 1.2_rp)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do p = 1, solver%particles%count
         solver%particles%sbar(:, p) = value_of(solver%particles%id(p) + 1000 * solver%particles%material(p), &
                                                [0, 0, 0], random_field, 4)
      end do
      before = material_sums(solver, comm)
      do m = 1, 2
         call smooth_stress(solver, m, reference_steps)
      end do
      after = material_sums(solver, comm)
      do m = 1, 2
         scale(m) = sum(abs(before(5:6, m)))
         call assertEqual(before(1:4, m), after(1:4, m), 1.0e-13_rp * scale(m), 'sum m s conserved per material')
         call assertTrue(maxval(abs(after(5:6, m) - before(5:6, m))) < scale(m), 'scale unchanged')
      end do
      call solver%free()
   end subroutine conservation_per_material

   !> NB of a material that has all the particles (context%sole_material, as the solver sets it) takes
   !> m_i from the grid's mass row of P2G instead of its own sum: the filtered stresses and strain rates
   !> are bitwise those of its own sum, on any number of ranks, in 2-D and 3-D and with both stencils.
   subroutine test_nb_sole_material_grid_mass(comm)
      type(MPI_Comm), intent(in) :: comm
      call nb_sole_material(comm, 2, 'linear')
      call nb_sole_material(comm, 2, 'bspline2')
      call nb_sole_material(comm, 3, 'linear')
   end subroutine test_nb_sole_material_grid_mass

   subroutine nb_sole_material(comm, dim, shape)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      character(len=*), intent(in) :: shape
      type(solver_t), target :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      type(stage_context_t) :: context
      real(rp), allocatable :: s0(:, :), d0(:, :), s_own(:, :), d_own(:, :)
      integer :: p, n, step
      logical :: sole
      scene = block_scene(dim, 'NB')
      scene%grid%shape_function = shape
      scene%bodies(1)%hydrostatic = .false.
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do step = 1, 5          ! a moving block: particles off the lattice
         call solver%advance()
      end do
      n = solver%particles%count
      do p = 1, n
         solver%particles%sbar(:, p) = value_of(solver%particles%id(p), [0, 0, 0], random_field, &
                                                solver%particles%n_sigma)
         solver%particles%strain_rate(:, p) = value_of(solver%particles%id(p) + 77, [0, 0, 0], random_field, &
                                                       solver%particles%n_sigma)
      end do
      s0 = solver%particles%sbar(:, 1:n)
      d0 = solver%particles%strain_rate(:, 1:n)
      ! the grid's rows of the current positions, as the step's P2G leaves them
      call particles_to_grid(solver%grid, solver%particles, solver%gravity)
      call sum_shared_nodes(solver%domain, solver%grid, solver%grid%accumulated)
      context%domain => solver%domain
      context%grid => solver%grid
      context%first = solver%particles%material_first(1)
      context%last = solver%particles%material_last(1)
      do step = 1, 2
         sole = step == 2
         context%sole_material = sole
         solver%particles%sbar(:, 1:n) = s0
         solver%particles%strain_rate(:, 1:n) = d0
         call solver%schemes(1)%scheme%prepare(context, solver%particles)
         call solver%schemes(1)%scheme%filter_strain_rate(context, solver%particles)
         call solver%schemes(1)%scheme%filter_stress(context, solver%particles)
         if (.not. sole) then
            s_own = solver%particles%sbar(:, 1:n)
            d_own = solver%particles%strain_rate(:, 1:n)
         end if
      end do
      call assertTrue(maxval(abs(s_own - s0)) > 0.0_rp, 'NB smoothed the stress')
      call assertEqual(0.0_rp, maxval(abs(solver%particles%sbar(:, 1:n) - s_own)), 0.0_rp, &
                       'grid mass row: stresses bitwise equal ('//shape//')')
      call assertEqual(0.0_rp, maxval(abs(solver%particles%strain_rate(:, 1:n) - d_own)), 0.0_rp, &
                       'grid mass row: strain rates bitwise equal ('//shape//')')
      call solver%free()
   end subroutine nb_sole_material

   !> C0 with volumetric_only: the mean normal stress becomes its cell's mass-weighted mean (so the sum of
   !> m_p times it is kept), and every particle keeps its deviatoric stress.
   subroutine test_c0_volumetric_only(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t), target :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      real(rp), allocatable :: deviator(:, :)
      real(rp) :: before(2), after(2), mean, spread
      integer :: p, c, q
      scene = block_scene(2, 'C0')
      scene%materials(1)%volumetric_only = .true.
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      allocate (deviator(4, solver%particles%count))
      do p = 1, solver%particles%count
         solver%particles%sbar(:, p) = value_of(solver%particles%id(p), [0, 0, 0], random_field, 4)
         mean = sum(solver%particles%sbar(1:3, p)) / 3.0_rp
         deviator(:, p) = solver%particles%sbar(:, p) - [mean, mean, mean, 0.0_rp]
      end do
      before = volumetric_sums(solver, comm)
      call smooth_stress(solver, 1)
      after = volumetric_sums(solver, comm)
      call assertEqual(before(1), after(1), 1.0e-13_rp * before(2), 'sum m_p mean stress kept')
      spread = 0.0_rp
      do p = 1, solver%particles%count
         mean = sum(solver%particles%sbar(1:3, p)) / 3.0_rp
         spread = max(spread, maxval(abs(solver%particles%sbar(:, p) - [mean, mean, mean, 0.0_rp] - deviator(:, p))))
         c = solver%particles%cell(p)
         do q = p + 1, min(p + 8, solver%particles%count)      ! particles of one cell share one mean
            if (solver%particles%cell(q) /= c) cycle
            call assertEqual(mean, sum(solver%particles%sbar(1:3, q)) / 3.0_rp, 1.0e-12_rp * before(2) / &
                             solver%particles%mass(p), 'one mean per cell')
         end do
      end do
      call assertTrue(spread < 1.0e-12_rp * before(2) / solver%particles%mass(1), 'deviatoric stress kept')
      call solver%free()
   end subroutine test_c0_volumetric_only

   !> sum m_p (mean normal stress of s_p) and sum m_p |s_p| (a scale), over all ranks.
   function volumetric_sums(solver, comm) result(sums)
      type(solver_t), intent(in) :: solver
      type(MPI_Comm), intent(in) :: comm
      real(rp) :: sums(2)
      integer :: p
      sums = 0.0_rp
      do p = 1, solver%particles%count
         sums(1) = sums(1) + solver%particles%mass(p) * sum(solver%particles%sbar(1:3, p)) / 3.0_rp
         sums(2) = sums(2) + solver%particles%mass(p) * sum(abs(solver%particles%sbar(:, p)))
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
   end function volumetric_sums

   !> Filter part B of material m's scheme on the solver's current state (its cells binned first), in a step
   !> of `reference_steps` (default 1).
   subroutine smooth_stress(solver, m, reference_steps)
      type(solver_t), intent(inout), target :: solver
      integer, intent(in) :: m
      real(rp), intent(in), optional :: reference_steps
      type(stage_context_t) :: context
      if (present(reference_steps)) context%reference_steps = reference_steps
      context%domain => solver%domain
      context%grid => solver%grid
      context%first = solver%particles%material_first(m)
      context%last = solver%particles%material_last(m)
      call solver%schemes(m)%scheme%prepare(context, solver%particles)
      call solver%schemes(m)%scheme%filter_stress(context, solver%particles)
   end subroutine smooth_stress

   !> Rows 1-4: sum m_p s_p per component; rows 5-6: sum m_p |s_p| (a scale); one column per material.
   function material_sums(solver, comm) result(sums)
      type(solver_t), intent(in) :: solver
      type(MPI_Comm), intent(in) :: comm
      real(rp) :: sums(6, 2)
      integer :: p, m
      sums = 0.0_rp
      do p = 1, solver%particles%count
         m = solver%particles%material(p)
         sums(1:4, m) = sums(1:4, m) + solver%particles%mass(p) * solver%particles%sbar(:, p)
         sums(5, m) = sums(5, m) + solver%particles%mass(p) * sum(abs(solver%particles%sbar(:, p)))
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, 12, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
   end function material_sums

   !> FOAL1 with gamma_max = 0 and C0 run 50 steps of a collapsing block to bitwise the same state.
   subroutine test_gamma_zero_is_c0(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: c0, foal1
      type(scene_t) :: scene
      type(status_t) :: status
      type(diagnostics_t) :: diag
      integer :: step, n
      scene = block_scene(2, 'C0')
      scene%bodies(1)%hydrostatic = .false.
      scene%run%cfl = 0.5_rp      ! the same step: by default a FOAL1 fluid steps longer than a C0 one
      call c0%init(scene, comm, status)
      scene%materials(1)%stabilization = 'FOAL1'
      scene%materials(1)%gamma_max = 0.0_rp
      call foal1%init(scene, comm, status)
      do step = 1, 50
         call c0%advance()
         call foal1%advance()
      end do
      call assertEqual(c0%particles%count, foal1%particles%count, 'same particles')
      n = c0%particles%count
      ! bitwise: the largest difference is exactly zero
      call assertEqual(0.0_rp, maxval(abs(c0%particles%sbar(:, 1:n) - foal1%particles%sbar(:, 1:n))), 0.0_rp, &
                       'stresses bitwise equal')
      call assertEqual(0.0_rp, maxval(abs(c0%particles%x(:, 1:n) - foal1%particles%x(:, 1:n))), 0.0_rp, &
                       'positions bitwise equal')
      diag = c0%diagnostics()
      call assertTrue(diag%kinetic_energy > 0.0_rp, 'the block moved')
      call c0%free()
      call foal1%free()
   end subroutine test_gamma_zero_is_c0

   !> With nodal velocities v_i arbitrary, C0's cell average of d_p equals sym(sum v_i (x) grad N_i(x_o^c))
   !> at the cell's mass centre x_o^c: sum_p m_p grad N_i(x_p) = m_c grad N_i(x_o^c) for bilinear N.
   subroutine test_c0_is_one_point_quadrature_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t), target :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      type(stage_context_t) :: context
      real(rp), allocatable :: centre(:, :), mass(:), x_n(:, :)
      real(rp) :: xi(2), n(4), g(2, 4), l(2, 2), d_expected(4), c_real(3)
      integer :: i, p, c, a, k, cell(3), base, checked
      scene = block_scene(2, 'C0')
      scene%run%update_scheme = 'USL'    ! the solver keeps particle rates (with MUSL C0 takes them from the grid)
      ! particles away from the lattice of cell centres, so that mass centres are not cell centres
      scene%bodies(1)%lower(1) = 0.33_rp
      scene%bodies(1)%upper(1) = 2.33_rp
      scene%bodies(1)%particles_per_cell = 3
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do i = 1, solver%grid%node_count
         solver%grid%velocity(:, i) = [sin(1.7_rp * i), cos(0.3_rp * i**2)]
      end do
      solver%grid%velocity_increment = 0.0_rp
      context%domain => solver%domain
      context%grid => solver%grid
      context%first = solver%particles%material_first(1)
      context%last = solver%particles%material_last(1)
      x_n = solver%particles%x(:, 1:solver%particles%count)
      call solver%schemes(1)%scheme%prepare(context, solver%particles)
      call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 1.0_rp, 1.0_rp, .false., .true., .false., &
                             solver%particles%strain_rate, solver%particles%spin)
      call solver%schemes(1)%scheme%filter_strain_rate(context, solver%particles)
      allocate (centre(2, solver%grid%cell_count), mass(solver%grid%cell_count))
      centre = 0.0_rp
      mass = 0.0_rp
      do p = 1, solver%particles%count
         c = solver%particles%cell(p)
         mass(c) = mass(c) + solver%particles%mass(p)
         centre(:, c) = centre(:, c) + solver%particles%mass(p) * x_n(:, p)
      end do
      checked = 0
      do p = 1, solver%particles%count
         c = solver%particles%cell(p)
         cell = solver%grid%cell_of_position(x_n(:, p))
         c_real = 0.0_rp
         c_real(1:2) = centre(:, c) / mass(c)
         xi = (c_real(1:2) - solver%grid%origin(1:2)) * solver%grid%inv_h - cell(1:2)
         call shape_values_and_gradients(2, xi, solver%grid%inv_h, n, g)
         base = solver%grid%local_node(cell(1:2))
         l = 0.0_rp
         do a = 1, n_corners(2)
            do k = 1, 2
               l(:, k) = l(:, k) + solver%grid%velocity(:, base + solver%grid%stencil_stride(a)) * g(k, a)
            end do
         end do
         d_expected = [l(1, 1), l(2, 2), 0.0_rp, 0.5_rp * (l(1, 2) + l(2, 1))]
         call assertEqual(d_expected, solver%particles%strain_rate(:, p), 1.0e-11_rp, 'd~_c = d(x_o^c)')
         checked = checked + 1
      end do
      call assertTrue(checked > 0 .and. corner_offset(4, 2) == 1, 'particles checked')
      call solver%free()
   end subroutine test_c0_is_one_point_quadrature_2d

   subroutine test_c0_rate_from_grid_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_rate_from_grid(comm, 2, 'C0')
   end subroutine test_c0_rate_from_grid_2d

   subroutine test_c0_rate_from_grid_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_rate_from_grid(comm, 3, 'C0')
   end subroutine test_c0_rate_from_grid_3d

   subroutine test_foal1_rate_from_grid_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_rate_from_grid(comm, 2, 'FOAL1')
   end subroutine test_foal1_rate_from_grid_2d

   subroutine test_foal1_rate_from_grid_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      call compare_rate_from_grid(comm, 3, 'FOAL1')
   end subroutine test_foal1_rate_from_grid_3d

   !> C0's d~_c from the grid (context%rate_from_grid: cell_strain_rate, from the cells' local moments) against
   !> the mass-weighted cell average of the particles' own rates from G2P, with the same arbitrary nodal
   !> velocities. The particles are moved off their lattice (within their cells), so that the mean of a
   !> product of two coordinates is not the product of their means: in 3-D the moments must carry it.
   subroutine compare_rate_from_grid(comm, dim, scheme_name)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      character(len=*), intent(in) :: scheme_name
      type(solver_t), target :: solver
      type(scene_t) :: scene
      type(status_t) :: status
      type(stage_context_t) :: context
      real(rp), allocatable, target :: velocity(:, :)
      real(rp), allocatable :: expected(:, :), from_grid(:, :)
      real(rp) :: scale
      integer :: i, k, p, first, last
      scene = block_scene(dim, scheme_name)
      scene%run%update_scheme = 'USL'    ! the solver keeps particle rates (the test chooses the path itself)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do p = 1, solver%particles%count
         do k = 1, dim
            solver%particles%x(k, p) = solver%particles%x(k, p) + 0.2_rp * scene%grid%cell_size * sin(3.1_rp * p + 1.7_rp * k)
         end do
      end do
      allocate (velocity(dim, solver%grid%node_count))
      do i = 1, solver%grid%node_count
         do k = 1, dim
            velocity(k, i) = sin(1.7_rp * i + 0.9_rp * k) + cos(0.3_rp * i**2 * k)
         end do
      end do
      first = solver%particles%material_first(1)
      last = solver%particles%material_last(1)
      context%domain => solver%domain
      context%grid => solver%grid
      context%first = first
      context%last = last
      context%strain_velocity => velocity
      ! the particles' own rates, averaged per cell
      context%rate_from_grid = .false.
      call solver%schemes(1)%scheme%prepare(context, solver%particles)
      call grid_to_particles(solver%grid, solver%particles, 1.0e-3_rp, 1.0_rp, 1.0_rp, .false., .true., .false., &
                             solver%particles%strain_rate, solver%particles%spin, strain_velocity=velocity)
      call solver%schemes(1)%scheme%filter_strain_rate(context, solver%particles)
      expected = solver%particles%strain_rate(:, first:last)
      ! the rates from the grid, as the solver's stress update takes them
      context%rate_from_grid = .true.
      call solver%schemes(1)%scheme%prepare(context, solver%particles)
      call solver%schemes(1)%scheme%filter_strain_rate(context, solver%particles)
      allocate (from_grid, mold=expected)
      from_grid = 0.0_rp
      select type (scheme => solver%schemes(1)%scheme)
      class is (c0_anti_locking_t)
         call assertTrue(scheme%takes_rate_from_grid(), scheme_name//' with full tensors takes its rate from the grid')
         call scheme%rates_of_particles(solver%particles, first, last, from_grid)
      end select
      scale = maxval(abs(expected))
      call assertTrue(last >= first .and. scale > 0.0_rp, 'particles with a rate')
      call assertEqual(0.0_rp, maxval(abs(from_grid - expected)) / scale, 1.0e-12_rp, &
                       scheme_name//': d~_c from the grid = the cell average of the particle rates')
      call solver%free()
   end subroutine compare_rate_from_grid

   !> FOAL1's stress stage (cell sums, packing with the division by m_c, halo, fluxes, and the particle update
   !> q_p := q_c + dq_c of eq. 13) against the same update assembled here from its parts: m_c, x_o^c and q_c
   !> summed particle by particle, dq_c from limited_flux_increments on those cell data. On one rank (the
   !> fluxes of a rank's border cells need its neighbours' cells; 1 against N ranks is compare_smoothing).
   subroutine test_foal1_particles_take_the_cell_smoothing(comm)
      type(MPI_Comm), intent(in) :: comm
      type(MPI_Comm) :: serial
      integer :: rank
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_split(comm, merge(0, MPI_UNDEFINED, rank == 0), 0, serial)
      if (.not. (serial /= MPI_COMM_NULL)) return
      call check_particle_update(serial, 2, 1.0_rp)
      call check_particle_update(serial, 3, 1.0_rp)
      call check_particle_update(serial, 2, 2.5_rp)
      call check_particle_update(serial, 3, 2.5_rp)
      call MPI_Comm_free(serial)
   end subroutine test_foal1_particles_take_the_cell_smoothing

   !> In a step of 2.5 reference steps the expected values are three passes of 5/6 of the increments, each
   !> from the cell values the last pass left (smoothing_passes).
   subroutine check_particle_update(comm, dim, reference_steps)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      real(rp), intent(in) :: reference_steps
      type(solver_t), target :: solver
      type(status_t) :: status
      type(padded_cells_t) :: box
      type(flux_options_t) :: options
      type(flux_workspace_t) :: workspace
      real(rp), allocatable :: mass(:), centre(:, :), q(:, :), dq(:, :), expected(:, :), q0(:, :)   ! (padded cells)
      logical, allocatable :: exists(:)
      integer, allocatable :: dest(:)
      integer :: p, i, nq, pass, passes
      real(rp) :: worst, largest_change, share
      character(len=:), allocatable :: label

      call solver%init(block_scene(dim, 'FOAL1'), comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      nq = solver%particles%n_sigma
      do p = 1, solver%particles%count      ! off the lattice: mass centres not at the cell centres
         solver%particles%sbar(:, p) = value_of(solver%particles%id(p), [0, 0, 0], random_field, nq)
         solver%particles%x(:, p) = solver%particles%x(:, p) + 0.02_rp * (hash01(7 * solver%particles%id(p)) - 0.5_rp)
      end do
      ! out of cell order (every 7th particle swapped with its mirror): cells come in several runs, and a run
      ! continues a sum left earlier (one material: the permutation keeps its range)
      dest = mirror_swaps(solver%particles%count, 3, 7)
      call solver%particles%permute(dest)
      select type (scheme => solver%schemes(1)%scheme)
      type is (foal1_smoothing_t)
         options = scheme%options
      class default
         call assertTrue(.false., 'the material runs FOAL1')
      end select

      ! the cell data, summed here by the particles' cells (particles%cell, as FOAL1 bins them)
      call box%init(solver%grid)
      allocate (mass(box%count), centre(dim, box%count), q(nq, box%count), dq(nq, box%count), exists(box%count))
      mass = 0.0_rp
      centre = 0.0_rp
      q = 0.0_rp
      do p = 1, solver%particles%count
         i = box%of_owned(solver%particles%cell(p))
         mass(i) = mass(i) + solver%particles%mass(p)
         centre(:, i) = centre(:, i) + solver%particles%mass(p) * solver%particles%x(:, p)
         q(:, i) = q(:, i) + solver%particles%mass(p) * solver%particles%sbar(:, p)
      end do
      exists = mass > 0.0_rp
      do i = 1, box%count
         if (.not. exists(i)) cycle
         centre(:, i) = centre(:, i) / mass(i)
         q(:, i) = q(:, i) / mass(i)
      end do
      passes = ceiling(reference_steps)
      share = min(1.0_rp, reference_steps / passes)
      q0 = q
      do pass = 1, passes
         call limited_flux_increments(box, solver%grid%h, exists, mass, centre, q, options, dq, workspace)
         q = q + share * dq
      end do
      allocate (expected(nq, solver%particles%count))
      do p = 1, solver%particles%count
         i = box%of_owned(solver%particles%cell(p))
         expected(:, p) = q(:, i)
      end do
      label = int_text(dim)//'-D, '//int_text(passes)//' pass(es): '

      call smooth_stress(solver, 1, reference_steps)
      worst = 0.0_rp
      do p = 1, solver%particles%count
         worst = max(worst, maxval(abs(solver%particles%sbar(:, p) - expected(:, p))))
      end do
      largest_change = maxval(abs(q - q0))
      call assertTrue(largest_change > 10.0_rp, label//'the fluxes change the cell averages, by up to '// &
                      real_text(largest_change))
      call assertTrue(worst <= 1.0e-12_rp * maxval(abs(expected)), label//'q_p = q_c + dq_c, largest '// &
                      'difference '//real_text(worst))
      call solver%free()
   end subroutine check_particle_update
end module test_stabilization_consistency
