!> Mass-weighted cell sums of one material's particles, the building block of C0 and FOAL1
!> ([Y17] eq. 4): m_c = sum m_p, x_o^c = sum m_p x_p / m_c, q_c = sum m_p q_p / m_c.
!> Particles are binned by particles%cell, their cell at x^n.
!>
!> Only the cells that hold particles are touched: binning the masses lists them (cell_list_t), and
!> every later routine works through the list. A range of cell numbers would also cover the empty
!> cells between them: a water column filling 40 % of the tank's width made 2.5 times as many cells to
!> clear, divide and pack. The list relies on cell_mass being 0 on every cell not listed (cleared when
!> the arrays are made and through the previous list at every binning) and on positive particle masses.
!>
!> The per-particle loops are memory-bound passes over the slice. Their kernels take the number of
!> values per particle as an argument and are called with a literal (2, 3, 4, 6) for the sizes that
!> occur, so the compiler specialises them: a section of unknown length per particle became a library
!> memcpy call per particle (measured: the C0 gather took three times as long as the sums).
module cell_binning
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use background_grid, only: grid_t
   implicit none
   private

   !> The distinct cells holding one material's particles, in the order the particles first reach them.
   type, public :: cell_list_t
      integer :: count = 0
      integer, allocatable :: cells(:)     !< cells(1:count); sized to the rank's cells
      ! work of replace_by_cell_average: where each listed cell's first run of particles starts (by cell), and
      ! the starts of the runs that come back to a cell met before (revisits(1:n_revisits))
      integer, allocatable :: first_run(:), revisits(:)
      integer :: n_revisits = 0
   end type cell_list_t

   public :: start_cell_list, bin_cell_mass, bin_cell_mass_and_centre, cell_average, replace_by_cell_average
   public :: bin_cell_mass_and_local_moments, bin_cell_mass_and_mean
   public :: divide_by_cell_mass, gather_cell_values

   !> Runs coming back to a cell met before that a new cell list notes (replace_by_cell_average; it grows
   !> when a pass needs more). Public for the tests.
   integer, parameter, public :: first_revisit_notes = 64

