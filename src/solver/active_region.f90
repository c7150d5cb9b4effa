!> The active region: the box of cells the decomposition covers, which follows the particles
!> (docs/theory.md section 6.2).
!>
!> The box is the cells of the particles and of the inlets still to inject (the "needed" cells),
!> widened by `margin` cells on every side and clipped to the grid. After every step the solver
!> checks, in the reduction that agrees on the next time step, whether a particle has come within
!> `guard` cells of an edge of the box that is not the grid's edge (then the box must grow before the
!> next step can carry a particle out of it), or whether the box has become wider than needed by more
!> than the margin (then it shrinks), and lays the box out anew. A particle moves less than one cell
!> per step, so no particle ever leaves the box, and cells without particles change no result: the
!> physics does not depend on which empty cells are allocated.
module active_region
   use kinds, only: rp
   use scene_description, only: scene_t, opening_far_end
   use body_lattice, only: body_bounds
   use world_frame, only: frame_t
   use particle_set, only: particle_set_t
   implicit none
   private

   !> Cells of room beyond the guard when the box is laid out [R]: it moves after about this many
   !> cells of travel. Small, because every cell of margin is grid work on each side of the particles.
   integer, parameter, public :: slack_cells = 4

   public :: scene_extent, particle_extent, cells_of_extent, guard_cells, box_needs_change, target_box

