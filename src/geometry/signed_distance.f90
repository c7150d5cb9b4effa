!> Signed distance of the structure shapes (issue 15): negative inside the solid, positive in the
!> space the material may occupy, zero on the surface. Pure point functions, in the world frame, for
!> 2-D (points of size 2) and 3-D (size 3) alike where the shape exists in both.
!>
!> A structure's constraint needs the distance (is a node inside or near?) and the outward normal
!> n = grad(phi). The formulas are the exact Euclidean distances of the primitives (so |grad phi| = 1
!> wherever phi is differentiable; Quilez, "distance functions"): a box as the distance to its faces,
!> edges and corners in its own axes, capped solids as the intersection with a slab.
module signed_distance
   use kinds, only: rp
   implicit none
   private

   public :: box_distance, ball_distance, capped_cylinder_distance, polygon_distance, &
             extruded_polygon_distance, combine_with_slab

contains

   !> Box of half sizes `half` centred at `centre`; the rows of `axes` are its unit axes in the world
   !> (the identity for a box aligned with the world axes).
   pure real(rp) function box_distance(x, centre, half, axes) result(phi)
      real(rp), intent(in) :: x(:), centre(:), half(:), axes(:, :)
      real(rp) :: q(size(x))
      q = abs(matmul(axes, x - centre)) - half
      phi = norm2(max(q, 0.0_rp)) + min(maxval(q), 0.0_rp)
   end function box_distance

   !> Disk (2-D) or sphere (3-D) of `radius` about `centre`.
   pure real(rp) function ball_distance(x, centre, radius) result(phi)
      real(rp), intent(in) :: x(:), centre(:), radius
      phi = norm2(x - centre) - radius
   end function ball_distance

   !> Cylinder of `radius` whose axis runs from `base` along the unit vector `axis` for `length`,
   !> closed by flat caps.
   pure real(rp) function capped_cylinder_distance(x, base, axis, length, radius) result(phi)
      real(rp), intent(in) :: x(3), base(3), axis(3), length, radius
      real(rp) :: along
      along = dot_product(x - base, axis)
      phi = combine_with_slab(norm2(x - base - along * axis) - radius, along, 0.0_rp, length)
   end function capped_cylinder_distance

   !> Closed polygon in the plane, vertices(:, k) in order (either sense; the last joins the first).
   !> The sign comes from the crossing number (even-odd rule), so the polygon must not cross itself.
   pure real(rp) function polygon_distance(x, vertices) result(phi)
      real(rp), intent(in) :: x(2), vertices(:, :)
      real(rp) :: a(2), b(2), edge(2), t, nearest
      logical :: inside
      integer :: k, n
      n = size(vertices, 2)
      nearest = huge(1.0_rp)
      inside = .false.
      do k = 1, n
         a = vertices(:, k)
         b = vertices(:, modulo(k, n) + 1)
         edge = b - a
         t = 0.0_rp       ! nearest point a + t (b - a) of the edge, t in [0, 1]
         if (dot_product(edge, edge) > 0.0_rp) &
            t = min(max(dot_product(x - a, edge) / dot_product(edge, edge), 0.0_rp), 1.0_rp)
         nearest = min(nearest, norm2(x - a - t * edge))
         ! a ray from x in +x direction crosses this edge (half-open in y so a vertex counts once)
         if ((a(2) > x(2)) .neqv. (b(2) > x(2))) then
            if (x(1) < a(1) + (x(2) - a(2)) * edge(1) / edge(2)) inside = .not. inside
         end if
      end do
      phi = merge(-nearest, nearest, inside)
   end function polygon_distance

   !> A polygon of the x-y plane extruded along z from z_low to z_high.
   pure real(rp) function extruded_polygon_distance(x, vertices, z_low, z_high) result(phi)
      real(rp), intent(in) :: x(3), vertices(:, :), z_low, z_high
      phi = combine_with_slab(polygon_distance(x(1:2), vertices), x(3), z_low, z_high)
   end function extruded_polygon_distance

   !> Intersection of a shape of cross-section distance `across` with the slab low <= s <= high of the
   !> coordinate `s` along its axis: the exact distance of the capped solid.
   pure real(rp) function combine_with_slab(across, s, low, high) result(phi)
      real(rp), intent(in) :: across, s, low, high
      real(rp) :: d(2)
      d = [across, max(low - s, s - high)]
      phi = min(maxval(d), 0.0_rp) + norm2(max(d, 0.0_rp))
   end function combine_with_slab
end module signed_distance
