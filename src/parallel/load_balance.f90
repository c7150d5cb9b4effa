!> The decomposition that spreads the particles most evenly over the ranks (docs/theory.md section 6).
!>
!> The boxes of a Cartesian decomposition are products of slabs: along each axis k the cuts split the
!> cell layers into dims(k) slabs. For one rank grid `dims` the cuts along k come from the global
!> histogram of particles per cell layer along k, split by cumulative count into dims(k) parts of as
!> equal a count as whole layers allow (at least two layers each: the smoothing's halo is two cells
!> deep). Every rank grid whose slabs can be that wide is tried (for 2 ranks in 2-D: split x or split
!> y), the particles are counted per box of each, and the one with the smallest largest box wins. All
!> of it is integer arithmetic on reduced counts, so every rank picks the same layout. The slabs split
!> the active region (domain_decomposition), not the whole grid.
module load_balance
   use kinds, only: i8
   use mpi_f08, only: MPI_Allreduce, MPI_IN_PLACE, MPI_INTEGER8, MPI_SUM
   use domain_decomposition, only: domain_t, min_slab_width
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use communication_counters, only: count_collective, comm_balance, int8_bytes
   implicit none
   private

   public :: min_slab_width, split_counts, rank_grids, balanced_layout

contains

   !> Cuts cuts(0:parts) that split the layers 0 .. size(counts) - 1 into `parts` slabs of at least
   !> `min_width` layers whose counts are as close to equal as whole layers allow: cut j is the layer
   !> boundary whose count below it is nearest to j/parts of the total (the lowest such boundary).
   !> For two parts this minimises the larger part. Needs size(counts) >= parts * min_width.
   pure function split_counts(counts, parts, min_width) result(cuts)
      integer(i8), intent(in) :: counts(0:)
      integer, intent(in) :: parts, min_width
      integer :: cuts(0:parts)
      integer(i8) :: below(0:size(counts)), total, miss, best
      integer :: n, j, c

      n = size(counts)
      below(0) = 0
      do c = 1, n
         below(c) = below(c - 1) + counts(c - 1)
      end do
      total = below(n)
      cuts(0) = 0
      cuts(parts) = n
      do j = 1, parts - 1
         best = huge(1_i8)
         cuts(j) = cuts(j - 1) + min_width
         ! room for the slabs still to come
         do c = cuts(j - 1) + min_width, n - (parts - j) * min_width
            miss = abs(parts * below(c) - j * total)
            if (miss < best) then
               best = miss
               cuts(j) = c
            end if
         end do
      end do
   end function split_counts

   !> The rank grids dims(1:3) with product nranks (1 beyond `dim`) in which every split axis has at
   !> least min_width (default min_slab_width) cells per slab (of `cells` along each axis), as columns of
   !> grids(3, :).
   pure function rank_grids(nranks, dim, cells, min_width) result(grids)
      integer, intent(in) :: nranks, dim, cells(3)
      integer, intent(in), optional :: min_width
      integer, allocatable :: grids(:, :)
      integer :: a, b, c, least
      least = min_slab_width
      if (present(min_width)) least = min_width
      allocate (grids(3, 0))
      do a = 1, nranks
         if (mod(nranks, a) /= 0 .or. .not. fits(a, 1)) cycle
         do b = 1, nranks / a
            if (mod(nranks / a, b) /= 0 .or. .not. fits(b, 2)) cycle
            c = nranks / (a * b)
            if ((dim == 2 .and. c /= 1) .or. .not. fits(c, 3)) cycle
            grids = reshape([grids, a, b, c], [3, size(grids, 2) + 1])
         end do
      end do
   contains
      pure logical function fits(d, k)
         integer, intent(in) :: d, k
         fits = d == 1 .or. least * d <= cells(k)
      end function fits
   end function rank_grids

   !> The layout (cuts as domain%cuts) of the active region lo..hi (default: the current one) that
   !> minimises the largest number of particles on one rank, and that number. Among equally good
   !> layouts the current rank grid is kept. Every particle must lie in the box. Collective: two
   !> reductions, the per-layer histograms and the box counts of every candidate rank grid.
   subroutine balanced_layout(domain, grid, particles, cuts, largest, lo, hi)
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, intent(out) :: cuts(0:domain%nranks, 3)
      integer(i8), intent(out) :: largest
      integer, intent(in), optional :: lo(3), hi(3)
      integer, allocatable :: grids(:, :), cell(:, :), slab(:, :), candidate_cuts(:, :, :)
      integer(i8), allocatable :: histogram(:), loads(:, :)
      integer :: first(3), n(3), c(3), k, g, p, box, best, stride, box_lo(3), box_hi(3)
      integer(i8) :: worst

      call domain%region(box_lo, box_hi)
      if (present(lo)) box_lo = lo
      if (present(hi)) box_hi = hi
      ! layers are counted from the box's first (cell - box_lo)
      n = box_hi - box_lo + 1
      first = [0, n(1), n(1) + n(2)]
      allocate (histogram(sum(n)), cell(3, particles%count))
      histogram = 0
      do p = 1, particles%count
         c = grid%cell_of_position(particles%x(:, p))
         cell(:, p) = 0
         cell(1:domain%dim, p) = min(max(c(1:domain%dim) - box_lo(1:domain%dim), 0), n(1:domain%dim) - 1)
         do k = 1, domain%dim
            histogram(first(k) + cell(k, p) + 1) = histogram(first(k) + cell(k, p) + 1) + 1
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, histogram, size(histogram), MPI_INTEGER8, MPI_SUM, domain%comm)
      call count_collective(comm_balance, size(histogram), int8_bytes)

      grids = rank_grids(domain%nranks, domain%dim, n, domain%min_width)
      allocate (candidate_cuts(0:domain%nranks, 3, size(grids, 2)), loads(0:domain%nranks - 1, size(grids, 2)))
      candidate_cuts = 0
      loads = 0
      allocate (slab(0:maxval(n) - 1, 3))
      do g = 1, size(grids, 2)
         do k = 1, 3
            associate (d => grids(k, g))
               candidate_cuts(0:d, k, g) = split_counts(histogram(first(k) + 1:first(k) + n(k)), d, &
                                                         merge(1, domain%min_width, d == 1))
               ! slab of every layer, then the box of every particle: slab_1 + d_1 (slab_2 + d_2 slab_3)
               do box = 0, d - 1
                  slab(candidate_cuts(box, k, g):candidate_cuts(box + 1, k, g) - 1, k) = box
               end do
            end associate
         end do
         do p = 1, particles%count
            box = 0
            stride = 1
            do k = 1, 3
               box = box + stride * slab(cell(k, p), k)
               stride = stride * grids(k, g)
            end do
            loads(box, g) = loads(box, g) + 1
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, loads, size(loads), MPI_INTEGER8, MPI_SUM, domain%comm)
      call count_collective(comm_balance, size(loads), int8_bytes)

      best = 0
      worst = huge(1_i8)
      do g = 1, size(grids, 2)
         if (maxval(loads(:, g)) < worst .or. &
             (maxval(loads(:, g)) == worst .and. all(grids(:, g) == domain%dims))) then
            worst = maxval(loads(:, g))
            best = g
         end if
      end do
      cuts = 0
      do k = 1, 3
         cuts(0:grids(k, best), k) = box_lo(k) + candidate_cuts(0:grids(k, best), k, best)
      end do
      largest = worst
   end subroutine balanced_layout
end module load_balance
