!> The limited constant-flux smoothing of FOAL1 on cell data (algorithms.md section 3.5): conservation,
!> maximum principle, linear preservation, checkerboard removal in 2-D and 3-D, and inert empty,
!> partly filled and foreign cells, the stress's own kernels (4 values in 2-D, 6 in 3-D) against the general
!> code of other value counts, and a workspace reused. One rank: the box's ghost layers lie outside the grid.
module test_limited_flux_smoothing
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use reproducible_numbers, only: hash01
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use cell_halo, only: padded_cells_t
   use limited_flux_smoothing, only: flux_options_t, flux_workspace_t, limited_flux_increments
   use stabilizer, only: smoothing_passes
   implicit none
   private

   public :: test_conservation_random_field, test_maximum_principle, test_linear_field_unchanged, &
             test_checkerboard_2d, test_checkerboard_3d, test_empty_and_partial_cells, test_gamma_zero_no_flux, &
             test_stress_kernels_match_general_code, test_workspace_reused, test_smoothing_passes

   real(rp), parameter :: h = 0.5_rp

   !> Cell data of one material on a padded box.
   type :: cells_t
      type(grid_t) :: grid
      type(padded_cells_t) :: box
      logical, allocatable :: exists(:)
      real(rp), allocatable :: mass(:), centre(:, :), q(:, :), dq(:, :)
   end type cells_t

