!> The map between the grid frame and the world frame (issue 5): points and vectors round trip, the
!> pivot stays, tensors rotate as R sigma R^T.
module test_world_frame
   use kinds, only: rp
   use assertions, only: assertRelativelyEqual, assertTrue
   use world_frame, only: frame_t
   implicit none
   private

   public :: test_frame_maps

contains

   subroutine test_frame_maps()
      type(frame_t) :: frame
      real(rp) :: x(2), g(2), v(2), s(4, 1), world(9, 1), a(3, 3), expected(3, 3), c, sn
      call frame%init(30.0_rp, [1.0_rp, 2.0_rp, 0.0_rp])
      x = [3.0_rp, -1.0_rp]
      g = frame%grid_point(x)
      call assertTrue(norm2(frame%world_point(g) - x) < 1.0e-14_rp, 'points round trip')
      call assertRelativelyEqual(norm2(g - [1.0_rp, 2.0_rp]), norm2(x - [1.0_rp, 2.0_rp]), 1.0e-14_rp, &
                                 'distance to the pivot kept')
      call assertTrue(norm2(frame%grid_point([1.0_rp, 2.0_rp]) - [1.0_rp, 2.0_rp]) < 1.0e-14_rp, 'the pivot stays')
      v = frame%world_vector([1.0_rp, 0.0_rp])
      call assertRelativelyEqual(v(1), cos(acos(-1.0_rp) / 6), 1.0e-14_rp, 'grid x axis in the world (cos 30)')
      call assertRelativelyEqual(v(2), 0.5_rp, 1.0e-14_rp, 'grid x axis in the world (sin 30)')
      ! a uniaxial stress along the grid's x axis is a stress along (cos 30, sin 30) in the world
      s(:, 1) = [2.0_rp, 0.0_rp, 0.0_rp, 0.0_rp]
      call frame%to_world_tensors(s, 2, world)
      a = reshape(world(:, 1), [3, 3])
      c = cos(acos(-1.0_rp) / 6)
      sn = 0.5_rp
      expected = 0.0_rp
      expected(1:2, 1:2) = 2.0_rp * reshape([c * c, c * sn, c * sn, sn * sn], [2, 2])
      call assertTrue(maxval(abs(a - expected)) < 1.0e-14_rp, 'tensor R sigma R^T')
      call assertRelativelyEqual(a(1, 1) + a(2, 2) + a(3, 3), 2.0_rp, 1.0e-14_rp, 'trace kept')
   end subroutine test_frame_maps
end module test_world_frame
