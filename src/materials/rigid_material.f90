!> A rigid solid (`&material model = 'rigid'`, docs/theory.md section 3.7): its particles move as one rigid
!> body of each `&body` (src/solver/rigid_bodies.f90), so the material itself has no stress and no waves.
!> Its particles keep sbar = 0 (they add no internal force to the grid: the fluid's and the walls' forces
!> on the body reach it through the nodal velocity increments) and their density (their volume is
!> constant). A wave speed of 0 takes the body out of the CFL step except through its velocity: the time
!> step no longer depends on a stiffness (issue 18).
module rigid_material
   use kinds, only: rp
   use material_model, only: material_model_t
   implicit none
   private

   type, extends(material_model_t), public :: rigid_material_t
   contains
      procedure :: update_stress => rigid_update_stress
      procedure :: wave_speed => rigid_wave_speed
   end type rigid_material_t

contains

   !> Nothing to update: a rigid body's particles carry no stress and keep their density.
   subroutine rigid_update_stress(self, dim, dt, strain_rate, spin, density, sbar)
      class(rigid_material_t), intent(in) :: self
      integer, intent(in) :: dim
      real(rp), intent(in) :: dt
      real(rp), intent(in), contiguous :: strain_rate(:, :), spin(:, :)
      real(rp), intent(inout), contiguous :: density(:), sbar(:, :)
      ! the interface's arguments are not needed: the particles keep their density and no stress
      if (dim < 0 .or. dt < 0.0_rp .or. size(strain_rate) < 0 .or. size(spin) < 0 .or. size(density) < 0) return
      if (size(sbar) > 0 .or. self%reference_density < 0.0_rp) sbar = 0.0_rp
   end subroutine rigid_update_stress

   !> No elastic waves: the body's speed alone enters the time step.
   pure real(rp) function rigid_wave_speed(self, density)
      class(rigid_material_t), intent(in) :: self
      real(rp), intent(in) :: density
      rigid_wave_speed = 0.0_rp
      ! (the interface's arguments are not needed)
      if (density < 0.0_rp .and. self%reference_density < 0.0_rp) rigid_wave_speed = 0.0_rp
   end function rigid_wave_speed
end module rigid_material
