!> The communication counters (communication_counters) against counts worked out by hand from the grid's
!> geometry: on 2 ranks the ghost-node sum sends each rank one message of the shared node planes
!> (rows x planes x nodes per plane x 8 bytes), and a step sends the messages docs/performance.md lists.
module test_communication_counters
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_size
   use assertions, only: assertTrue, assertEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use node_halo, only: sum_shared_nodes
   use communication_counters, only: comm_counts_t, communication_totals, counts_between, comm_node_halo, &
                                     comm_migration, comm_time_step, comm_cell_halo
   use input_text, only: int_text
   use test_scenes, only: water_scene, add_body
   implicit none
   private

   public :: test_node_halo_bytes_match_geometry, test_step_messages

contains

   !> A tank full of water (the active region is the whole grid), split over 2 ranks along its longest
   !> axis: one ghost-node sum sends one message per rank of rows x planes x (cells + 1 + 2 ghost) per
   !> other axis x 8 bytes. Multilinear: 1 plane, no ghost layer; bspline2: 3 planes, 1 ghost layer.
   subroutine test_node_halo_bytes_match_geometry(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_halo(comm, 2, 'linear', 1, 0)
      call check_halo(comm, 3, 'linear', 1, 0)
      call check_halo(comm, 2, 'bspline2', 3, 1)
   end subroutine test_node_halo_bytes_match_geometry

   subroutine check_halo(comm, dim, shape, planes, ghost)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim, planes, ghost
      character(len=*), intent(in) :: shape
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      type(comm_counts_t) :: counts
      integer :: cells(3), split, k, ranks
      integer(i8) :: plane_nodes
      character(len=:), allocatable :: label

      call MPI_Comm_size(comm, ranks)
      if (ranks /= 2) return
      call make_tank(dim, shape, scene)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      if (.not. status%ok) return
      cells = scene%grid%ncells
      split = maxloc(cells(1:dim), dim=1)
      plane_nodes = 1
      do k = 1, dim
         if (k /= split) plane_nodes = plane_nodes * (cells(k) + 1 + 2 * ghost)
      end do
      label = int_text(dim)//'-D, '//shape
      counts = communication_totals()
      call sum_shared_nodes(solver%domain, solver%grid, solver%grid%accumulated)
      counts = counts_between(counts, communication_totals())
      call assertEqual(1_i8, counts%messages(comm_node_halo), label//': one message per rank')
      call assertEqual(int(size(solver%grid%accumulated, 1), i8) * planes * plane_nodes * 8, &
                       counts%bytes(comm_node_halo), label//': rows x planes x nodes per plane x 8 bytes')
      call assertEqual(0_i8, sum(counts%collectives), label//': no collective')
      call solver%free()
   end subroutine check_halo

   !> One MUSL step of the full tank on 2 ranks, standard MPM: two ghost-node sums (mass, momentum and
   !> force rows; the remapped momentum, dim rows), one migration message per rank (the particles, maybe
   !> none, to the one neighbour), no cell halo, one reduction (time step and extent together).
   subroutine test_step_messages(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      type(comm_counts_t) :: counts
      integer :: cells(3), split, k, ranks, dim
      integer(i8) :: plane_nodes

      call MPI_Comm_size(comm, ranks)
      if (ranks /= 2) return
      dim = 2
      call make_tank(dim, 'linear', scene)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      if (.not. status%ok) return
      cells = scene%grid%ncells
      split = maxloc(cells(1:dim), dim=1)
      plane_nodes = 1
      do k = 1, dim
         if (k /= split) plane_nodes = plane_nodes * (cells(k) + 1)
      end do
      counts = communication_totals()
      call solver%advance()
      counts = counts_between(counts, communication_totals())
      call assertEqual(2_i8, counts%messages(comm_node_halo), 'two ghost-node sums per step')
      call assertEqual(int(size(solver%grid%accumulated, 1) + dim, i8) * plane_nodes * 8, counts%bytes(comm_node_halo), &
                       'node halo bytes: (rows + dim) x nodes per plane x 8')
      call assertEqual(1_i8, counts%messages(comm_migration), 'migration: one message to the neighbour')
      call assertEqual(0_i8, counts%messages(comm_cell_halo), 'no cell halo without FOAL1')
      call assertEqual(1_i8, counts%collectives(comm_time_step), 'one reduction for the time step')
      call assertEqual(1_i8, sum(counts%collectives), 'no other collective in a step')
      call solver%free()
   end subroutine test_step_messages

   !> A 1.0 x 0.6 (x 0.4) m tank of 0.1 m cells full of water at rest.
   subroutine make_tank(dim, shape, scene)
      integer, intent(in) :: dim
      character(len=*), intent(in) :: shape
      type(scene_t), intent(out) :: scene
      real(rp), parameter :: extent(3) = [1.0_rp, 0.6_rp, 0.4_rp]
      scene = water_scene(dim, 0.1_rp, extent, 2.0e6_rp, 9.81_rp)
      scene%grid%shape_function = shape
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], extent, 2, .true., extent(dim))
   end subroutine make_tank
end module test_communication_counters
