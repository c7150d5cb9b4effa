!> MPI test suite exercising the framework: every rank count of the suite (RANKS 1 2 4) must agree
!> with the closed forms below, and every rank checks its own result.
module test_mpi_framework
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Allreduce, MPI_Bcast, MPI_Sendrecv, &
                      MPI_INTEGER, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_STATUS_IGNORE
   use kinds, only: rp
   use assertions, only: assertEqual, assertRelativelyEqual
   implicit none
   private

   public :: test_allreduce_rank_sum, test_allreduce_real_sum, test_broadcast_from_root, test_ring_exchange

contains

   !> sum of the ranks 0..n-1 = n(n-1)/2 on every rank.
   subroutine test_allreduce_rank_sum(comm)
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, n_ranks, total
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      call MPI_Allreduce(rank, total, 1, MPI_INTEGER, MPI_SUM, comm)
      call assertEqual(n_ranks * (n_ranks - 1) / 2, total, 'sum of ranks')
   end subroutine test_allreduce_rank_sum

   !> sum of 0.1 (rank + 1) = 0.1 n(n+1)/2, up to rounding.
   subroutine test_allreduce_real_sum(comm)
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, n_ranks
      real(rp) :: total
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      call MPI_Allreduce(0.1_rp * (rank + 1), total, 1, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call assertRelativelyEqual(0.05_rp * n_ranks * (n_ranks + 1), total, 1.0e-14_rp, 'sum of 0.1 (rank + 1)')
   end subroutine test_allreduce_real_sum

   subroutine test_broadcast_from_root(comm)
      type(MPI_Comm), intent(in) :: comm
      integer :: rank
      real(rp) :: value(3)
      call MPI_Comm_rank(comm, rank)
      value = -1.0_rp
      if (rank == 0) value = [1.0_rp, 2.5_rp, -3.75_rp]
      call MPI_Bcast(value, 3, MPI_DOUBLE_PRECISION, 0, comm)
      call assertEqual([1.0_rp, 2.5_rp, -3.75_rp], value, 0.0_rp, 'broadcast values')
   end subroutine test_broadcast_from_root

   !> Each rank sends its rank to the right neighbour and receives the left one's (itself on 1 rank).
   subroutine test_ring_exchange(comm)
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, n_ranks, left, right, received
      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      right = modulo(rank + 1, n_ranks)
      left = modulo(rank - 1, n_ranks)
      call MPI_Sendrecv(rank, 1, MPI_INTEGER, right, 7, received, 1, MPI_INTEGER, left, 7, comm, MPI_STATUS_IGNORE)
      call assertEqual(left, received, 'rank received from the left neighbour')
   end subroutine test_ring_exchange
end module test_mpi_framework
