!> `condition = 'free'`: a surface that constrains nothing (docs/input.md). Its loads.csv entry is
!> written and stays zero; the material passes through it, the volume correction does not count it, and
!> rigid bodies do not touch it. For a wall switched off in a variant of a scene without renumbering the
!> load columns a study compares. The worked example of docs/conventions.md, "Where to add a boundary
!> condition".
module free_condition
   use kinds, only: rp
   use surface_condition, only: surface_condition_t, condition_traits_t
   implicit none
   private

   type, extends(surface_condition_t), public :: free_condition_t
   contains
      procedure :: constrain_node => leave_node
      procedure :: traits => absent
   end type free_condition_t

contains

   !> Never called (the surface never holds, so it is never active); the law of a surface that is not there.
   pure function leave_node(self, before, vw, n, moving) result(after)
      class(free_condition_t), intent(in) :: self
      real(rp), intent(in) :: before(:), vw(:), n(:)
      logical, intent(in) :: moving
      real(rp) :: after(size(before))
      after = before
   end function leave_node

   !> It never acts, closes no space and touches no body.
   pure function absent(self) result(traits)
      class(free_condition_t), intent(in) :: self
      type(condition_traits_t) :: traits
      traits = condition_traits_t(holds=.false., blocks_flow=.false.)
   end function absent
end module free_condition
