!> Tests of the test framework itself (tests/framework/assertions.f90): which comparisons pass,
!> that failures are counted, and that NaN, infinities and huge values neither pass nor trap.
module test_assertions
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf, ieee_negative_inf
   use kinds, only: rp, i8
   use assertions, only: assertEqual, assertTrue, assertFalse, assertLessThanOrEqual, assertRelativelyEqual, &
                         begin_expected_failures, end_expected_failures, within_tolerance, &
                         within_relative_tolerance
   implicit none
   private

   public :: test_passing_assertions_do_not_count, test_failing_assertions_count, test_tolerance_edge_cases
   public :: test_relative_tolerance_near_zero

contains

   subroutine test_passing_assertions_do_not_count()
      integer :: n
      call begin_expected_failures()
      call assertEqual(1.0_rp, 1.0_rp + 1.0e-13_rp, 1.0e-12_rp, 'scalar within tolerance')
      call assertEqual([1.0_rp, 2.0_rp], [1.0_rp, 2.0_rp], 0.0_rp)
      call assertEqual(reshape([1.0_rp, 2.0_rp, 3.0_rp, 4.0_rp], [2, 2]), &
                       reshape([1.0_rp, 2.0_rp, 3.0_rp, 4.0_rp], [2, 2]), 0.0_rp, 'matrix')
      call assertEqual(0.5_rp, [0.5_rp, 0.5_rp, 0.5_rp], 0.0_rp, 'scalar expected, array actual')
      call assertEqual(2.5_rp, 2.5_rp, 'exact real')
      call assertEqual(3, 3)
      call assertEqual(3_i8, 3_i8, 'i8')
      call assertEqual(3, 3_i8, 'mixed integer kinds')
      call assertEqual([1, 2, 3], [1, 2, 3], 'integer array')
      call assertEqual('water', 'water   ', 'trailing blanks do not matter')
      call assertTrue(.true.)
      call assertFalse(.false., 'assertFalse')
      call assertLessThanOrEqual(1.0_rp, 1.0_rp, 'equal is allowed')
      call assertLessThanOrEqual(1, 2)
      call assertLessThanOrEqual(1_i8, 1_i8)
      call assertRelativelyEqual(1.0e6_rp, 1.0e6_rp + 0.5_rp, 1.0e-6_rp, 'relative')
      call assertRelativelyEqual([1.0e-9_rp, -2.0e9_rp], [1.0e-9_rp, -2.0e9_rp], 1.0e-15_rp)
      n = end_expected_failures()
      call assertEqual(0, n, 'passing assertions counted as failures')
   end subroutine test_passing_assertions_do_not_count

   subroutine test_failing_assertions_count()
      integer :: n
      call begin_expected_failures()
      call assertEqual(1.0_rp, 1.1_rp, 0.01_rp, 'scalar outside tolerance')
      call assertEqual([1.0_rp, 2.0_rp], [1.0_rp, 2.5_rp], 0.1_rp)
      call assertEqual([1.0_rp, 2.0_rp], [1.0_rp, 2.0_rp, 3.0_rp], 0.1_rp, 'size mismatch')
      call assertEqual(reshape([1.0_rp, 2.0_rp], [1, 2]), reshape([1.0_rp, 2.0_rp], [2, 1]), 0.0_rp, 'shape')
      call assertEqual(3, 4)
      call assertEqual(3_i8, 4_i8)
      call assertEqual([1, 2, 3], [1, 5, 3])
      call assertEqual('water', 'sand')
      call assertTrue(.false.)
      call assertFalse(.true.)
      call assertLessThanOrEqual(2.0_rp, 1.0_rp)
      call assertLessThanOrEqual(2, 1)
      call assertRelativelyEqual(100.0_rp, 102.0_rp, 0.01_rp)
      n = end_expected_failures()
      call assertEqual(13, n, 'every failing assertion is counted once')
   end subroutine test_failing_assertions_count

   subroutine test_tolerance_edge_cases()
      real(rp) :: nan, inf, minus_inf
      nan = ieee_value(1.0_rp, ieee_quiet_nan)
      inf = ieee_value(1.0_rp, ieee_positive_inf)
      minus_inf = ieee_value(1.0_rp, ieee_negative_inf)
      call assertFalse(within_tolerance(nan, nan, huge(1.0_rp)), 'NaN never equals NaN')
      call assertFalse(within_tolerance(1.0_rp, nan, huge(1.0_rp)), 'NaN never equals a number')
      call assertTrue(within_tolerance(inf, inf, 0.0_rp), '+inf equals +inf')
      call assertFalse(within_tolerance(inf, minus_inf, huge(1.0_rp)), '+inf differs from -inf')
      call assertFalse(within_tolerance(huge(1.0_rp), inf, huge(1.0_rp)), 'a finite value differs from inf')
      call assertFalse(within_tolerance(huge(1.0_rp), -huge(1.0_rp), 1.0_rp), 'no overflow for +-huge')
      call assertTrue(within_tolerance(1.0_rp, 1.0_rp + epsilon(1.0_rp), epsilon(1.0_rp)), 'tolerance is inclusive')
      call begin_expected_failures()
      call assertLessThanOrEqual(nan, 1.0_rp, 'NaN is not <= anything')
      call assertRelativelyEqual(nan, 1.0_rp, 1.0_rp)
      call assertEqual([1.0_rp, nan], [1.0_rp, nan], 1.0_rp)
      call assertEqual(3, end_expected_failures(), 'NaN comparisons fail without trapping')
   end subroutine test_tolerance_edge_cases

   subroutine test_relative_tolerance_near_zero()
      call assertTrue(within_relative_tolerance(0.0_rp, 0.0_rp, 1.0e-12_rp), 'zero equals zero')
      call assertFalse(within_relative_tolerance(0.0_rp, 1.0e-300_rp, 1.0e-12_rp), 'nothing else is close to zero')
      call assertTrue(within_relative_tolerance(-1.0e-200_rp, -1.0e-200_rp * (1 + 1.0e-13_rp), 1.0e-12_rp), &
                      'tiny values compare relatively')
      call assertFalse(within_relative_tolerance(1.0e-200_rp, 2.0e-200_rp, 1.0e-12_rp), 'and still fail relatively')
      call assertTrue(within_relative_tolerance(-3.0_rp, -3.0_rp * (1 - 1.0e-13_rp), 1.0e-12_rp), 'negative values')
   end subroutine test_relative_tolerance_near_zero
end module test_assertions
