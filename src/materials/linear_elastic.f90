!> Hypoelastic linear-elastic solid with the Jaumann stress rate (algorithms.md section 5.2):
!>   sigma^{n+1} = sigma^n + dt ( lambda tr(d) I + 2 G d + W sigma^n - sigma^n W ),
!>   rho^{n+1} = rho^n / det(I + dt d).
module linear_elastic
   use kinds, only: rp
   use tensor_layout, only: to_components, to_matrix
   use material_model, only: material_model_t, volume_ratio_increment
   implicit none
   private

   type, extends(material_model_t), public :: linear_elastic_t
      real(rp) :: lame_lambda = 0.0_rp   !< lambda = E nu / ((1 + nu)(1 - 2 nu)) [Pa]
      real(rp) :: shear_modulus = 0.0_rp !< G = E / (2 (1 + nu)) [Pa]
   contains
      procedure :: set_from_young_poisson => elastic_set_from_young_poisson
      procedure :: update_stress => elastic_update_stress
      procedure :: wave_speed => elastic_wave_speed
   end type linear_elastic_t

   public :: elastic_point_update, spin_matrix

contains

   subroutine elastic_set_from_young_poisson(self, youngs_modulus, poisson_ratio)
      class(linear_elastic_t), intent(inout) :: self
      real(rp), intent(in) :: youngs_modulus, poisson_ratio
      self%shear_modulus = youngs_modulus / (2.0_rp * (1.0_rp + poisson_ratio))
      self%lame_lambda = youngs_modulus * poisson_ratio / ((1.0_rp + poisson_ratio) * (1.0_rp - 2.0_rp * poisson_ratio))
   end subroutine elastic_set_from_young_poisson

   subroutine elastic_update_stress(self, dim, dt, strain_rate, spin, density, sbar)
      class(linear_elastic_t), intent(in) :: self
      integer, intent(in) :: dim
      real(rp), intent(in) :: dt
      real(rp), intent(in), contiguous :: strain_rate(:, :), spin(:, :)
      real(rp), intent(inout), contiguous :: density(:), sbar(:, :)
      integer :: p
      do p = 1, size(density)
         call elastic_point_update(self%lame_lambda, self%shear_modulus, dim, dt, strain_rate(:, p), spin(:, p), &
                                   density(p), sbar(:, p))
      end do
   end subroutine elastic_update_stress

   !> One particle: Jaumann-rate update of sigma = rho sbar, then sbar = sigma / rho^{n+1}.
   pure subroutine elastic_point_update(lame_lambda, shear_modulus, dim, dt, d, w, density, sbar)
      real(rp), intent(in) :: lame_lambda, shear_modulus, dt, d(:), w(:)
      integer, intent(in) :: dim
      real(rp), intent(inout) :: density, sbar(:)
      real(rp) :: sigma(3, 3), rate(3, 3), spin(3, 3), new_density
      integer :: k
      sigma = density * to_matrix(sbar, dim)
      spin = spin_matrix(w, dim)
      rate = 2.0_rp * shear_modulus * to_matrix(d, dim) + matmul(spin, sigma) - matmul(sigma, spin)
      do k = 1, 3
         rate(k, k) = rate(k, k) + lame_lambda * (d(1) + d(2) + d(3))
      end do
      sigma = sigma + dt * rate
      new_density = density / volume_ratio_increment(dim, dt, d)
      sbar = to_components(sigma, dim) / new_density
      density = new_density
   end subroutine elastic_point_update

   !> Skew spin matrix W = (L - L^T)/2 from its stored components (2-D: w_xy; 3-D: w_yz, w_xz, w_xy).
   pure function spin_matrix(w, dim) result(spin)
      real(rp), intent(in) :: w(:)
      integer, intent(in) :: dim
      real(rp) :: spin(3, 3)
      spin = 0.0_rp
      if (dim == 2) then
         spin(1, 2) = w(1)
      else
         spin(2, 3) = w(1)
         spin(1, 3) = w(2)
         spin(1, 2) = w(3)
      end if
      spin(2, 1) = -spin(1, 2)
      spin(3, 1) = -spin(1, 3)
      spin(3, 2) = -spin(2, 3)
   end function spin_matrix

   !> P-wave speed sqrt((lambda + 2 G) / rho).
   pure real(rp) function elastic_wave_speed(self, density)
      class(linear_elastic_t), intent(in) :: self
      real(rp), intent(in) :: density
      elastic_wave_speed = sqrt((self%lame_lambda + 2.0_rp * self%shear_modulus) / density)
   end function elastic_wave_speed
end module linear_elastic
