!> Cartesian block decomposition of the grid's cells over the ranks of a communicator.
!>
!> Each rank owns a box of cells [cell_lo, cell_hi] (global, 0-based, inclusive) and the particles
!> inside it. The box boundaries along axis k are `cuts(0:dims(k), k)`. The slabs need not span the
!> whole grid: their union, the active region [cuts(0, k), cuts(dims(k), k) - 1], covers only the cells
!> near the particles (the solver moves it with them, docs/theory.md section 6.2), and cells outside
!> it are not allocated anywhere. Load balancing (load_balance, section 6.1) moves the inner cuts and
!> may change the rank grid `dims` itself (set_layout): the rank numbers stay, the Cartesian
!> communicator is made anew.
module domain_decomposition
   use mpi_f08, only: MPI_Comm, MPI_Dims_create, MPI_Cart_create, MPI_Cart_shift, MPI_Cart_coords, &
                      MPI_Comm_rank, MPI_Comm_size, MPI_Comm_free, MPI_PROC_NULL
   use error_status, only: status_t
   use kinds, only: i8
   implicit none
   private

   integer, parameter :: max_cuts = 4096

   !> Fewest cell layers in a slab of a split axis: the smoothing's cell halo is two layers deep. A wider
   !> shape function may ask for more (domain_t%min_width).
   integer, parameter, public :: min_slab_width = 2

   public :: layout_dims, valid_layout, fit_box, uniform_cuts

   !> The calling rank's view of the decomposition.
   type, public :: domain_t
      type(MPI_Comm) :: comm                      !< Cartesian communicator of the run
      integer :: rank = 0, nranks = 1, dim = 2
      integer :: dims(3) = 1                      !< ranks along each axis
      integer :: coords(3) = 0                    !< this rank's position in the rank grid
      integer :: neighbour(2, 3) = -1             !< lower/upper face neighbour (MPI_PROC_NULL at the edge)
      integer :: global_cells(3) = 1              !< cells of the whole grid along each axis
      integer, allocatable :: cuts(:, :)          !< (0:nranks, axis) first cell of each slab, region end, 0s
      integer :: cell_lo(3) = 0, cell_hi(3) = 0   !< owned cells, global 0-based inclusive
      !> fewest cells of a slab on a split axis (set before init): 3 with bspline2, whose node halo is 3
      !> layers deep, so that a node is only ever shared by face neighbours (node_halo)
      integer :: min_width = min_slab_width
   contains
      procedure :: init => domain_init
      procedure :: free => domain_free
      procedure :: set_cuts => domain_set_cuts
      procedure :: set_layout => domain_set_layout
      procedure :: owns_cell => domain_owns_cell
      procedure :: region => domain_region
      procedure :: box_cuts => domain_box_cuts
   end type domain_t

