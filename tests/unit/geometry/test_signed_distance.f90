!> Signed distances of the structure shapes (src/geometry/signed_distance.f90) against distances
!> known by construction (points placed at a chosen distance from a face, an edge or a corner) and
!> against independent computations: a square polygon and a square box must agree everywhere, and a
!> triangle's distance is checked against a brute-force search over its edges and a barycentric inside test.
module test_signed_distance
   use kinds, only: rp
   use assertions, only: assertRelativelyEqual, assertTrue
   use signed_distance, only: box_distance, ball_distance, capped_cylinder_distance, polygon_distance, &
                              extruded_polygon_distance
   implicit none
   private

   public :: test_box_and_ball, test_capped_cylinder, test_polygon_against_box_and_brute_force, &
             test_extruded_polygon_against_box

   real(rp), parameter :: tol = 1.0e-13_rp

contains

   subroutine test_box_and_ball()
      real(rp) :: axes(2, 2), c, s, centre(2), half(2), x(2)
      c = cos(acos(-1.0_rp) / 6)
      s = 0.5_rp
      axes = reshape([c, -s, s, c], [2, 2])        ! rows: the box's axes (cos 30, sin 30), (-sin 30, cos 30)
      centre = [1.0_rp, 2.0_rp]
      half = [0.8_rp, 0.3_rp]
      call assertRelativelyEqual(-0.3_rp, box_distance(centre, centre, half, axes), tol, 'box centre: nearer face')
      ! 0.5 beyond the face of the first axis
      x = centre + (0.8_rp + 0.5_rp) * axes(1, :) + 0.1_rp * axes(2, :)
      call assertRelativelyEqual(0.5_rp, box_distance(x, centre, half, axes), tol, 'box: beyond a face')
      ! beyond a corner by (0.3, 0.4) in the box's axes: distance 0.5
      x = centre - (0.8_rp + 0.3_rp) * axes(1, :) + (0.3_rp + 0.4_rp) * axes(2, :)
      call assertRelativelyEqual(0.5_rp, box_distance(x, centre, half, axes), tol, 'box: beyond a corner')
      ! inside, 0.1 from the second axis' face
      x = centre + 0.2_rp * axes(1, :) - 0.2_rp * axes(2, :)
      call assertRelativelyEqual(-0.1_rp, box_distance(x, centre, half, axes), tol, 'box: inside, nearest face')
      call assertRelativelyEqual(1.0_rp, ball_distance([3.0_rp, 4.0_rp, 0.0_rp], [0.0_rp, 0.0_rp, 0.0_rp], 4.0_rp), &
                                 tol, 'sphere: outside')
      call assertRelativelyEqual(-0.5_rp, ball_distance([1.0_rp, 1.0_rp], [1.0_rp, 1.5_rp], 1.0_rp), tol, &
                                 'disk: inside')
   end subroutine test_box_and_ball

   subroutine test_capped_cylinder()
      real(rp) :: axis(3), radial(3), base(3), x(3)
      axis = [1.0_rp, 1.0_rp, 1.0_rp] / sqrt(3.0_rp)
      radial = [1.0_rp, -1.0_rp, 0.0_rp] / sqrt(2.0_rp)      ! normal to the axis
      base = [0.5_rp, -1.0_rp, 2.0_rp]
      ! radius 0.4, length 2
      call assertRelativelyEqual(-0.4_rp, cyl(base + axis), tol, 'centre: the mantle is nearer than the caps')
      call assertRelativelyEqual(0.5_rp, cyl(base + 2.5_rp * axis), tol, 'on the axis beyond the top cap')
      call assertRelativelyEqual(0.2_rp, cyl(base + axis + 0.6_rp * radial), tol, 'beside the mantle')
      x = base - 0.4_rp * axis + 0.7_rp * radial        ! 0.4 below the base, 0.3 beyond the rim
      call assertRelativelyEqual(0.5_rp, cyl(x), tol, 'beyond the rim of the base')
      call assertRelativelyEqual(-0.1_rp, cyl(base + 1.9_rp * axis + 0.1_rp * radial), tol, 'inside, near the top cap')
   contains
      real(rp) function cyl(point)
         real(rp), intent(in) :: point(3)
         cyl = capped_cylinder_distance(point, base, axis, 2.0_rp, 0.4_rp)
      end function cyl
   end subroutine test_capped_cylinder

   subroutine test_polygon_against_box_and_brute_force()
      real(rp), parameter :: square(2, 4) = reshape([0.0_rp, 0.0_rp, 2.0_rp, 0.0_rp, 2.0_rp, 1.0_rp, 0.0_rp, 1.0_rp], &
                                                    [2, 4])
      real(rp), parameter :: triangle(2, 3) = reshape([0.1_rp, 0.2_rp, 1.7_rp, 0.4_rp, 0.6_rp, 1.5_rp], [2, 3])
      real(rp), parameter :: notch(2, 6) = reshape([0.0_rp, 0.0_rp, 2.0_rp, 0.0_rp, 2.0_rp, 2.0_rp, 1.0_rp, 2.0_rp, &
                                                    1.0_rp, 1.0_rp, 0.0_rp, 1.0_rp], [2, 6])   ! an L
      real(rp) :: identity(2, 2), x(2), worst_box, worst_brute, worst_reversed
      integer :: i, j

      identity = reshape([1.0_rp, 0.0_rp, 0.0_rp, 1.0_rp], [2, 2])
      worst_box = 0.0_rp
      worst_brute = 0.0_rp
      worst_reversed = 0.0_rp
      do i = 0, 40
         do j = 0, 30
            x = [-1.0_rp + 0.1_rp * i + 0.0123_rp, -1.0_rp + 0.1_rp * j + 0.0071_rp]
            worst_box = max(worst_box, abs(polygon_distance(x, square) - &
                                           box_distance(x, [1.0_rp, 0.5_rp], [1.0_rp, 0.5_rp], identity)))
            worst_brute = max(worst_brute, abs(polygon_distance(x, triangle) - brute_force_triangle(x)))
            worst_reversed = max(worst_reversed, abs(polygon_distance(x, notch) - &
                                                     polygon_distance(x, notch(:, 6:1:-1))))
         end do
      end do
      call assertTrue(worst_box < tol, 'a square polygon is the box (1271 points)')
      call assertTrue(worst_brute < 1.0e-6_rp, 'triangle: brute force over the edges, barycentric sign')
      call assertTrue(worst_reversed < tol, 'the order of the vertices does not matter')
      ! the notch [0, 1] x [1, 2] of the L is outside; its reflex corner (1, 1) is no nearest point there
      call assertRelativelyEqual(0.3_rp, polygon_distance([0.7_rp, 1.6_rp], notch), tol, 'L: in the notch, outside')
      call assertRelativelyEqual(-0.2_rp, polygon_distance([1.2_rp, 1.5_rp], notch), tol, &
                                 'L: inside the upright, nearest the notch face')
      call assertRelativelyEqual(-0.2_rp, polygon_distance([0.5_rp, 0.8_rp], notch), tol, &
                                 'L: inside the bar, under the notch')
   contains
      !> |phi| by sampling every edge at 20001 points, the sign from the barycentric coordinates.
      real(rp) function brute_force_triangle(point) result(phi)
         real(rp), intent(in) :: point(2)
         real(rp) :: a(2), b(2), c(2), l1, l2, det
         integer :: k, m
         phi = huge(1.0_rp)
         do k = 1, 3
            a = triangle(:, k)
            b = triangle(:, modulo(k, 3) + 1)
            do m = 0, 20000
               phi = min(phi, norm2(point - a - (real(m, rp) / 20000.0_rp) * (b - a)))
            end do
         end do
         a = triangle(:, 1)
         b = triangle(:, 2)
         c = triangle(:, 3)
         det = (b(1) - a(1)) * (c(2) - a(2)) - (c(1) - a(1)) * (b(2) - a(2))
         l1 = ((point(1) - a(1)) * (c(2) - a(2)) - (c(1) - a(1)) * (point(2) - a(2))) / det
         l2 = ((b(1) - a(1)) * (point(2) - a(2)) - (point(1) - a(1)) * (b(2) - a(2))) / det
         if (l1 > 0.0_rp .and. l2 > 0.0_rp .and. l1 + l2 < 1.0_rp) phi = -phi
      end function brute_force_triangle
   end subroutine test_polygon_against_box_and_brute_force

   subroutine test_extruded_polygon_against_box()
      real(rp), parameter :: square(2, 4) = reshape([0.0_rp, 0.0_rp, 2.0_rp, 0.0_rp, 2.0_rp, 1.0_rp, 0.0_rp, 1.0_rp], &
                                                    [2, 4])
      real(rp) :: identity(3, 3), x(3), worst
      integer :: i, j, k
      identity = 0.0_rp
      identity(1, 1) = 1.0_rp
      identity(2, 2) = 1.0_rp
      identity(3, 3) = 1.0_rp
      worst = 0.0_rp
      do i = 0, 12
         do j = 0, 10
            do k = 0, 14
               x = [-1.0_rp, -1.0_rp, -1.0_rp] + 0.33_rp * [i, j, k] + [0.011_rp, 0.007_rp, 0.013_rp]
               worst = max(worst, abs(extruded_polygon_distance(x, square, 0.5_rp, 2.5_rp) - &
                                      box_distance(x, [1.0_rp, 0.5_rp, 1.5_rp], [1.0_rp, 0.5_rp, 1.0_rp], identity)))
            end do
         end do
      end do
      call assertTrue(worst < tol, 'an extruded square is the box (2145 points)')
   end subroutine test_extruded_polygon_against_box
end module test_signed_distance
