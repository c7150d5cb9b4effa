!> Vectors and 3 x 3 matrices of rigid motion: cross product, identity, rotation from a rotation vector
!> (Rodrigues) and the inverse of a 3 x 3 matrix (body_motion, rigid_bodies).
module small_matrices
   use kinds, only: rp
   implicit none
   private

   public :: cross, identity, rotation_of, inverse_3x3

contains

   pure function cross(a, b) result(c)
      real(rp), intent(in) :: a(3), b(3)
      real(rp) :: c(3)
      c = [a(2) * b(3) - a(3) * b(2), a(3) * b(1) - a(1) * b(3), a(1) * b(2) - a(2) * b(1)]
   end function cross

   pure function identity() result(r)
      real(rp) :: r(3, 3)
      integer :: k
      r = 0.0_rp
      do k = 1, 3
         r(k, k) = 1.0_rp
      end do
   end function identity

   !> exp([a]): the rotation by |a| about a / |a| (Rodrigues).
   pure function rotation_of(a) result(r)
      real(rp), intent(in) :: a(3)
      real(rp) :: r(3, 3), angle, k(3, 3), n(3)
      angle = norm2(a)
      r = identity()
      if (angle == 0.0_rp) return
      n = a / angle
      k = reshape([0.0_rp, n(3), -n(2), -n(3), 0.0_rp, n(1), n(2), -n(1), 0.0_rp], [3, 3])
      r = r + sin(angle) * k + (1.0_rp - cos(angle)) * matmul(k, k)
   end function rotation_of

   !> The inverse of a (by cofactors; 0 for a singular a).
   pure function inverse_3x3(a) result(inverse)
      real(rp), intent(in) :: a(3, 3)
      real(rp) :: inverse(3, 3), det
      inverse(1, 1) = a(2, 2) * a(3, 3) - a(2, 3) * a(3, 2)
      inverse(1, 2) = a(1, 3) * a(3, 2) - a(1, 2) * a(3, 3)
      inverse(1, 3) = a(1, 2) * a(2, 3) - a(1, 3) * a(2, 2)
      inverse(2, 1) = a(2, 3) * a(3, 1) - a(2, 1) * a(3, 3)
      inverse(2, 2) = a(1, 1) * a(3, 3) - a(1, 3) * a(3, 1)
      inverse(2, 3) = a(1, 3) * a(2, 1) - a(1, 1) * a(2, 3)
      inverse(3, 1) = a(2, 1) * a(3, 2) - a(2, 2) * a(3, 1)
      inverse(3, 2) = a(1, 2) * a(3, 1) - a(1, 1) * a(3, 2)
      inverse(3, 3) = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)
      det = a(1, 1) * inverse(1, 1) + a(1, 2) * inverse(2, 1) + a(1, 3) * inverse(3, 1)
      if (det /= 0.0_rp) then
         inverse = inverse / det
      else
         inverse = 0.0_rp
      end if
   end function inverse_3x3
end module small_matrices