contains

   !> A new, empty list for `cell_count` cells; cell_mass (of that size) is cleared to match.
   subroutine start_cell_list(cell_count, occupied, cell_mass)
      integer, intent(in) :: cell_count
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(inout) :: cell_mass(:)
      if (allocated(occupied%cells)) deallocate (occupied%cells)
      if (allocated(occupied%first_run)) deallocate (occupied%first_run)
      allocate (occupied%cells(cell_count), occupied%first_run(cell_count))
      occupied%count = 0
      cell_mass = 0.0_rp
   end subroutine start_cell_list

   !> m_c of the cells holding particles first..last, which `occupied` lists afterwards.
   subroutine bin_cell_mass(particles, first, last, occupied, cell_mass)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(inout) :: cell_mass(:)
      call clear_listed(occupied, cell_mass)
      if (last < first) return
      call mass_sums(particles%cell(first:last), particles%mass(first:last), cell_mass, occupied%cells, occupied%count)
   end subroutine bin_cell_mass

   !> m_c and the mass centre x_o^c (where m_c > 0) of the particles first..last, in one pass; `occupied`
   !> lists their cells afterwards. `centre` is written on the listed cells only.
   subroutine bin_cell_mass_and_centre(particles, first, last, occupied, cell_mass, centre)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(inout) :: cell_mass(:), centre(:, :)
      call clear_listed(occupied, cell_mass)
      if (last < first) return
      select case (size(centre, 1))
      case (2)
         call mass_and_moment_sums(2, particles%cell(first:last), particles%mass(first:last), particles%x(:, first:last), &
                                   cell_mass, centre, occupied%cells, occupied%count)
         call divide_by_cell_mass(2, occupied, cell_mass, centre)
      case default
         call mass_and_moment_sums(3, particles%cell(first:last), particles%mass(first:last), particles%x(:, first:last), &
                                   cell_mass, centre, occupied%cells, occupied%count)
         call divide_by_cell_mass(3, occupied, cell_mass, centre)
      end select
   end subroutine bin_cell_mass_and_centre

   !> m_c and the mass-weighted mean mean(1, c) = sum m_p values(p - first + 1) / m_c (where m_c > 0) of one
   !> value per particle, for the particles first..last, in one pass: the sums of bin_cell_mass and of
   !> cell_average, in the same order (bit for bit theirs). `occupied` lists the cells afterwards; `mean` is
   !> written on the listed cells only.
   subroutine bin_cell_mass_and_mean(particles, first, last, values, occupied, cell_mass, mean)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(in), contiguous :: values(:)
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(inout) :: cell_mass(:), mean(:, :)
      call clear_listed(occupied, cell_mass)
      if (last < first) return
      call mass_and_moment_sums(1, particles%cell(first:last), particles%mass(first:last), values, cell_mass, mean, &
                                occupied%cells, occupied%count)
      call divide_by_cell_mass(1, occupied, cell_mass, mean)
   end subroutine bin_cell_mass_and_mean

   !> 3-D: m_c and the mass-weighted means over the cell's particles of their position xi in the cell (in
   !> cells, 0..1 from its lower corner: G2P's xi at x^n) and of xi_2 xi_3, xi_1 xi_3, xi_1 xi_2, moments(1:6, c):
   !> what the mean of the trilinear shape gradients over the particles needs (cell_strain_rate). With
   !> `centre` also the mass centre x_o^c (the sums of bin_cell_mass_and_centre, in the same order: bit for
   !> bit its result). One pass over the particles; `occupied` lists the cells afterwards; moments and centre
   !> are written on the listed cells.
   subroutine bin_cell_mass_and_local_moments(grid, particles, first, last, occupied, cell_mass, moments, centre)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(inout) :: cell_mass(:), moments(:, :)
      real(rp), intent(inout), optional :: centre(:, :)
      call clear_listed(occupied, cell_mass)
      if (last < first) return
      associate (cell => particles%cell(first:last), mass => particles%mass(first:last), x => particles%x(:, first:last))
         if (present(centre)) then
            call mass_and_local_moment_sums(grid, cell, mass, x, cell_mass, moments, occupied%cells, occupied%count, &
                                            centre)
            call divide_by_cell_mass(3, occupied, cell_mass, centre)
         else
            call mass_and_local_moment_sums(grid, cell, mass, x, cell_mass, moments, occupied%cells, occupied%count)
         end if
         call divide_by_cell_mass(6, occupied, cell_mass, moments)
      end associate
   end subroutine bin_cell_mass_and_local_moments

   !> cell_mass := 0 on the listed cells, and the list emptied (so cell_mass is 0 everywhere).
   subroutine clear_listed(occupied, cell_mass)
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(inout) :: cell_mass(:)
      integer :: i
      do i = 1, occupied%count
         cell_mass(occupied%cells(i)) = 0.0_rp
      end do
      occupied%count = 0
   end subroutine clear_listed

   !> average(:, c) = sum m_p values(:, p) / m_c over the particles first..last; values(:, p - first + 1)
   !> belongs to particle p; `occupied` lists their cells (made by binning the same particles in the same
   !> cells, in the same order). Only the listed cells are written. `average` is read as (n, cells) with
   !> n = size(values, 1) (it may be a larger work array).
   subroutine cell_average(particles, first, last, occupied, cell_mass, values, average)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: cell_mass(:), values(:, :)
      real(rp), intent(inout) :: average(:, :)
      if (last < first) return
      call cell_sums(particles, first, last, occupied, values, average)
      select case (size(values, 1))    ! literal sizes: the division per cell too (a runtime n cost 48 instructions per cell)
      case (4)
         call divide_by_cell_mass(4, occupied, cell_mass, average)
      case (6)
         call divide_by_cell_mass(6, occupied, cell_mass, average)
      case default
         call divide_by_cell_mass(size(values, 1), occupied, cell_mass, average)
      end select
   end subroutine cell_average

   !> sums(:, c) = sum m_p values(:, p) over the particles first..last: cell_average's sums, before its division
   !> by m_c (the order of FOAL1's sum_and_pack too). Arguments as cell_average's.
   subroutine cell_sums(particles, first, last, occupied, values, sums)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: values(:, :)
      real(rp), intent(inout) :: sums(:, :)
      integer :: n
      n = size(values, 1)
      if (last < first) return
      associate (cell => particles%cell(first:last), mass => particles%mass(first:last))
         select case (n)
         case (4)
            call mass_weighted_sums(4, occupied, cell, mass, values, sums)
         case (6)
            call mass_weighted_sums(6, occupied, cell, mass, values, sums)
         case default
            call mass_weighted_sums(n, occupied, cell, mass, values, sums)
         end select
      end associate
   end subroutine cell_sums

   !> Replace values(:, p) of particles first..last by the average of their cell (C0: "replace, not
   !> increment" [P]+[D], algorithms.md section 2.2): cell_average's result, bit for bit, in one pass
   !> (average_runs). `average` is work space of at least size(values, 1) * size(cell_mass) values (it
   !> holds the cells' sums afterwards); `occupied` keeps the pass's notes.
   subroutine replace_by_cell_average(particles, first, last, occupied, cell_mass, values, average)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(in) :: cell_mass(:)
      real(rp), intent(inout) :: values(:, :)
      real(rp), intent(inout) :: average(:, :)
      if (last < first) return
      associate (cell => particles%cell(first:last), mass => particles%mass(first:last))
         select case (size(values, 1))
         case (4)
            call average_runs(4, occupied, cell, mass, cell_mass, values, average)
         case (6)
            call average_runs(6, occupied, cell, mass, cell_mass, values, average)
         case default
            call average_runs(size(values, 1), occupied, cell, mass, cell_mass, values, average)
         end select
      end associate
   end subroutine replace_by_cell_average

   !> values(:, i) := cell_values(:, cell(i)), with cell_values read as (size(values, 1), cells).
   subroutine gather_cell_values(cell, cell_values, values)
      integer, intent(in) :: cell(:)
      real(rp), intent(in) :: cell_values(:, :)
      real(rp), intent(inout) :: values(:, :)
      select case (size(values, 1))
      case (4)
         call gather(4, cell, cell_values, values)
      case (6)
         call gather(6, cell, cell_values, values)
      case default
         call gather(size(values, 1), cell, cell_values, values)
      end select
   end subroutine gather_cell_values

   !> sums(:, c) := sums(:, c) / m_c where m_c > 0, for the listed cells.
   subroutine divide_by_cell_mass(n, occupied, cell_mass, sums)
      integer, intent(in) :: n
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: cell_mass(:)
      real(rp), intent(inout) :: sums(n, *)
      integer :: i, c
      real(rp) :: m, quotient(n)
      ! the n divisions unconditional (by 1 where m_c = 0), the store conditional: so they become one vector
      ! division (under the test they stayed n scalar ones, 5 % of a C0 step)
      do i = 1, occupied%count
         c = occupied%cells(i)
         m = cell_mass(c)
         quotient = sums(:, c) / merge(m, 1.0_rp, m > 0.0_rp)
         if (m > 0.0_rp) sums(:, c) = quotient
      end do
   end subroutine divide_by_cell_mass

   ! --- kernels: n is a literal at every call that matters (see the module header). The particles are
   ! sorted by cell (nearly, between two full sorts), so a sum is kept in registers along a run of equal
   ! cells and stored once per run; a cell met again later continues from its stored sum. These are the
   ! same additions in the same order as summing in memory particle by particle, without a store-to-load
   ! round trip per particle on the dependency chain (measured: half the time of the plain loop).
   ! The mass sums list a cell when a run starts on it with a mass of 0: its first visit (cell_mass is 0
   ! on unlisted cells, particle masses are positive). ---

   subroutine mass_sums(cell, mass, cell_mass, list, count)
      integer, intent(in) :: cell(:)
      real(rp), intent(in) :: mass(:)
      real(rp), intent(inout) :: cell_mass(:)
      integer, intent(inout) :: list(:), count
      integer :: i, c
      real(rp) :: running_mass
      c = cell(1)
      running_mass = 0.0_rp
      count = 1
      list(1) = c
      do i = 1, size(cell)
         if (cell(i) /= c) then
            cell_mass(c) = running_mass
            c = cell(i)
            running_mass = cell_mass(c)
            if (running_mass <= 0.0_rp) then
               count = count + 1
               list(count) = c
            end if
         end if
         running_mass = running_mass + mass(i)
      end do
      cell_mass(c) = running_mass
   end subroutine mass_sums

   subroutine mass_weighted_sums(n, occupied, cell, mass, values, sums)
      integer, intent(in) :: n, cell(:)
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: mass(:), values(n, *)
      real(rp), intent(inout) :: sums(n, *)
      integer :: i, c, next
      logical :: first_visit
      real(rp) :: running(n)
      ! The runs of equal cells come in the order in which the list was made (same particles, same
      ! cells), so a run on the next cell of the list is that cell's first visit: its sum starts at 0
      ! without a clearing pass over the cells.
      if (occupied%count == 0) return
      c = cell(1)
      running = 0.0_rp
      next = 2
      do i = 1, size(cell)
         if (cell(i) /= c) then
            sums(:, c) = running
            c = cell(i)
            first_visit = .false.
            if (next <= occupied%count) first_visit = c == occupied%cells(next)
            if (first_visit) then
               next = next + 1
               running = 0.0_rp
            else
               running = sums(:, c)
            end if
         end if
         running = running + mass(i) * values(:, i)
      end do
      sums(:, c) = running
   end subroutine mass_weighted_sums

   subroutine mass_and_moment_sums(n, cell, mass, x, cell_mass, moment, list, count)
      integer, intent(in) :: n, cell(:)
      real(rp), intent(in) :: mass(:), x(n, *)
      real(rp), intent(inout) :: cell_mass(:), moment(n, *)
      integer, intent(inout) :: list(:), count
      integer :: i, c
      real(rp) :: running_mass, running_moment(n)
      c = cell(1)
      running_mass = 0.0_rp
      running_moment = 0.0_rp
      count = 1
      list(1) = c
      do i = 1, size(cell)
         if (cell(i) /= c) then
            cell_mass(c) = running_mass
            moment(:, c) = running_moment
            c = cell(i)
            running_mass = cell_mass(c)
            if (running_mass <= 0.0_rp) then      ! first visit: the moment is not cleared in memory
               count = count + 1
               list(count) = c
               running_moment = 0.0_rp
            else
               running_moment = moment(:, c)
            end if
         end if
         running_mass = running_mass + mass(i)
         running_moment = running_moment + mass(i) * x(:, i)
      end do
      cell_mass(c) = running_mass
      moment(:, c) = running_moment
   end subroutine mass_and_moment_sums

   !> The sums of bin_cell_mass_and_local_moments, and with `centre` of m_p x_p. A run's cell gives the lower
   !> corner (grid%cell_indices: its global indices, the lower node G2P's LOCATE finds for the particles in it),
   !> and xi = (x - origin) / h - lower as LOCATE computes it.
   subroutine mass_and_local_moment_sums(grid, cell, mass, x, cell_mass, moment, list, count, centre)
      type(grid_t), intent(in) :: grid
      integer, intent(in) :: cell(:)
      real(rp), intent(in) :: mass(:), x(3, *)
      real(rp), intent(inout) :: cell_mass(:), moment(6, *)
      integer, intent(inout) :: list(:), count
      real(rp), intent(inout), optional :: centre(3, *)
      integer :: i, c
      real(rp) :: running_mass, running_moment(6), running_centre(3), xi(3), origin(3), lower(3), inv_h
      origin = grid%origin
      inv_h = grid%inv_h
      c = 0
      running_mass = 0.0_rp
      running_moment = 0.0_rp
      running_centre = 0.0_rp
      lower = 0.0_rp
      count = 0
      do i = 1, size(cell)
         if (cell(i) /= c) then
            if (c > 0) then
               cell_mass(c) = running_mass
               moment(:, c) = running_moment
               if (present(centre)) centre(:, c) = running_centre
            end if
            c = cell(i)
            running_mass = cell_mass(c)
            if (running_mass <= 0.0_rp) then      ! first visit: the sums are not cleared in memory
               count = count + 1
               list(count) = c
               running_moment = 0.0_rp
               running_centre = 0.0_rp
            else
               running_moment = moment(:, c)
               if (present(centre)) running_centre = centre(:, c)
            end if
            lower = real(grid%cell_indices(c), rp)
         end if
         xi = (x(:, i) - origin) * inv_h - lower
         running_mass = running_mass + mass(i)
         running_moment = running_moment + mass(i) * [xi, xi(2) * xi(3), xi(1) * xi(3), xi(1) * xi(2)]
         if (present(centre)) running_centre = running_centre + mass(i) * x(:, i)
      end do
      cell_mass(c) = running_mass
      moment(:, c) = running_moment
      if (present(centre)) centre(:, c) = running_centre
   end subroutine mass_and_local_moment_sums

   !> replace_by_cell_average's pass. The sums are mass_weighted_sums', and a run of particles of one cell
   !> gets the quotient of divide_by_cell_mass as it ends (sum / m_c, while its values are in cache): the
   !> final average, unless the cell comes back in a later run (a particle that changed cell since the last
   !> full sort). Those later runs are noted, and once the sums are complete every run of their cells (its
   !> first and the noted ones) is written again. Where a cell has one run this saves cell_average's pass
   !> over the cells and the gather's pass over the particles.
   subroutine average_runs(n, occupied, cell, mass, cell_mass, values, sums)
      integer, intent(in) :: n, cell(:)
      type(cell_list_t), intent(inout) :: occupied
      real(rp), intent(in) :: mass(:), cell_mass(:)
      real(rp), intent(inout) :: values(n, *), sums(n, *)
      integer :: i, c, next, start, j, p, n_revisits, run
      real(rp) :: running(n), quotient(n)
      occupied%n_revisits = 0
      if (occupied%count == 0) return
      if (.not. allocated(occupied%revisits)) allocate (occupied%revisits(first_revisit_notes))
      n_revisits = 0
      c = cell(1)
      running = 0.0_rp
      next = 2
      start = 1
      occupied%first_run(c) = 1
      ! (the loop of mass_weighted_sums, with the run's quotient written where the run ends; no call in it: with
      ! one gcc kept the running sums in memory; the short write loop scalar: gcc had vectorised it over the
      ! particles with a division for each; the list tests nested, not mass_weighted_sums' first_visit flag,
      ! which made C0's stabilization phase 6-9 % slower here)
      do i = 1, size(cell)
         if (cell(i) /= c) then
            sums(:, c) = running
            quotient = running / merge(cell_mass(c), 1.0_rp, cell_mass(c) > 0.0_rp)
            !GCC$ novector
            do p = start, i - 1
               values(:, p) = quotient
            end do
            c = cell(i)
            start = i
            if (next <= occupied%count) then
               if (c == occupied%cells(next)) then
                  next = next + 1
                  occupied%first_run(c) = i
                  running = 0.0_rp
               else
                  n_revisits = n_revisits + 1
                  if (n_revisits <= size(occupied%revisits)) occupied%revisits(n_revisits) = i
                  running = sums(:, c)
               end if
            else
               n_revisits = n_revisits + 1
               if (n_revisits <= size(occupied%revisits)) occupied%revisits(n_revisits) = i
               running = sums(:, c)
            end if
         end if
         running = running + mass(i) * values(:, i)
      end do
      sums(:, c) = running
      quotient = running / merge(cell_mass(c), 1.0_rp, cell_mass(c) > 0.0_rp)
      do p = start, size(cell)
         values(:, p) = quotient
      end do
      occupied%n_revisits = n_revisits
      if (n_revisits > size(occupied%revisits)) then
         ! more than the notes hold: the averages gathered as cell_average and gather_cell_values do, and
         ! room for twice as many notes next time
         call divide_by_cell_mass(n, occupied, cell_mass, sums)
         call gather(n, cell, sums, values)
         deallocate (occupied%revisits)
         allocate (occupied%revisits(2 * n_revisits))
         return
      end if
      ! the cells that came back: their first run and every noted one get the final average (a first run
      ! twice where its cell came back twice)
      do j = 1, n_revisits
         c = cell(occupied%revisits(j))
         quotient = sums(:, c) / merge(cell_mass(c), 1.0_rp, cell_mass(c) > 0.0_rp)
         do run = 1, 2
            start = merge(occupied%first_run(c), occupied%revisits(j), run == 1)
            do p = start, size(cell)
               if (cell(p) /= c) exit
               values(:, p) = quotient
            end do
         end do
      end do
   end subroutine average_runs

   subroutine gather(n, cell, cell_values, values)
      integer, intent(in) :: n, cell(:)
      real(rp), intent(in) :: cell_values(n, *)
      real(rp), intent(inout) :: values(n, *)
      integer :: i
      ! one particle's n values in one vector load and store: vectorised over the particles instead, with
      ! gathers of 8 values and permutations, the loop took 7 % of a C0 step
      !GCC$ novector
      do i = 1, size(cell)
         values(:, i) = cell_values(:, cell(i))
      end do
   end subroutine gather
end module cell_binning
