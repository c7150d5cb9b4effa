!> Cartesian block decomposition of the grid's cells over the ranks of a communicator.
!>
!> Each rank owns a box of cells [cell_lo, cell_hi] (global, 0-based, inclusive) and the particles
!> inside it. The box boundaries along axis k are `cuts(0:dims(k), k)`; they start uniform. Load
!> balancing (load_balance, docs/theory.md section 6) moves them and may change the rank grid `dims`
!> itself (set_layout): the rank numbers stay, the Cartesian communicator is made anew.
module domain_decomposition
   use mpi_f08, only: MPI_Comm, MPI_Dims_create, MPI_Cart_create, MPI_Cart_shift, MPI_Cart_coords, &
                      MPI_Comm_rank, MPI_Comm_size, MPI_Comm_free, MPI_PROC_NULL
   use error_status, only: status_t
   use kinds, only: i8
   implicit none
   private

   integer, parameter :: max_cuts = 4096

   public :: layout_dims, valid_layout

   !> The calling rank's view of the decomposition.
   type, public :: domain_t
      type(MPI_Comm) :: comm                      !< Cartesian communicator of the run
      integer :: rank = 0, nranks = 1, dim = 2
      integer :: dims(3) = 1                      !< ranks along each axis
      integer :: coords(3) = 0                    !< this rank's position in the rank grid
      integer :: neighbour(2, 3) = -1             !< lower/upper face neighbour (MPI_PROC_NULL at the edge)
      integer :: global_cells(3) = 1              !< cells of the whole grid along each axis
      integer, allocatable :: cuts(:, :)          !< (0:nranks, axis) first cell of each rank slab, then 0
      integer :: cell_lo(3) = 0, cell_hi(3) = 0   !< owned cells, global 0-based inclusive
   contains
      procedure :: init => domain_init
      procedure :: free => domain_free
      procedure :: set_cuts => domain_set_cuts
      procedure :: set_layout => domain_set_layout
      procedure :: owns_cell => domain_owns_cell
   end type domain_t

contains

   !> Create the Cartesian communicator and a uniform split of the cells. Collective.
   !> The factor of ranks that is largest goes to the axis with most cells (smallest halos).
   subroutine domain_init(self, comm, dim, global_cells, status)
      class(domain_t), intent(inout) :: self
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim, global_cells(3)
      type(status_t), intent(inout) :: status
      integer :: dims(dim), order(dim), k, j, tmp
      integer, allocatable :: uniform(:, :)
      character(len=200) :: msg

      self%dim = dim
      self%global_cells = global_cells
      call MPI_Comm_size(comm, self%nranks)
      dims = 0
      call MPI_Dims_create(self%nranks, dim, dims)
      ! MPI_Dims_create returns dims in non-increasing order: give the largest to the longest axis.
      order = [(k, k = 1, dim)]
      do k = 1, dim - 1
         do j = k + 1, dim
            if (global_cells(order(j)) > global_cells(order(k))) then
               tmp = order(k); order(k) = order(j); order(j) = tmp
            end if
         end do
      end do
      self%dims = 1
      do k = 1, dim
         self%dims(order(k)) = dims(k)
      end do
      do k = 1, dim
         ! a split axis needs at least two cells per rank: the smoothing's cell halo is two layers deep
         if (self%dims(k) > 1 .and. 2 * self%dims(k) > global_cells(k)) then
            write (msg, '(a,i0,a,i0,a,i0,a)') 'cannot split ', global_cells(k), ' cells along axis ', k, &
               ' over ', self%dims(k), ' ranks (at least 2 cells per rank): use fewer ranks or a finer grid'
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
      allocate (self%cuts(0:self%nranks, 3), uniform(0:self%nranks, 3))
      uniform = 0
      do k = 1, 3
         do j = 0, self%dims(k)
            ! uniform split; integer arithmetic keeps every rank's view identical
            uniform(j, k) = int((int(j, i8) * global_cells(k)) / self%dims(k))
         end do
      end do
      call self%set_cuts(uniform)
   end subroutine domain_init

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
   !> (dims(k) slabs along axis k, see layout_dims) and the slab boundaries. Collective when the rank
   !> grid changes.
   subroutine domain_set_layout(self, cuts)
      class(domain_t), intent(inout) :: self
      integer, intent(in) :: cuts(0:, :)
      type(MPI_Comm) :: old
      integer :: dims(3)
      dims = layout_dims(cuts, self%global_cells)
      if (any(dims /= self%dims)) then
         old = self%comm
         self%dims = dims
         call make_cartesian(self, old)
         call MPI_Comm_free(old)
      end if
      call self%set_cuts(cuts)
   end subroutine domain_set_layout

   !> The rank grid of a layout: along axis k, the number of slabs before cuts(:, k) reaches the
   !> last cell.
   pure function layout_dims(cuts, global_cells) result(dims)
      integer, intent(in) :: cuts(0:, :), global_cells(3)
      integer :: dims(3), k
      do k = 1, 3
         dims(k) = findloc(cuts(1:, k), global_cells(k), 1)
      end do
   end function layout_dims

   !> True if `cuts` is a layout of `nranks` ranks over `global_cells`: slabs along each of the first
   !> `dim` axes ascending from 0 to the last cell, at least 2 cells wide on a split axis, the product of
   !> the slab counts nranks, and zeros after the last cut.
   pure logical function valid_layout(cuts, global_cells, dim, nranks) result(valid)
      integer, intent(in) :: cuts(0:, :), global_cells(3), dim, nranks
      integer :: dims(3), k
      valid = size(cuts, 1) == nranks + 1 .and. size(cuts, 2) == 3
      if (.not. valid) return
      dims = layout_dims(cuts, global_cells)
      valid = all(dims >= 1) .and. product(dims) == nranks .and. all(dims(dim + 1:) == 1)
      if (.not. valid) return
      do k = 1, 3
         valid = valid .and. cuts(0, k) == 0 .and. all(cuts(dims(k) + 1:, k) == 0)
         if (dims(k) > 1) valid = valid .and. all(cuts(1:dims(k), k) - cuts(0:dims(k) - 1, k) >= 2)
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
