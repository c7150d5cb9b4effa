!> The scene's damping zones (`&damping_zone`, docs/theory.md section 3.9): boxes in which the velocity of
!> every fluid particle relaxes toward a target after G2P,
!>     v_p <- v_t + (v_p - v_t) exp(-r(s) dt),   r(s) = rate s^2,
!> s in [0, 1] the particle's place along the zone's ramp (0 at its inner face, 1 at its outer one; 1
!> everywhere with ramp = 'none'). The factor is exact for the relaxation dv/dt = -r (v - v_t) over the
!> step, so the damping is a rate per unit time and stable at any rate and step; the quadratic ramp starts
!> with zero slope, so the zone's inner face reflects little of a wave entering it. Solids (debris) pass
!> undamped. The next P2G maps the damped momentum: the grid and the loads see it from the next step on.
module damping_zone
   use kinds, only: rp
   use scene_description, only: scene_t, damping_zone_spec_t, model_newtonian_fluid
   use step_component, only: step_component_t, step_state_t
   implicit none
   private

   public :: damping_factor, ramp_place

   type, extends(step_component_t), public :: damping_zones_t
      type(damping_zone_spec_t), allocatable :: zones(:)   !< world frame, as the scene gives them
      logical, allocatable :: fluid(:)                     !< per material: damped
   contains
      procedure :: init => zones_init
      procedure :: particles_moved => zones_damp
   end type damping_zones_t

contains

   !> The zones and which materials they damp (the fluids).
   subroutine zones_init(self, scene)
      class(damping_zones_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      integer :: m
      self%zones = scene%damping_zones
      allocate (self%fluid(size(scene%materials)))
      do m = 1, size(scene%materials)
         self%fluid(m) = scene%materials(m)%model == model_newtonian_fluid
      end do
   end subroutine zones_init

   !> Where the world point x lies along the zone's ramp: s in [0, 1] inside the box, -1 outside it.
   pure real(rp) function ramp_place(zone, x, dim) result(s)
      type(damping_zone_spec_t), intent(in) :: zone
      real(rp), intent(in) :: x(:)
      integer, intent(in) :: dim
      integer :: axis
      s = -1.0_rp
      if (any(x(1:dim) < zone%lower(1:dim)) .or. any(x(1:dim) > zone%upper(1:dim))) return
      if (zone%ramp == 'none') then
         s = 1.0_rp
         return
      end if
      axis = index('xyz', zone%ramp(1:1))
      s = (x(axis) - zone%lower(axis)) / (zone%upper(axis) - zone%lower(axis))
      if (zone%ramp(2:2) == '-') s = 1.0_rp - s
   end function ramp_place

   !> The factor exp(-rate s^2 dt) by which v - v_t shrinks over a step dt at ramp place s.
   pure real(rp) function damping_factor(rate, s, dt) result(factor)
      real(rp), intent(in) :: rate, s, dt
      factor = exp(-rate * s * s * dt)
   end function damping_factor

   !> After G2P: each fluid particle inside a zone relaxes toward the zone's target (the first zone that
   !> holds it; zones are not meant to overlap). Positions are not moved: the extent stays.
   subroutine zones_damp(self, state, extent)
      class(damping_zones_t), intent(inout) :: self
      type(step_state_t), intent(inout) :: state
      real(rp), intent(inout) :: extent(3, 2)
      real(rp) :: world(3), target(3, size(self%zones)), s, factor
      integer :: p, z, dim
      dim = state%grid%dim
      associate (particles => state%particles, frame => state%grid%frame)
         ! the targets in the grid frame, once per step
         do z = 1, size(self%zones)
            target(1:dim, z) = frame%grid_vector(self%zones(z)%target_velocity(1:dim))
         end do
         do p = 1, particles%count
            if (.not. self%fluid(particles%material(p))) cycle
            world(1:dim) = frame%world_point(particles%x(1:dim, p))
            do z = 1, size(self%zones)
               s = ramp_place(self%zones(z), world, dim)
               if (s < 0.0_rp) cycle
               factor = damping_factor(self%zones(z)%rate, s, state%dt)
               particles%v(1:dim, p) = target(1:dim, z) + (particles%v(1:dim, p) - target(1:dim, z)) * factor
               exit
            end do
         end do
      end associate
   end subroutine zones_damp
end module damping_zone
