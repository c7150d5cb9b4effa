!> Cell-based anti-locking C0 of Mast et al. (2012) as used in [Y17] (algorithms.md section 2.2).
!>
!> Per material and cell, with masses as weights (the rho-weighted projections of eq. 1):
!>   d~_c = sum m_p d_p / m_c   -> d_p := d~_c        (before the constitutive update)
!>   s~_c = sum m_p s_p / m_c   -> s_p := s~_c        (after it; s = sigma / rho, eq. 4)
!> Full tensors by default [P]. Option volumetric_only [R] (B-bar-like, section 2.5): only the
!> volumetric rate (tr d shared over the dim in-plane normal components, so d_zz stays 0 in plane
!> strain) and the mean specific stress are averaged; the particle keeps its deviatoric parts.
!> The spin is never filtered [R].
!> Full tensors and context%rate_from_grid (set by the solver where it holds: multilinear shape functions,
!> MUSL, a material in no &contact, a model without spin): d~_c comes from the nodal velocities per cell
!> (cell_strain_rate), G2P forms no rates of deformation, and `prepare` bins the cells' local moments.
module c0_anti_locking
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use stabilizer, only: stabilizer_t, stage_context_t
   use background_grid, only: grid_t
   use cell_binning, only: cell_list_t, start_cell_list, bin_cell_mass, bin_cell_mass_and_centre, &
                           bin_cell_mass_and_local_moments, replace_by_cell_average, gather_cell_values
   use cell_strain_rate, only: cell_rates_from_nodes
   implicit none
   private

   type, extends(stabilizer_t), public :: c0_anti_locking_t
      logical :: volumetric_only = .false.
      type(cell_list_t) :: occupied              !< the owned cells holding the material at x^n
      real(rp), allocatable :: cell_mass(:)      !< m_c of the owned cells (this material; 0 where unlisted)
      real(rp), allocatable :: average(:, :)     !< work: cell averages (kept between steps)
      !> with the rate from the grid: the cells' mass centres (2-D) or local moments (3-D) (cell_strain_rate)
      real(rp), allocatable :: means(:, :)
   contains
      procedure :: takes_rate_from_grid
      procedure :: rates_of_particles
      procedure :: prepare => c0_prepare
      procedure :: size_means => c0_size_means
      procedure :: rates_from_grid
      procedure :: size_cell_arrays => c0_size_cell_arrays
      procedure :: filter_strain_rate => c0_filter_strain_rate
      procedure :: filter_stress => c0_filter_stress
   end type c0_anti_locking_t

contains

   !> The full-tensor average of d_p is sym(sum_i v_i (x) Gbar_i) (cell_strain_rate); the volumetric one is not.
   pure logical function takes_rate_from_grid(self)
      class(c0_anti_locking_t), intent(in) :: self
      takes_rate_from_grid = .not. self%volumetric_only
   end function takes_rate_from_grid

   !> With the rate from the grid: the filtered rates of deformation of the slice's particles b..e into
   !> rates(:, 1:e - b + 1), their cells' d~_c. The solver's stress update takes them block by block, so
   !> that no particle array holds them (filter_strain_rate leaves them per cell).
   subroutine rates_of_particles(self, particles, b, e, rates)
      class(c0_anti_locking_t), intent(in) :: self
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: b, e
      real(rp), intent(inout) :: rates(:, :)
      call gather_cell_values(particles%cell(b:e), self%average, rates(:, 1:e - b + 1))
   end subroutine rates_of_particles

   !> Cell masses at x^n (and the means the rate from the grid needs).
   subroutine c0_prepare(self, context, particles)
      class(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call self%size_cell_arrays(context%grid%cell_count, particles%n_sigma)
      if (.not. context%rate_from_grid) then
         call bin_cell_mass(particles, context%first, context%last, self%occupied, self%cell_mass)
      else
         call self%size_means(context%grid)
         if (context%grid%dim == 2) then
            call bin_cell_mass_and_centre(particles, context%first, context%last, self%occupied, self%cell_mass, &
                                          self%means)
         else
            call bin_cell_mass_and_local_moments(context%grid, particles, context%first, context%last, self%occupied, &
                                                 self%cell_mass, self%means)
         end if
      end if
   end subroutine c0_prepare

   !> (Re)allocate the cell means for the grid's cells: the mass centre in 2-D, 6 local moments in 3-D.
   subroutine c0_size_means(self, grid)
      class(c0_anti_locking_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      integer :: rows
      rows = merge(2, 6, grid%dim == 2)
      if (allocated(self%means)) then
         if (size(self%means, 2) == grid%cell_count .and. size(self%means, 1) == rows) return
         deallocate (self%means)
      end if
      allocate (self%means(rows, grid%cell_count))
   end subroutine c0_size_means

   !> d~_c of the listed cells from the nodal velocities and the cells' means (cell_strain_rate), into
   !> self%average, where rates_of_particles reads them.
   subroutine rates_from_grid(self, context, means)
      class(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      real(rp), intent(in), contiguous :: means(:, :)
      call cell_rates_from_nodes(context%grid, self%occupied, self%cell_mass, means, context%strain_velocity, &
                                 self%average)
   end subroutine rates_from_grid

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
   !> With the rate from the grid, d~_c of every listed cell, kept per cell (rates_of_particles).
   subroutine c0_filter_strain_rate(self, context, particles)
      class(c0_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      if (context%rate_from_grid) then
         call self%rates_from_grid(context, self%means)
      else
         call filter_slice(self, context, particles, particles%strain_rate, context%grid%dim)
      end if
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
