!> The cuts of load balancing on known histograms (split_counts) and the rank grids it tries
!> (rank_grids): serial, the expected cuts worked out by hand.
module test_load_balance_cuts
   use kinds, only: i8
   use assertions, only: assertEqual
   use load_balance, only: split_counts, rank_grids, min_slab_width
   implicit none
   private

   public :: test_two_parts_minimise_the_larger, test_many_parts_follow_the_cumulative_count, &
             test_minimum_slab_width, test_rank_grids

contains

   !> Water filling from the left: 10 layers hold 40, 30, 20, 10, then nothing. Cumulative below each
   !> boundary 0, 40, 70, 90, 100: half (50) is nearest at 40 (miss 10; 70 misses 20), so with slabs
   !> of one layer the cut is 1 (40 | 60); with the two-layer minimum it is 2 (70 | 30).
   subroutine test_two_parts_minimise_the_larger()
      integer(i8), parameter :: counts(0:9) = [40_i8, 30_i8, 20_i8, 10_i8, 0_i8, 0_i8, 0_i8, 0_i8, 0_i8, 0_i8]
      integer :: c
      call assertEqual([0, 1, 10], split_counts(counts, 2, 1), 'two parts, slabs of one layer allowed')
      call assertEqual([0, 2, 10], split_counts(counts, 2, min_slab_width), 'two parts, slabs of two layers')
      ! an even histogram splits in the middle
      call assertEqual([0, 5, 10], split_counts([(7_i8, c = 1, 10)], 2, 2), 'even histogram')
      ! all in the last two layers: no cut can share them, every admissible one is as good; the lowest
      call assertEqual([0, 2, 10], split_counts([0_i8, 0_i8, 0_i8, 0_i8, 0_i8, 0_i8, 0_i8, 0_i8, 5_i8, 5_i8], 2, 2), &
                       'all in the last two layers')
   end subroutine test_two_parts_minimise_the_larger

   !> Four parts of 16 layers with counts 1..16 (total 136): cut j nearest to j 136 / 4 = 34, 68, 102.
   !> Cumulative below boundary c: c (c + 1) / 2 = ... 28 36 45 55 66 78 91 105 ... -> boundary 8 (36;
   !> 28 misses more), 11 (66; 78 misses more), 14 (105; 91 misses more).
   subroutine test_many_parts_follow_the_cumulative_count()
      integer(i8) :: counts(0:15)
      integer :: c
      counts = [(int(c + 1, i8), c = 0, 15)]
      call assertEqual([0, 8, 11, 14, 16], split_counts(counts, 4, 2), 'four parts of a ramp')
      ! an empty histogram keeps the lowest admissible cuts
      counts(0:11) = 0
      call assertEqual([0, 2, 4, 6, 12], split_counts(counts(0:11), 4, 2), 'no particles')
   end subroutine test_many_parts_follow_the_cumulative_count

   !> Everything in the first layer, three parts of six layers: the cuts are pushed to the two-layer
   !> minimum behind each other (2, 4), however uneven that leaves the counts.
   subroutine test_minimum_slab_width()
      integer(i8), parameter :: counts(0:5) = [60_i8, 0_i8, 0_i8, 0_i8, 0_i8, 0_i8]
      call assertEqual([0, 2, 4, 6], split_counts(counts, 3, 2), 'three parts, all in layer 0')
      call assertEqual([0, 6], split_counts(counts, 1, 2), 'one part')
   end subroutine test_minimum_slab_width

   !> Rank grids of 4 ranks: in 2-D 1x4, 2x2, 4x1; an axis of 5 cells takes at most 2 slabs (4 x 2 > 5
   !> rules out 1x4 there). In 3-D 2 ranks: along x, y or z.
   subroutine test_rank_grids()
      integer, allocatable :: grids(:, :)
      grids = rank_grids(4, 2, [20, 20, 1])
      call assertEqual(3, size(grids, 2), '4 ranks in 2-D: three grids')
      call assertEqual([1, 4, 1, 2, 2, 1, 4, 1, 1], reshape(grids, [9]), '1x4, 2x2, 4x1')
      grids = rank_grids(4, 2, [20, 5, 1])
      call assertEqual([2, 2, 1, 4, 1, 1], reshape(grids, [6]), 'y has 5 cells: 2x2 and 4x1 only')
      grids = rank_grids(2, 3, [10, 10, 10])
      call assertEqual([1, 1, 2, 1, 2, 1, 2, 1, 1], reshape(grids, [9]), '2 ranks in 3-D')
      grids = rank_grids(1, 2, [3, 3, 1])
      call assertEqual([1, 1, 1], reshape(grids, [3]), 'one rank')
   end subroutine test_rank_grids
end module test_load_balance_cuts
