!> Tests of src/input/time_table.f90: a table read from a CSV file (columns in any order and case, other
!> columns, comments and blank lines), its interpolation, rate and exact integral against values computed
!> by hand, and a one-line message naming the file and line for each kind of bad table.
module test_time_table
   use kinds, only: rp, message_len
   use assertions, only: assertEqual, assertTrue
   use time_table, only: time_table_t, read_time_table, time_table_checksum
   implicit none
   private

   public :: test_read_any_order_and_comments, test_value_at, test_rate_at, test_integral, test_bad_tables

   character(len=*), parameter :: nl = new_line('a')
   real(rp), parameter :: tol = 1.0e-14_rp

   !> v = 0, 2, 2, 1 and H = 0.2, 0.2, 0.4, 0.4 at t = 0, 1, 3, 4 (header in another order and case, an
   !> extra column, comments, a blank line, a Windows line end).
   character(len=*), parameter :: hydrograph = &
      '# a hydrograph'//nl// &
      'T, Height, note, Velocity'//nl// &
      '0.0, 0.2, a, 0.0'//nl// &
      '  # comment between rows'//nl// &
      '1.0, 0.2, b, 2.0'//achar(13)//nl// &
      nl// &
      '3.0, 0.4, c, 2.0'//nl// &
      '4e0, 0.4, d, 1.0'

