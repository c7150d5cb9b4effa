!> Ghost-node summation: nodes on the boundary between two ranks' cell boxes receive particle
!> contributions on both ranks; afterwards each rank must hold the full sum.
!>
!> One axis at a time, each rank packs its boundary node planes (whole local extent of the other axes)
!> into contiguous buffers, exchanges them with both face neighbours and adds what it receives. Axis by
!> axis, edge and corner nodes pick up the sums of all 2**dim ranks that share them. Neighbours share
!> 1 + 2 ghost planes: the plane of their common cell face and the grid's ghost layers on both sides of it
!> (bspline2: 3 planes). A slab is at least that many cells wide (domain_t%min_width), so only face
!> neighbours share a plane.
module node_halo
   use kinds, only: rp
   use mpi_f08, only: MPI_PROC_NULL
   use face_exchange, only: exchange_with_face_neighbours
   use communication_counters, only: comm_node_halo
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   implicit none
   private

   public :: sum_shared_nodes

contains

   !> field(:, node) := sum over all ranks sharing the node. Collective over domain%comm.
   subroutine sum_shared_nodes(domain, grid, field)
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      real(rp), intent(inout) :: field(:, :)
      real(rp), allocatable :: send_buf(:, :), recv_buf(:, :)
      integer :: k, side, nv, plane_size, count, plane_index(2), layers, layer
      integer, parameter :: tag = 101

      nv = size(field, 1)
      layers = 1 + 2 * grid%ghost
      do k = 1, domain%dim
         if (all(domain%neighbour(:, k) == MPI_PROC_NULL)) cycle
         plane_size = grid%node_count / grid%n_nodes(k)
         count = nv * plane_size
         allocate (send_buf(count * layers, 2), recv_buf(count * layers, 2))
         ! the first plane of each side's group, the planes in ascending order on both ranks
         plane_index = [1, grid%n_nodes(k) - layers + 1]
         do side = 1, 2
            do layer = 0, layers - 1
               call pack_plane(grid, k, plane_index(side) + layer, field, &
                               send_buf(layer * count + 1:(layer + 1) * count, side))
            end do
         end do
         call exchange_with_face_neighbours(domain, k, send_buf, recv_buf, tag, comm_node_halo)
         do side = 1, 2
            if (domain%neighbour(side, k) == MPI_PROC_NULL) cycle
            do layer = 0, layers - 1
               call add_plane(grid, k, plane_index(side) + layer, recv_buf(layer * count + 1:(layer + 1) * count, side), &
                              field)
            end do
         end do
         deallocate (send_buf, recv_buf)
      end do
   end subroutine sum_shared_nodes

   !> Copy the node plane with local index `layer` along axis k into a contiguous buffer.
   subroutine pack_plane(grid, k, layer, field, buf)
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: k, layer
      real(rp), intent(in) :: field(:, :)
      real(rp), intent(out) :: buf(:)
      integer :: i, j, l, nv, pos, node
      nv = size(field, 1)
      pos = 0
      do l = 1, plane_extent(grid, k, 2)
         do j = 1, plane_extent(grid, k, 1)
            node = plane_node(grid, k, layer, j, l)
            do i = 1, nv
               buf(pos + i) = field(i, node)
            end do
            pos = pos + nv
         end do
      end do
   end subroutine pack_plane

   !> Add a received plane to the node plane with local index `layer` along axis k.
   subroutine add_plane(grid, k, layer, buf, field)
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: k, layer
      real(rp), intent(in) :: buf(:)
      real(rp), intent(inout) :: field(:, :)
      integer :: i, j, l, nv, pos, node
      nv = size(field, 1)
      pos = 0
      do l = 1, plane_extent(grid, k, 2)
         do j = 1, plane_extent(grid, k, 1)
            node = plane_node(grid, k, layer, j, l)
            do i = 1, nv
               field(i, node) = field(i, node) + buf(pos + i)
            end do
            pos = pos + nv
         end do
      end do
   end subroutine add_plane

   !> Node count of the plane normal to k along its first (which = 1) or second (which = 2) in-plane axis.
   pure integer function plane_extent(grid, k, which)
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: k, which
      integer :: axes(2)
      axes = in_plane_axes(k)
      plane_extent = grid%n_nodes(axes(which))
   end function plane_extent

   !> Local flat node index of in-plane position (j, l) (1-based) in layer `layer` along axis k.
   pure integer function plane_node(grid, k, layer, j, l)
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: k, layer, j, l
      integer :: local(3), axes(2)
      axes = in_plane_axes(k)
      local(k) = layer
      local(axes(1)) = j
      local(axes(2)) = l
      plane_node = local(1) + grid%n_nodes(1) * ((local(2) - 1) + grid%n_nodes(2) * (local(3) - 1))
   end function plane_node

   pure function in_plane_axes(k) result(axes)
      integer, intent(in) :: k
      integer :: axes(2)
      select case (k)
      case (1); axes = [2, 3]
      case (2); axes = [1, 3]
      case default; axes = [1, 2]
      end select
   end function in_plane_axes
end module node_halo
