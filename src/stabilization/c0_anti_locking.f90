!> Cell-based anti-locking C0 of Mast et al. (2012) as used in [Y17] (algorithms.md section 2.2).
!>
!> Per material and cell, with masses as weights (the rho-weighted projections of eq. 1):
!>   d~_c = sum m_p d_p / m_c   -> d_p := d~_c        (before the constitutive update)
!>   s~_c = sum m_p s_p / m_c   -> s_p := s~_c        (after it; s = sigma / rho, eq. 4)
!> Full tensors by default [P]. Option volumetric_only [R] (B-bar-like, section 2.5): only the
!> volumetric rate (tr d shared over the dim in-plane normal components, so d_zz stays 0 in plane
!> strain) and the mean specific stress are averaged; the particle keeps its deviatoric parts.
!> The spin is never filtered [R].
module c0_anti_locking
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use stabilizer, only: stabilizer_t, stage_context_t
   use cell_binning, only: cell_list_t, start_cell_list, bin_cell_mass, replace_by_cell_average
   implicit none
   private

   type, extends(stabilizer_t), public :: c0_anti_locking_t
      logical :: volumetric_only = .false.
      type(cell_list_t) :: occupied              !< the owned cells holding the material at x^n
      real(rp), allocatable :: cell_mass(:)      !< m_c of the owned cells (this material; 0 where unlisted)
      real(rp), allocatable :: average(:, :)     !< work: cell averages (kept between steps)
   contains
      procedure :: prepare => c0_prepare
      procedure :: size_cell_arrays => c0_size_cell_arrays
      procedure :: filter_strain_rate => c0_filter_strain_rate
      procedure :: filter_stress => c0_filter_stress
   end type c0_anti_locking_t

contains

   !> Cell masses at x^n.
   subroutine c0_prepare(self, context, particles)
      class(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call self%size_cell_arrays(context%grid%cell_count, particles%n_sigma)
      call bin_cell_mass(particles, context%first, context%last, self%occupied, self%cell_mass)
   end subroutine c0_prepare

   !> (Re)allocate the per-cell arrays when the rank's cells change.
   subroutine c0_size_cell_arrays(self, cell_count, n_sigma)
      class(c0_anti_locking_t), intent(inout) :: self
      integer, intent(in) :: cell_count, n_sigma
      if (allocated(self%cell_mass)) then
         if (size(self%cell_mass) == cell_count) return
         deallocate (self%cell_mass, self%average)
      end if
      allocate (self%cell_mass(cell_count), self%average(n_sigma, cell_count))
      call start_cell_list(cell_count, self%occupied, self%cell_mass)
   end subroutine c0_size_cell_arrays

   !> Filter part A: d_p := d~_c ([Y17] eq. 4, left). Volumetric part: the dim in-plane normal components.
   subroutine c0_filter_strain_rate(self, context, particles)
      class(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call filter_slice(self, context, particles, particles%strain_rate, context%grid%dim)
   end subroutine c0_filter_strain_rate

   !> Filter part B: s_p := s~_c ([Y17] eq. 4, right). Volumetric part: the mean of the 3 normal components.
   subroutine c0_filter_stress(self, context, particles)
      class(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call filter_slice(self, context, particles, particles%sbar, 3)
   end subroutine c0_filter_stress

   !> Replace the tensors of the material's slice by their cell average (or only their volumetric part,
   !> the mean of the first n_normal components, with volumetric_only).
   subroutine filter_slice(self, context, particles, tensors, n_normal)
      type(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(inout) :: tensors(:, :)
      integer, intent(in) :: n_normal
      integer :: first, last
      first = context%first
      last = context%last
      if (last < first) return
      if (self%volumetric_only) then
         call replace_volumetric_part(self, particles, first, last, tensors(:, first:last), n_normal)
      else
         call replace_by_cell_average(particles, first, last, self%occupied, self%cell_mass, tensors(:, first:last), &
                                      self%average)
      end if
   end subroutine filter_slice

   !> Replace the mean of the first n_normal normal components by its cell average:
   !> t_p(k) += (mean_c - mean_p) for k = 1..n_normal.
   subroutine replace_volumetric_part(self, particles, first, last, tensors, n_normal)
      type(c0_anti_locking_t), intent(inout) :: self
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, n_normal
      real(rp), intent(inout) :: tensors(:, :)
      real(rp), allocatable :: mean(:, :)
      integer :: p
      allocate (mean(1, last - first + 1))
      do p = 1, last - first + 1
         mean(1, p) = sum(tensors(1:n_normal, p)) / n_normal
      end do
      call replace_by_cell_average(particles, first, last, self%occupied, self%cell_mass, mean, self%average)
      do p = 1, last - first + 1
         tensors(1:n_normal, p) = tensors(1:n_normal, p) - sum(tensors(1:n_normal, p)) / n_normal + mean(1, p)
      end do
   end subroutine replace_volumetric_part
end module c0_anti_locking
