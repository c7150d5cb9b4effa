!> Tests of src/io/hdf5_file.f90: collective slabs placed by MPI_Exscan (with a rank that holds
!> nothing), grid blocks, attributes, and the refusal of wrong shapes, missing and truncated files.
module test_hdf5_file
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Barrier
   use assertions, only: assertEqual, assertTrue, assertFalse
   use error_status, only: status_t
   use hdf5_file, only: hdf5_file_t, slab_t, distributed_slab, even_slab
   implicit none
   private

   public :: test_slabs_round_trip, test_grid_block_round_trip, test_attributes_round_trip, &
             test_wrong_shape_is_refused, test_missing_and_truncated_files_are_refused

contains

   !> Rank r holds 3 r + 1 entries, except rank 1, which holds none; the value of global entry g is g.
   integer function local_count(rank)
      integer, intent(in) :: rank
      local_count = merge(0, 3 * rank + 1, rank == 1)
   end function local_count

   subroutine test_slabs_round_trip(comm)
      type(MPI_Comm), intent(in) :: comm
      type(hdf5_file_t) :: file
      type(status_t) :: status
      type(slab_t) :: slab, share
      integer :: rank, n_ranks, n, p, r
      real(rp), allocatable :: values(:), vectors(:, :), back(:), back_vectors(:, :)
      integer, allocatable :: integers(:), back_integers(:)
      integer(i8), allocatable :: ids(:), back_ids(:)
      integer(i8) :: expected_total

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      n = local_count(rank)
      slab = distributed_slab(comm, n)
      expected_total = 0
      do r = 0, n_ranks - 1
         expected_total = expected_total + local_count(r)
      end do
      call assertEqual(expected_total, slab%total, 'global count')
      call assertEqual(int(sum([(local_count(r), r = 0, rank - 1)]), i8), slab%offset, 'Exscan offset')

      allocate (values(max(n, 1)), vectors(3, max(n, 1)), integers(max(n, 1)), ids(max(n, 1)))
      do p = 1, n
         values(p) = real(slab%offset + p - 1, rp)
         vectors(:, p) = values(p) + [0.1_rp, 0.2_rp, 0.3_rp]
         integers(p) = int(slab%offset) + p - 1
         ids(p) = slab%offset + p - 1 + 2_i8**40
      end do
      call file%create('slabs.h5', comm, status)
      call file%create_group('particles', status)
      call file%write_slab('particles/values', slab, values, status)
      call file%write_slab('particles/vectors', slab, vectors, status)
      call file%write_slab('particles/integers', slab, integers, status)
      call file%write_slab('particles/ids', slab, ids, status)
      call file%close(status, flush=.true.)
      call assertTrue(status%ok, 'write: '//trim(status%message))

      ! read back an even share of the entries, whoever wrote them
      share = even_slab(slab%total, rank, n_ranks)
      n = int(share%count)
      allocate (back(max(n, 1)), back_vectors(3, max(n, 1)), back_integers(max(n, 1)), back_ids(max(n, 1)))
      call file%open('slabs.h5', comm, status)
      call assertEqual([3, int(slab%total)], int(file%dataset_dims('particles/vectors', status)), 'Fortran shape (3, N)')
      call file%read_slab('particles/values', share, back, status)
      call file%read_slab('particles/vectors', share, back_vectors, status)
      call file%read_slab('particles/integers', share, back_integers, status)
      call file%read_slab('particles/ids', share, back_ids, status)
      call file%close(status)
      call assertTrue(status%ok, 'read: '//trim(status%message))
      do p = 1, n
         call assertEqual(real(share%offset + p - 1, rp), back(p), 0.0_rp, 'value of a global entry')
         call assertEqual(back(p) + [0.1_rp, 0.2_rp, 0.3_rp], back_vectors(:, p), 0.0_rp, 'vector components')
         call assertEqual(int(share%offset) + p - 1, back_integers(p), 'integer')
         call assertEqual(share%offset + p - 1 + 2_i8**40, back_ids(p), 'int64 beyond 2**32')
      end do
   end subroutine test_slabs_round_trip

   !> A (2, nx, ny) grid field (a pair per node) written in blocks of whole y-columns, rank r owning a
   !> contiguous range of columns (rank 1 none), read back by even shares of the columns.
   subroutine test_grid_block_round_trip(comm)
      type(MPI_Comm), intent(in) :: comm
      type(hdf5_file_t) :: file
      type(status_t) :: status
      type(slab_t) :: columns, share
      integer :: rank, n_ranks, i, j, c
      real(rp), allocatable :: block(:)
      integer, parameter :: nx = 5
      integer(i8), parameter :: pair = 2, row = nx
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      columns = distributed_slab(comm, local_count(rank))
      call fill(columns, block)
      call file%create('grid.h5', comm, status)
      call file%write_block('field', [pair, row, columns%total], [0_i8, 0_i8, columns%offset], &
                            [pair, row, columns%count], block, status)
      call file%close(status)
      call assertTrue(status%ok, 'write: '//trim(status%message))

      share = even_slab(columns%total, rank, n_ranks)
      call fill(share, block)
      block = -1.0_rp
      call file%open('grid.h5', comm, status)
      call assertEqual(int([pair, row, columns%total]), int(file%dataset_dims('field', status)), 'shape (2, nx, ny)')
      call file%read_block('field', [pair, row, columns%total], [0_i8, 0_i8, share%offset], &
                           [pair, row, share%count], block, status)
      call file%close(status)
      call assertTrue(status%ok, 'read: '//trim(status%message))
      c = 0
      do j = 1, int(share%count)
         do i = 1, nx
            call assertEqual([real(i, rp), real(share%offset + j, rp)], block(c + 1:c + 2), 0.0_rp, 'node pair')
            c = c + 2
         end do
      end do

   contains

      !> The pairs (i, global column) of the columns of `slab`.
      subroutine fill(slab, values)
         type(slab_t), intent(in) :: slab
         real(rp), allocatable, intent(out) :: values(:)
         allocate (values(max(1_i8, pair * row * slab%count)))
         c = 0
         do j = 1, int(slab%count)
            do i = 1, nx
               values(c + 1:c + 2) = [real(i, rp), real(slab%offset + j, rp)]
               c = c + 2
            end do
         end do
      end subroutine fill
   end subroutine test_grid_block_round_trip

   subroutine test_attributes_round_trip(comm)
      type(MPI_Comm), intent(in) :: comm
      type(hdf5_file_t) :: file
      type(status_t) :: status
      real(rp) :: time, origin(3)
      integer :: count, cells(3)
      integer(i8) :: step
      character(len=40) :: text
      call file%create('attributes.h5', comm, status)
      call file%write_attribute('time', 0.125_rp, status)
      call file%write_attribute('count', 42, status)
      call file%write_attribute('step', 2_i8**40 + 3_i8, status)
      call file%write_attribute('format', 'flotsam test', status)
      call file%write_attribute('origin', [1.0_rp, -2.5_rp, 3.0e-9_rp], status)
      call file%write_attribute('cells', [4, 5, 6], status)
      call file%close(status)
      call assertTrue(status%ok, 'write: '//trim(status%message))
      time = 0.0_rp
      count = 0
      step = 0
      origin = 0.0_rp
      cells = 0
      text = ''
      call file%open('attributes.h5', comm, status)
      call file%read_attribute('time', time, status)
      call file%read_attribute('count', count, status)
      call file%read_attribute('step', step, status)
      call file%read_attribute('format', text, status)
      call file%read_attribute('origin', origin, status)
      call file%read_attribute('cells', cells, status)
      call assertTrue(status%ok, 'read: '//trim(status%message))
      call assertEqual(0.125_rp, time, 0.0_rp, 'real')
      call assertEqual(42, count, 'integer')
      call assertEqual(2_i8**40 + 3_i8, step, 'int64')
      call assertEqual('flotsam test', text, 'string')
      call assertEqual([1.0_rp, -2.5_rp, 3.0e-9_rp], origin, 0.0_rp, 'real array')
      call assertEqual([4, 5, 6], cells, 'integer array')
      call assertFalse(file%has_attribute('missing'), 'absent attribute')
      call file%read_attribute('missing', count, status)
      call assertFalse(status%ok, 'reading an absent attribute fails')
      call assertTrue(index(status%message, 'has no attribute missing') > 0, 'message: '//trim(status%message))
      call status%reset()
      call file%read_attribute('origin', cells(1:2), status)
      call assertTrue(index(status%message, 'wrong number of values') > 0, 'message: '//trim(status%message))
      call status%reset()
      call file%close(status)
   end subroutine test_attributes_round_trip

   subroutine test_wrong_shape_is_refused(comm)
      type(MPI_Comm), intent(in) :: comm
      type(hdf5_file_t) :: file
      type(status_t) :: status
      type(slab_t) :: slab
      real(rp) :: values(4)
      values = 1.0_rp
      slab = distributed_slab(comm, 4)
      call file%create('shape.h5', comm, status)
      call file%write_slab('x', slab, values, status)
      call file%close(status)
      call file%open('shape.h5', comm, status)
      call file%read_slab('x', slab_t(0, 4, slab%total + 1), values, status)
      call assertFalse(status%ok, 'a dataset of another length is refused')
      call assertTrue(index(status%message, 'wrong shape') > 0, 'message: '//trim(status%message))
      call status%reset()
      call file%read_slab('y', slab, values, status)
      call assertTrue(index(status%message, 'has no dataset y') > 0, 'message: '//trim(status%message))
      call status%reset()
      call file%close(status)
   end subroutine test_wrong_shape_is_refused

   subroutine test_missing_and_truncated_files_are_refused(comm)
      type(MPI_Comm), intent(in) :: comm
      type(hdf5_file_t) :: file
      type(status_t) :: status
      type(slab_t) :: slab
      real(rp), allocatable :: values(:)
      character(len=1), allocatable :: bytes(:)
      integer :: rank, unit, size_bytes
      call MPI_Comm_rank(comm, rank)
      call file%open('does_not_exist.h5', comm, status)
      call assertFalse(status%ok, 'a missing file is refused')
      call assertTrue(index(status%message, 'does_not_exist.h5') > 0, 'message names it: '//trim(status%message))
      call status%reset()

      allocate (values(10000))
      values = 2.0_rp
      slab = distributed_slab(comm, size(values))
      call file%create('whole.h5', comm, status)
      call file%write_slab('x', slab, values, status)
      call file%close(status)
      if (rank == 0) then
         open (newunit=unit, file='whole.h5', access='stream', form='unformatted', action='read')
         inquire (unit=unit, size=size_bytes)
         allocate (bytes(size_bytes / 2))
         read (unit) bytes
         close (unit)
         open (newunit=unit, file='truncated.h5', access='stream', form='unformatted', action='write', &
               status='replace')
         write (unit) bytes
         close (unit)
      end if
      call MPI_Barrier(comm)
      call file%open('truncated.h5', comm, status)
      call assertFalse(status%ok, 'a truncated file is refused')
      call status%reset()
   end subroutine test_missing_and_truncated_files_are_refused
end module test_hdf5_file
