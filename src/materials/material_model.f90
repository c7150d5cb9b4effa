!> Interface every constitutive model implements. A model updates the stress of a contiguous slice of
!> particles (the particles of one material after sorting), so the model is selected once per slice,
!> never by a branch per particle; the per-particle work is a pure point update in each model's module.
module material_model
   use kinds, only: rp, name_len
   implicit none
   private

   type, abstract, public :: material_model_t
      character(len=name_len) :: name = ''
      real(rp) :: reference_density = 0.0_rp
      logical :: is_fluid = .false.     !< counts towards the fluid volume and h_eq
      logical :: uses_spin = .false.    !< its update_stress reads the spin (else the step does not compute it)
   contains
      procedure(update_stress_interface), deferred :: update_stress
      procedure(wave_speed_interface), deferred :: wave_speed
   end type material_model_t

   abstract interface
      !> Advance density and mass-specific stress of a slice of particles over dt with the (filtered)
      !> rate of deformation d~ and spin w (algorithms.md section 1.2, step 5). The spin is computed
      !> only for a model with uses_spin; other models must not read it.
      subroutine update_stress_interface(self, dim, dt, strain_rate, spin, density, sbar)
         import :: material_model_t, rp
         class(material_model_t), intent(in) :: self
         integer, intent(in) :: dim
         real(rp), intent(in) :: dt
         real(rp), intent(in), contiguous :: strain_rate(:, :), spin(:, :)
         real(rp), intent(inout), contiguous :: density(:), sbar(:, :)
      end subroutine update_stress_interface

      !> Speed of the fastest wave at the given density [m/s] (time step, algorithms.md section 5.4).
      pure real(rp) function wave_speed_interface(self, density)
         import :: material_model_t, rp
         class(material_model_t), intent(in) :: self
         real(rp), intent(in) :: density
      end function wave_speed_interface
   end interface

   !> A polymorphic model in an array of materials.
   type, public :: material_slot_t
      class(material_model_t), allocatable :: model
   end type material_slot_t

   public :: volume_ratio_increment

contains

   !> det(I + dt d): ratio of new to old volume over one step (algorithms.md section 5.1).
   pure real(rp) function volume_ratio_increment(dim, dt, d)
      integer, intent(in) :: dim
      real(rp), intent(in) :: dt, d(:)
      real(rp) :: a11, a22, a33, a12, a13, a23
      a11 = 1.0_rp + dt * d(1)
      a22 = 1.0_rp + dt * d(2)
      if (dim == 2) then
         a12 = dt * d(4)
         volume_ratio_increment = a11 * a22 - a12 * a12
      else
         a33 = 1.0_rp + dt * d(3)
         a23 = dt * d(4); a13 = dt * d(5); a12 = dt * d(6)
         volume_ratio_increment = a11 * (a22 * a33 - a23 * a23) - a12 * (a12 * a33 - a23 * a13) &
                                  + a13 * (a12 * a23 - a22 * a13)
      end if
   end function volume_ratio_increment
end module material_model
