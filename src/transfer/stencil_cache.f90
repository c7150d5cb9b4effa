!> Where each particle's stencil lies at x^n, kept from P2G for the other passes of the same step that
!> visit the particles' stencils: the re-map and G2P (src/transfer/grid_transfer.F90) and NB's shape values
!> (src/stabilization/node_based_anti_locking.f90). They read the base node and the position in cells from
!> here instead of locating each particle again, which was a sixth of a 3-D step (docs/performance.md,
!> "Stencils located once per step"). Only the 3-D kernels keep them (28 bytes per particle).
!>
!> Valid while the particles neither move nor change order: the solver gives it to P2G, which fills it, and
!> to the passes up to G2P, and forgets it once G2P has moved the particles. A reader takes it only when it
!> holds as many particles as the set it visits (holds_stencils); else it locates them itself.
!>
!> With keep_weights (set by NB, src/stabilization/node_based_anti_locking.f90) the 2-D multilinear P2G also
!> keeps each particle's base node and shape values N_a(x_p^n), which NB projects with after G2P: they stay
!> valid, as values at x^n, until the solver forgets them at the end of the step's stabilization
!> (holds_weights, forget_weights). NB then neither evaluates nor stores them itself (36 bytes per
!> particle: the same memory, now here).
module stencil_cache
   use kinds, only: rp
   implicit none
   private

   public :: size_stencil_cache, holds_stencils, forget_stencils, holds_weights, forget_weights

   type, public :: stencil_cache_t
      integer :: count = -1                  !< particles whose stencils are held (-1: none)
      integer, allocatable :: base(:)        !< (particle): local index of the stencil's base node
      real(rp), allocatable :: xi(:, :)      !< (3, particle): position in cells from the base node (3-D)
      logical :: keep_weights = .false.      !< P2G (multilinear) is asked to keep the shape values too
      integer :: weights_count = -1          !< particles whose base and weight are held (-1: none)
      real(rp), allocatable :: weight(:, :)  !< (stencil node, particle): N_a(x_p^n)
   end type stencil_cache_t

contains

   !> Room for `capacity` particles (the particle set's capacity: reallocated when it grew): base and xi in
   !> 3-D, base and the `stencil_size` shape values per particle with keep_weights; nothing else.
   subroutine size_stencil_cache(stencils, capacity, dim, stencil_size)
      type(stencil_cache_t), intent(inout) :: stencils
      integer, intent(in) :: capacity, dim, stencil_size
      if (dim == 3 .or. stencils%keep_weights) call size_base(stencils%base)
      if (dim == 3) call size_rows(stencils%xi, 3)
      if (stencils%keep_weights) call size_rows(stencils%weight, stencil_size)
   contains
      subroutine size_base(base)
         integer, allocatable, intent(inout) :: base(:)
         if (allocated(base)) then
            if (size(base) >= capacity) return
            deallocate (base)
         end if
         allocate (base(capacity))
      end subroutine size_base
      subroutine size_rows(values, rows)
         real(rp), allocatable, intent(inout) :: values(:, :)
         integer, intent(in) :: rows
         if (allocated(values)) then
            if (size(values, 2) >= capacity .and. size(values, 1) == rows) return
            deallocate (values)
         end if
         allocate (values(rows, capacity))
      end subroutine size_rows
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
   !> Whether the cache holds base nodes and shape values of a set of `count` particles (this step's P2G).
   pure logical function holds_weights(stencils, count)
      type(stencil_cache_t), intent(in) :: stencils
      integer, intent(in) :: count
      holds_weights = stencils%weights_count == count .and. count >= 0
   end function holds_weights

   !> The cache holds no shape values any more (the step's stabilization is done; the next sort may
   !> reorder the particles).
   subroutine forget_weights(stencils)
      type(stencil_cache_t), intent(inout) :: stencils
      stencils%weights_count = -1
   end subroutine forget_weights
end module stencil_cache
