!> What a constraint surface does to the material that meets it (docs/theory.md section 3.4): the law a
!> wall or structure applies to a nodal velocity, to a particle the safeguard puts back on its surface, and
!> to a rigid body's contact. The surface (constraint) decides where it acts and along which normal n
!> (pointing into the material); its condition decides what happens there. The standard conditions are in
!> wall_conditions, with the one place a `condition` keyword becomes a condition (condition_of).
!>
!> A moving surface passes its mean velocity v_w over the step and `moving`; the laws then act on the
!> velocity relative to v_w. A fixed one keeps its own arithmetic (v, not v - 0), so that a fixed wall's
!> results do not depend on how the moving case is written.
module surface_condition
   use kinds, only: rp
   implicit none
   private

   !> What the step needs to know of a condition besides its laws.
   type, public :: condition_traits_t
      logical :: holds = .true.          !< it acts at all (a free wall: reports a zero load, constrains nothing)
      logical :: blocks_flow = .true.    !< it closes the fluid's space (an inlet's feeder lets fluid through:
                                         !< the volume correction does not count it)
      real(rp) :: body_friction = 0.0_rp !< Coulomb's mu for a rigid body's contact: 0 frictionless, < 0 it sticks
   end type condition_traits_t

   type, abstract, public :: surface_condition_t
   contains
      !> The nodal velocity after the constraint (`before` itself where it does not act).
      procedure(node_law_interface), deferred :: constrain_node
      !> The safeguard's law for a particle moving into the surface (v.n < 0 relative to it): by default
      !> its normal part removed (eq. 14). on_plane: a fixed planar wall (the impulse -m v_n n; on one
      !> normal to grid axis k, without the dot products).
      procedure :: particle_on_plane => remove_normal_on_plane
      procedure :: particle_velocity => remove_normal
      procedure :: traits => plain_traits
      !> Set the velocity the condition imposes (an inlet's feeder; other conditions have none).
      procedure :: prescribe => ignore_velocity
   end type surface_condition_t

   abstract interface
      pure function node_law_interface(self, before, vw, n, moving) result(after)
         import :: surface_condition_t, rp
         class(surface_condition_t), intent(in) :: self
         real(rp), intent(in) :: before(:), vw(:), n(:)
         logical, intent(in) :: moving
         real(rp) :: after(size(before))
      end function node_law_interface
   end interface

   public :: unilateral_velocity, friction_node

contains

   !> The velocity v after a unilateral contact with Coulomb friction mu against a surface of unit normal
   !> n (pointing into the material): unchanged when separating (v.n >= 0); else the normal part v_n is
   !> removed and the tangential part v_t shortened by mu |v_n|, to zero at most (it sticks when
   !> |v_t| <= mu |v_n|, it is never reversed). Over a step this is the impulse of a normal force N dt =
   !> m |v_n| with a friction impulse at most mu N dt opposing the sliding [R] (the grid-node form of
   !> Bardenhagen et al. 2001's contact against a rigid surface, algorithms.md section 9.4).
   pure function unilateral_velocity(v, n, mu) result(constrained)
      real(rp), intent(in) :: v(:), n(:), mu
      real(rp) :: constrained(size(v))
      real(rp) :: vn, tangential(size(v)), speed, remaining
      vn = dot_product(v, n)
      if (vn >= 0.0_rp) then
         constrained = v
         return
      end if
      tangential = v - vn * n
      speed = norm2(tangential)
      remaining = speed + mu * vn
      if (remaining <= 0.0_rp) then
         constrained = 0.0_rp
      else
         constrained = tangential * (remaining / speed)
      end if
   end function unilateral_velocity

   !> The law of Coulomb friction mu (the friction condition's, at nodes and in the safeguard, and a body
   !> field's against a structure of its &contact, body_contact): a node or particle moving into the
   !> surface, relative to it, gets unilateral_velocity.
   pure function friction_node(mu, before, vw, n, moving) result(after)
      real(rp), intent(in) :: mu, before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      after = before
      if (moving) then
         if (dot_product(before - vw, n) < 0.0_rp) after = vw + unilateral_velocity(before - vw, n, mu)
      else
         if (dot_product(before, n) < 0.0_rp) after = unilateral_velocity(before, n, mu)
      end if
   end function friction_node

   !> A fixed planar wall's safeguard: v := v - v_n n, the impulse -m v_n n (v_n = v.n < 0 given); with
   !> `axis` k (n = +-e_k): v_k := 0, the impulse -m v_k e_k.
   pure subroutine remove_normal_on_plane(self, v, n, vn, mass, dp, axis)
      class(surface_condition_t), intent(in) :: self
      real(rp), intent(inout) :: v(:)
      real(rp), intent(in) :: n(:), vn, mass
      real(rp), intent(out) :: dp(:)
      integer, intent(in), optional :: axis
      if (present(axis)) then
         dp = 0.0_rp
         dp(axis) = -mass * v(axis)
         v(axis) = 0.0_rp
         return
      end if
      v = v - vn * n
      dp = -mass * vn * n
   end subroutine remove_normal_on_plane

   !> The safeguard's law on a moving wall or a structure: v - ((v - v_w).n) n (a fixed one: v_w = 0 unused).
   pure function remove_normal(self, before, vw, n, moving) result(after)
      class(surface_condition_t), intent(in) :: self
      real(rp), intent(in) :: before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      if (moving) then
         after = before - dot_product(before - vw, n) * n
      else
         after = before - dot_product(before, n) * n
      end if
   end function remove_normal

   !> A condition that acts, closes the fluid's space and lets rigid bodies slide.
   pure function plain_traits(self) result(traits)
      class(surface_condition_t), intent(in) :: self
      type(condition_traits_t) :: traits
      traits = condition_traits_t()
   end function plain_traits

   pure subroutine ignore_velocity(self, velocity)
      class(surface_condition_t), intent(inout) :: self
      real(rp), intent(in) :: velocity(:)
   end subroutine ignore_velocity
end module surface_condition
