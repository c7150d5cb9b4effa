!> Global diagnostics of the run (one CSV row per output interval), reduced over all ranks.
module run_diagnostics
   use kinds, only: rp, i8
   use communication_counters, only: count_collective, comm_diagnostics, real_bytes, int8_bytes
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_INTEGER8, MPI_SUM, MPI_MAX
   use particle_set, only: particle_set_t
   use material_model, only: material_slot_t
   use input_text, only: real_text
   implicit none
   private

   type, public :: diagnostics_t
      real(rp) :: time = 0.0_rp, dt = 0.0_rp
      integer(i8) :: step = 0, particles = 0
      real(rp) :: total_mass = 0.0_rp
      real(rp) :: kinetic_energy = 0.0_rp   !< sum 1/2 m |v|^2 [J] (per unit thickness in 2-D)
      real(rp) :: fluid_volume = 0.0_rp     !< sum of fluid particle volumes m / rho
      real(rp) :: h_eq = 0.0_rp             !< fluid_volume / floor size (algorithms.md section 6.2)
      real(rp) :: max_speed = 0.0_rp
      integer(i8) :: lost_particles = 0     !< particles that left the grid (open sides)
      integer(i8) :: wall_corrections = 0   !< particles put back behind a wall (cumulative)
      real(rp) :: max_rank_share = 0.0_rp   !< largest fraction of the particles on one rank (0: none)
   end type diagnostics_t

   public :: compute_diagnostics, diagnostics_header, diagnostics_row, diagnostics_comments

contains

   !> Reduce particle sums over `comm`. Collective.
   subroutine compute_diagnostics(comm, particles, materials, floor_size, lost, corrections, diag)
      type(MPI_Comm), intent(in) :: comm
      type(particle_set_t), intent(in) :: particles
      type(material_slot_t), intent(in) :: materials(:)
      real(rp), intent(in) :: floor_size
      integer(i8), intent(in) :: lost, corrections
      type(diagnostics_t), intent(inout) :: diag
      real(rp) :: sums(3), speed2
      integer(i8) :: counts(3), largest
      integer :: p, m
      sums = 0.0_rp
      speed2 = 0.0_rp
      do m = 1, size(materials)
         do p = particles%material_first(m), particles%material_last(m)
            sums(1) = sums(1) + particles%mass(p)
            sums(2) = sums(2) + 0.5_rp * particles%mass(p) * sum(particles%v(:, p)**2)
            if (materials(m)%model%is_fluid) sums(3) = sums(3) + particles%mass(p) / particles%density(p)
            speed2 = max(speed2, sum(particles%v(:, p)**2))
         end do
      end do
      counts = [int(particles%count, i8), lost, corrections]
      call MPI_Allreduce(MPI_IN_PLACE, sums, 3, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call MPI_Allreduce(MPI_IN_PLACE, speed2, 1, MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      call MPI_Allreduce(MPI_IN_PLACE, counts, 3, MPI_INTEGER8, MPI_SUM, comm)
      call MPI_Allreduce(int(particles%count, i8), largest, 1, MPI_INTEGER8, MPI_MAX, comm)
      call count_collective(comm_diagnostics, 3, real_bytes)
      call count_collective(comm_diagnostics, 1, real_bytes)
      call count_collective(comm_diagnostics, 3, int8_bytes)
      call count_collective(comm_diagnostics, 1, int8_bytes)
      diag%total_mass = sums(1)
      diag%kinetic_energy = sums(2)
      diag%fluid_volume = sums(3)
      diag%h_eq = sums(3) / floor_size
      diag%max_speed = sqrt(speed2)
      diag%particles = counts(1)
      diag%lost_particles = counts(2)
      diag%wall_corrections = counts(3)
      diag%max_rank_share = 0.0_rp
      if (counts(1) > 0) diag%max_rank_share = real(largest, rp) / real(counts(1), rp)
   end subroutine compute_diagnostics

   pure function diagnostics_header() result(line)
      character(len=:), allocatable :: line
      line = 'time,step,dt,particles,total_mass,kinetic_energy,fluid_volume,h_eq,max_speed,' // &
             'lost_particles,wall_corrections,max_rank_share'
   end function diagnostics_header

   !> The comment lines of diagnostics.csv after the provenance line: what the file holds and its units
   !> (lines separated by new_line).
   function diagnostics_comments(dim) result(text)
      integer, intent(in) :: dim
      character(len=:), allocatable :: text, mass, energy, volume
      if (dim == 2) then
         mass = 'kg/m'
         energy = 'J/m'
         volume = 'm^2'
      else
         mass = 'kg'
         energy = 'J'
         volume = 'm^3'
      end if
      text = '# diagnostics.csv: one row per output time (row n describes the state of fields_<n>.h5), sums '// &
             'and extremes over all particles and ranks'//new_line('a')// &
             '# units: time s; step -; dt s (time step); particles count; total_mass '//mass// &
             '; kinetic_energy '//energy//'; fluid_volume '//volume//'; h_eq m (fluid volume / floor size); '// &
             'max_speed m/s; lost_particles count (left the grid); wall_corrections count (cumulative); '// &
             'max_rank_share - (largest fraction of the particles on one rank)'
      if (dim == 2) text = text//'; 2-D plane strain: per metre of thickness'
   end function diagnostics_comments

   !> One CSV row; reals in full precision (g0) so rows can be compared to round-off. The time in the
   !> fewest digits that read back exactly: an output time k x interval prints as 0.3, not 0.30000000000000000.
   function diagnostics_row(diag) result(line)
      type(diagnostics_t), intent(in) :: diag
      character(len=:), allocatable :: line
      character(len=512) :: buffer
      write (buffer, '(i0,",",g0,",",i0,5(",",g0),2(",",i0),",",g0)') &
         diag%step, diag%dt, diag%particles, diag%total_mass, diag%kinetic_energy, &
         diag%fluid_volume, diag%h_eq, diag%max_speed, diag%lost_particles, diag%wall_corrections, &
         diag%max_rank_share
      line = real_text(diag%time)//','//trim(adjustl(buffer))
   end function diagnostics_row
end module run_diagnostics
