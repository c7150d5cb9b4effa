!> Copy a scene from the rank that read the file to every rank.
module scene_broadcast
   use mpi_f08, only: MPI_Comm, MPI_Bcast, MPI_CHARACTER, MPI_INTEGER
   use scene_description, only: scene_t
   implicit none
   private

   public :: broadcast_scene

   !> Mould of `transfer` to and from bytes.
   character(len=1), parameter :: byte_mold(0) = [character(len=1) ::]

contains

   !> Copy `root`'s scene to every rank: array sizes first, then the contents. Collective over `comm`.
   !> Every component of the scene types has a fixed size, so each part travels as its bytes
   !> (all ranks run the same executable); an allocatable or pointer component added to one of
   !> these types would need its own broadcast here.
   subroutine broadcast_scene(scene, comm, root)
      type(scene_t), intent(inout) :: scene
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: root
      character(len=1), allocatable :: bytes(:)
      integer :: counts(4), rank_count(4)

      call resize(bytes, size(transfer(scene%source_file, byte_mold)))
      bytes(:) = transfer(scene%source_file, byte_mold)
      call broadcast_bytes(bytes, comm, root)
      scene%source_file = transfer(bytes, scene%source_file)

      call resize(bytes, size(transfer(scene%run, byte_mold)))
      bytes(:) = transfer(scene%run, byte_mold)
      call broadcast_bytes(bytes, comm, root)
      scene%run = transfer(bytes, scene%run)

      call resize(bytes, size(transfer(scene%grid, byte_mold)))
      bytes(:) = transfer(scene%grid, byte_mold)
      call broadcast_bytes(bytes, comm, root)
      scene%grid = transfer(bytes, scene%grid)

      call resize(bytes, size(transfer(scene%gravity, byte_mold)))
      bytes(:) = transfer(scene%gravity, byte_mold)
      call broadcast_bytes(bytes, comm, root)
      scene%gravity = transfer(bytes, scene%gravity, size(scene%gravity))

      ! -1 stands for "not allocated".
      counts = -1
      if (allocated(scene%materials)) counts(1) = size(scene%materials)
      if (allocated(scene%bodies)) counts(2) = size(scene%bodies)
      if (allocated(scene%walls)) counts(3) = size(scene%walls)
      if (allocated(scene%inlets)) counts(4) = size(scene%inlets)
      rank_count = counts
      call MPI_Bcast(counts, size(counts), MPI_INTEGER, root, comm)
      if (any(counts /= rank_count)) then
         if (allocated(scene%materials)) deallocate (scene%materials)
         if (allocated(scene%bodies)) deallocate (scene%bodies)
         if (allocated(scene%walls)) deallocate (scene%walls)
         if (allocated(scene%inlets)) deallocate (scene%inlets)
         if (counts(1) >= 0) allocate (scene%materials(counts(1)))
         if (counts(2) >= 0) allocate (scene%bodies(counts(2)))
         if (counts(3) >= 0) allocate (scene%walls(counts(3)))
         if (counts(4) >= 0) allocate (scene%inlets(counts(4)))
      end if

      if (counts(1) > 0) then
         call resize(bytes, size(transfer(scene%materials, byte_mold)))
         bytes(:) = transfer(scene%materials, byte_mold)
         call broadcast_bytes(bytes, comm, root)
         scene%materials(:) = transfer(bytes, scene%materials, counts(1))
      end if
      if (counts(2) > 0) then
         call resize(bytes, size(transfer(scene%bodies, byte_mold)))
         bytes(:) = transfer(scene%bodies, byte_mold)
         call broadcast_bytes(bytes, comm, root)
         scene%bodies(:) = transfer(bytes, scene%bodies, counts(2))
      end if
      if (counts(3) > 0) then
         call resize(bytes, size(transfer(scene%walls, byte_mold)))
         bytes(:) = transfer(scene%walls, byte_mold)
         call broadcast_bytes(bytes, comm, root)
         scene%walls(:) = transfer(bytes, scene%walls, counts(3))
      end if
      if (counts(4) > 0) then
         call resize(bytes, size(transfer(scene%inlets, byte_mold)))
         bytes(:) = transfer(scene%inlets, byte_mold)
         call broadcast_bytes(bytes, comm, root)
         scene%inlets(:) = transfer(bytes, scene%inlets, counts(4))
      end if
   end subroutine broadcast_scene

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

   subroutine broadcast_bytes(bytes, comm, root)
      character(len=1), intent(inout) :: bytes(:)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: root
      call MPI_Bcast(bytes, size(bytes), MPI_CHARACTER, root, comm)
   end subroutine broadcast_bytes
end module scene_broadcast