contains

   subroutine write_file(path, text)
      character(len=*), intent(in) :: path, text
      integer :: unit
      open (newunit=unit, file=path, status='replace', action='write', access='stream', form='unformatted')
      write (unit) text
      close (unit)
   end subroutine write_file

   subroutine read_hydrograph(table)
      type(time_table_t), intent(out) :: table
      character(len=message_len) :: message
      call write_file('time_table_hydrograph.csv', hydrograph)
      call read_time_table('time_table_hydrograph.csv', ['velocity', 'height  '], table, message)
      call assertEqual('', trim(message), 'the hydrograph reads')
   end subroutine read_hydrograph

   subroutine test_read_any_order_and_comments()
      type(time_table_t) :: table, changed
      character(len=message_len) :: message
      call read_hydrograph(table)
      call assertEqual(4, size(table%time), 'four rows')
      call assertEqual([0.0_rp, 1.0_rp, 3.0_rp, 4.0_rp], table%time, 0.0_rp, 'times')
      call assertEqual([0.0_rp, 2.0_rp, 2.0_rp, 1.0_rp], table%values(1, :), 0.0_rp, 'velocity column first')
      call assertEqual([0.2_rp, 0.2_rp, 0.4_rp, 0.4_rp], table%values(2, :), 0.0_rp, 'height column second')
      call assertEqual('velocity', trim(table%columns(1)), 'first column name')
      call assertEqual('height', trim(table%columns(2)), 'second column name')
      call assertTrue(table%path(1:1) == '/', 'absolute path')
      call assertTrue(index(table%path, '/time_table_hydrograph.csv') > 0, 'path names the file')
      call assertEqual(16, len_trim(table%checksum), 'checksum of 16 digits')
      call assertEqual(table%checksum, time_table_checksum(table), 'checksum recomputed from the numbers')
      ! one value changed in the last digit: another checksum
      call write_file('time_table_changed.csv', hydrograph(1:len(hydrograph) - 1)//'1')
      call read_time_table('time_table_changed.csv', ['velocity', 'height  '], changed, message)
      call assertEqual('', trim(message), 'the changed file reads')
      call assertTrue(changed%checksum /= table%checksum, 'a changed number changes the checksum')
   end subroutine test_read_any_order_and_comments

   subroutine test_value_at()
      type(time_table_t) :: table
      call read_hydrograph(table)
      call assertEqual([0.0_rp, 0.2_rp], table%value_at(-1.0_rp), tol, 'before the first row: held')
      call assertEqual([0.0_rp, 0.2_rp], table%value_at(0.0_rp), tol, 'at the first row')
      call assertEqual([1.0_rp, 0.2_rp], table%value_at(0.5_rp), tol, 'inside the first interval')
      call assertEqual([2.0_rp, 0.2_rp], table%value_at(1.0_rp), tol, 'at a row')
      call assertEqual([2.0_rp, 0.3_rp], table%value_at(2.0_rp), tol, 'height ramps')
      call assertEqual([1.5_rp, 0.4_rp], table%value_at(3.5_rp), tol, 'velocity falls')
      call assertEqual([1.0_rp, 0.4_rp], table%value_at(4.0_rp), tol, 'at the last row')
      call assertEqual([1.0_rp, 0.4_rp], table%value_at(10.0_rp), tol, 'after the last row: held')
   end subroutine test_value_at

   subroutine test_rate_at()
      type(time_table_t) :: table
      call read_hydrograph(table)
      call assertEqual([0.0_rp, 0.0_rp], table%rate_at(-1.0_rp), tol, 'before the first row')
      call assertEqual([2.0_rp, 0.0_rp], table%rate_at(0.0_rp), tol, 'at the first row: the slope after it')
      call assertEqual([2.0_rp, 0.0_rp], table%rate_at(0.5_rp), tol, 'first interval')
      call assertEqual([0.0_rp, 0.1_rp], table%rate_at(1.0_rp), tol, 'at a row: the slope after it')
      call assertEqual([0.0_rp, 0.1_rp], table%rate_at(2.0_rp), tol, 'second interval')
      call assertEqual([-1.0_rp, 0.0_rp], table%rate_at(3.5_rp), tol, 'third interval')
      call assertEqual([0.0_rp, 0.0_rp], table%rate_at(4.0_rp), tol, 'at the last row')
      call assertEqual([0.0_rp, 0.0_rp], table%rate_at(5.0_rp), tol, 'after the last row')
   end subroutine test_rate_at

   subroutine test_integral()
      type(time_table_t) :: table
      call read_hydrograph(table)
      call assertEqual([1.0_rp, 0.2_rp], table%integral(0.0_rp, 1.0_rp), tol, 'first interval')
      call assertEqual([6.5_rp, 1.2_rp], table%integral(0.0_rp, 4.0_rp), tol, 'whole table')
      call assertEqual([0.25_rp, 0.3_rp], table%integral(-1.0_rp, 0.5_rp), tol, 'from before the first row')
      call assertEqual([2.625_rp, 1.0_rp], table%integral(3.5_rp, 6.0_rp), tol, 'beyond the last row')
      call assertEqual([-2.75_rp, -0.35_rp], table%integral(2.0_rp, 0.5_rp), tol, 'backwards: negative')
      call assertEqual([0.0_rp, 0.0_rp], table%integral(2.0_rp, 2.0_rp), tol, 'empty interval')
      call assertEqual([2.9375_rp, 0.4_rp], table%integral(1.25_rp, 2.0_rp) + table%integral(0.25_rp, 1.25_rp), &
                       tol, 'additive across a row')
   end subroutine test_integral

   subroutine test_bad_tables()
      call expect_error('time_table_not_increasing.csv', 't,velocity'//nl//'0,1'//nl//'1,2'//nl//'# c'//nl//'1,3', &
                        'time_table_not_increasing.csv: line 5: t = 1', 'the times must increase strictly')
      call expect_error('time_table_bad_number.csv', 't,velocity'//nl//'0,1'//nl//'1,O.5', &
                        'time_table_bad_number.csv: line 3: column velocity', "'O.5' is not a finite number")
      call expect_error('time_table_missing_column.csv', '# t, velocity'//nl//'t,speed'//nl//'0,1'//nl//'1,2', &
                        'time_table_missing_column.csv: line 2: the header names no column velocity', &
                        '(it must name t and velocity)')
      call expect_error('time_table_one_row.csv', 't,velocity'//nl//'0,1'//nl, &
                        'time_table_one_row.csv: ', 'a time table needs at least 2 rows, the file has 1')
      call expect_error('time_table_empty.csv', '# nothing'//nl, 'time_table_empty.csv: no header line (t, velocity)', &
                        'no rows')
      call expect_error('', '', 'time_table_no_such_file.csv: file not found', 'time_table_no_such_file.csv')
   end subroutine test_bad_tables

   !> Reading `text` as file `path` ('' : no file, read time_table_no_such_file.csv) fails with a message
   !> of one line containing `first` and `second`.
   subroutine expect_error(path, text, first, second)
      character(len=*), intent(in) :: path, text, first, second
      type(time_table_t) :: table
      character(len=message_len) :: message
      character(len=:), allocatable :: name
      name = path
      if (len(path) == 0) then
         name = 'time_table_no_such_file.csv'
      else
         call write_file(path, text)
      end if
      call read_time_table(name, ['velocity'], table, message)
      call assertTrue(index(message, first) > 0, name//': message "'//trim(message)//'" contains "'//first//'"')
      call assertTrue(index(message, second) > 0, name//': message "'//trim(message)//'" contains "'//second//'"')
      call assertTrue(index(trim(message), nl) == 0, name//': one line')
   end subroutine expect_error
end module test_time_table
