!> Assertions of the Flotsam test framework, with pFUnit's names and argument order.
!>
!> A failed assertion prints one line
!>   FAIL <test name>: <message> (expected ..., actual ..., tolerance ...)
!> counts the failure and returns: the test goes on, so one run reports every broken check.
!> The runner (test_runner) reads failure_count() before and after each test to decide its result.
!> Nothing here uses MPI: on several ranks each rank counts its own failures and the runner reduces.
module assertions
   use, intrinsic :: iso_fortran_env, only: output_unit
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite
   use kinds, only: rp, i8
   implicit none
   private

   public :: assertEqual, assertTrue, assertFalse, assertLessThanOrEqual, assertRelativelyEqual
   public :: set_current_test, failure_count, begin_expected_failures, end_expected_failures
   public :: within_tolerance, within_relative_tolerance

   !> assertEqual(expected, actual, tolerance[, message]) for reals (absolute tolerance);
   !> assertEqual(expected, actual[, message]) for integers, strings and exact reals.
   interface assertEqual
      module procedure assert_equal_real_tol, assert_equal_real_1d_tol, assert_equal_real_2d_tol
      module procedure assert_equal_real_0d_1d_tol
      module procedure assert_equal_real, assert_equal_real_1d
      module procedure assert_equal_int, assert_equal_i8, assert_equal_int_i8, assert_equal_i8_int
      module procedure assert_equal_int_1d, assert_equal_string
   end interface assertEqual

   !> assertLessThanOrEqual(a, b[, message]) passes when a <= b.
   interface assertLessThanOrEqual
      module procedure assert_less_equal_real, assert_less_equal_int, assert_less_equal_i8
   end interface assertLessThanOrEqual

   !> assertRelativelyEqual(expected, actual, rel_tol[, message]): |actual - expected| <= rel_tol |expected|.
   interface assertRelativelyEqual
      module procedure assert_relatively_equal, assert_relatively_equal_1d
   end interface assertRelativelyEqual

   character(len=:), allocatable :: test_name      ! name printed in FAIL lines
   character(len=:), allocatable :: rank_label     ! ' [rank r of n]' in MPI tests with several ranks
   integer :: failures = 0                         ! failed assertions since the program started
   logical :: capturing = .false.                  ! inside begin/end_expected_failures
   integer :: captured_failures = 0

