!> Checks every scene group's validation makes (src/input/*_validation.f90): a real against its bounds, a
!> name against the identifier rule, and the small tests and texts they share. Each failure names the
!> group, the variable, the rule and the value given.
module input_checks
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use input_text, only: int_text, real_text
   use shape_geometry, only: no_vertex
   implicit none
   private

   public :: check_real, check_upper_above_lower, check_name, is_identifier, is_none, differs, pair_text, given_or, &
             count_text, name_detail

   !> Tolerance of "body inside the grid", in cell sizes.
   real(rp), parameter, public :: inside_tolerance = 1.0e-9_rp
   character(len=1), parameter, public :: axis_letter(3) = ['x', 'y', 'z']

contains

   !> Fail with "<where>: variable upper(k) must be > lower(k) = <lower>, got <upper>" for the first of the
   !> dim axes on which the box lower .. upper has no length (the corners themselves already checked finite).
   subroutine check_upper_above_lower(where, lower, upper, dim, status)
      character(len=*), intent(in) :: where
      real(rp), intent(in) :: lower(:), upper(:)
      integer, intent(in) :: dim
      type(status_t), intent(inout) :: status
      integer :: k
      do k = 1, dim
         if (.not. (upper(k) > lower(k))) then
            call status%fail(where//': variable upper('//int_text(k)//') must be > lower('//int_text(k)//') = '// &
                             real_text(lower(k))//', got '//real_text(upper(k)))
            return
         end if
      end do
   end subroutine check_upper_above_lower

   !> Fail with "<where>: variable <variable> must be <range>, got <value>" unless `value` is finite and
   !> inside the range given by the optional bounds.
   subroutine check_real(where, variable, value, status, greater_than, at_least, less_than, at_most)
      character(len=*), intent(in) :: where, variable
      real(rp), intent(in) :: value
      type(status_t), intent(inout) :: status
      real(rp), intent(in), optional :: greater_than, at_least, less_than, at_most
      character(len=:), allocatable :: range
      logical :: ok

      ! Comparisons only after the finiteness test: NaN must not reach them (-ffpe-trap=invalid).
      ok = ieee_is_finite(value)
      if (ok .and. present(greater_than)) ok = value > greater_than
      if (ok .and. present(at_least)) ok = value >= at_least
      if (ok .and. present(less_than)) ok = value < less_than
      if (ok .and. present(at_most)) ok = value <= at_most
      if (ok) return

      if (present(greater_than) .and. present(at_most)) then
         range = 'in ('//bound_text(greater_than)//', '//bound_text(at_most)//']'
      else if (present(greater_than) .and. present(less_than)) then
         range = 'in ('//bound_text(greater_than)//', '//bound_text(less_than)//')'
      else if (present(at_least) .and. present(at_most)) then
         range = 'in ['//bound_text(at_least)//', '//bound_text(at_most)//']'
      else if (present(greater_than)) then
         range = '> '//bound_text(greater_than)
      else if (present(at_least)) then
         range = '>= '//bound_text(at_least)
      else
         range = 'a finite number'
      end if
      call status%fail(where//': variable '//variable//' must be '//range//', got '//real_text(value))
   end subroutine check_real

   !> A bound in a message: 0 rather than 0.0, so that ranges read "> 0".
   function bound_text(bound) result(text)
      real(rp), intent(in) :: bound
      character(len=:), allocatable :: text
      if (abs(bound - anint(bound)) < tiny(bound) .and. abs(bound) < 1.0e9_rp) then
         text = int_text(nint(bound))
      else
         text = real_text(bound)
      end if
   end function bound_text

   !> Fail unless the name a scene gives (empty: the default name) is a plain identifier.
   subroutine check_name(where, variable, name, status)
      character(len=*), intent(in) :: where, variable, name
      type(status_t), intent(inout) :: status
      if (.not. status%ok .or. len_trim(name) == 0) return
      if (.not. is_identifier(name)) then
         call status%fail(where//': variable '//variable//" must be a plain identifier (a letter, then letters, "// &
                          "digits or '_'), got '"//trim(name)//"'")
      end if
   end subroutine check_name

   !> A name is a plain identifier: a letter, then letters, digits or underscores (no blanks), so that
   !> it can prefix csv columns and be used in plots and scripts as is.
   pure logical function is_identifier(name)
      character(len=*), intent(in) :: name
      integer :: i
      character :: c
      is_identifier = .false.
      if (len_trim(name) == 0) return
      do i = 1, len_trim(name)
         c = name(i:i)
         if (is_letter(c)) cycle
         if (i > 1 .and. (c == '_' .or. (c >= '0' .and. c <= '9'))) cycle
         return
      end do
      is_identifier = .true.
   end function is_identifier

   pure logical function is_letter(c)
      character, intent(in) :: c
      is_letter = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z')
   end function is_letter

   !> The value that marks the end of a vertex list (a NaN is a value given, and reported as such).
   elemental logical function is_none(value)
      real(rp), intent(in) :: value
      is_none = .false.
      if (ieee_is_finite(value)) is_none = value >= no_vertex
   end function is_none

   !> a and b differ (a comparison of given values with their defaults, not of computed ones).
   elemental logical function differs(a, b)
      real(rp), intent(in) :: a, b
      differs = a > b .or. a < b
   end function differs

   !> "'steel', 'wood'" for messages.
   pure function pair_text(names) result(text)
      character(len=*), intent(in) :: names(2)
      character(len=:), allocatable :: text
      text = "'"//trim(names(1))//"', '"//trim(names(2))//"'"
   end function pair_text

   !> `given` if the scene gave it, else `default` (a name of loads.csv).
   pure function given_or(given, default) result(name)
      character(len=*), intent(in) :: given, default
      character(len=name_len) :: name
      name = default
      if (len_trim(given) > 0) name = given
   end function given_or

   !> A particle count: the integer below 1e18, else in exponent form.
   function count_text(n) result(text)
      real(rp), intent(in) :: n
      character(len=:), allocatable :: text
      character(len=16) :: buffer
      if (n < 1.0e18_rp) then
         text = int_text(int(n, i8))
      else
         write (buffer, '(es10.3)') n
         text = trim(adjustl(buffer))
      end if
   end function count_text

   !> "name 'left'" for a message's group context; '' when no name is given.
   pure function name_detail(name) result(detail)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: detail
      detail = ''
      if (len_trim(name) > 0) detail = "name '"//trim(name)//"'"
   end function name_detail
end module input_checks
