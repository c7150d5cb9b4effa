!> The mass-weighted cell averages of C0 and FOAL1 (cell_binning, [Y17] eq. 4) against averages summed
!> directly cell by cell, and C0's replacement of the particles' values by them and FOAL1's packed cell field
!> against the averages. The particles come in runs of one cell, as the sort leaves them, with later visits
!> to cells met before (particles that arrived or moved since the last full sort), which the running sums
!> must continue.
module test_cell_binning
   use kinds, only: rp, i8
   use assertions, only: assertEqual, assertTrue
   use reproducible_numbers, only: hash01
   use particle_set, only: particle_set_t
   use cell_binning, only: cell_list_t, start_cell_list, bin_cell_mass, cell_average, replace_by_cell_average, &
                           first_revisit_notes
   use foal1_smoothing, only: sum_and_pack
   implicit none
   private

   public :: test_average_is_the_mass_weighted_mean, test_replaced_values_are_the_cell_averages, &
             test_packed_field_holds_the_cell_averages

   integer, parameter :: n_cells = 60, n_particles = 400

contains

   !> n_particles particles of dimension dim with random masses and stresses; cells in runs of 1 to 7
   !> particles over the first 50 cells, every 53rd particle back in cell 1 (a cell met before while cells
   !> not met yet are still to come), then 40 particles back in cells met before.
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
         else if (mod(p, 53) == 0) then
            particles%cell(p) = 1
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

   !> The number of particles at the start of the set whose cells do not decrease: before the first that
   !> comes back to a cell met before.
   integer function particles_in_cell_order(particles) result(in_order)
      type(particle_set_t), intent(in) :: particles
      in_order = 1
      do while (particles%cell(in_order + 1) >= particles%cell(in_order))
         in_order = in_order + 1
      end do
   end function particles_in_cell_order

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

   !> replace_by_cell_average (one pass: each run of a cell written as it ends, the runs of cells that come
   !> back written again) gives every particle cell_average's value of its cell bit for bit, 4, 6 and 1 values
   !> per particle: with the particles that come back to cells met before and the runs after the cells'
   !> numbers wrap round (over 64 runs come back: a new cell list notes 64, so its first pass gathers every
   !> particle instead, asserted, and a second pass with the same list, grown, rewrites the noted runs), and
   !> with the particles before the first one that comes back alone (no run comes back).
   subroutine test_replaced_values_are_the_cell_averages()
      type(particle_set_t) :: particles
      type(cell_list_t) :: occupied
      real(rp) :: cell_mass(n_cells)
      real(rp), allocatable :: average(:, :), values(:, :), work(:, :)
      integer :: dim, n, p, last, ones, case, in_order, pass
      do dim = 2, 3
         particles = sample_particles(dim)
         in_order = particles_in_cell_order(particles)
         do ones = 0, 1
            n = merge(1, particles%n_sigma, ones == 1)
            do case = 1, 2
               last = merge(particles%count, in_order, case == 1)
               occupied = cell_list_t()
               call start_cell_list(n_cells, occupied, cell_mass)
               call bin_cell_mass(particles, 1, last, occupied, cell_mass)
               allocate (average(n, n_cells), work(n, n_cells))
               values = particles%sbar(1:n, 1:last)
               call cell_average(particles, 1, last, occupied, cell_mass, values, average)
               do pass = 1, 2
                  values = particles%sbar(1:n, 1:last)
                  call replace_by_cell_average(particles, 1, last, occupied, cell_mass, values, work)
                  if (case == 1 .and. pass == 1) then
                     call assertTrue(occupied%n_revisits > first_revisit_notes, &
                                     'more runs came back than a new list notes')
                  else if (case == 1) then
                     call assertTrue(occupied%n_revisits > 0 .and. occupied%n_revisits <= size(occupied%revisits), &
                                     'the runs that came back were noted')
                  else
                     call assertEqual(0, occupied%n_revisits, 'no run comes back to a cell')
                  end if
                  do p = 1, last
                     call assertTrue(all(values(:, p) == average(:, particles%cell(p))), &
                                     'the particle holds its cell''s average, bit for bit')
                  end do
               end do
               deallocate (average, work)
            end do
         end do
      end do
   end subroutine test_replaced_values_are_the_cell_averages

   !> FOAL1's sums and packing in one pass (foal1_smoothing's sum_and_pack) give each listed cell the entry
   !> [1, m_c, x_o^c, q_c] with q_c cell_average's value bit for bit, and leave the other cells of the field
   !> as they were: with the cells that come back in later runs (the last run's write must stay) and with
   !> the particles before the first one that comes back alone; 4, 6 and 1 values per cell. The field's
   !> cells are numbered apart from the particles' (of_owned: a shift of 3, as a padded box's are).
   subroutine test_packed_field_holds_the_cell_averages()
      integer, parameter :: shift = 3
      type(particle_set_t) :: particles
      type(cell_list_t) :: occupied
      real(rp) :: cell_mass(n_cells)
      real(rp), allocatable :: average(:, :), values(:, :), sums(:, :), field(:, :), centre(:, :)
      logical :: exists(n_cells + 2 * shift), listed(n_cells)
      integer :: of_owned(n_cells), dim, n, c, last, ones, case, in_order
      of_owned = [(c + shift, c=1, n_cells)]
      do dim = 2, 3
         particles = sample_particles(dim)
         in_order = particles_in_cell_order(particles)
         allocate (centre(dim, n_cells))
         centre = reshape([(0.1_rp * c, c=1, dim * n_cells)], [dim, n_cells])
         do ones = 0, 1
            n = merge(1, particles%n_sigma, ones == 1)
            do case = 1, 2
               last = merge(particles%count, in_order, case == 1)
               call start_cell_list(n_cells, occupied, cell_mass)
               call bin_cell_mass(particles, 1, last, occupied, cell_mass)
               listed = .false.
               listed(occupied%cells(1:occupied%count)) = .true.
               values = particles%sbar(1:n, 1:last)
               allocate (average(n, n_cells), sums(n, n_cells), field(2 + dim + n, n_cells + 2 * shift))
               call cell_average(particles, 1, last, occupied, cell_mass, values, average)
               field = -7.0_rp
               exists = .false.
               call sum_and_pack(dim, n, occupied, particles%cell(1:last), particles%mass(1:last), values, of_owned, &
                                 cell_mass, centre, sums, field, exists)
               do c = 1, n_cells
                  if (listed(c)) then
                     call assertTrue(exists(c + shift) .and. field(1, c + shift) == 1.0_rp .and. &
                                     field(2, c + shift) == cell_mass(c) .and. &
                                     all(field(3:2 + dim, c + shift) == centre(:, c)), 'flag, mass and centre packed')
                     call assertTrue(all(field(3 + dim:, c + shift) == average(:, c)), &
                                     'the packed value is the cell average, bit for bit')
                  else
                     call assertTrue(.not. exists(c + shift) .and. all(field(:, c + shift) == -7.0_rp), &
                                     'a cell without particles is not written')
                  end if
               end do
               deallocate (average, sums, field)
            end do
         end do
         deallocate (centre)
      end do
   end subroutine test_packed_field_holds_the_cell_averages
end module test_cell_binning
