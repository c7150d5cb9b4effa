!> The conditions a `&wall`, a `&box_walls` side or a `&structure` may have (docs/input.md, `condition`),
!> and an inlet's feeder; condition_of is the one place a keyword becomes one (surface_condition):
!>   slip       [Y17] eq. 14, unilateral and frictionless: v := v - (v.n) n only where v.n < 0
!>   friction   unilateral with Coulomb friction mu where v.n < 0: the normal part removed, the tangential
!>              part shortened by mu |v.n| and never reversed (unilateral_velocity) [R]
!>   no_slip    v := v_w (0 on a fixed wall)
!>   prescribed v := v_0 (the feeder of an inlet, algorithms.md section 4.3; it lets fluid through)
!>   free       nothing (free_condition: a `&wall` that only reports its zero load)
!> The safeguard removes a particle's normal velocity on all but friction, which applies Coulomb there too.
module wall_conditions
   use kinds, only: rp
   use scene_description, only: wall_no_slip, wall_friction
   use wall_group, only: wall_free
   use surface_condition, only: surface_condition_t, condition_traits_t, friction_node, unilateral_velocity
   use free_condition, only: free_condition_t
   implicit none
   private

   type, extends(surface_condition_t), public :: slip_condition_t
   contains
      procedure :: constrain_node => slip_node
   end type slip_condition_t

   type, extends(surface_condition_t), public :: no_slip_condition_t
   contains
      procedure :: constrain_node => no_slip_node
      procedure :: traits => sticking
   end type no_slip_condition_t

   type, extends(surface_condition_t), public :: friction_condition_t
      real(rp) :: mu = 0.0_rp   !< Coulomb coefficient [-]
   contains
      procedure :: constrain_node => coulomb_node
      procedure :: particle_on_plane => coulomb_on_plane
      procedure :: particle_velocity => coulomb_node
      procedure :: traits => coulomb_traits
   end type friction_condition_t

   type, extends(surface_condition_t), public :: prescribed_condition_t
      real(rp) :: velocity(3) = 0.0_rp   !< v_0, grid frame [m/s]
   contains
      procedure :: constrain_node => prescribed_node
      procedure :: traits => lets_through
      procedure :: prescribe => set_velocity
   end type prescribed_condition_t

   public :: condition_of

contains

   !> The condition of keyword `condition` ('slip', 'no_slip', 'friction' with Coulomb `mu`, 'free'; scene_validation
   !> admits no other).
   function condition_of(condition, mu) result(made)
      character(len=*), intent(in) :: condition
      real(rp), intent(in) :: mu
      class(surface_condition_t), allocatable :: made
      select case (condition)
      case (wall_no_slip)
         allocate (made, source=no_slip_condition_t())
      case (wall_friction)
         allocate (made, source=friction_condition_t(mu=mu))
      case (wall_free)
         allocate (made, source=free_condition_t())
      case default
         allocate (made, source=slip_condition_t())
      end select
   end function condition_of

   pure function slip_node(self, before, vw, n, moving) result(after)
      class(slip_condition_t), intent(in) :: self
      real(rp), intent(in) :: before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      real(rp) :: vn
      if (moving) then
         vn = dot_product(before - vw, n)
      else
         vn = dot_product(before, n)
      end if
      after = before
      if (vn < 0.0_rp) after = before - vn * n
   end function slip_node

   pure function no_slip_node(self, before, vw, n, moving) result(after)
      class(no_slip_condition_t), intent(in) :: self
      real(rp), intent(in) :: before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      if (moving) then
         after = vw
      else
         after = 0.0_rp
      end if
   end function no_slip_node

   !> A rigid body sticks to a no-slip surface.
   pure function sticking(self) result(traits)
      class(no_slip_condition_t), intent(in) :: self
      type(condition_traits_t) :: traits
      traits = condition_traits_t(body_friction=-1.0_rp)
   end function sticking

   pure function coulomb_node(self, before, vw, n, moving) result(after)
      class(friction_condition_t), intent(in) :: self
      real(rp), intent(in) :: before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      after = friction_node(self%mu, before, vw, n, moving)
   end function coulomb_node

   !> A fixed planar wall (any normal, `axis` or not): v := unilateral_velocity(v), the impulse m (v^c - v).
   pure subroutine coulomb_on_plane(self, v, n, vn, mass, dp, axis)
      class(friction_condition_t), intent(in) :: self
      real(rp), intent(inout) :: v(:)
      real(rp), intent(in) :: n(:), vn, mass
      real(rp), intent(out) :: dp(:)
      integer, intent(in), optional :: axis
      real(rp) :: before(size(v))
      before = v
      v = unilateral_velocity(before, n, self%mu)
      dp = mass * (v - before)
   end subroutine coulomb_on_plane

   !> A rigid body meets the surface's mu.
   pure function coulomb_traits(self) result(traits)
      class(friction_condition_t), intent(in) :: self
      type(condition_traits_t) :: traits
      traits = condition_traits_t(body_friction=self%mu)
   end function coulomb_traits

   !> v := v_0 (a feeder does not move).
   pure function prescribed_node(self, before, vw, n, moving) result(after)
      class(prescribed_condition_t), intent(in) :: self
      real(rp), intent(in) :: before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      after = self%velocity(1:size(after))
   end function prescribed_node

   !> A feeder lets the fluid through (the volume correction does not count it).
   pure function lets_through(self) result(traits)
      class(prescribed_condition_t), intent(in) :: self
      type(condition_traits_t) :: traits
      traits = condition_traits_t(blocks_flow=.false.)
   end function lets_through

   pure subroutine set_velocity(self, velocity)
      class(prescribed_condition_t), intent(inout) :: self
      real(rp), intent(in) :: velocity(:)
      self%velocity = 0.0_rp
      self%velocity(1:size(velocity)) = velocity
   end subroutine set_velocity
end module wall_conditions
