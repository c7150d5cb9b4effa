!> Make a status decided on one rank (or on any rank) known to every rank of a communicator, so all
!> ranks take the same branch and exit together.
module status_broadcast
   use kinds, only: message_len
   use mpi_f08, only: MPI_Comm, MPI_Bcast, MPI_Allreduce, MPI_IN_PLACE, MPI_LOGICAL, MPI_CHARACTER, &
                      MPI_INTEGER, MPI_LAND, MPI_MIN, MPI_Comm_rank
   use error_status, only: status_t
   use communication_counters, only: count_collective, comm_status, logical_bytes, int_bytes
   implicit none
   private

   public :: broadcast_status, agree_on_status

contains

   !> Copy `root`'s status to every rank. Collective.
   subroutine broadcast_status(status, comm, root)
      type(status_t), intent(inout) :: status
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: root
      call MPI_Bcast(status%ok, 1, MPI_LOGICAL, root, comm)
      call count_collective(comm_status, 1, logical_bytes)
      if (.not. status%ok) then
         call MPI_Bcast(status%message, message_len, MPI_CHARACTER, root, comm)
         call count_collective(comm_status, message_len, 1)
      end if
   end subroutine broadcast_status

   !> Fail everywhere if any rank failed; the message of the lowest failing rank is kept. Collective.
   subroutine agree_on_status(status, comm)
      type(status_t), intent(inout) :: status
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, first_failing
      logical :: all_ok
      all_ok = status%ok
      call MPI_Allreduce(MPI_IN_PLACE, all_ok, 1, MPI_LOGICAL, MPI_LAND, comm)
      call count_collective(comm_status, 1, logical_bytes)
      if (all_ok) return
      call MPI_Comm_rank(comm, rank)
      first_failing = merge(huge(1), rank, status%ok)
      call MPI_Allreduce(MPI_IN_PLACE, first_failing, 1, MPI_INTEGER, MPI_MIN, comm)
      call count_collective(comm_status, 1, int_bytes)
      call broadcast_status(status, comm, first_failing)
   end subroutine agree_on_status
end module status_broadcast
