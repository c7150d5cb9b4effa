!> What this rank sent, per category of communication (docs/performance.md, "Scaling model"): point-to-point
!> messages and their bytes, collective calls and their bytes. Every MPI call site of the step adds to it
!> with one call (`count_sent`, `count_collective`); flotsam_bench and the time loop report the counts per
!> step from two snapshots (`communication_totals`). Integer additions only: no MPI here, so that every
!> layer from `domain` up may count (agree_on_status sits below `parallel`), and no change of behaviour.
!>
!> Bytes of a point-to-point message: what it carries (a message to MPI_PROC_NULL is not one and is not
!> counted; an empty message is, it still costs a latency). Bytes of a collective: the payload one rank
!> holds after the call (an allreduce's or broadcast's buffer, an allgather's whole result), for the
!> all-to-alls what this rank sends.
module communication_counters
   use kinds, only: i8
   implicit none
   private

   !> The categories (rows of the table).
   integer, parameter, public :: comm_node_halo = 1      !< ghost-node sums (node_halo)
   integer, parameter, public :: comm_cell_halo = 2      !< ghost cells of the face-flux smoothing (cell_halo)
   integer, parameter, public :: comm_migration = 3      !< particles to the face neighbours (particle_migration)
   integer, parameter, public :: comm_balance = 4        !< balance check, layout search, redistribution
   integer, parameter, public :: comm_time_step = 5      !< the step's one reduction (time step, extent, loop flags)
   integer, parameter, public :: comm_volume = 6         !< the volume correction's surface heights
   integer, parameter, public :: comm_records = 7        !< loads, gauges, bodies (load_interval)
   integer, parameter, public :: comm_diagnostics = 8    !< diagnostics rows (output times)
   integer, parameter, public :: comm_status = 9         !< status agreement and broadcast
   integer, parameter, public :: comm_other = 10         !< the solver's set-up
   integer, parameter, public :: comm_rigid = 11         !< rigid bodies: increments and contact points (rigid_bodies)
   integer, parameter, public :: comm_categories = 11
   character(len=*), parameter :: names_(comm_categories) = [character(len=11) :: 'node_halo', 'cell_halo', &
                                                             'migration', 'balance', 'time_step', 'volume', &
                                                             'records', 'diagnostics', 'status', 'other', 'rigid']
   character(len=11), parameter, public :: comm_category_names(comm_categories) = names_

   !> Bytes of one element of the MPI types counted.
   integer, parameter, public :: real_bytes = 8, int_bytes = 4, int8_bytes = 8, logical_bytes = 4

   !> Cumulative counts of this rank, per category.
   type, public :: comm_counts_t
      integer(i8) :: messages(comm_categories) = 0          !< point-to-point messages sent
      integer(i8) :: bytes(comm_categories) = 0             !< their bytes
      integer(i8) :: collectives(comm_categories) = 0       !< collective calls
      integer(i8) :: collective_bytes(comm_categories) = 0  !< their payload (see the header)
   end type comm_counts_t

   type(comm_counts_t), save :: totals

   public :: count_sent, count_collective, communication_totals, counts_between

contains

   !> One point-to-point message of `elements` elements of `element_bytes` bytes each.
   subroutine count_sent(category, elements, element_bytes)
      integer, intent(in) :: category, elements, element_bytes
      totals%messages(category) = totals%messages(category) + 1
      totals%bytes(category) = totals%bytes(category) + int(elements, i8) * element_bytes
   end subroutine count_sent

   !> One collective call with a payload of `elements` elements of `element_bytes` bytes each.
   subroutine count_collective(category, elements, element_bytes)
      integer, intent(in) :: category, elements, element_bytes
      totals%collectives(category) = totals%collectives(category) + 1
      totals%collective_bytes(category) = totals%collective_bytes(category) + int(elements, i8) * element_bytes
   end subroutine count_collective

   !> This rank's counts since the start of the program.
   function communication_totals() result(counts)
      type(comm_counts_t) :: counts
      counts = totals
   end function communication_totals

   !> The counts from snapshot `before` to snapshot `after`.
   pure function counts_between(before, after) result(counts)
      type(comm_counts_t), intent(in) :: before, after
      type(comm_counts_t) :: counts
      counts%messages = after%messages - before%messages
      counts%bytes = after%bytes - before%bytes
      counts%collectives = after%collectives - before%collectives
      counts%collective_bytes = after%collective_bytes - before%collective_bytes
   end function counts_between
end module communication_counters
