!> Weakly compressible Newtonian fluid in rate form (algorithms.md section 5.1):
!>   p^{n+1} = p^n - K tr(d~) dt,   sigma = -p^{n+1} I + 2 mu dev(d~),   rho^{n+1} = rho^n / det(I + dt d~).
!> The pressure is integrated, not recomputed from J, so that a smoothed stress persists [D].
module newtonian_fluid
   use kinds, only: rp
   use material_model, only: material_model_t, volume_ratio_increment
   implicit none
   private

   type, extends(material_model_t), public :: newtonian_fluid_t
      real(rp) :: bulk_modulus = 0.0_rp   !< K [Pa]
      real(rp) :: viscosity = 0.0_rp      !< mu [Pa s]
   contains
      procedure :: update_stress => fluid_update_stress
      procedure :: wave_speed => fluid_wave_speed
   end type newtonian_fluid_t

   public :: fluid_point_update, eos_pressure, eos_density

contains

   subroutine fluid_update_stress(self, dim, dt, strain_rate, spin, density, sbar)
      class(newtonian_fluid_t), intent(in) :: self
      integer, intent(in) :: dim
      real(rp), intent(in) :: dt
      real(rp), intent(in), contiguous :: strain_rate(:, :), spin(:, :)
      real(rp), intent(inout), contiguous :: density(:), sbar(:, :)
      integer :: p
      ! The spin is not used: the pressure is isotropic and the viscous stress is recomputed from d~
      ! every step, so neither has a Jaumann rotation term.
      if (size(spin) < 0) return
      if (self%viscosity > 0.0_rp) then
         call viscous_update(self%bulk_modulus, self%viscosity, dim, dt, strain_rate, density, sbar)
      else
         do p = 1, size(density)
            call inviscid_point_update(self%bulk_modulus, dim, dt, strain_rate(:, p), density(p), sbar(:, p))
         end do
      end if
   end subroutine fluid_update_stress

   !> One particle: update density and mass-specific stress sbar = sigma / rho.
   pure subroutine fluid_point_update(bulk_modulus, viscosity, dim, dt, d, density, sbar)
      real(rp), intent(in) :: bulk_modulus, viscosity, dt, d(:)
      integer, intent(in) :: dim
      real(rp), intent(inout) :: density, sbar(:)
      real(rp) :: pressure, trace_d, new_density, two_mu
      integer :: n_normal
      pressure = -density * (sbar(1) + sbar(2) + sbar(3)) / 3.0_rp
      trace_d = d(1) + d(2) + d(3)
      pressure = pressure - bulk_modulus * trace_d * dt
      new_density = density / volume_ratio_increment(dim, dt, d)
      two_mu = 2.0_rp * viscosity
      n_normal = 3
      sbar(1:n_normal) = (-pressure + two_mu * (d(1:n_normal) - trace_d / 3.0_rp)) / new_density
      sbar(n_normal + 1:) = two_mu * d(n_normal + 1:) / new_density
      density = new_density
   end subroutine fluid_point_update

   !> fluid_point_update for every particle, bit for bit, with its components written out (2-D: xx, yy,
   !> zz, xy; 3-D: xx, yy, zz, yz, xz, xy): a loop over the particles without inner loops, which the
   !> compiler vectorises (five divisions per particle; the per-particle calls were 17 % of a 2-D step's
   !> time, docs/performance-history.md, "Vectorised passes outside the transfers").
   pure subroutine viscous_update(bulk_modulus, viscosity, dim, dt, d, density, sbar)
      real(rp), intent(in) :: bulk_modulus, viscosity, dt
      real(rp), intent(in), contiguous :: d(:, :)
      integer, intent(in) :: dim
      real(rp), intent(inout), contiguous :: density(:), sbar(:, :)
      real(rp) :: pressure, trace_d, new_density, two_mu
      integer :: p
      two_mu = 2.0_rp * viscosity
      ! one loop per dimension: a branch on dim inside would keep the compiler from vectorising
      if (dim == 2) then
         do p = 1, size(density)
            pressure = -density(p) * (sbar(1, p) + sbar(2, p) + sbar(3, p)) / 3.0_rp
            trace_d = d(1, p) + d(2, p) + d(3, p)
            pressure = pressure - bulk_modulus * trace_d * dt
            new_density = density(p) / volume_ratio_increment(2, dt, d(:, p))
            sbar(1, p) = (-pressure + two_mu * (d(1, p) - trace_d / 3.0_rp)) / new_density
            sbar(2, p) = (-pressure + two_mu * (d(2, p) - trace_d / 3.0_rp)) / new_density
            sbar(3, p) = (-pressure + two_mu * (d(3, p) - trace_d / 3.0_rp)) / new_density
            sbar(4, p) = two_mu * d(4, p) / new_density
            density(p) = new_density
         end do
      else
         do p = 1, size(density)
            pressure = -density(p) * (sbar(1, p) + sbar(2, p) + sbar(3, p)) / 3.0_rp
            trace_d = d(1, p) + d(2, p) + d(3, p)
            pressure = pressure - bulk_modulus * trace_d * dt
            new_density = density(p) / volume_ratio_increment(3, dt, d(:, p))
            sbar(1, p) = (-pressure + two_mu * (d(1, p) - trace_d / 3.0_rp)) / new_density
            sbar(2, p) = (-pressure + two_mu * (d(2, p) - trace_d / 3.0_rp)) / new_density
            sbar(3, p) = (-pressure + two_mu * (d(3, p) - trace_d / 3.0_rp)) / new_density
            sbar(4, p) = two_mu * d(4, p) / new_density
            sbar(5, p) = two_mu * d(5, p) / new_density
            sbar(6, p) = two_mu * d(6, p) / new_density
            density(p) = new_density
         end do
      end if
   end subroutine viscous_update

   !> fluid_point_update with viscosity 0, bit for bit, without the viscous terms: -p + 0 dev(d) is -p
   !> unless p = 0 (then the zero's sign is dev(d)'s), and 0 d / rho is a zero with the sign of d.
   !> One division for the normal components instead of three, none for the shear.
   pure subroutine inviscid_point_update(bulk_modulus, dim, dt, d, density, sbar)
      real(rp), intent(in) :: bulk_modulus, dt, d(:)
      integer, intent(in) :: dim
      real(rp), intent(inout) :: density, sbar(:)
      real(rp) :: pressure, trace_d, new_density, normal
      pressure = -density * (sbar(1) + sbar(2) + sbar(3)) / 3.0_rp
      trace_d = d(1) + d(2) + d(3)
      pressure = pressure - bulk_modulus * trace_d * dt
      new_density = density / volume_ratio_increment(dim, dt, d)
      if (abs(pressure) > 0.0_rp) then
         normal = -pressure / new_density
         sbar(1:3) = normal
      else
         sbar(1:3) = (-pressure + 0.0_rp * (d(1:3) - trace_d / 3.0_rp)) / new_density
      end if
      sbar(4:) = sign(0.0_rp, d(4:))
      density = new_density
   end subroutine inviscid_point_update

   pure real(rp) function fluid_wave_speed(self, density)
      class(newtonian_fluid_t), intent(in) :: self
      real(rp), intent(in) :: density
      fluid_wave_speed = sqrt(self%bulk_modulus / density)
   end function fluid_wave_speed

   !> The equation of state the rate form integrates, p = K ln(rho/rho_0) (dp = -K tr(d) dt, d(ln rho) =
   !> -tr(d) dt). The code keeps p and rho apart (smoothing acts on the stress); the volume correction
   !> 'eos_relaxation' pulls p back toward this value (docs/volume-conservation.md).
   pure real(rp) function eos_pressure(reference_density, bulk_modulus, density) result(pressure)
      real(rp), intent(in) :: reference_density, bulk_modulus, density
      pressure = bulk_modulus * log(density / reference_density)
   end function eos_pressure

   !> Density of the EOS state at pressure p: rho_0 exp(p/K).
   pure real(rp) function eos_density(reference_density, bulk_modulus, pressure) result(density)
      real(rp), intent(in) :: reference_density, bulk_modulus, pressure
      density = reference_density * exp(pressure / bulk_modulus)
   end function eos_density
end module newtonian_fluid