contains

   !> n(1) x n(2) (x n(3)) cells, all filled uniformly: unit density, centres at the cell centres.
   function uniform_cells(dim, n, nq) result(cells)
      integer, intent(in) :: dim, n(3), nq
      type(cells_t) :: cells
      type(domain_t) :: domain
      integer :: c, k, g(3)
      domain%dim = dim
      domain%global_cells = 1
      domain%global_cells(1:dim) = n(1:dim)
      domain%cell_lo = 0
      domain%cell_hi = 0
      domain%cell_hi(1:dim) = n(1:dim) - 1
      call cells%grid%init(domain, [0.0_rp, 0.0_rp, 0.0_rp], h)
      call cells%box%init(cells%grid)
      allocate (cells%exists(cells%box%count), cells%mass(cells%box%count), cells%centre(dim, cells%box%count), &
                cells%q(nq, cells%box%count), cells%dq(nq, cells%box%count))
      cells%exists = cells%box%owned
      cells%mass = merge(h**dim, 0.0_rp, cells%exists)
      cells%q = 0.0_rp
      do c = 1, cells%box%count
         g = global_cell(cells%box, c)
         do k = 1, dim
            cells%centre(k, c) = (g(k) + 0.5_rp) * h
         end do
      end do
   end function uniform_cells

   !> Global cell indices of padded cell c.
   pure function global_cell(box, c) result(g)
      type(padded_cells_t), intent(in) :: box
      integer, intent(in) :: c
      integer :: g(3), k
      do k = 1, 3
         g(k) = box%lo(k) + mod((c - 1) / box%stride(k), box%n(k))
      end do
   end function global_cell

   subroutine smooth(cells, options)
      type(cells_t), intent(inout) :: cells
      type(flux_options_t), intent(in), optional :: options
      type(flux_options_t) :: defaults
      type(flux_workspace_t) :: workspace
      if (present(options)) defaults = options
      call limited_flux_increments(cells%box, h, cells%exists, cells%mass, cells%centre, cells%q, defaults, cells%dq, &
                                   workspace)
   end subroutine smooth

   !> Mass centres of every cell at reproducible random places inside it (5 % of h or more from its faces).
   subroutine scatter_centres(cells, dim)
      type(cells_t), intent(inout) :: cells
      integer, intent(in) :: dim
      integer :: c, k, g(3)
      do c = 1, cells%box%count
         g = global_cell(cells%box, c)
         do k = 1, dim
            cells%centre(k, c) = (g(k) + 0.05_rp + 0.9_rp * hash01(5 * c + k)) * h
         end do
      end do
   end subroutine scatter_centres

   !> Random masses, mass centres inside the cells and values: sum_c m_c q^_c = sum_c m_c q_c.
   subroutine test_conservation_random_field()
      type(cells_t) :: cells
      integer :: c, j, dim
      real(rp) :: before, after, scale
      do dim = 2, 3
         cells = uniform_cells(dim, [7, 6, 5], 4)
         call scatter_centres(cells, dim)
         do c = 1, cells%box%count
            if (.not. cells%exists(c)) cycle
            cells%mass(c) = h**dim * (0.1_rp + hash01(3 * c))
            do j = 1, 4
               cells%q(j, c) = 1.0e4_rp * (hash01(7 * c + j) - 0.5_rp)
            end do
         end do
         call smooth(cells)
         do j = 1, 4
            before = sum(cells%mass * cells%q(j, :), mask=cells%exists)
            after = sum(cells%mass * (cells%q(j, :) + cells%dq(j, :)), mask=cells%exists)
            scale = sum(cells%mass * abs(cells%q(j, :)), mask=cells%exists)
            call assertEqual(before, after, 1.0e-14_rp * scale, 'sum m q conserved')
         end do
         call assertTrue(maxval(abs(cells%dq)) > 0.0_rp, 'the random field was smoothed')
      end do
   end subroutine test_conservation_random_field

   !> Every smoothed value lies between the extremes of its cell and face neighbours.
   subroutine test_maximum_principle()
      type(cells_t) :: cells
      integer :: c, k, dim, g(3)
      real(rp) :: low, high, smoothed
      do dim = 2, 3
         cells = uniform_cells(dim, [8, 7, 4], 1)
         do c = 1, cells%box%count
            if (.not. cells%exists(c)) cycle
            g = global_cell(cells%box, c)
            cells%mass(c) = h**dim * (0.2_rp + hash01(11 * c))
            cells%q(1, c) = 100.0_rp * (hash01(13 * c) - 0.5_rp)
         end do
         call smooth(cells)
         do c = 1, cells%box%count
            if (.not. cells%exists(c)) cycle
            low = cells%q(1, c)
            high = cells%q(1, c)
            do k = 1, dim
               associate (l => c - cells%box%stride(k), r => c + cells%box%stride(k))
                  if (cells%exists(l)) low = min(low, cells%q(1, l))
                  if (cells%exists(l)) high = max(high, cells%q(1, l))
                  if (cells%exists(r)) low = min(low, cells%q(1, r))
                  if (cells%exists(r)) high = max(high, cells%q(1, r))
               end associate
            end do
            smoothed = cells%q(1, c) + cells%dq(1, c)
            call assertTrue(smoothed >= low - 1.0e-12_rp .and. smoothed <= high + 1.0e-12_rp, 'no new extremum')
         end do
      end do
   end subroutine test_maximum_principle

   !> A linear field on uniformly filled cells (the hydrostatic state) is left exactly as it is.
   subroutine test_linear_field_unchanged()
      type(cells_t) :: cells
      integer :: c, dim
      do dim = 2, 3
         cells = uniform_cells(dim, [6, 8, 5], 2)
         do c = 1, cells%box%count
            if (.not. cells%exists(c)) cycle
            cells%q(1, c) = -1.0e4_rp * (3.2_rp - cells%centre(dim, c))     ! hydrostatic pressure profile
            cells%q(2, c) = 2.0_rp * cells%centre(1, c) - 3.0_rp * cells%centre(2, c) + 0.5_rp
         end do
         call smooth(cells)
         call assertEqual(0.0_rp, maxval(abs(cells%dq)), 1.0e-9_rp, 'linear field unchanged')
      end do
   end subroutine test_linear_field_unchanged

   !> q = +-A checkerboard with equal masses on 8 x 6 cells: removed in one step in every cell whose face
   !> neighbours all have two-sided slopes (two cells or more from the edge). Next to the edge the
   !> one-sided slope of an edge cell makes part of the jump "allowable" (docs/theory.md, section on
   !> FOAL1): |q^| = 3/8 A on an edge (A/8 across the face to the interior, 2 x A/4 along the edge),
   !> 1/2 A beside a corner, 3/4 A in a corner; 1/8 A in the second ring, 1/4 A at its corners.
   subroutine test_checkerboard_2d()
      type(cells_t) :: cells
      integer :: c, g(3), distance(2)
      real(rp), parameter :: a = 1.0_rp
      real(rp) :: smoothed, expected
      cells = uniform_cells(2, [8, 6, 1], 1)
      do c = 1, cells%box%count
         g = global_cell(cells%box, c)
         if (cells%exists(c)) cells%q(1, c) = a * (-1)**(g(1) + g(2))
      end do
      call smooth(cells)
      do c = 1, cells%box%count
         if (.not. cells%exists(c)) cycle
         g = global_cell(cells%box, c)
         distance = [min(g(1), 7 - g(1)), min(g(2), 5 - g(2))]    ! to the edge, along x and along y
         smoothed = abs(cells%q(1, c) + cells%dq(1, c))
         if (minval(distance) >= 2) then
            expected = 0.0_rp
         else if (all(distance == 0)) then
            expected = 0.75_rp * a
         else if (minval(distance) == 0 .and. maxval(distance) == 1) then
            expected = 0.5_rp * a
         else if (minval(distance) == 0) then
            expected = 0.375_rp * a
         else if (all(distance == 1)) then
            expected = 0.25_rp * a
         else
            expected = 0.125_rp * a
         end if
         call assertEqual(expected, smoothed, 1.0e-14_rp, 'checkerboard after one step')
      end do
   end subroutine test_checkerboard_2d

   subroutine test_checkerboard_3d()
      type(cells_t) :: cells
      integer :: c, g(3), interior
      cells = uniform_cells(3, [6, 6, 7], 1)
      do c = 1, cells%box%count
         g = global_cell(cells%box, c)
         if (cells%exists(c)) cells%q(1, c) = (-1.0_rp)**(g(1) + g(2) + g(3))
      end do
      call smooth(cells)
      interior = 0
      do c = 1, cells%box%count
         if (.not. cells%exists(c)) cycle
         g = global_cell(cells%box, c)
         if (minval([g(1), g(2), g(3), 5 - g(1), 5 - g(2), 6 - g(3)]) < 2) cycle
         interior = interior + 1
         call assertEqual(0.0_rp, cells%q(1, c) + cells%dq(1, c), 1.0e-14_rp, '3-D interior checkerboard removed')
      end do
      call assertEqual(2 * 2 * 3, interior, 'interior cells checked')
   end subroutine test_checkerboard_3d

   !> Empty cells, a partly filled cell and cells holding only another material (not "existing" for
   !> this one) get no flux and produce no NaN; fluxes still flow between the existing cells.
   subroutine test_empty_and_partial_cells()
      type(cells_t) :: cells
      integer :: c, g(3)
      cells = uniform_cells(2, [8, 8, 1], 1)
      do c = 1, cells%box%count
         if (.not. cells%exists(c)) cycle
         g = global_cell(cells%box, c)
         cells%q(1, c) = (-1.0_rp)**(g(1) + g(2))
         if (g(1) == 4) then                  ! a column of cells with only the other material
            cells%exists(c) = .false.
            cells%mass(c) = 0.0_rp
            cells%q(1, c) = huge(1.0_rp)      ! whatever is stored there must not be read
         end if
         if (g(1) == 2 .and. g(2) == 3) then  ! a partly filled cell: little mass near its lower face
            cells%mass(c) = 1.0e-6_rp * h**2
            cells%centre(2, c) = (g(2) + 1.0e-9_rp) * h
         end if
      end do
      call smooth(cells)
      call assertTrue(all(abs(cells%dq) < 10.0_rp), 'finite increments everywhere')
      do c = 1, cells%box%count
         if (.not. cells%exists(c)) call assertEqual(0.0_rp, cells%dq(1, c), 0.0_rp, 'no flux into a foreign cell')
      end do
      call assertTrue(maxval(abs(cells%dq)) > 0.0_rp, 'existing cells still smoothed')
   end subroutine test_empty_and_partial_cells

   !> gamma_max = 0 opens no face: all increments are exactly zero (FOAL1 reduces to C0).
   subroutine test_gamma_zero_no_flux()
      type(cells_t) :: cells
      type(flux_options_t) :: options
      integer :: c, g(3)
      cells = uniform_cells(2, [8, 6, 1], 1)
      do c = 1, cells%box%count
         g = global_cell(cells%box, c)
         if (cells%exists(c)) cells%q(1, c) = (-1.0_rp)**(g(1) + g(2))
      end do
      options%gamma_max = 0.0_rp
      call smooth(cells, options)
      call assertEqual(0.0_rp, maxval(abs(cells%dq)), 0.0_rp, 'no increment with gamma_max = 0')
   end subroutine test_gamma_zero_no_flux

   !> The stress's kernels (2-D with 4 values, 3-D with 6, compiled with these sizes) against the general
   !> code, which serves any other count: the same field split in two (values 1 to nq - 1, and values 1 and
   !> nq) goes through the general code, and the increments must agree to round-off (the two are compiled
   !> with different multiply-add fusions). Value 1 is the largest in every cell, so that the noise scale is
   !> the same in every call. A random field with holes, existing ghost cells (their faces add to the owned
   !> side only), oscillations along every axis, both oscillation rules and gamma_max < 1.
   subroutine test_stress_kernels_match_general_code()
      type(cells_t) :: cells, first_values, last_value
      type(flux_options_t) :: options
      integer :: dim, nq, c, k, j, g(3), rule
      real(rp) :: largest
      real(rp), allocatable :: general(:, :)
      do dim = 2, 3
         nq = merge(4, 6, dim == 2)
         do rule = 1, 2
            cells = uniform_cells(dim, [9, 8, 7], nq)
            call scatter_centres(cells, dim)
            do c = 1, cells%box%count
               g = global_cell(cells%box, c)
               cells%exists(c) = hash01(11 * c) > 0.15_rp     ! ghost cells too; about one cell in seven missing
               cells%mass(c) = merge(h**dim * (0.1_rp + hash01(3 * c)), 0.0_rp, cells%exists(c))
               do j = 1, nq      ! a trend under noise: about half of the cells oscillate, along every axis
                  cells%q(j, c) = 10.0_rp * j * g(2) + 60.0_rp * (hash01(7 * c + j) - 0.5_rp)
               end do
               cells%q(1, c) = cells%q(1, c) + 1.0e4_rp
            end do
            options%both_cells_oscillate = rule == 2
            options%gamma_max = 0.7_rp
            first_values = with_values(cells, [(j, j=1, nq - 1)])
            last_value = with_values(cells, [1, nq])
            call smooth(cells, options)
            call smooth(first_values, options)
            call smooth(last_value, options)
            if (allocated(general)) deallocate (general)
            allocate (general(nq, cells%box%count))
            general(1:nq - 1, :) = first_values%dq
            general(nq, :) = last_value%dq(2, :)
            largest = maxval(abs(general))
            call assertTrue(largest > 0.0_rp, 'the field was smoothed')
            do k = 1, dim
               call assertTrue(oscillating_cells(cells, k) > 20, 'cells oscillate along every axis')
            end do
            call assertEqual(0.0_rp, maxval(abs(cells%dq - general)), 1.0e-12_rp * largest, &
                             'the stress kernels give the general code''s increments')
            call assertEqual(0.0_rp, maxval(abs(first_values%dq(1, :) - last_value%dq(1, :))), 0.0_rp, &
                             'value 1 smoothed alike in both general calls')
            call assertTrue(all(cells%dq(:, pack([(c, c=1, cells%box%count)], .not. cells%box%owned)) == 0.0_rp), &
                            'nothing added to a ghost cell')
         end do
      end do
   end subroutine test_stress_kernels_match_general_code

   !> A workspace kept from a call on a wider field, with its dq (a workspace belongs to one dq: it clears
   !> what the last call wrote), gives the increments of a fresh one, bit for bit, in 2-D and 3-D: nothing
   !> of the last call is left or read.
   subroutine test_workspace_reused()
      type(cells_t) :: wide, narrow, fresh
      type(flux_options_t) :: options
      type(flux_workspace_t) :: workspace
      integer :: dim, nq, c, k, g(3)
      do dim = 2, 3
         nq = merge(4, 6, dim == 2)
         wide = uniform_cells(dim, [9, 8, 7], nq)
         call scatter_centres(wide, dim)
         do c = 1, wide%box%count
            wide%q(:, c) = 60.0_rp * [(hash01(7 * c + k), k=1, nq)]
         end do
         ! the outer owned layer along axis 1 and the top one along the last axis empty, their masses and
         ! values left as they were (as FOAL1's cell field keeps a former step's)
         narrow = wide
         do c = 1, narrow%box%count
            g = global_cell(narrow%box, c)
            if (g(1) == 0 .or. g(1) == 8 .or. g(dim) == merge(7, 6, dim == 2)) narrow%exists(c) = .false.
         end do
         fresh = narrow
         call limited_flux_increments(wide%box, h, wide%exists, wide%mass, wide%centre, wide%q, options, wide%dq, &
                                      workspace)
         call limited_flux_increments(narrow%box, h, narrow%exists, narrow%mass, narrow%centre, narrow%q, options, &
                                      wide%dq, workspace)
         call smooth(fresh, options)
         call assertTrue(maxval(abs(fresh%dq)) > 0.0_rp, 'the narrow field was smoothed')
         call assertTrue(all(wide%dq == fresh%dq), 'a reused workspace gives the increments of a fresh one')
      end do
   end subroutine test_workspace_reused

   !> A smoothing made per reference step in a step of a reference steps (stabilizer's smoothing_passes): one
   !> pass of share a up to a = 1 (the reference step itself, to its round-off, whole), ceiling(a) passes of
   !> a / ceiling(a) beyond, so that the passes' shares add up to a and none exceeds 1.
   subroutine test_smoothing_passes()
      real(rp), parameter :: steps(*) = [0.05_rp, 0.5_rp, 1.0_rp, 1.0_rp + 1.0e-12_rp, 1.5_rp, 2.0_rp, 2.12_rp, &
                                         2.6_rp, 7.3_rp]
      integer, parameter :: expected(*) = [1, 1, 1, 1, 2, 2, 3, 3, 8]
      integer :: i, passes
      real(rp) :: share
      do i = 1, size(steps)
         call smoothing_passes(steps(i), passes, share)
         call assertEqual(expected(i), passes, 'passes')
         call assertTrue(share <= 1.0_rp .and. share > 0.5_rp * min(1.0_rp, steps(i)), 'a share of at most 1')
         call assertEqual(min(steps(i), 1.0_rp * passes), passes * share, 1.0e-11_rp, 'the shares add up to the step')
      end do
   end subroutine test_smoothing_passes

   !> Number of owned cells whose value 2 oscillates along axis k (eq. 6: the differences to both
   !> neighbours of opposite sign): each opens the faces along k on both of its sides.
   integer function oscillating_cells(cells, k)
      type(cells_t), intent(in) :: cells
      integer, intent(in) :: k
      integer :: c, s
      s = cells%box%stride(k)
      oscillating_cells = 0
      do c = 1 + s, cells%box%count - s
         if (.not. (cells%box%owned(c) .and. cells%exists(c) .and. cells%exists(c - s) .and. cells%exists(c + s))) cycle
         if ((cells%q(2, c) - cells%q(2, c - s)) * (cells%q(2, c + s) - cells%q(2, c)) < 0.0_rp) &
            oscillating_cells = oscillating_cells + 1
      end do
   end function oscillating_cells

   !> A copy of `cells` with the listed values only.
   function with_values(cells, values) result(copy)
      type(cells_t), intent(in) :: cells
      integer, intent(in) :: values(:)
      type(cells_t) :: copy
      copy = cells
      deallocate (copy%q, copy%dq)
      allocate (copy%q(size(values), cells%box%count), copy%dq(size(values), cells%box%count))
      copy%q = cells%q(values, :)
   end function with_values
end module test_limited_flux_smoothing
