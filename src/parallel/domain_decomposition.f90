!> Cartesian block decomposition of the grid's cells over the ranks of a communicator.
!>
!> Each rank owns a box of cells [cell_lo, cell_hi] (global, 0-based, inclusive) and the particles
!> inside it. The box boundaries along axis k are `cuts(0:dims(k), k)`; they start uniform and can be
!> moved (load balancing) without changing anything else.
module domain_decomposition
   use mpi_f08, only: MPI_Comm, MPI_Dims_create, MPI_Cart_create, MPI_Cart_shift, MPI_Cart_coords, &
                      MPI_Comm_rank, MPI_Comm_size, MPI_Comm_free, MPI_PROC_NULL
   use error_status, only: status_t
   use kinds, only: i8
   implicit none
   private

   integer, parameter :: max_cuts = 4096

   !> The calling rank's view of the decomposition.
   type, public :: domain_t
      type(MPI_Comm) :: comm                      !< Cartesian communicator of the run
      integer :: rank = 0, nranks = 1, dim = 2
      integer :: dims(3) = 1                      !< ranks along each axis
      integer :: coords(3) = 0                    !< this rank's position in the rank grid
      integer :: neighbour(2, 3) = -1             !< lower/upper face neighbour (MPI_PROC_NULL at the edge)
      integer :: global_cells(3) = 1              !< cells of the whole grid along each axis
      integer, allocatable :: cuts(:, :)          !< (0:max dims, axis) first cell of each rank slab
      integer :: cell_lo(3) = 0, cell_hi(3) = 0   !< owned cells, global 0-based inclusive
   contains
      procedure :: init => domain_init
      procedure :: free => domain_free
      procedure :: set_cuts => domain_set_cuts
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
      logical :: periods(dim)
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
      periods = .false.
      call MPI_Cart_create(comm, dim, self%dims(1:dim), periods, .false., self%comm)
      call MPI_Comm_rank(self%comm, self%rank)
      call MPI_Cart_coords(self%comm, self%rank, dim, self%coords(1:dim))
      self%neighbour = MPI_PROC_NULL
      do k = 1, dim
         call MPI_Cart_shift(self%comm, k - 1, 1, self%neighbour(1, k), self%neighbour(2, k))
      end do

      if (allocated(self%cuts)) deallocate (self%cuts)
      allocate (self%cuts(0:maxval(self%dims), 3), uniform(0:maxval(self%dims), 3))
      uniform = 0
      do k = 1, 3
         do j = 0, self%dims(k)
            ! uniform split; integer arithmetic keeps every rank's view identical
            uniform(j, k) = int((int(j, i8) * global_cells(k)) / self%dims(k))
         end do
      end do
      call self%set_cuts(uniform)
      if (maxval(self%dims) > max_cuts) call status%fail('too many ranks along one axis')
   end subroutine domain_init

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
