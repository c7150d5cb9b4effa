!> How much memory each rank of a run may still use, so that a scene too large for the machine is
!> refused before its particles are made (docs/input.md, "Scenes too large for the machine").
!>
!> The rule, per rank: the node's room is the smaller of MemAvailable (/proc/meminfo) and the room
!> under the cgroup memory limit (a batch job's or container's), shared equally among the ranks on the
!> node (MPI_COMM_TYPE_SHARED); a rank's room is that share, or less if its own address-space limit
!> (`ulimit -v`) leaves less. The budget is the smallest room of all ranks: every rank must fit.
!> Measured at start-up: memory that other programs take later is not foreseen.
module memory_budget
   use kinds, only: i8, rp
   use mpi_f08, only: MPI_Comm, MPI_Comm_split_type, MPI_COMM_TYPE_SHARED, MPI_INFO_NULL, MPI_Comm_size, &
                      MPI_Comm_rank, MPI_Comm_free, MPI_Allreduce, MPI_Bcast, MPI_IN_PLACE, MPI_INTEGER8, MPI_INTEGER, &
                      MPI_MIN
   use process_memory, only: meminfo_available_bytes, cgroup_room_bytes, address_space_room_bytes
   implicit none
   private

   integer, parameter :: limit_unknown = 0, limit_meminfo = 1, limit_cgroup = 2, limit_address_space = 3

   !> The smallest room of the ranks and what set it.
   type, public :: memory_budget_t
      integer(i8) :: per_rank = -1        !< bytes every rank may still use; -1: unknown (no check)
      integer(i8) :: source_bytes = -1    !< the figure it came from: the node's room, or the address-space room
      integer :: node_ranks = 1           !< ranks sharing the node of the rank with the least room
      integer :: limited_by = limit_unknown
   contains
      procedure :: describe => budget_describe
   end type memory_budget_t

   public :: measure_memory_budget, byte_text

contains

   !> Measure every rank's room and agree on the smallest. Collective over `comm`.
   function measure_memory_budget(comm) result(budget)
      type(MPI_Comm), intent(in) :: comm
      type(memory_budget_t) :: budget
      type(MPI_Comm) :: node
      integer(i8) :: room, node_room, cgroup, address_space, smallest, facts(2)
      integer :: node_ranks, rank, holder, by

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, node)
      call MPI_Comm_size(node, node_ranks)
      call MPI_Comm_free(node)

      by = limit_unknown
      node_room = meminfo_available_bytes()
      if (node_room >= 0) by = limit_meminfo
      cgroup = cgroup_room_bytes()
      if (cgroup >= 0 .and. (node_room < 0 .or. cgroup < node_room)) then
         node_room = cgroup
         by = limit_cgroup
      end if
      room = -1
      facts(1) = node_room
      if (node_room >= 0) room = node_room / node_ranks
      address_space = address_space_room_bytes()
      if (address_space >= 0 .and. (room < 0 .or. address_space < room)) then
         room = address_space
         facts(1) = address_space
         by = limit_address_space
      end if

      ! the smallest known room, and the lowest rank holding it tells what set it
      smallest = merge(huge(1_i8), room, room < 0)
      call MPI_Allreduce(MPI_IN_PLACE, smallest, 1, MPI_INTEGER8, MPI_MIN, comm)
      if (smallest == huge(1_i8)) return
      holder = merge(rank, huge(1), room == smallest)
      call MPI_Allreduce(MPI_IN_PLACE, holder, 1, MPI_INTEGER, MPI_MIN, comm)
      facts(2) = int(by * 1000000 + node_ranks, i8)
      call MPI_Bcast(facts, 2, MPI_INTEGER8, holder, comm)
      budget%per_rank = smallest
      budget%source_bytes = facts(1)
      budget%limited_by = int(facts(2) / 1000000)
      budget%node_ranks = int(mod(facts(2), 1000000_i8))
   end function measure_memory_budget

   !> "1.2 GB per rank (MemAvailable 4.8 GB shared by the 4 ranks of the node)" and the like.
   function budget_describe(self) result(text)
      class(memory_budget_t), intent(in) :: self
      character(len=:), allocatable :: text, shared
      shared = ''
      if (self%node_ranks > 1) shared = ' shared by the '//int_string(self%node_ranks)//' ranks of the node'
      select case (self%limited_by)
      case (limit_meminfo)
         text = byte_text(self%per_rank)//' per rank (MemAvailable '//byte_text(self%source_bytes)//shared//')'
      case (limit_cgroup)
         text = byte_text(self%per_rank)//' per rank (room under the cgroup memory limit '// &
                byte_text(self%source_bytes)//shared//')'
      case (limit_address_space)
         text = byte_text(self%per_rank)//' per rank (left under the address-space limit, ulimit -v)'
      case default
         text = 'unknown'
      end select
   end function budget_describe

   !> Bytes in MB or GB with 3 significant digits: "413 MB", "1.25 GB", "2.6e+05 GB".
   function byte_text(bytes) result(text)
      class(*), intent(in) :: bytes      !< integer(i8) or real(rp)
      character(len=:), allocatable :: text
      character(len=32) :: buffer
      real(rp) :: value
      select type (bytes)
      type is (integer(i8))
         value = real(bytes, rp)
      type is (real(rp))
         value = bytes
      class default
         value = 0.0_rp
      end select
      if (value < 1.0e9_rp) then
         write (buffer, '(f0.0)') max(1.0_rp, value / 1.0e6_rp)
         text = buffer(1:len_trim(buffer) - 1)//' MB'
      else if (value < 1.0e13_rp) then
         write (buffer, '(f0.1)') value / 1.0e9_rp
         text = trim(adjustl(buffer))//' GB'
      else
         write (buffer, '(es9.2)') value / 1.0e9_rp
         text = trim(adjustl(buffer))//' GB'
      end if
   end function byte_text

   pure function int_string(n) result(text)
      integer, intent(in) :: n
      character(len=:), allocatable :: text
      character(len=16) :: buffer
      write (buffer, '(i0)') n
      text = trim(buffer)
   end function int_string
end module memory_budget
