!> Cell data across subdomain boundaries for the face-flux smoothing (algorithms.md section 3.8).
!>
!> A rank's owned cells are padded by `halo_width` = 2 ghost layers on both sides of every axis
!> ("padded box"). A face halo exchange copies, axis by axis, the two owned layers next to a face
!> neighbour into that neighbour's ghost layers. Only face neighbours are exchanged (the smoothing
!> couples cells along one axis at a time, never diagonally), so the ghost layers hold values only
!> within the owned extent of the other axes; the rest of the padding is never read.
module cell_halo
   use kinds, only: rp
   use mpi_f08, only: MPI_PROC_NULL
   use face_exchange, only: exchange_with_face_neighbours
   use communication_counters, only: comm_cell_halo
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   implicit none
   private

   integer, parameter, public :: halo_width = 2

   !> Flat indexing of the padded box of a rank's cells.
   type, public :: padded_cells_t
      integer :: dim = 2
      integer :: lo(3) = 0, hi(3) = 0            !< global cell range including the ghost layers
      integer :: n(3) = 1, count = 0
      integer :: stride(3) = 1                   !< flat-index step along each axis
      integer, allocatable :: of_owned(:)        !< padded index of each owned (grid-local) cell
      logical, allocatable :: owned(:)           !< padded cell is owned by this rank
   contains
      procedure :: init => padded_init
      procedure :: index_of => padded_index_of
   end type padded_cells_t

   public :: exchange_cell_halo

contains

   subroutine padded_init(self, grid)
      class(padded_cells_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer :: i, j, l, c(3), owned_index
      self%dim = grid%dim
      self%lo = grid%cell_lo
      self%hi = grid%cell_hi
      self%lo(1:grid%dim) = grid%cell_lo(1:grid%dim) - halo_width
      self%hi(1:grid%dim) = grid%cell_hi(1:grid%dim) + halo_width
      self%n = self%hi - self%lo + 1
      self%count = product(self%n)
      self%stride = [1, self%n(1), self%n(1) * self%n(2)]
      if (allocated(self%of_owned)) deallocate (self%of_owned, self%owned)
      allocate (self%of_owned(grid%cell_count), self%owned(self%count))
      self%owned = .false.
      owned_index = 0
      do l = grid%cell_lo(3), grid%cell_hi(3)
         do j = grid%cell_lo(2), grid%cell_hi(2)
            do i = grid%cell_lo(1), grid%cell_hi(1)
               c = [i, j, l]
               owned_index = owned_index + 1     ! the order of grid%local_cell: x fastest
               self%of_owned(owned_index) = self%index_of(c)
               self%owned(self%of_owned(owned_index)) = .true.
            end do
         end do
      end do
   end subroutine padded_init

   !> Flat padded index of global cell c.
   pure integer function padded_index_of(self, c) result(index)
      class(padded_cells_t), intent(in) :: self
      integer, intent(in) :: c(3)
      index = 1 + sum((c - self%lo) * self%stride)
   end function padded_index_of

   !> Fill the ghost layers of field(:, padded cell) from the face neighbours. Collective.
   !> Ghost cells beyond the edge of the whole grid, or of a face without a neighbour, are left untouched.
   !> With `flags`: field(1, c) is a 0/1 flag, and flags(c) := field(1, c) > 1/2 for every ghost cell
   !> written (while its values are in cache; a pass over all ghost cells afterwards cost 1 % of a FOAL1
   !> step on one rank, where none is written).
   subroutine exchange_cell_halo(domain, grid, box, field, flags)
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(inout) :: field(:, :)
      logical, intent(inout), optional :: flags(:)
      real(rp), allocatable :: send_buf(:, :), recv_buf(:, :)
      integer :: k, side, count, nv, first_owned(2), first_ghost(2)
      integer, parameter :: tag = 301

      nv = size(field, 1)
      do k = 1, domain%dim
         if (all(domain%neighbour(:, k) == MPI_PROC_NULL)) cycle
         count = nv * halo_width * (grid%cell_count / grid%n_cells(k))
         allocate (send_buf(count, 2), recv_buf(count, 2))
         ! side 1: lower face (send the first two owned layers, receive into the two ghost layers below)
         first_owned = [grid%cell_lo(k), grid%cell_hi(k) - halo_width + 1]
         first_ghost = [grid%cell_lo(k) - halo_width, grid%cell_hi(k) + 1]
         do side = 1, 2
            call copy_layers(grid, box, k, first_owned(side), field, send_buf(:, side), to_buffer=.true.)
         end do
         call exchange_with_face_neighbours(domain, k, send_buf, recv_buf, tag, comm_cell_halo)
         do side = 1, 2
            if (domain%neighbour(side, k) /= MPI_PROC_NULL) &
               call copy_layers(grid, box, k, first_ghost(side), field, recv_buf(:, side), to_buffer=.false., &
                                flags=flags)
         end do
         deallocate (send_buf, recv_buf)
      end do
   end subroutine exchange_cell_halo

   !> Copy `halo_width` cell layers starting at global index `first` along axis k, over the owned
   !> extent of the other axes, between the padded field and a contiguous buffer (either way); into the
   !> field with `flags`, also flags(c) := field(1, c) > 1/2.
   subroutine copy_layers(grid, box, k, first, field, buf, to_buffer, flags)
      type(grid_t), intent(in) :: grid
      type(padded_cells_t), intent(in) :: box
      integer, intent(in) :: k, first
      real(rp), intent(inout) :: field(:, :), buf(:)
      logical, intent(in) :: to_buffer
      logical, intent(inout), optional :: flags(:)
      integer :: lo(3), hi(3), i, j, l, c, nv, pos
      nv = size(field, 1)
      lo = grid%cell_lo
      hi = grid%cell_hi
      lo(k) = first
      hi(k) = first + halo_width - 1
      pos = 0
      do l = lo(3), hi(3)
         do j = lo(2), hi(2)
            do i = lo(1), hi(1)
               c = box%index_of([i, j, l])
               if (to_buffer) then
                  buf(pos + 1:pos + nv) = field(:, c)
               else
                  field(:, c) = buf(pos + 1:pos + nv)
                  if (present(flags)) flags(c) = field(1, c) > 0.5_rp
               end if
               pos = pos + nv
            end do
         end do
      end do
   end subroutine copy_layers
end module cell_halo
