!> The one message pattern of both halo exchanges: along axis k, send a contiguous buffer to each face
!> neighbour and receive one from each (lower neighbour = side 1, upper = side 2). Missing neighbours
!> (MPI_PROC_NULL at the edge of the grid) make the transfer a no-op. Buffers are contiguous and live
!> until MPI_Waitall returns (toolchain.md: no sub-array support in MPI here).
module face_exchange
   use kinds, only: rp
   use mpi_f08, only: MPI_Request, MPI_Isend, MPI_Irecv, MPI_Waitall, MPI_DOUBLE_PRECISION, MPI_STATUSES_IGNORE, &
                      MPI_PROC_NULL
   use communication_counters, only: count_sent, real_bytes
   use domain_decomposition, only: domain_t
   implicit none
   private

   public :: exchange_with_face_neighbours

contains

   !> recv_buf(:, side) := what the neighbour on `side` along axis k sent towards this rank. Collective
   !> over the ranks of the axis. The messages count as `category` (communication_counters).
   subroutine exchange_with_face_neighbours(domain, k, send_buf, recv_buf, tag, category)
      type(domain_t), intent(in) :: domain
      integer, intent(in) :: k, tag, category
      real(rp), intent(in) :: send_buf(:, :)
      real(rp), intent(inout) :: recv_buf(:, :)
      type(MPI_Request) :: requests(4)
      integer :: side, count
      count = size(send_buf, 1)
      do side = 1, 2
         call MPI_Irecv(recv_buf(:, side), count, MPI_DOUBLE_PRECISION, domain%neighbour(side, k), tag, &
                        domain%comm, requests(side))
      end do
      do side = 1, 2
         call MPI_Isend(send_buf(:, side), count, MPI_DOUBLE_PRECISION, domain%neighbour(side, k), tag, &
                        domain%comm, requests(2 + side))
         if (domain%neighbour(side, k) /= MPI_PROC_NULL) call count_sent(category, count, real_bytes)
      end do
      call MPI_Waitall(4, requests, MPI_STATUSES_IGNORE)
   end subroutine exchange_with_face_neighbours
end module face_exchange