contains

   !> Grid-frame extent lo..hi of what the scene will put into the grid from `time` on: with
   !> `bodies`, the bounding boxes of the bodies (body_lattice; their corners mapped into the grid frame), and the openings of
   !> the inlets that have not closed, each with one cell downstream where its new layers appear
   !> (fluid_inflow places them within v0 dt + Dp/2 of the opening). With `lead`, only the inlets that
   !> open before time + lead: an inlet that opens later costs no grid until then (the check after every
   !> step takes it in before its first layer). lo > hi if there is nothing.
   pure subroutine scene_extent(scene, frame, h, time, bodies, lo, hi, lead)
      type(scene_t), intent(in) :: scene
      type(frame_t), intent(in) :: frame
      real(rp), intent(in) :: h, time
      logical, intent(in) :: bodies
      real(rp), intent(out) :: lo(3), hi(3)
      real(rp), intent(in), optional :: lead
      real(rp), allocatable :: points(:, :)        ! world points to cover (3, n)
      real(rp) :: far_end(3), shift(3), g(3), body_lower(3), body_upper(3)
      integer :: dim, b, i, corner, n

      dim = scene%grid%dim
      n = 0
      if (bodies .and. allocated(scene%bodies)) n = n + 2**dim * size(scene%bodies)
      if (allocated(scene%inlets)) n = n + 4 * size(scene%inlets)
      allocate (points(3, n))
      n = 0
      if (bodies .and. allocated(scene%bodies)) then
         do b = 1, size(scene%bodies)
            call body_bounds(scene, b, body_lower, body_upper)
            do corner = 0, 2**dim - 1
               n = n + 1
               points(:, n) = merge(body_upper, body_lower, [btest(corner, 0), btest(corner, 1), btest(corner, 2)])
            end do
         end do
      end if
      if (allocated(scene%inlets)) then
         do i = 1, size(scene%inlets)
            associate (inlet => scene%inlets(i))
               if (time >= inlet%end_time) cycle
               if (present(lead)) then
                  if (inlet%start_time > time + lead) cycle
               end if
               far_end = opening_far_end(inlet, dim)
               shift = h * inlet%direction / norm2(inlet%direction(1:dim))
               points(:, n + 1:n + 4) = reshape([inlet%point, far_end, inlet%point + shift, far_end + shift], [3, 4])
               n = n + 4
            end associate
         end do
      end if
      lo = huge(1.0_rp)
      hi = -huge(1.0_rp)
      g = 0.0_rp
      do i = 1, n
         g(1:dim) = frame%grid_point(points(1:dim, i))
         lo(1:dim) = min(lo(1:dim), g(1:dim))
         hi(1:dim) = max(hi(1:dim), g(1:dim))
      end do
      lo(dim + 1:) = 0.0_rp
      hi(dim + 1:) = 0.0_rp
   end subroutine scene_extent

   !> Extent lo..hi of this rank's particle positions (grid frame); lo > hi without particles. One
   !> pass over the positions per axis (minval/maxval vectorise).
   pure subroutine particle_extent(particles, lo, hi)
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(out) :: lo(3), hi(3)
      integer :: k
      lo = huge(1.0_rp)
      hi = -huge(1.0_rp)
      if (particles%count == 0) return
      do k = 1, particles%dim
         lo(k) = minval(particles%x(k, 1:particles%count))
         hi(k) = maxval(particles%x(k, 1:particles%count))
      end do
   end subroutine particle_extent

   !> The cells lo..hi (global, inclusive, clipped to the grid of `cells` cells) holding the grid-frame
   !> extent x_lo..x_hi of a grid with lower corner `origin` and cell edge 1/inv_h. Empty (lo > hi) when
   !> the extent is.
   pure subroutine cells_of_extent(origin, inv_h, cells, dim, x_lo, x_hi, lo, hi)
      real(rp), intent(in) :: origin(3), inv_h, x_lo(3), x_hi(3)
      integer, intent(in) :: cells(3), dim
      integer, intent(out) :: lo(3), hi(3)
      integer :: k
      lo = 0
      hi = 0
      if (any(x_lo(1:dim) > x_hi(1:dim))) then
         lo(1) = 1
         return
      end if
      do k = 1, dim
         ! clipped in real arithmetic first: an extent far outside the grid must not overflow floor()
         lo(k) = floor(min(max((x_lo(k) - origin(k)) * inv_h, 0.0_rp), real(cells(k) - 1, rp)))
         hi(k) = floor(min(max((x_hi(k) - origin(k)) * inv_h, 0.0_rp), real(cells(k) - 1, rp)))
      end do
   end subroutine cells_of_extent

   !> Cells a particle must keep from an inner edge of the box so that the next step, of `travel` cells
   !> at most by the particle speeds (dt times the largest signal speed over h), cannot carry it out:
   !> twice that (nodal velocities may exceed the particles'), rounded up, plus one [R].
   pure integer function guard_cells(travel) result(guard)
      real(rp), intent(in) :: travel
      guard = 1 + ceiling(2.0_rp * min(travel, 1.0e6_rp))
   end function guard_cells

   !> The box lo..hi for the needed cells need_lo..need_hi: margin cells more on each side, clipped to
   !> the grid (fit_box then widens it where the rank grid needs room).
   pure subroutine target_box(need_lo, need_hi, margin, cells, dim, lo, hi)
      integer, intent(in) :: need_lo(3), need_hi(3), margin, cells(3), dim
      integer, intent(out) :: lo(3), hi(3)
      lo = 0
      hi = 0
      lo(1:dim) = max(need_lo(1:dim) - margin, 0)
      hi(1:dim) = min(need_hi(1:dim) + margin, cells(1:dim) - 1)
   end subroutine target_box

   !> True if the box lo..hi must be laid out anew for the needed cells need_lo..need_hi: they come
   !> within `guard` cells of an edge of the box that is not an edge of the grid, or the box reaches
   !> more than `margin` cells beyond the target box target_lo..target_hi.
   pure logical function box_needs_change(lo, hi, need_lo, need_hi, guard, margin, target_lo, target_hi, cells, dim) &
      result(change)
      integer, intent(in) :: lo(3), hi(3), need_lo(3), need_hi(3), guard, margin, target_lo(3), target_hi(3), &
                             cells(3), dim
      integer :: k
      change = .false.
      do k = 1, dim
         if (lo(k) > 0 .and. need_lo(k) - lo(k) < guard) change = .true.
         if (hi(k) < cells(k) - 1 .and. hi(k) - need_hi(k) < guard) change = .true.
         if (lo(k) < target_lo(k) - margin .or. hi(k) > target_hi(k) + margin) change = .true.
      end do
   end function box_needs_change
end module active_region