contains

   !> Create the Cartesian communicator and a uniform split of the active region box_lo..box_hi (global
   !> cells, inclusive; default the whole grid), widened where it is too narrow for two cells per rank.
   !> Collective. The factor of ranks that is largest goes to the axis with most cells (smallest halos).
   subroutine domain_init(self, comm, dim, global_cells, status, box_lo, box_hi)
      class(domain_t), intent(inout) :: self
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim, global_cells(3)
      type(status_t), intent(inout) :: status
      integer, intent(in), optional :: box_lo(3), box_hi(3)
      integer :: dims(dim), order(dim), k, j, tmp, lo(3), hi(3)
      character(len=200) :: msg

      self%dim = dim
      self%global_cells = global_cells
      lo = 0
      hi = global_cells - 1
      if (present(box_lo)) lo(1:dim) = max(box_lo(1:dim), 0)
      if (present(box_hi)) hi(1:dim) = min(box_hi(1:dim), global_cells(1:dim) - 1)
      call MPI_Comm_size(comm, self%nranks)
      dims = 0
      call MPI_Dims_create(self%nranks, dim, dims)
      ! MPI_Dims_create returns dims in non-increasing order: give the largest to the longest axis
      ! (of the active region: that is where the cells are)
      order = [(k, k = 1, dim)]
      do k = 1, dim - 1
         do j = k + 1, dim
            if (hi(order(j)) - lo(order(j)) > hi(order(k)) - lo(order(k))) then
               tmp = order(k); order(k) = order(j); order(j) = tmp
            end if
         end do
      end do
      self%dims = 1
      do k = 1, dim
         self%dims(order(k)) = dims(k)
      end do
      do k = 1, dim
         if (self%dims(k) > 1 .and. self%min_width * self%dims(k) > global_cells(k)) then
            write (msg, '(a,i0,a,i0,a,i0,a,i0,a)') 'cannot split ', global_cells(k), ' cells along axis ', k, &
               ' over ', self%dims(k), ' ranks (at least ', self%min_width, &
               ' cells per rank): use fewer ranks or a finer grid'
            call status%fail(trim(msg))
            return
         end if
      end do
      if (maxval(self%dims) > max_cuts) then
         call status%fail('too many ranks along one axis')
         return
      end if
      call make_cartesian(self, comm)

      ! cuts has room for any rank grid: its size depends on the number of ranks alone
      if (allocated(self%cuts)) deallocate (self%cuts)
      allocate (self%cuts(0:self%nranks, 3))
      call fit_box(self%dims, global_cells, lo, hi, self%min_width)
      call self%set_cuts(uniform_cuts(self%dims, lo, hi, self%nranks))
   end subroutine domain_init

   !> Widen lo..hi (global cells, inclusive) inside the grid until every axis has room for dims(k) slabs
   !> (min_width cells each on a split axis, default min_slab_width): cells are added on both sides in turn.
   pure subroutine fit_box(dims, global_cells, lo, hi, min_width)
      integer, intent(in) :: dims(3), global_cells(3)
      integer, intent(inout) :: lo(3), hi(3)
      integer, intent(in), optional :: min_width
      integer :: k, width, least
      least = min_slab_width
      if (present(min_width)) least = min_width
      do k = 1, 3
         width = dims(k) * merge(least, 1, dims(k) > 1)
         do while (hi(k) - lo(k) + 1 < width)
            if (lo(k) > 0) lo(k) = lo(k) - 1
            if (hi(k) - lo(k) + 1 < width .and. hi(k) < global_cells(k) - 1) hi(k) = hi(k) + 1
         end do
      end do
   end subroutine fit_box

   !> Cuts (as domain%cuts) that split lo..hi into dims(k) slabs of equal width (as nearly as whole cells
   !> allow) along each axis. Integer arithmetic keeps every rank's view identical.
   pure function uniform_cuts(dims, lo, hi, nranks) result(cuts)
      integer, intent(in) :: dims(3), lo(3), hi(3), nranks
      integer :: cuts(0:nranks, 3), j, k
      cuts = 0
      do k = 1, 3
         do j = 0, dims(k)
            cuts(j, k) = lo(k) + int((int(j, i8) * (hi(k) - lo(k) + 1)) / dims(k))
         end do
      end do
   end function uniform_cuts

   !> The active region: the cells of all slabs, lo..hi (global, inclusive).
   pure subroutine domain_region(self, lo, hi)
      class(domain_t), intent(in) :: self
      integer, intent(out) :: lo(3), hi(3)
      integer :: k
      do k = 1, 3
         lo(k) = self%cuts(0, k)
         hi(k) = self%cuts(self%dims(k), k) - 1
      end do
   end subroutine domain_region

   !> Cuts for this rank grid over a new active region lo..hi (which fit_box has fitted): along each axis
   !> the inner cuts are kept where the first and last slab stay wide enough (no particle then changes
   !> rank), else that axis is split uniformly. `kept` is true if no axis was re-split.
   pure subroutine domain_box_cuts(self, lo, hi, cuts, kept)
      class(domain_t), intent(in) :: self
      integer, intent(in) :: lo(3), hi(3)
      integer, intent(out) :: cuts(0:self%nranks, 3)
      logical, intent(out) :: kept
      integer :: k, d, width, uniform(0:self%nranks, 3)
      uniform = uniform_cuts(self%dims, lo, hi, self%nranks)
      cuts = self%cuts
      kept = .true.
      do k = 1, 3
         d = self%dims(k)
         width = merge(self%min_width, 1, d > 1)
         cuts(0, k) = lo(k)
         cuts(d, k) = hi(k) + 1
         if (d > 1) then
            if (cuts(1, k) - lo(k) < width .or. hi(k) + 1 - cuts(d - 1, k) < width) then
               cuts(:, k) = uniform(:, k)
               kept = .false.
            end if
         end if
      end do
   end subroutine domain_box_cuts

   !> The Cartesian communicator of the rank grid self%dims over `comm`, this rank's coordinates and
   !> face neighbours. No reordering: a rank keeps its number. Collective.
   subroutine make_cartesian(self, comm)
      class(domain_t), intent(inout) :: self
      type(MPI_Comm), intent(in) :: comm
      logical :: periods(self%dim)
      integer :: k
      periods = .false.
      call MPI_Cart_create(comm, self%dim, self%dims(1:self%dim), periods, .false., self%comm)
      call MPI_Comm_rank(self%comm, self%rank)
      self%coords = 0
      call MPI_Cart_coords(self%comm, self%rank, self%dim, self%coords(1:self%dim))
      self%neighbour = MPI_PROC_NULL
      do k = 1, self%dim
         call MPI_Cart_shift(self%comm, k - 1, 1, self%neighbour(1, k), self%neighbour(2, k))
      end do
   end subroutine make_cartesian

   !> Adopt the layout that `cuts` (identical on every rank, as domain%cuts) describes: the rank grid
   !> (dims(k) slabs along axis k, see layout_dims), the slab boundaries and so the active region.
   !> Collective when the rank grid changes.
   subroutine domain_set_layout(self, cuts)
      class(domain_t), intent(inout) :: self
      integer, intent(in) :: cuts(0:, :)
      type(MPI_Comm) :: old
      integer :: dims(3)
      dims = layout_dims(cuts)
      if (any(dims /= self%dims)) then
         old = self%comm
         self%dims = dims
         call make_cartesian(self, old)
         call MPI_Comm_free(old)
      end if
      call self%set_cuts(cuts)
   end subroutine domain_set_layout

   !> The rank grid of a layout: along axis k, the number of slabs, i.e. of rising cuts after cuts(0, k)
   !> (the entries after the end of the active region are 0).
   pure function layout_dims(cuts) result(dims)
      integer, intent(in) :: cuts(0:, :)
      integer :: dims(3), k, j
      do k = 1, 3
         dims(k) = 0
         do j = 1, size(cuts, 1) - 1
            if (cuts(j, k) <= cuts(j - 1, k)) exit
            dims(k) = j
         end do
      end do
   end function layout_dims

   !> True if `cuts` is a layout of `nranks` ranks over `global_cells`: along each of the first `dim`
   !> axes slabs ascending inside the grid (an active region, not necessarily the whole grid), at least
   !> min_width (default min_slab_width) cells wide on a split axis, the product of the slab counts nranks,
   !> and zeros after the last cut; the unused axes one cell.
   pure logical function valid_layout(cuts, global_cells, dim, nranks, min_width) result(valid)
      integer, intent(in) :: cuts(0:, :), global_cells(3), dim, nranks
      integer, intent(in), optional :: min_width
      integer :: dims(3), k, least
      least = min_slab_width
      if (present(min_width)) least = min_width
      valid = size(cuts, 1) == nranks + 1 .and. size(cuts, 2) == 3
      if (.not. valid) return
      dims = layout_dims(cuts)
      valid = all(dims >= 1) .and. product(dims) == nranks .and. all(dims(dim + 1:) == 1)
      if (.not. valid) return
      do k = 1, 3
         valid = valid .and. cuts(0, k) >= 0 .and. cuts(dims(k), k) <= global_cells(k) .and. &
                 all(cuts(dims(k) + 1:, k) == 0)
         if (dims(k) > 1) valid = valid .and. all(cuts(1:dims(k), k) - cuts(0:dims(k) - 1, k) >= least)
      end do
   end function valid_layout

   !> Adopt new slab boundaries (identical on every rank) and update the owned cell box.
   subroutine domain_set_cuts(self, cuts)
      class(domain_t), intent(inout) :: self
      integer, intent(in) :: cuts(0:, :)
      integer :: k
      self%cuts(:, :) = cuts
      do k = 1, 3
         self%cell_lo(k) = self%cuts(self%coords(k), k)
         self%cell_hi(k) = self%cuts(self%coords(k) + 1, k) - 1
      end do
   end subroutine domain_set_cuts

   !> True if global cell `c` (0-based) lies in this rank's box.
   pure logical function domain_owns_cell(self, c)
      class(domain_t), intent(in) :: self
      integer, intent(in) :: c(:)
      integer :: k
      domain_owns_cell = .true.
      do k = 1, self%dim
         if (c(k) < self%cell_lo(k) .or. c(k) > self%cell_hi(k)) domain_owns_cell = .false.
      end do
   end function domain_owns_cell

   subroutine domain_free(self)
      class(domain_t), intent(inout) :: self
      call MPI_Comm_free(self%comm)
      if (allocated(self%cuts)) deallocate (self%cuts)
   end subroutine domain_free
end module domain_decomposition
