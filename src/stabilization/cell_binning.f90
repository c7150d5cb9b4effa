!> Mass-weighted cell sums of one material's particles, the building block of C0 and FOAL1
!> ([Y17] eq. 4): m_c = sum m_p, x_o^c = sum m_p x_p / m_c, q_c = sum m_p q_p / m_c.
!> Particles are binned by particles%cell, their cell at x^n.
!>
!> The per-particle loops are memory-bound passes over the slice. Their kernels take the number of
!> values per particle as an argument and are called with a literal (2, 3, 4, 6) for the sizes that
!> occur, so the compiler specialises them: a section of unknown length per particle became a library
!> memcpy call per particle (measured: the C0 gather took three times as long as the sums).
module cell_binning
   use kinds, only: rp
   use particle_set, only: particle_set_t
   implicit none
   private

   public :: occupied_cells, bin_cell_mass, bin_cell_mass_and_centre, cell_average, replace_by_cell_average
   public :: divide_by_cell_mass, gather_cell_values

contains

   !> Lowest and highest cell of the particles first..last ([1, 0] if there are none). The routines below
   !> write the cells of this range only (half the grid is air in a tank); cells outside it keep stale
   !> values and must not be read.
   pure function occupied_cells(particles, first, last) result(occupied)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      integer :: occupied(2)
      occupied = [1, 0]
      if (last < first) return
      occupied = [minval(particles%cell(first:last)), maxval(particles%cell(first:last))]
   end function occupied_cells

   !> m_c of the cells holding particles first..last.
   subroutine bin_cell_mass(particles, first, last, occupied, cell_mass)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, occupied(2)
      real(rp), intent(inout) :: cell_mass(:)
      if (last < first) return
      cell_mass(occupied(1):occupied(2)) = 0.0_rp
      call mass_sums(particles%cell(first:last), particles%mass(first:last), cell_mass)
   end subroutine bin_cell_mass

   !> m_c and the mass centre x_o^c (where m_c > 0) of the particles first..last, in one pass.
   subroutine bin_cell_mass_and_centre(particles, first, last, occupied, cell_mass, centre)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, occupied(2)
      real(rp), intent(inout) :: cell_mass(:), centre(:, :)
      if (last < first) return
      cell_mass(occupied(1):occupied(2)) = 0.0_rp
      centre(:, occupied(1):occupied(2)) = 0.0_rp
      select case (size(centre, 1))
      case (2)
         call mass_and_moment_sums(2, particles%cell(first:last), particles%mass(first:last), particles%x(:, first:last), &
                                   cell_mass, centre)
         call divide_by_cell_mass(2, occupied, cell_mass, centre)
      case default
         call mass_and_moment_sums(3, particles%cell(first:last), particles%mass(first:last), particles%x(:, first:last), &
                                   cell_mass, centre)
         call divide_by_cell_mass(3, occupied, cell_mass, centre)
      end select
   end subroutine bin_cell_mass_and_centre

   !> average(:, c) = sum m_p values(:, p) / m_c over the particles first..last; values(:, p - first + 1)
   !> belongs to particle p. Empty cells of the occupied range get 0. `average` is read as (n, cells) with
   !> n = size(values, 1) (it may be a larger work array).
   subroutine cell_average(particles, first, last, occupied, cell_mass, values, average)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, occupied(2)
      real(rp), intent(in) :: cell_mass(:), values(:, :)
      real(rp), intent(inout) :: average(:, :)
      integer :: n
      n = size(values, 1)
      if (last < first) return
      associate (cell => particles%cell(first:last), mass => particles%mass(first:last))
         select case (n)
         case (4)
            call mass_weighted_sums(4, occupied, cell, mass, values, average)
         case (6)
            call mass_weighted_sums(6, occupied, cell, mass, values, average)
         case default
            call mass_weighted_sums(n, occupied, cell, mass, values, average)
         end select
      end associate
      call divide_by_cell_mass(n, occupied, cell_mass, average)
   end subroutine cell_average

   !> Replace values(:, p) of particles first..last by the average of their cell (C0: "replace, not
   !> increment" [P]+[D], algorithms.md section 2.2).
   !> `average` is work space of at least size(values, 1) * size(cell_mass) values.
   subroutine replace_by_cell_average(particles, first, last, occupied, cell_mass, values, average)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, occupied(2)
      real(rp), intent(in) :: cell_mass(:)
      real(rp), intent(inout) :: values(:, :)
      real(rp), intent(inout) :: average(:, :)
      call cell_average(particles, first, last, occupied, cell_mass, values, average)
      call gather_cell_values(particles%cell(first:last), average, values)
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

   !> sums(:, c) := sums(:, c) / m_c where m_c > 0, for the occupied cells.
   subroutine divide_by_cell_mass(n, occupied, cell_mass, sums)
      integer, intent(in) :: n, occupied(2)
      real(rp), intent(in) :: cell_mass(:)
      real(rp), intent(inout) :: sums(n, *)
      integer :: c
      do c = occupied(1), occupied(2)
         if (cell_mass(c) > 0.0_rp) sums(:, c) = sums(:, c) / cell_mass(c)
      end do
   end subroutine divide_by_cell_mass

   ! --- kernels: n is a literal at every call that matters (see the module header). The particles are
   ! sorted by cell (nearly, between two full sorts), so a sum is kept in registers along a run of equal
   ! cells and stored once per run; a cell met again later continues from its stored sum. These are the
   ! same additions in the same order as summing in memory particle by particle, without a store-to-load
   ! round trip per particle on the dependency chain (measured: half the time of the plain loop). ---

   subroutine mass_sums(cell, mass, cell_mass)
      integer, intent(in) :: cell(:)
      real(rp), intent(in) :: mass(:)
      real(rp), intent(inout) :: cell_mass(:)
      integer :: i, c
      real(rp) :: running_mass
      c = cell(1)
      running_mass = cell_mass(c)
      do i = 1, size(cell)
         if (cell(i) /= c) then
            cell_mass(c) = running_mass
            c = cell(i)
            running_mass = cell_mass(c)
         end if
         running_mass = running_mass + mass(i)
      end do
      cell_mass(c) = running_mass
   end subroutine mass_sums

   subroutine mass_weighted_sums(n, occupied, cell, mass, values, sums)
      integer, intent(in) :: n, occupied(2), cell(:)
      real(rp), intent(in) :: mass(:), values(n, *)
      real(rp), intent(inout) :: sums(n, *)
      integer :: i, c
      real(rp) :: running(n)
      sums(:, occupied(1):occupied(2)) = 0.0_rp
      c = cell(1)
      running = sums(:, c)
      do i = 1, size(cell)
         if (cell(i) /= c) then
            sums(:, c) = running
            c = cell(i)
            running = sums(:, c)
         end if
         running = running + mass(i) * values(:, i)
      end do
      sums(:, c) = running
   end subroutine mass_weighted_sums

   subroutine mass_and_moment_sums(n, cell, mass, x, cell_mass, moment)
      integer, intent(in) :: n, cell(:)
      real(rp), intent(in) :: mass(:), x(n, *)
      real(rp), intent(inout) :: cell_mass(:), moment(n, *)
      integer :: i, c
      real(rp) :: running_mass, running_moment(n)
      c = cell(1)
      running_mass = cell_mass(c)
      running_moment = moment(:, c)
      do i = 1, size(cell)
         if (cell(i) /= c) then
            cell_mass(c) = running_mass
            moment(:, c) = running_moment
            c = cell(i)
            running_mass = cell_mass(c)
            running_moment = moment(:, c)
         end if
         running_mass = running_mass + mass(i)
         running_moment = running_moment + mass(i) * x(:, i)
      end do
      cell_mass(c) = running_mass
      moment(:, c) = running_moment
   end subroutine mass_and_moment_sums

   subroutine gather(n, cell, cell_values, values)
      integer, intent(in) :: n, cell(:)
      real(rp), intent(in) :: cell_values(n, *)
      real(rp), intent(inout) :: values(n, *)
      integer :: i
      do i = 1, size(cell)
         values(:, i) = cell_values(:, cell(i))
      end do
   end subroutine gather
end module cell_binning
