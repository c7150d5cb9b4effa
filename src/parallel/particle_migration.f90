!> Hands particles that left a rank's cell box to the neighbour that owns them, one axis at a time
!> (a diagonal move takes two hops). Particles that leave the whole grid are removed and counted.
!> Per axis one message to each face neighbour, its particle records (maybe none): the receiver learns
!> their number from the message itself (MPI_Probe), so no count travels ahead of it, and both sides'
!> messages are in flight at once (docs/performance.md, Scaling model: a message is a latency).
module particle_migration
   use kinds, only: rp
   use mpi_f08, only: MPI_Isend, MPI_Probe, MPI_Get_count, MPI_Recv, MPI_Waitall, MPI_Request, MPI_Status, &
                      MPI_DOUBLE_PRECISION, MPI_STATUS_IGNORE, MPI_STATUSES_IGNORE, MPI_PROC_NULL
   use domain_decomposition, only: domain_t
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   use communication_counters, only: count_sent, comm_migration, real_bytes
   implicit none
   private

   !> The records going to one side: a buffer of its own, alive until MPI_Waitall (no array sections
   !> in non-blocking calls, docs/conventions.md).
   type :: records_t
      real(rp), allocatable :: values(:, :)
   end type records_t

   public :: migrate_particles

contains

   !> Move every particle to the rank owning its cell and set particles%cell (local cell) of every
   !> particle kept or received. `lost` counts particles that left the grid, `arrived` the particles
   !> received from other ranks. Collective over domain%comm.
   subroutine migrate_particles(domain, grid, particles, lost, arrived)
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer, intent(inout) :: lost
      integer, intent(out) :: arrived
      type(records_t) :: outgoing(2)
      real(rp), allocatable :: incoming(:, :)
      type(MPI_Request) :: requests(2)
      type(MPI_Status) :: probed
      integer :: k, p, kept, side, c, n_out(2), n_in, width, other, n_outside, first_new, received
      integer, parameter :: tag_data = 202

      ! cells of all particles; cell = 0 marks a particle outside this rank's box
      call grid%owned_local_cells(particles%count, particles%x, particles%cell, n_outside)

      width = particles%record_size()
      arrived = 0
      do k = 1, domain%dim
         n_out = 0
         do side = 1, 2
            allocate (outgoing(side)%values(width, max(1, n_outside)))
         end do
         if (n_outside > 0) then
            kept = 0
            do p = 1, particles%count
               side = 0
               if (particles%cell(p) == 0) then
                  c = grid%cell_along(particles%x(k, p), k)
                  if (c < domain%cell_lo(k)) side = 1
                  if (c > domain%cell_hi(k)) side = 2
               end if
               if (side == 0) then
                  kept = kept + 1
                  if (kept /= p) call particles%copy_particle(p, kept)
               else
                  n_outside = n_outside - 1
                  ! off the grid: lost here, also when a neighbour's box lies between (the neighbour
                  ! would find it outside its box and keep it, with no cell)
                  if (domain%neighbour(side, k) == MPI_PROC_NULL .or. c < 0 .or. c >= grid%global_cells(k)) then
                     lost = lost + 1
                  else
                     n_out(side) = n_out(side) + 1
                     call particles%pack_record(p, outgoing(side)%values(:, n_out(side)))
                  end if
               end if
            end do
            particles%count = kept
         end if

         do side = 1, 2
            call MPI_Isend(outgoing(side)%values, width * n_out(side), MPI_DOUBLE_PRECISION, domain%neighbour(side, k), &
                           tag_data, domain%comm, requests(side))
            if (domain%neighbour(side, k) /= MPI_PROC_NULL) &
               call count_sent(comm_migration, width * n_out(side), real_bytes)
         end do
         ! first what the upper neighbour sent, then the lower one's (the order of the particles appended)
         do side = 1, 2
            other = 3 - side
            n_in = 0
            if (domain%neighbour(other, k) /= MPI_PROC_NULL) then
               call MPI_Probe(domain%neighbour(other, k), tag_data, domain%comm, probed)
               call MPI_Get_count(probed, MPI_DOUBLE_PRECISION, received)
               n_in = received / width
            end if
            allocate (incoming(width, max(1, n_in)))
            call MPI_Recv(incoming, width * n_in, MPI_DOUBLE_PRECISION, domain%neighbour(other, k), tag_data, &
                          domain%comm, MPI_STATUS_IGNORE)
            call particles%reserve(particles%count + n_in)
            first_new = particles%count + 1
            do p = 1, n_in
               call particles%append_record(incoming(:, p))
            end do
            ! a diagonal move may still be outside along a later axis
            do p = first_new, particles%count
               call locate_particle(p)
            end do
            arrived = arrived + n_in
            deallocate (incoming)
         end do
         call MPI_Waitall(2, requests, MPI_STATUSES_IGNORE)
         do side = 1, 2
            deallocate (outgoing(side)%values)
         end do
      end do

   contains

      subroutine locate_particle(q)
         integer, intent(in) :: q
         particles%cell(q) = grid%owned_local_cell(particles%x(:, q))
         if (particles%cell(q) == 0) n_outside = n_outside + 1
      end subroutine locate_particle
   end subroutine migrate_particles
end module particle_migration