contains

   !> Name the running test in FAIL lines (the runner calls this; `label` is appended to each line).
   subroutine set_current_test(name, label)
      character(len=*), intent(in) :: name
      character(len=*), intent(in), optional :: label
      test_name = trim(name)
      rank_label = ''
      if (present(label)) rank_label = label
   end subroutine set_current_test

   !> Number of failed assertions of this process so far.
   integer function failure_count()
      failure_count = failures
   end function failure_count

   !> Start counting failures silently and without failing the test: for tests of the framework itself.
   subroutine begin_expected_failures()
      capturing = .true.
      captured_failures = 0
   end subroutine begin_expected_failures

   !> Stop the silent count started by begin_expected_failures and return it.
   integer function end_expected_failures()
      end_expected_failures = captured_failures
      capturing = .false.
      captured_failures = 0
   end function end_expected_failures

   !> |actual - expected| <= tolerance; false when either is NaN; infinities only match themselves.
   elemental logical function within_tolerance(expected, actual, tolerance)
      real(rp), intent(in) :: expected, actual, tolerance
      if (ieee_is_nan(expected) .or. ieee_is_nan(actual)) then
         within_tolerance = .false.
      else if (.not. (ieee_is_finite(expected) .and. ieee_is_finite(actual))) then
         within_tolerance = same_infinity(expected, actual)
      else
         ! Halved so that huge values of opposite sign cannot overflow (the Debug build traps overflow).
         within_tolerance = abs(0.5_rp * actual - 0.5_rp * expected) <= 0.5_rp * tolerance
      end if
   end function within_tolerance

   !> |actual - expected| <= rel_tol * max(|expected|, tiny): near expected = 0 only an exact (or
   !> subnormal) zero passes; compare with an absolute tolerance (assertEqual) where zero is expected.
   elemental logical function within_relative_tolerance(expected, actual, rel_tol)
      real(rp), intent(in) :: expected, actual, rel_tol
      if (ieee_is_nan(expected) .or. ieee_is_nan(actual)) then
         within_relative_tolerance = .false.
      else if (.not. (ieee_is_finite(expected) .and. ieee_is_finite(actual))) then
         within_relative_tolerance = same_infinity(expected, actual)
      else
         within_relative_tolerance = abs(0.5_rp * actual - 0.5_rp * expected) &
                                     <= 0.5_rp * rel_tol * max(abs(expected), tiny(1.0_rp))
      end if
   end function within_relative_tolerance

   elemental logical function same_infinity(x, y)
      real(rp), intent(in) :: x, y
      same_infinity = .not. ieee_is_finite(x) .and. .not. ieee_is_finite(y) .and. ((x > 0.0_rp) .eqv. (y > 0.0_rp))
   end function same_infinity

   ! --- reals -------------------------------------------------------------------------------------

   subroutine assert_equal_real_tol(expected, actual, tolerance, message)
      real(rp), intent(in) :: expected, actual, tolerance
      character(len=*), intent(in), optional :: message
      if (within_tolerance(expected, actual, tolerance)) return
      call record_failure('assertEqual', message, 'expected '//real_text(expected)//', actual '//real_text(actual) &
                          //', tolerance '//real_text(tolerance))
   end subroutine assert_equal_real_tol

   subroutine assert_equal_real_1d_tol(expected, actual, tolerance, message)
      real(rp), intent(in) :: expected(:), actual(:), tolerance
      character(len=*), intent(in), optional :: message
      logical :: matches(size(actual))
      integer :: i
      if (size(expected) /= size(actual)) then
         call record_failure('assertEqual', message, 'expected size '//int_text(size(expected)) &
                             //', actual size '//int_text(size(actual)))
         return
      end if
      matches = within_tolerance(expected, actual, tolerance)
      if (all(matches)) return
      i = findloc(matches, .false., dim=1)
      call record_failure('assertEqual', message, 'expected '//real_text(expected(i))//', actual ' &
                          //real_text(actual(i))//', tolerance '//real_text(tolerance)//'; at index ' &
                          //int_text(i)//', '//int_text(count(.not. matches))//' of '//int_text(size(matches)) &
                          //' elements differ')
   end subroutine assert_equal_real_1d_tol

   subroutine assert_equal_real_2d_tol(expected, actual, tolerance, message)
      real(rp), intent(in) :: expected(:, :), actual(:, :), tolerance
      character(len=*), intent(in), optional :: message
      logical :: matches(size(actual, 1), size(actual, 2))
      integer :: ij(2)
      if (any(shape(expected) /= shape(actual))) then
         call record_failure('assertEqual', message, 'expected shape ('//int_text(size(expected, 1))//',' &
                             //int_text(size(expected, 2))//'), actual shape ('//int_text(size(actual, 1)) &
                             //','//int_text(size(actual, 2))//')')
         return
      end if
      matches = within_tolerance(expected, actual, tolerance)
      if (all(matches)) return
      ij = findloc(matches, .false.)
      call record_failure('assertEqual', message, 'expected '//real_text(expected(ij(1), ij(2)))//', actual ' &
                          //real_text(actual(ij(1), ij(2)))//', tolerance '//real_text(tolerance)//'; at (' &
                          //int_text(ij(1))//','//int_text(ij(2))//'), '//int_text(count(.not. matches))//' of ' &
                          //int_text(size(matches))//' elements differ')
   end subroutine assert_equal_real_2d_tol

   !> One expected value for every element of `actual`.
   subroutine assert_equal_real_0d_1d_tol(expected, actual, tolerance, message)
      real(rp), intent(in) :: expected, actual(:), tolerance
      character(len=*), intent(in), optional :: message
      call assert_equal_real_1d_tol(spread(expected, 1, size(actual)), actual, tolerance, message)
   end subroutine assert_equal_real_0d_1d_tol

   !> Exact comparison (tolerance 0), as pFUnit does without a tolerance.
   subroutine assert_equal_real(expected, actual, message)
      real(rp), intent(in) :: expected, actual
      character(len=*), intent(in), optional :: message
      call assert_equal_real_tol(expected, actual, 0.0_rp, message)
   end subroutine assert_equal_real

   subroutine assert_equal_real_1d(expected, actual, message)
      real(rp), intent(in) :: expected(:), actual(:)
      character(len=*), intent(in), optional :: message
      call assert_equal_real_1d_tol(expected, actual, 0.0_rp, message)
   end subroutine assert_equal_real_1d

   subroutine assert_relatively_equal(expected, actual, rel_tol, message)
      real(rp), intent(in) :: expected, actual, rel_tol
      character(len=*), intent(in), optional :: message
      if (within_relative_tolerance(expected, actual, rel_tol)) return
      call record_failure('assertRelativelyEqual', message, 'expected '//real_text(expected)//', actual ' &
                          //real_text(actual)//', relative tolerance '//real_text(rel_tol)//zero_hint(expected))
   end subroutine assert_relatively_equal

   subroutine assert_relatively_equal_1d(expected, actual, rel_tol, message)
      real(rp), intent(in) :: expected(:), actual(:), rel_tol
      character(len=*), intent(in), optional :: message
      logical :: matches(size(actual))
      integer :: i
      if (size(expected) /= size(actual)) then
         call record_failure('assertRelativelyEqual', message, 'expected size '//int_text(size(expected)) &
                             //', actual size '//int_text(size(actual)))
         return
      end if
      matches = within_relative_tolerance(expected, actual, rel_tol)
      if (all(matches)) return
      i = findloc(matches, .false., dim=1)
      call record_failure('assertRelativelyEqual', message, 'expected '//real_text(expected(i))//', actual ' &
                          //real_text(actual(i))//', relative tolerance '//real_text(rel_tol)//'; at index ' &
                          //int_text(i)//', '//int_text(count(.not. matches))//' of '//int_text(size(matches)) &
                          //' elements differ'//zero_hint(expected(i)))
   end subroutine assert_relatively_equal_1d

   subroutine assert_less_equal_real(a, b, message)
      real(rp), intent(in) :: a, b
      character(len=*), intent(in), optional :: message
      ! NaN first: an ordered comparison with NaN raises 'invalid', which the Debug build traps.
      if (.not. (ieee_is_nan(a) .or. ieee_is_nan(b))) then
         if (a <= b) return
      end if
      call record_failure('assertLessThanOrEqual', message, 'expected <= '//real_text(b)//', actual '//real_text(a))
   end subroutine assert_less_equal_real

   ! --- integers, strings, logicals -------------------------------------------------------------

   subroutine assert_equal_int(expected, actual, message)
      integer, intent(in) :: expected, actual
      character(len=*), intent(in), optional :: message
      if (expected == actual) return
      call record_failure('assertEqual', message, 'expected '//int_text(expected)//', actual '//int_text(actual))
   end subroutine assert_equal_int

   subroutine assert_equal_i8(expected, actual, message)
      integer(i8), intent(in) :: expected, actual
      character(len=*), intent(in), optional :: message
      if (expected == actual) return
      call record_failure('assertEqual', message, 'expected '//i8_text(expected)//', actual '//i8_text(actual))
   end subroutine assert_equal_i8

   subroutine assert_equal_int_i8(expected, actual, message)
      integer, intent(in) :: expected
      integer(i8), intent(in) :: actual
      character(len=*), intent(in), optional :: message
      call assert_equal_i8(int(expected, i8), actual, message)
   end subroutine assert_equal_int_i8

   subroutine assert_equal_i8_int(expected, actual, message)
      integer(i8), intent(in) :: expected
      integer, intent(in) :: actual
      character(len=*), intent(in), optional :: message
      call assert_equal_i8(expected, int(actual, i8), message)
   end subroutine assert_equal_i8_int

   subroutine assert_equal_int_1d(expected, actual, message)
      integer, intent(in) :: expected(:), actual(:)
      character(len=*), intent(in), optional :: message
      integer :: i
      if (size(expected) /= size(actual)) then
         call record_failure('assertEqual', message, 'expected size '//int_text(size(expected)) &
                             //', actual size '//int_text(size(actual)))
         return
      end if
      if (all(expected == actual)) return
      i = findloc(expected == actual, .false., dim=1)
      call record_failure('assertEqual', message, 'expected '//int_text(expected(i))//', actual ' &
                          //int_text(actual(i))//'; at index '//int_text(i)//', ' &
                          //int_text(count(expected /= actual))//' of '//int_text(size(actual))//' elements differ')
   end subroutine assert_equal_int_1d

   subroutine assert_less_equal_int(a, b, message)
      integer, intent(in) :: a, b
      character(len=*), intent(in), optional :: message
      if (a <= b) return
      call record_failure('assertLessThanOrEqual', message, 'expected <= '//int_text(b)//', actual '//int_text(a))
   end subroutine assert_less_equal_int

   subroutine assert_less_equal_i8(a, b, message)
      integer(i8), intent(in) :: a, b
      character(len=*), intent(in), optional :: message
      if (a <= b) return
      call record_failure('assertLessThanOrEqual', message, 'expected <= '//i8_text(b)//', actual ' &
                          //i8_text(a))
   end subroutine assert_less_equal_i8

   !> Strings compare as Fortran does: trailing blanks do not matter.
   subroutine assert_equal_string(expected, actual, message)
      character(len=*), intent(in) :: expected, actual
      character(len=*), intent(in), optional :: message
      if (expected == actual) return
      call record_failure('assertEqual', message, 'expected "'//trim(expected)//'", actual "'//trim(actual)//'"')
   end subroutine assert_equal_string

   subroutine assertTrue(condition, message)
      logical, intent(in) :: condition
      character(len=*), intent(in), optional :: message
      if (condition) return
      call record_failure('assertTrue', message, 'expected .true., actual .false.')
   end subroutine assertTrue

   subroutine assertFalse(condition, message)
      logical, intent(in) :: condition
      character(len=*), intent(in), optional :: message
      if (.not. condition) return
      call record_failure('assertFalse', message, 'expected .false., actual .true.')
   end subroutine assertFalse

   ! --- reporting ---------------------------------------------------------------------------------

   subroutine record_failure(assertion, message, details)
      character(len=*), intent(in) :: assertion
      character(len=*), intent(in), optional :: message
      character(len=*), intent(in) :: details
      character(len=:), allocatable :: text
      if (capturing) then
         captured_failures = captured_failures + 1
         return
      end if
      failures = failures + 1
      text = assertion//' failed'
      if (present(message)) then
         if (len_trim(message) > 0) text = trim(message)
      end if
      if (.not. allocated(test_name)) call set_current_test('(no test)')
      write (output_unit, '(a)') 'FAIL '//test_name//': '//text//' ('//details//')'//rank_label
      flush (output_unit)
   end subroutine record_failure

   function zero_hint(expected) result(hint)
      real(rp), intent(in) :: expected
      character(len=:), allocatable :: hint
      hint = ''
      if (ieee_is_nan(expected)) return
      if (abs(expected) < tiny(1.0_rp)) hint = '; expected is zero: use assertEqual with an absolute tolerance'
   end function zero_hint

   function real_text(x) result(text)
      real(rp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buffer
      write (buffer, '(es24.16e3)') x
      text = trim(adjustl(buffer))
   end function real_text

   function int_text(i) result(text)
      integer, intent(in) :: i
      character(len=:), allocatable :: text
      character(len=16) :: buffer
      write (buffer, '(i0)') i
      text = trim(buffer)
   end function int_text

   function i8_text(i) result(text)
      integer(i8), intent(in) :: i
      character(len=:), allocatable :: text
      character(len=24) :: buffer
      write (buffer, '(i0)') i
      text = trim(buffer)
   end function i8_text
end module assertions
