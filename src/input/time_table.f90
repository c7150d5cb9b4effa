!> Quantities that follow a table of time (`&inlet velocity_file`, moving walls): a CSV file with a
!> column `t` [s], strictly increasing, and named value columns (csv_table: any order, any case, other
!> columns ignored, '#' comment lines and blank lines skipped). Between rows the values are linear in t;
!> before the first and after the last row they hold the first and the last row's values. value_at, rate_at
!> and integral are exact for that piecewise-linear function and depend on t alone (no state), so a run
!> and its restart evaluate the same numbers.
module time_table
   use kinds, only: rp, path_len, name_len
   use error_status, only: status_t
   use input_text, only: int_text, real_text, lower_case
   use csv_table, only: read_csv_columns, numbers_checksum, absolute_path
   implicit none
   private

   !> A table of values over time, read by read_time_table.
   type, public :: time_table_t
      character(len=path_len) :: path = ''                  !< absolute path of the file read
      character(len=16) :: checksum = ''                    !< numbers_checksum of (t, values) per row
      character(len=name_len), allocatable :: columns(:)    !< the value columns' names, in the order asked for
      real(rp), allocatable :: time(:)                      !< (n), strictly increasing [s]
      real(rp), allocatable :: values(:, :)                 !< (size(columns), n)
   contains
      procedure :: value_at => table_value_at
      procedure :: rate_at => table_rate_at
      procedure :: integral => table_integral
   end type time_table_t

   public :: read_time_table, time_table_checksum

contains

   !> Read the table of `path` with the value columns `columns` (besides `t`). On error `message` is one
   !> line naming the file (and the line): a missing file or column, a bad number, a time not strictly
   !> increasing, fewer than 2 rows; '' on success.
   subroutine read_time_table(path, columns, table, message)
      character(len=*), intent(in) :: path, columns(:)
      type(time_table_t), intent(out) :: table
      character(len=*), intent(out) :: message
      type(status_t) :: status
      character(len=name_len), allocatable :: names(:)
      character(len=:), allocatable :: absolute
      real(rp), allocatable :: rows(:, :)
      integer, allocatable :: line(:)
      integer :: k, r

      message = ''
      absolute = absolute_path(path)
      if (len(absolute) == 0) then
         message = path//': file not found'
         return
      else if (len(absolute) > path_len) then
         message = absolute//': the path is longer than '//int_text(path_len)//' characters'
         return
      end if
      allocate (names(size(columns) + 1))
      names(1) = 't'
      do k = 1, size(columns)
         names(k + 1) = lower_case(trim(adjustl(columns(k))))
      end do
      call read_csv_columns(absolute, names, 'rows', rows, line, status)
      if (status%ok .and. size(rows, 2) < 2) then
         call status%fail(absolute//': a time table needs at least 2 rows, the file has '//int_text(size(rows, 2)))
      end if
      if (status%ok) then
         do r = 2, size(rows, 2)
            if (.not. rows(1, r) > rows(1, r - 1)) then
               call status%fail(absolute//': line '//int_text(line(r))//': t = '//real_text(rows(1, r))// &
                                ' is not after the previous row''s t = '//real_text(rows(1, r - 1))// &
                                ' (the times must increase strictly)')
               exit
            end if
         end do
      end if
      if (.not. status%ok) then
         message = status%message
         return
      end if
      table%path = absolute
      table%columns = names(2:)
      table%time = rows(1, :)
      table%values = rows(2:, :)
      table%checksum = numbers_checksum(rows)
   end subroutine read_time_table

   !> The checksum read_time_table records: numbers_checksum of (t, values) row by row.
   function time_table_checksum(table) result(text)
      type(time_table_t), intent(in) :: table
      character(len=16) :: text
      real(rp), allocatable :: rows(:, :)
      allocate (rows(size(table%values, 1) + 1, size(table%time)))
      rows(1, :) = table%time
      rows(2:, :) = table%values
      text = numbers_checksum(rows)
   end function time_table_checksum

   !> The row i with time(i) <= t < time(i + 1) (1 <= i < n); 0 before time(1), n from time(n) on.
   pure integer function segment_of(time, t) result(i)
      real(rp), intent(in) :: time(:), t
      integer :: upper, middle
      i = 0
      if (t < time(1)) return
      upper = size(time) + 1
      i = 1
      ! time(i) <= t < time(upper), with time(n + 1) = infinity
      do while (upper - i > 1)
         middle = (i + upper) / 2
         if (t < time(middle)) then
            upper = middle
         else
            i = middle
         end if
      end do
   end function segment_of

   !> The values at time t: linear between rows, the first / last row held outside [time(1), time(n)].
   pure function table_value_at(self, t) result(v)
      class(time_table_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp) :: v(size(self%values, 1))
      integer :: i, n
      real(rp) :: w
      n = size(self%time)
      i = segment_of(self%time, t)
      if (i == 0) then
         v = self%values(:, 1)
      else if (i == n) then
         v = self%values(:, n)
      else
         w = (t - self%time(i)) / (self%time(i + 1) - self%time(i))
         v = (1.0_rp - w) * self%values(:, i) + w * self%values(:, i + 1)
      end if
   end function table_value_at

   !> d values / dt at time t: the slope of the row interval that starts at or before t (the slope after a
   !> row's time at that row); 0 before time(1) and from time(n) on.
   pure function table_rate_at(self, t) result(rate)
      class(time_table_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp) :: rate(size(self%values, 1))
      integer :: i
      i = segment_of(self%time, t)
      rate = 0.0_rp
      if (i == 0 .or. i == size(self%time)) return
      rate = (self%values(:, i + 1) - self%values(:, i)) / (self%time(i + 1) - self%time(i))
   end function table_rate_at

   !> The exact integral of the piecewise-linear values from t0 to t1 (negative if t1 < t0).
   pure function table_integral(self, t0, t1) result(area)
      class(time_table_t), intent(in) :: self
      real(rp), intent(in) :: t0, t1
      real(rp) :: area(size(self%values, 1))
      area = antiderivative(self, t1) - antiderivative(self, t0)
   end function table_integral

   !> F(t) = integral of the values from time(1) to t (trapezoids of the whole intervals before t, summed
   !> in row order, so F depends on t alone).
   pure function antiderivative(table, t) result(f)
      type(time_table_t), intent(in) :: table
      real(rp), intent(in) :: t
      real(rp) :: f(size(table%values, 1))
      integer :: i, j
      f = 0.0_rp
      i = segment_of(table%time, t)
      if (i == 0) then
         f = (t - table%time(1)) * table%values(:, 1)
         return
      end if
      do j = 1, i - 1
         f = f + 0.5_rp * (table%time(j + 1) - table%time(j)) * (table%values(:, j) + table%values(:, j + 1))
      end do
      f = f + 0.5_rp * (t - table%time(i)) * (table%values(:, i) + table%value_at(t))
   end function antiderivative
end module time_table
