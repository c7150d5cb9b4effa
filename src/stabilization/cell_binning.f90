!> Mass-weighted cell sums of one material's particles, the building block of C0 and FOAL1
!> ([Y17] eq. 4): m_c = sum m_p, x_o^c = sum m_p x_p / m_c, q_c = sum m_p q_p / m_c.
!> Particles are binned by particles%cell, their cell at x^n.
module cell_binning
   use kinds, only: rp
   use particle_set, only: particle_set_t
   implicit none
   private

   public :: bin_cell_mass, bin_cell_mass_and_centre, cell_average, replace_by_cell_average

contains

   !> m_c of the cells holding particles first..last.
   subroutine bin_cell_mass(particles, first, last, cell_mass)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(out) :: cell_mass(:)
      integer :: p
      cell_mass = 0.0_rp
      do p = first, last
         cell_mass(particles%cell(p)) = cell_mass(particles%cell(p)) + particles%mass(p)
      end do
   end subroutine bin_cell_mass

   !> m_c and the mass centre x_o^c (where m_c > 0) of the particles first..last, in one pass.
   subroutine bin_cell_mass_and_centre(particles, first, last, cell_mass, centre)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(out) :: cell_mass(:), centre(:, :)
      integer :: p, c, k
      cell_mass = 0.0_rp
      centre = 0.0_rp
      do p = first, last
         c = particles%cell(p)
         cell_mass(c) = cell_mass(c) + particles%mass(p)
         do k = 1, size(centre, 1)
            centre(k, c) = centre(k, c) + particles%mass(p) * particles%x(k, p)
         end do
      end do
      do c = 1, size(cell_mass)
         if (cell_mass(c) > 0.0_rp) centre(:, c) = centre(:, c) / cell_mass(c)
      end do
   end subroutine bin_cell_mass_and_centre

   !> average(:, c) = sum m_p values(:, p) / m_c over the particles first..last; values(:, p - first + 1)
   !> belongs to particle p. Cells without particles get 0.
   subroutine cell_average(particles, first, last, cell_mass, values, average)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(in) :: cell_mass(:), values(:, :)
      real(rp), intent(inout) :: average(:, :)
      integer :: p, c
      average(:, 1:size(cell_mass)) = 0.0_rp
      do p = first, last
         c = particles%cell(p)
         average(:, c) = average(:, c) + particles%mass(p) * values(:, p - first + 1)
      end do
      do c = 1, size(cell_mass)
         if (cell_mass(c) > 0.0_rp) average(:, c) = average(:, c) / cell_mass(c)
      end do
   end subroutine cell_average

   !> Replace values(:, p) of particles first..last by the average of their cell (C0: "replace, not
   !> increment" [P]+[D], algorithms.md section 2.2).
   !> `average` is work space of at least (size(values, 1), size(cell_mass)).
   subroutine replace_by_cell_average(particles, first, last, cell_mass, values, average)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(in) :: cell_mass(:)
      real(rp), intent(inout) :: values(:, :)
      real(rp), intent(inout) :: average(:, :)
      integer :: p
      call cell_average(particles, first, last, cell_mass, values, average)
      do p = first, last
         values(:, p - first + 1) = average(:, particles%cell(p))
      end do
   end subroutine replace_by_cell_average
end module cell_binning
