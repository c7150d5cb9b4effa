!> The batch cell location (grid%owned_local_cells, written to vectorise) against the per-particle one
!> (grid%owned_local_cell), integer for integer, and its count of particles outside the owned cells.
module test_cell_location
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   implicit none
   private

   public :: test_batch_matches_single_2d, test_batch_matches_single_3d

   real(rp), parameter :: h = 0.25_rp

contains

   subroutine test_batch_matches_single_2d()
      call check_dimension(2)
   end subroutine test_batch_matches_single_2d

   subroutine test_batch_matches_single_3d()
      call check_dimension(3)
   end subroutine test_batch_matches_single_3d

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
