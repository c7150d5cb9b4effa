!> The mass-weighted cell averages of C0 and FOAL1 (cell_binning, [Y17] eq. 4) against averages summed
!> directly cell by cell. The particles come in runs of one cell, as the sort leaves them, with later visits
!> to cells met before (particles that arrived or moved since the last full sort), which the running sums
!> must continue.
module test_cell_binning
   use kinds, only: rp, i8
   use assertions, only: assertEqual, assertTrue
   use reproducible_numbers, only: hash01
   use particle_set, only: particle_set_t
   use cell_binning, only: cell_list_t, start_cell_list, bin_cell_mass, cell_average
   implicit none
   private

   public :: test_average_is_the_mass_weighted_mean

   integer, parameter :: n_cells = 60, n_particles = 400

contains

   !> n_particles particles of dimension dim with random masses and stresses; cells in runs of 1 to 7
   !> particles over the first 50 cells, then 40 particles back in cells met before.
   function sample_particles(dim) result(particles)
      integer, intent(in) :: dim
      type(particle_set_t) :: particles
      integer :: p, k, cell, left_in_run
      real(rp) :: stress(6)
      call particles%init(dim, 1, n_particles)
      do p = 1, n_particles
         stress = 1.0e3_rp * [hash01(7 * p), hash01(7 * p + 1), hash01(7 * p + 2), hash01(7 * p + 3), &
                              hash01(7 * p + 4), hash01(7 * p + 5)] - 500.0_rp
         call particles%add([(0.0_rp, k=1, dim)], [(0.0_rp, k=1, dim)], 0.01_rp * (0.5_rp + hash01(3 * p)), &
                            1000.0_rp, stress(1:particles%n_sigma), 1, int(p, i8))
      end do
      cell = 1
      left_in_run = 3
      do p = 1, n_particles
         if (p > n_particles - 40) then
            particles%cell(p) = 1 + int(50 * hash01(11 * p))
         else
            particles%cell(p) = cell
            left_in_run = left_in_run - 1
            if (left_in_run == 0) then
               cell = 1 + modulo(cell, 50)
               left_in_run = 1 + int(7 * hash01(13 * p))
            end if
         end if
      end do
   end function sample_particles

   !> cell_average against sum_p m_p s_p / sum_p m_p summed directly per cell (another order): equal to
   !> round-off on every cell holding particles, untouched elsewhere.
   subroutine test_average_is_the_mass_weighted_mean()
      type(particle_set_t) :: particles
      type(cell_list_t) :: occupied
      real(rp) :: cell_mass(n_cells), mass_sum, expected(6)
      real(rp), allocatable :: average(:, :)
      integer :: dim, n, c, p
      do dim = 2, 3
         particles = sample_particles(dim)
         n = particles%n_sigma
         call start_cell_list(n_cells, occupied, cell_mass)
         call bin_cell_mass(particles, 1, particles%count, occupied, cell_mass)
         allocate (average(n, n_cells), source=-7.0_rp)
         call cell_average(particles, 1, particles%count, occupied, cell_mass, particles%sbar(:, 1:particles%count), &
                           average)
         call assertEqual(50, occupied%count, 'the cells holding particles are listed')
         do c = 1, n_cells
            mass_sum = 0.0_rp
            expected = 0.0_rp
            do p = particles%count, 1, -1
               if (particles%cell(p) /= c) cycle
               mass_sum = mass_sum + particles%mass(p)
               expected(1:n) = expected(1:n) + particles%mass(p) * particles%sbar(:, p)
            end do
            if (mass_sum > 0.0_rp) then
               call assertEqual(mass_sum, cell_mass(c), 1.0e-15_rp, 'cell mass')
               call assertEqual(0.0_rp, maxval(abs(average(:, c) - expected(1:n) / mass_sum)), 1.0e-11_rp, &
                                'the cell average is the mass-weighted mean')
            else
               call assertTrue(all(average(:, c) == -7.0_rp), 'a cell without particles is not written')
            end if
         end do
         deallocate (average)
      end do
   end subroutine test_average_is_the_mass_weighted_mean
end module test_cell_binning
