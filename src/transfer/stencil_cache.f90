!> Where each particle's stencil lies at x^n, kept from P2G for the other passes of the same step that
!> visit the particles' stencils: the re-map and G2P (src/transfer/grid_transfer.F90) and NB's shape values
!> (src/stabilization/node_based_anti_locking.f90). They read the base node and the position in cells from
!> here instead of locating each particle again, which was a sixth of a 3-D step (docs/performance-history.md,
!> "Stencils located once per step"). Only the 3-D kernels keep them (28 bytes per particle).
!>
!> Valid while the particles neither move nor change order: the solver gives it to P2G, which fills it, and
!> to the passes up to G2P, and forgets it once G2P has moved the particles (the volume correction's
!> occupancy and gradient transfers, between P2G and G2P, read it too). A reader takes it only when it holds
!> as many particles as the set it visits (holds_stencils); else it locates them itself.
module stencil_cache
   use kinds, only: rp
   implicit none
   private

   public :: size_stencil_cache, holds_stencils, forget_stencils

   type, public :: stencil_cache_t
      integer :: count = -1                  !< particles whose stencils are held (-1: none)
      integer, allocatable :: base(:)        !< (particle): local index of the stencil's base node
      real(rp), allocatable :: xi(:, :)      !< (3, particle): position in cells from the base node
   end type stencil_cache_t

contains

   !> Room for `capacity` particles (the particle set's capacity: reallocated when it grew).
   subroutine size_stencil_cache(stencils, capacity)
      type(stencil_cache_t), intent(inout) :: stencils
      integer, intent(in) :: capacity
      if (allocated(stencils%base)) then
         if (size(stencils%base) >= capacity) return
         deallocate (stencils%base, stencils%xi)
      end if
      allocate (stencils%base(capacity), stencils%xi(3, capacity))
   end subroutine size_stencil_cache

   !> Whether the cache holds the stencils of a set of `count` particles (those P2G filled it with).
   pure logical function holds_stencils(stencils, count)
      type(stencil_cache_t), intent(in) :: stencils
      integer, intent(in) :: count
      holds_stencils = stencils%count == count .and. count >= 0
   end function holds_stencils

   !> The cache holds no stencils any more (the particles moved or changed order).
   subroutine forget_stencils(stencils)
      type(stencil_cache_t), intent(inout) :: stencils
      stencils%count = -1
   end subroutine forget_stencils
end module stencil_cache
