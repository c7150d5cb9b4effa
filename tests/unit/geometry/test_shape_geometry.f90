!> The scene shapes (src/geometry/shape_geometry.f90): the bounding box against the extreme points of the
!> shape found by sampling its surface, the area/volume against a count of lattice points inside (an
!> independent estimate from shape_distance), normals on faces and the polygon checks on shapes known to
!> be bad (a bow tie, two vertices, a folded edge) and good (a polygon written closed).
module test_shape_geometry
   use kinds, only: rp
   use assertions, only: assertRelativelyEqual, assertTrue
   use shape_geometry, only: shape_t, box_from_corners, vertex_count, shape_distance, shape_normal, shape_bounds, &
                             shape_measure, shape_problem, box_axes
   implicit none
   private

   public :: test_bounds_hold_the_shape, test_measure_against_lattice_count, test_normals_and_axes, &
             test_polygon_problems

   real(rp), parameter :: pi = acos(-1.0_rp)

contains

   function turned_box() result(box)
      type(shape_t) :: box
      box%kind = 'box'
      box%centre = [1.0_rp, 2.0_rp, 0.5_rp]
      box%size = [0.8_rp, 0.3_rp, 0.4_rp]
      box%rotation = 30.0_rp
      box%rotation_axis = [1.0_rp, 1.0_rp, 0.0_rp]
   end function turned_box

   function tilted_cylinder() result(cylinder)
      type(shape_t) :: cylinder
      cylinder%kind = 'cylinder'
      cylinder%centre = [0.2_rp, -0.1_rp, 0.3_rp]
      cylinder%axis = [1.0_rp, 2.0_rp, 2.0_rp]
      cylinder%length = 0.9_rp
      cylinder%radius = 0.25_rp
   end function tilted_cylinder

   function l_polygon() result(polygon)
      type(shape_t) :: polygon
      polygon%kind = 'polygon'
      polygon%vertices(:, 1:6) = reshape([0.0_rp, 0.0_rp, 2.0_rp, 0.0_rp, 2.0_rp, 1.0_rp, 1.0_rp, 1.0_rp, &
                                          1.0_rp, 3.0_rp, 0.0_rp, 3.0_rp], [2, 6])
   end function l_polygon

   !> Every lattice point inside lies in the bounds, and the bounds are reached within a lattice step.
   subroutine test_bounds_hold_the_shape()
      call check_bounds(turned_box(), 3, 'turned box')
      call check_bounds(tilted_cylinder(), 3, 'tilted cylinder')
      call check_bounds(l_polygon(), 2, 'L polygon')
   end subroutine test_bounds_hold_the_shape

   subroutine check_bounds(shape, dim, what)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      character(len=*), intent(in) :: what
      real(rp) :: lower(3), upper(3), seen_lo(3), seen_hi(3), x(3), step
      integer :: i, j, l, n
      call shape_bounds(shape, dim, lower, upper)
      n = merge(400, 60, dim == 2)
      step = maxval(upper(1:dim) - lower(1:dim)) * 1.2_rp / n
      seen_lo = huge(1.0_rp)
      seen_hi = -huge(1.0_rp)
      do l = 0, merge(0, n, dim == 2)
         do j = 0, n
            do i = 0, n
               x = lower - 0.1_rp * (upper - lower) + [i, j, l] * step
               if (shape_distance(shape, x(1:dim)) > 0.0_rp) cycle
               seen_lo = min(seen_lo, x)
               seen_hi = max(seen_hi, x)
            end do
         end do
      end do
      call assertTrue(all(seen_lo(1:dim) >= lower(1:dim)) .and. all(seen_hi(1:dim) <= upper(1:dim)), &
                      what//': points inside lie in the bounds')
      call assertTrue(all(seen_lo(1:dim) - lower(1:dim) < 1.5_rp * step) .and. &
                      all(upper(1:dim) - seen_hi(1:dim) < 1.5_rp * step), what//': the bounds are reached')
   end subroutine check_bounds

   !> Area/volume against the count of lattice points with phi < 0 times the lattice cell (error of the
   !> count ~ surface x step).
   subroutine test_measure_against_lattice_count()
      type(shape_t) :: circle, sphere
      circle%kind = 'circle'
      circle%centre = [0.3_rp, 0.1_rp, 0.0_rp]
      circle%radius = 0.7_rp
      sphere%kind = 'sphere'
      sphere%radius = 0.5_rp
      call assertRelativelyEqual(pi * 0.49_rp, shape_measure(circle, 2), 1.0e-15_rp, 'circle: pi r^2')
      call check_measure(circle, 2, 2.0e-3_rp, 'circle')
      call check_measure(l_polygon(), 2, 2.0e-3_rp, 'L polygon')
      call assertRelativelyEqual(4.0_rp, shape_measure(l_polygon(), 2), 1.0e-15_rp, 'L polygon: shoelace area')
      call check_measure(turned_box(), 3, 1.0e-2_rp, 'turned box')
      call check_measure(tilted_cylinder(), 3, 1.0e-2_rp, 'tilted cylinder')
      call check_measure(sphere, 3, 1.0e-2_rp, 'sphere')
   end subroutine test_measure_against_lattice_count

   subroutine check_measure(shape, dim, tolerance, what)
      type(shape_t), intent(in) :: shape
      integer, intent(in) :: dim
      real(rp), intent(in) :: tolerance
      character(len=*), intent(in) :: what
      real(rp) :: lower(3), upper(3), x(3), step, counted
      integer :: i, j, l, n
      call shape_bounds(shape, dim, lower, upper)
      n = merge(1000, 100, dim == 2)
      step = maxval(upper(1:dim) - lower(1:dim)) / n
      counted = 0.0_rp
      do l = 0, merge(0, n - 1, dim == 2)
         do j = 0, n - 1
            do i = 0, n - 1
               x = lower + ([i, j, l] + 0.5_rp) * step
               if (shape_distance(shape, x(1:dim)) < 0.0_rp) counted = counted + step**dim
            end do
         end do
      end do
      call assertRelativelyEqual(shape_measure(shape, dim), counted, tolerance, what//': measure = lattice count')
   end subroutine check_measure

   subroutine test_normals_and_axes()
      type(shape_t) :: box, flat
      real(rp) :: axes(3, 3), x(3)
      box = turned_box()
      axes = box_axes(box, 3)
      call assertRelativelyEqual(1.0_rp, 1.0_rp + maxval(abs(matmul(axes, transpose(axes)) - &
                                 reshape([1, 0, 0, 0, 1, 0, 0, 0, 1], [3, 3]))), 1.0e-15_rp, 'box axes orthonormal')
      ! the rotation axis is its own image: it has the same components in the box's axes and the world's
      call assertRelativelyEqual(1.0_rp, dot_product(matmul(axes, [1.0_rp, 1.0_rp, 0.0_rp]), &
                                 [1.0_rp, 1.0_rp, 0.0_rp]) / 2.0_rp, 1.0e-15_rp, 'rotation axis kept')
      ! just outside the middle of a face the normal is that face's axis
      x = box%centre + (0.4_rp + 1.0e-3_rp) * axes(1, :)
      call assertRelativelyEqual(1.0_rp, dot_product(shape_normal(box, x, 1.0e-6_rp), axes(1, :)), 1.0e-9_rp, &
                                 'normal on a face')
      x = box%centre - (0.15_rp - 1.0e-2_rp) * axes(2, :)
      call assertRelativelyEqual(1.0_rp, -dot_product(shape_normal(box, x, 1.0e-6_rp), axes(2, :)), 1.0e-9_rp, &
                                 'normal inside, nearest face')
      ! in 2-D the rotation turns about z whatever rotation_axis says
      flat = box_from_corners([0.0_rp, 0.0_rp, 0.0_rp], [2.0_rp, 1.0_rp, 0.0_rp])
      flat%rotation = 90.0_rp
      call assertRelativelyEqual(0.0_rp + 1.0_rp, 1.0_rp + shape_distance(flat, [1.0_rp, 1.5_rp]), 1.0e-12_rp, &
                                 'rectangle turned 90 degrees: (1, 1.5) on its face')
   end subroutine test_normals_and_axes

   subroutine test_polygon_problems()
      type(shape_t) :: polygon
      polygon = l_polygon()
      call assertTrue(shape_problem(polygon, 2) == '', 'L polygon is fine')
      call assertTrue(shape_problem(polygon, 3) /= '', "'polygon' is not a 3-D shape")
      polygon%vertices(:, 7) = polygon%vertices(:, 1)
      call assertTrue(vertex_count(polygon) == 6 .and. shape_problem(polygon, 2) == '', 'written closed: same polygon')
      polygon = shape_t()
      polygon%kind = 'polygon'
      ! a bow tie: edge 2, (2, 0)-(0, 2), crosses edge 4, (2, 2)-(0, 0)
      polygon%vertices(:, 1:4) = reshape([0.0_rp, 0.0_rp, 2.0_rp, 0.0_rp, 0.0_rp, 2.0_rp, 2.0_rp, 2.0_rp], [2, 4])
      call assertTrue(index(shape_problem(polygon, 2), 'crosses itself') > 0, 'self-crossing polygon refused')
      polygon = shape_t()
      polygon%kind = 'polygon'
      polygon%vertices(:, 1:2) = reshape([0.0_rp, 0.0_rp, 1.0_rp, 0.0_rp], [2, 2])
      call assertTrue(index(shape_problem(polygon, 2), 'at least 3') > 0, 'two vertices refused')
      polygon%vertices(:, 3) = [2.0_rp, 0.0_rp]
      call assertTrue(shape_problem(polygon, 2) /= '', 'three vertices on a line refused')
      polygon = shape_t()
      polygon%kind = 'circle'
      call assertTrue(index(shape_problem(polygon, 2), 'radius') == 1, 'circle without radius refused')
   end subroutine test_polygon_problems
end module test_shape_geometry
