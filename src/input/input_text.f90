!> Small text helpers of the scene reader: case folding, keyword lists and the number formatting
!> of error messages (docs/input.md, "Error messages").
module input_text
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use, intrinsic :: ieee_exceptions, only: ieee_overflow, ieee_get_halting_mode, ieee_set_halting_mode, ieee_set_flag
   use kinds, only: rp, i8
   implicit none
   private

   public :: lower_case, upper_case, int_text, real_text, real_list_text, ordinal, quoted_list, quoted, logical_text
   public :: keyword_index, canonical_keyword, group_context

   !> Integer to text, for default and 8-byte integers.
   interface int_text
      module procedure int_text_default, int_text_i8
   end interface int_text

contains

   pure function lower_case(text) result(folded)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: folded
      folded = shifted_letters(text, 'A', 'Z', 32)
   end function lower_case

   pure function upper_case(text) result(folded)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: folded
      folded = shifted_letters(text, 'a', 'z', -32)
   end function upper_case

   !> `text` with the ASCII letters first .. last moved by `shift` codes (the other case).
   pure function shifted_letters(text, first, last, shift) result(folded)
      character(len=*), intent(in) :: text
      character(len=1), intent(in) :: first, last
      integer, intent(in) :: shift
      character(len=len(text)) :: folded
      integer :: i, code
      folded = text
      do i = 1, len(text)
         code = iachar(text(i:i))
         if (code >= iachar(first) .and. code <= iachar(last)) folded(i:i) = achar(code + shift)
      end do
   end function shifted_letters

   pure function int_text_default(value) result(text)
      integer, intent(in) :: value
      character(len=:), allocatable :: text
      character(len=24) :: buffer
      write (buffer, '(i0)') value
      text = trim(buffer)
   end function int_text_default

   pure function int_text_i8(value) result(text)
      integer(i8), intent(in) :: value
      character(len=:), allocatable :: text
      character(len=24) :: buffer
      write (buffer, '(i0)') value
      text = trim(buffer)
   end function int_text_i8

   !> "1.0, -9.81, 0.0": each value as real_text writes it.
   function real_list_text(values) result(text)
      real(rp), intent(in) :: values(:)
      character(len=:), allocatable :: text
      integer :: i
      text = real_text(values(1))
      do i = 2, size(values)
         text = text//', '//real_text(values(i))
      end do
   end function real_list_text

   !> Shortest decimal text that reads back as exactly `value`: 0.5, -1.0, 2200000000.0, 1.0e-10.
   function real_text(value) result(text)
      real(rp), intent(in) :: value
      character(len=:), allocatable :: text
      character(len=48) :: buffer
      character(len=24) :: form
      character(len=:), allocatable :: digits, sign
      real(rp) :: back
      integer :: significant, mark, exponent, ios
      logical :: halting

      if (ieee_is_nan(value)) then
         text = 'NaN'
         return
      else if (.not. ieee_is_finite(value)) then
         text = merge('+Infinity', '-Infinity', value > 0.0_rp)
         return
      else if (.not. (value > 0.0_rp .or. value < 0.0_rp)) then
         text = '0.0'
         return
      end if
      ! Near huge() a rounded text can lie beyond it (2.0e308): reading it back must give no trap.
      call ieee_get_halting_mode(ieee_overflow, halting)
      call ieee_set_halting_mode(ieee_overflow, .false.)
      do significant = 1, 17
         write (form, '(a, i0, a)') '(es40.', significant - 1, 'e4)'
         write (buffer, form) value
         read (buffer, *, iostat=ios) back
         ! Bitwise equality: the text must read back as exactly this value.
         if (ios == 0 .and. transfer(back, 0_i8) == transfer(value, 0_i8)) exit
      end do
      call ieee_set_flag(ieee_overflow, .false.)
      call ieee_set_halting_mode(ieee_overflow, halting)
      buffer = adjustl(buffer)
      sign = ''
      if (buffer(1:1) == '-') then
         sign = '-'
         buffer = buffer(2:)
      end if
      mark = index(buffer, 'E')
      read (buffer(mark + 1:), *) exponent
      ! Mantissa digits without the decimal point, trailing zeros removed.
      digits = buffer(1:1)//buffer(3:mark - 1)
      do while (len(digits) > 1)
         if (digits(len(digits):len(digits)) /= '0') exit
         digits = digits(1:len(digits) - 1)
      end do
      if (exponent >= 0 .and. exponent < 16) then
         if (len(digits) <= exponent + 1) then
            text = sign//digits//repeat('0', exponent + 1 - len(digits))//'.0'
         else
            text = sign//digits(1:exponent + 1)//'.'//digits(exponent + 2:)
         end if
      else if (exponent < 0 .and. exponent >= -4) then
         text = sign//'0.'//repeat('0', -exponent - 1)//digits
      else if (len(digits) == 1) then
         text = sign//digits//'.0e'//int_text(exponent)
      else
         text = sign//digits(1:1)//'.'//digits(2:)//'e'//int_text(exponent)
      end if
   end function real_text

   !> 1st, 2nd, 3rd, 4th, ..., 11th, 12th, 13th, ..., 21st.
   pure function ordinal(n) result(text)
      integer, intent(in) :: n
      character(len=:), allocatable :: text
      character(len=2) :: suffix
      select case (mod(n, 10))
      case (1)
         suffix = 'st'
      case (2)
         suffix = 'nd'
      case (3)
         suffix = 'rd'
      case default
         suffix = 'th'
      end select
      if (mod(n, 100) >= 11 .and. mod(n, 100) <= 13) suffix = 'th'
      text = int_text(n)//suffix
   end function ordinal

   !> "'none', 'slip', 'no_slip'"
   pure function quoted_list(words) result(text)
      character(len=*), intent(in) :: words(:)
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, size(words)
         if (i > 1) text = text//', '
         text = text//"'"//trim(words(i))//"'"
      end do
   end function quoted_list

   !> Position of `word` in `keywords`, compared without regard to case and trailing blanks; 0 if absent.
   pure integer function keyword_index(word, keywords) result(found)
      character(len=*), intent(in) :: word
      character(len=*), intent(in) :: keywords(:)
      integer :: i
      found = 0
      do i = 1, size(keywords)
         if (lower_case(trim(word)) == lower_case(trim(keywords(i)))) then
            found = i
            return
         end if
      end do
   end function keyword_index

   !> The spelling of `word` in `keywords` if it is one of them in any case, else `word` unchanged.
   pure function canonical_keyword(word, keywords) result(spelled)
      character(len=*), intent(in) :: word
      character(len=*), intent(in) :: keywords(:)
      character(len=len(word)) :: spelled
      integer :: found
      found = keyword_index(word, keywords)
      if (found > 0) then
         spelled = keywords(found)
      else
         spelled = word
      end if
   end function canonical_keyword

   !> Where a message is about: "scene.nml: group &run" or, for the n-th of a repeated group,
   !> "scene.nml: group &material (2nd, name 'water')". `occurrence` 0 marks a singleton group.
   pure function group_context(path, group, occurrence, detail) result(text)
      character(len=*), intent(in) :: path, group
      integer, intent(in) :: occurrence
      character(len=*), intent(in), optional :: detail
      character(len=:), allocatable :: text
      text = trim(path)//': group &'//trim(group)
      if (occurrence > 0) then
         text = text//' ('//ordinal(occurrence)
         if (present(detail)) then
            if (len_trim(detail) > 0) text = text//', '//trim(detail)
         end if
         text = text//')'
      end if
   end function group_context

   !> 'text' with an apostrophe doubled, trailing blanks removed.
   pure function quoted(value) result(text)
      character(len=*), intent(in) :: value
      character(len=:), allocatable :: text
      integer :: i
      text = "'"
      do i = 1, len_trim(value)
         text = text//value(i:i)
         if (value(i:i) == "'") text = text//"'"
      end do
      text = text//"'"
   end function quoted

   pure function logical_text(value) result(text)
      logical, intent(in) :: value
      character(len=:), allocatable :: text
      text = merge('.true. ', '.false.', value)
      text = trim(text)
   end function logical_text
end module input_text
