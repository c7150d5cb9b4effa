!> Copy a scene from the rank that read the file to every rank.
module scene_broadcast
   use mpi_f08, only: MPI_Comm, MPI_Bcast, MPI_Comm_rank, MPI_CHARACTER, MPI_INTEGER, MPI_DOUBLE_PRECISION, &
                      MPI_LOGICAL
   use scene_description, only: scene_t
   use time_table, only: time_table_t
   implicit none
   private

   public :: broadcast_scene

   !> Mould of `transfer` to and from bytes.
   character(len=1), parameter :: byte_mold(0) = [character(len=1) ::]

contains

   !> Copy `root`'s scene to every rank: array sizes first, then the contents in one message. Collective
   !> over `comm`. Every component of the scene types has a fixed size, so each part travels as its
   !> bytes (all ranks run the same executable); an allocatable or pointer component added to one of
   !> these types would need its own broadcast here.
   subroutine broadcast_scene(scene, comm, root)
      type(scene_t), intent(inout) :: scene
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: root
      character(len=1), allocatable :: bytes(:)
      integer :: counts(9), rank_count(9), rank, n, at

      ! -1 stands for "not allocated".
      counts = -1
      if (allocated(scene%materials)) counts(1) = size(scene%materials)
      if (allocated(scene%bodies)) counts(2) = size(scene%bodies)
      if (allocated(scene%walls)) counts(3) = size(scene%walls)
      if (allocated(scene%inlets)) counts(4) = size(scene%inlets)
      if (allocated(scene%gauges)) counts(5) = size(scene%gauges)
      if (allocated(scene%contacts)) counts(6) = size(scene%contacts)
      if (allocated(scene%structures)) counts(7) = size(scene%structures)
      if (allocated(scene%panels)) counts(8) = size(scene%panels)
      if (allocated(scene%damping_zones)) counts(9) = size(scene%damping_zones)
      rank_count = counts
      call MPI_Bcast(counts, size(counts), MPI_INTEGER, root, comm)
      if (any(counts /= rank_count)) then
         if (allocated(scene%materials)) deallocate (scene%materials)
         if (allocated(scene%bodies)) deallocate (scene%bodies)
         if (allocated(scene%walls)) deallocate (scene%walls)
         if (allocated(scene%inlets)) deallocate (scene%inlets)
         if (allocated(scene%gauges)) deallocate (scene%gauges)
         if (allocated(scene%contacts)) deallocate (scene%contacts)
         if (allocated(scene%structures)) deallocate (scene%structures)
         if (allocated(scene%panels)) deallocate (scene%panels)
         if (allocated(scene%damping_zones)) deallocate (scene%damping_zones)
         if (counts(1) >= 0) allocate (scene%materials(counts(1)))
         if (counts(2) >= 0) allocate (scene%bodies(counts(2)))
         if (counts(3) >= 0) allocate (scene%walls(counts(3)))
         if (counts(4) >= 0) allocate (scene%inlets(counts(4)))
         if (counts(5) >= 0) allocate (scene%gauges(counts(5)))
         if (counts(6) >= 0) allocate (scene%contacts(counts(6)))
         if (counts(7) >= 0) allocate (scene%structures(counts(7)))
         if (counts(8) >= 0) allocate (scene%panels(counts(8)))
         if (counts(9) >= 0) allocate (scene%damping_zones(counts(9)))
      end if

      ! the parts one after the other, packed on root and unpacked in the same order elsewhere
      call MPI_Comm_rank(comm, rank)
      n = 0
      if (rank == root) then
         bytes = [transfer(scene%source_file, byte_mold), transfer(scene%run, byte_mold), &
                  transfer(scene%grid, byte_mold), transfer(scene%gravity, byte_mold)]
         if (counts(1) > 0) bytes = [bytes, transfer(scene%materials, byte_mold)]
         if (counts(2) > 0) bytes = [bytes, transfer(scene%bodies, byte_mold)]
         if (counts(3) > 0) bytes = [bytes, transfer(scene%walls, byte_mold)]
         if (counts(4) > 0) bytes = [bytes, transfer(scene%inlets, byte_mold)]
         if (counts(5) > 0) bytes = [bytes, transfer(scene%gauges, byte_mold)]
         if (counts(6) > 0) bytes = [bytes, transfer(scene%contacts, byte_mold)]
         if (counts(7) > 0) bytes = [bytes, transfer(scene%structures, byte_mold)]
         if (counts(8) > 0) bytes = [bytes, transfer(scene%panels, byte_mold)]
         if (counts(9) > 0) bytes = [bytes, transfer(scene%damping_zones, byte_mold)]
         n = size(bytes)
      end if
      call MPI_Bcast(n, 1, MPI_INTEGER, root, comm)
      if (rank /= root) call resize(bytes, n)
      call MPI_Bcast(bytes, n, MPI_CHARACTER, root, comm)
      call broadcast_body_points(scene, counts(2), comm, root, rank)
      call broadcast_tables(scene%inlet_tables, counts(4), comm, root, rank)
      call broadcast_tables(scene%wall_tables, counts(3), comm, root, rank)
      call broadcast_tables(scene%structure_tables, counts(7), comm, root, rank)
      if (rank == root) return

      at = 1
      scene%source_file = transfer(next_bytes(size(transfer(scene%source_file, byte_mold))), scene%source_file)
      scene%run = transfer(next_bytes(size(transfer(scene%run, byte_mold))), scene%run)
      scene%grid = transfer(next_bytes(size(transfer(scene%grid, byte_mold))), scene%grid)
      scene%gravity = transfer(next_bytes(size(transfer(scene%gravity, byte_mold))), scene%gravity, size(scene%gravity))
      if (counts(1) > 0) scene%materials(:) = transfer(next_bytes(counts(1) * size(transfer(scene%materials(1), &
                                                       byte_mold))), scene%materials, counts(1))
      if (counts(2) > 0) scene%bodies(:) = transfer(next_bytes(counts(2) * size(transfer(scene%bodies(1), byte_mold))), &
                                                    scene%bodies, counts(2))
      if (counts(3) > 0) scene%walls(:) = transfer(next_bytes(counts(3) * size(transfer(scene%walls(1), byte_mold))), &
                                                   scene%walls, counts(3))
      if (counts(4) > 0) scene%inlets(:) = transfer(next_bytes(counts(4) * size(transfer(scene%inlets(1), byte_mold))), &
                                                    scene%inlets, counts(4))
      if (counts(5) > 0) scene%gauges(:) = transfer(next_bytes(counts(5) * size(transfer(scene%gauges(1), byte_mold))), &
                                                    scene%gauges, counts(5))
      if (counts(6) > 0) scene%contacts(:) = transfer(next_bytes(counts(6) * size(transfer(scene%contacts(1), &
                                                      byte_mold))), scene%contacts, counts(6))
      if (counts(7) > 0) scene%structures(:) = transfer(next_bytes(counts(7) * size(transfer(scene%structures(1), &
                                                        byte_mold))), scene%structures, counts(7))
      if (counts(8) > 0) scene%panels(:) = transfer(next_bytes(counts(8) * size(transfer(scene%panels(1), byte_mold))), &
                                                    scene%panels, counts(8))
      if (counts(9) > 0) scene%damping_zones(:) = transfer(next_bytes(counts(9) * size(transfer(scene%damping_zones(1), &
                                                           byte_mold))), scene%damping_zones, counts(9))

   contains

      !> The next `length` bytes of the buffer.
      function next_bytes(length) result(part)
         integer, intent(in) :: length
         character(len=1) :: part(length)
         part = bytes(at:at + length - 1)
         at = at + length
      end function next_bytes
   end subroutine broadcast_scene

   !> The points of the bodies read from files (scene%body_points, allocatable arrays): per body the
   !> count (-1: none), then positions and volumes.
   subroutine broadcast_body_points(scene, bodies, comm, root, rank)
      type(scene_t), intent(inout) :: scene
      integer, intent(in) :: bodies, root, rank
      type(MPI_Comm), intent(in) :: comm
      integer :: b, shape(3)
      logical :: has_points
      if (bodies < 0) return
      has_points = allocated(scene%body_points)
      call MPI_Bcast(has_points, 1, MPI_LOGICAL, root, comm)
      if (.not. has_points) then
         if (allocated(scene%body_points)) deallocate (scene%body_points)
         return
      end if
      if (rank /= root) then
         if (allocated(scene%body_points)) deallocate (scene%body_points)
         allocate (scene%body_points(bodies))
      end if
      do b = 1, bodies
         associate (points => scene%body_points(b))
            shape = -1
            if (rank == root .and. allocated(points%position)) shape(1:2) = [size(points%position, 1), &
                                                                             size(points%position, 2)]
            call MPI_Bcast(shape, 2, MPI_INTEGER, root, comm)
            if (shape(1) < 0) cycle
            if (rank /= root) allocate (points%position(shape(1), shape(2)), points%volume(shape(2)))
            call MPI_Bcast(points%position, size(points%position), MPI_DOUBLE_PRECISION, root, comm)
            call MPI_Bcast(points%volume, size(points%volume), MPI_DOUBLE_PRECISION, root, comm)
         end associate
      end do
   end subroutine broadcast_body_points

   !> Time tables of the inlets, the walls or the structures (scene%inlet_tables, wall_tables,
   !> structure_tables; none: unallocated):
   !> per entry the numbers of columns and rows (-1: no table), then path, checksum, column names, times,
   !> values and lines.
   subroutine broadcast_tables(tables, entries, comm, root, rank)
      type(time_table_t), allocatable, intent(inout) :: tables(:)
      integer, intent(in) :: entries, root, rank
      type(MPI_Comm), intent(in) :: comm
      integer :: i, shape(2)
      logical :: has_tables
      if (entries < 0) return
      has_tables = allocated(tables)
      call MPI_Bcast(has_tables, 1, MPI_LOGICAL, root, comm)
      if (.not. has_tables) then
         if (allocated(tables)) deallocate (tables)
         return
      end if
      if (rank /= root) then
         if (allocated(tables)) deallocate (tables)
         allocate (tables(entries))
      end if
      do i = 1, entries
         associate (table => tables(i))
            shape = -1
            if (rank == root .and. allocated(table%time)) shape = [size(table%values, 1), size(table%time)]
            call MPI_Bcast(shape, 2, MPI_INTEGER, root, comm)
            if (shape(1) < 0) cycle
            if (rank /= root) allocate (table%columns(shape(1)), table%time(shape(2)), table%values(shape(1), shape(2)), &
                                        table%line(shape(2)))
            call MPI_Bcast(table%path, len(table%path), MPI_CHARACTER, root, comm)
            call MPI_Bcast(table%checksum, len(table%checksum), MPI_CHARACTER, root, comm)
            call MPI_Bcast(table%columns, len(table%columns) * shape(1), MPI_CHARACTER, root, comm)
            call MPI_Bcast(table%time, shape(2), MPI_DOUBLE_PRECISION, root, comm)
            call MPI_Bcast(table%values, size(table%values), MPI_DOUBLE_PRECISION, root, comm)
            call MPI_Bcast(table%line, shape(2), MPI_INTEGER, root, comm)
         end associate
      end do
   end subroutine broadcast_tables

   !> Allocate `bytes` with `n` elements (assigning to an unallocated array first makes gfortran 12
   !> warn falsely about uninitialised bounds).
   subroutine resize(bytes, n)
      character(len=1), allocatable, intent(inout) :: bytes(:)
      integer, intent(in) :: n
      if (allocated(bytes)) then
         if (size(bytes) == n) return
         deallocate (bytes)
      end if
      allocate (bytes(n))
   end subroutine resize
end module scene_broadcast
