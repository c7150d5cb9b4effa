!> The batch cell location (grid%owned_local_cells, written to vectorise) against the per-particle one
!> (grid%owned_local_cell), integer for integer, and its count of particles outside the owned cells; and
!> grid%cell_indices (floating-point quotients) as the inverse of grid%local_cell for every owned cell.
module test_cell_location
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   implicit none
   private

   public :: test_batch_matches_single_2d, test_batch_matches_single_3d, test_cell_indices_invert_local_cell

   real(rp), parameter :: h = 0.25_rp

contains

   subroutine test_batch_matches_single_2d()
      call check_dimension(2)
   end subroutine test_batch_matches_single_2d

   subroutine test_batch_matches_single_3d()
      call check_dimension(3)
   end subroutine test_batch_matches_single_3d

   !> Every owned cell of a small 2-D and 3-D box (off the origin) and of a large 3-D box (2000 x 1500 x 700
   !> cells, 2.1e9 of them: sampled, with every cell of its first and last rows and layers) comes back from
   !> its local index to its global indices. The large box's node arrays would not fit in memory: its grid
   !> gets the sizes grid%init would give it by hand.
   subroutine test_cell_indices_invert_local_cell()
      call check_inverse(2, [3, 2, 0], [7, 7, 0], 1)
      call check_inverse(3, [3, 2, 1], [7, 7, 4], 1)
      call check_inverse(3, [5, 0, 3], [2004, 1499, 702], 97)
   end subroutine test_cell_indices_invert_local_cell

   subroutine check_inverse(dim, lo, hi, sample)
      integer, intent(in) :: dim, lo(3), hi(3), sample
      type(domain_t) :: domain
      type(grid_t) :: grid
      integer, allocatable :: along(:, :)
      integer :: c, g(3), i1, i2, i3, wrong, checked
      if (sample == 1) then
         domain%dim = dim
         domain%global_cells = 1
         domain%global_cells(1:dim) = hi(1:dim) + 3
         domain%cell_lo = lo
         domain%cell_hi = hi
         call grid%init(domain, [0.0_rp, 0.0_rp, 0.0_rp], h)
      else
         grid%dim = dim
         grid%cell_lo = lo
         grid%cell_hi = hi
         grid%n_cells = hi - lo + 1
         grid%inv_row_cells = 1.0_rp / real([grid%n_cells(1), grid%n_cells(1) * grid%n_cells(2)], rp)
      end if
      ! per axis the indices to visit: all of a small box; of a large one the first three, the last three
      ! and every sample-th
      allocate (along(0:maxval(hi - lo) + 1, 3))
      do i1 = 1, 3
         along(0, i1) = 0
         do i2 = lo(i1), hi(i1)
            if (sample > 1 .and. i2 > lo(i1) + 2 .and. i2 < hi(i1) - 2 .and. mod(i2 - lo(i1), sample) /= 0) cycle
            along(0, i1) = along(0, i1) + 1
            along(along(0, i1), i1) = i2
         end do
      end do
      wrong = 0
      checked = 0
      do i3 = 1, along(0, 3)
         do i2 = 1, along(0, 2)
            do i1 = 1, along(0, 1)
               g = [along(i1, 1), along(i2, 2), along(i3, 3)]
               c = grid%local_cell(g(1:dim))
               if (any(grid%cell_indices(c) /= g)) wrong = wrong + 1
               checked = checked + 1
            end do
         end do
      end do
      call assertTrue(checked == product(along(0, :)) .and. checked > 0, 'cells checked')
      call assertTrue(sample > 1 .or. checked == product(hi(1:dim) - lo(1:dim) + 1), 'every cell of the small box')
      call assertEqual(0, wrong, 'cells whose indices do not come back')
   end subroutine check_inverse

   !> A rank owning cells 3..7 of 10 along x, 2..7 (the last) of 8 along y and 0..4 of 6 along z, origin
   !> (-1, 0.5, 2): positions on a lattice of quarter cells from 2 cells before the grid to 2 beyond it
   !> (every face, the last global face, which belongs to the last cell, and outside on every side), and
   !> a point a few ulps past the last face on each axis.
   subroutine check_dimension(dim)
      integer, intent(in) :: dim
      type(domain_t) :: domain
      type(grid_t) :: grid
      real(rp), parameter :: origin(3) = [-1.0_rp, 0.5_rp, 2.0_rp]
      integer, parameter :: global(3) = [10, 8, 6], lo(3) = [3, 2, 0], hi(3) = [7, 7, 4]
      real(rp), allocatable :: x(:, :)
      integer, allocatable :: cell(:)
      integer :: n, p, k, steps(3), i(3), i1, i2, i3, outside, expected_outside, expected
      logical :: same

      domain%dim = dim
      domain%global_cells = 1
      domain%global_cells(1:dim) = global(1:dim)
      domain%cell_lo = 0
      domain%cell_hi = 0
      domain%cell_lo(1:dim) = lo(1:dim)
      domain%cell_hi(1:dim) = hi(1:dim)
      call grid%init(domain, origin, h)

      steps = 1
      steps(1:dim) = 4 * (global(1:dim) + 4) + 1
      n = product(steps) + dim
      allocate (x(dim, n), cell(n))
      p = 0
      do i3 = 0, steps(3) - 1
         do i2 = 0, steps(2) - 1
            do i1 = 0, steps(1) - 1
               i = [i1, i2, i3]
               p = p + 1
               x(:, p) = origin(1:dim) + (0.25_rp * real(i(1:dim), rp) - 2.0_rp) * h
            end do
         end do
      end do
      do k = 1, dim
         p = p + 1
         x(:, p) = origin(1:dim) + (real(lo(1:dim), rp) + 0.5_rp) * h
         x(k, p) = origin(k) + real(global(k), rp) * h
         x(k, p) = x(k, p) + 3.0_rp * spacing(x(k, p))
      end do

      cell = -1
      call grid%owned_local_cells(n, x, cell, outside)
      same = .true.
      expected_outside = 0
      do p = 1, n
         expected = grid%owned_local_cell(x(:, p))
         if (expected == 0) expected_outside = expected_outside + 1
         same = same .and. cell(p) == expected
      end do
      call assertTrue(same, 'every cell as owned_local_cell finds it')
      call assertEqual(expected_outside, outside, 'particles outside the owned cells')
      call assertTrue(expected_outside > 0 .and. expected_outside < n, 'the lattice has particles in and out')
   end subroutine check_dimension
end module test_cell_location
