!> Sends every particle to the rank owning its cell in one all-to-all exchange, wherever it is now:
!> used when particles were read without regard to the decomposition (a checkpoint written on another
!> number of ranks). Migration (particle_migration) handles the small moves of a time step.
module particle_redistribution
   use kinds, only: rp
   use mpi_f08, only: MPI_Alltoall, MPI_Alltoallv, MPI_Cart_rank, MPI_INTEGER, MPI_DOUBLE_PRECISION
   use error_status, only: status_t
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use status_broadcast, only: agree_on_status
   use communication_counters, only: count_collective, comm_balance, int_bytes, real_bytes
   implicit none
   private

   public :: redistribute_particles

contains

   !> Move each particle to the rank owning the cell at its position. The particles keep their relative
   !> order per source rank; the caller re-sorts. Fails if a particle lies outside the grid. Collective.
   subroutine redistribute_particles(domain, grid, particles, status)
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      type(status_t), intent(inout) :: status
      integer, allocatable :: owner(:), rank_of(:, :, :), send_counts(:), receive_counts(:), send_first(:), &
                              receive_first(:), next(:)
      real(rp), allocatable :: outgoing(:, :), incoming(:, :)
      integer :: p, k, c(3), coords(3), width, r, n_in, i, j, l

      ! rank of every position in the rank grid (MPI_Cart_rank once per rank, not per particle)
      allocate (rank_of(0:domain%dims(1) - 1, 0:domain%dims(2) - 1, 0:domain%dims(3) - 1))
      do l = 0, domain%dims(3) - 1
         do j = 0, domain%dims(2) - 1
            do i = 0, domain%dims(1) - 1
               call MPI_Cart_rank(domain%comm, [i, j, l], rank_of(i, j, l))
            end do
         end do
      end do

      allocate (owner(particles%count), send_counts(0:domain%nranks - 1), receive_counts(0:domain%nranks - 1))
      send_counts = 0
      do p = 1, particles%count
         c = grid%cell_of_position(particles%x(:, p))
         coords = 0
         do k = 1, domain%dim
            if (c(k) < 0 .or. c(k) >= domain%global_cells(k)) then
               call status%fail('a particle read from the checkpoint lies outside the grid')
               exit
            end if
            coords(k) = slab_of(domain%cuts(0:domain%dims(k), k), c(k))
         end do
         if (.not. status%ok) exit
         owner(p) = rank_of(coords(1), coords(2), coords(3))
         send_counts(owner(p)) = send_counts(owner(p)) + 1
      end do
      call agree_on_status(status, domain%comm)
      if (.not. status%ok) return

      width = particles%record_size()
      call MPI_Alltoall(send_counts, 1, MPI_INTEGER, receive_counts, 1, MPI_INTEGER, domain%comm)
      call count_collective(comm_balance, domain%nranks, int_bytes)
      allocate (send_first(0:domain%nranks - 1), receive_first(0:domain%nranks - 1), next(0:domain%nranks - 1))
      send_first(0) = 0
      receive_first(0) = 0
      do r = 1, domain%nranks - 1
         send_first(r) = send_first(r - 1) + send_counts(r - 1)
         receive_first(r) = receive_first(r - 1) + receive_counts(r - 1)
      end do
      n_in = sum(receive_counts)
      allocate (outgoing(width, max(1, particles%count)), incoming(width, max(1, n_in)))
      next = send_first
      do p = 1, particles%count
         next(owner(p)) = next(owner(p)) + 1
         call particles%pack_record(p, outgoing(:, next(owner(p))))
      end do
      call MPI_Alltoallv(outgoing, width * send_counts, width * send_first, MPI_DOUBLE_PRECISION, &
                         incoming, width * receive_counts, width * receive_first, MPI_DOUBLE_PRECISION, domain%comm)
      call count_collective(comm_balance, width * (particles%count - send_counts(domain%rank)), real_bytes)

      particles%count = 0
      call particles%reserve(n_in)
      do p = 1, n_in
         call particles%append_record(incoming(:, p))
      end do
   end subroutine redistribute_particles

   !> The slab j with cuts(j) <= c < cuts(j + 1).
   pure integer function slab_of(cuts, c) result(j)
      integer, intent(in) :: cuts(0:), c
      do j = 0, size(cuts) - 2
         if (c < cuts(j + 1)) return
      end do
      j = size(cuts) - 2
   end function slab_of
end module particle_redistribution
