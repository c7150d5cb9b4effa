!> A CSV file written row by row and flushed after each row, so a killed run leaves at most one partial
!> row, at the end; `keep_rows_until` and `keep_rows_through_time` cut a file back to the rows of a
!> restart point. Lines starting with '#' are comments (what the file holds, its units): they are kept.
module csv_writer
   use kinds, only: i8, rp
   use error_status, only: status_t
   use file_system, only: rename_path
   use output_layout, only: temporary_suffix
   implicit none
   private

   public :: keep_rows_until, keep_rows_through_time

   !> Longest line a file to be continued may hold (a row of many walls or gauges).
   integer, parameter :: max_line = 65536

   type, public :: csv_writer_t
      integer :: unit = 0
      logical :: is_open = .false.    !< newunit= numbers are negative: track the state separately
   contains
      procedure :: open => csv_open
      procedure :: write_row => csv_write_row
      procedure :: close => csv_close
   end type csv_writer_t

contains

   !> Start `path` with the `header` row, or with `append`, continue an existing file after its last row.
   subroutine csv_open(self, path, header, status, append)
      class(csv_writer_t), intent(inout) :: self
      character(len=*), intent(in) :: path, header
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: append
      integer :: ios
      logical :: continuing
      character(len=256) :: msg
      continuing = .false.
      if (present(append)) continuing = append
      if (continuing) then
         open (newunit=self%unit, file=path, status='old', position='append', action='write', iostat=ios, iomsg=msg)
      else
         open (newunit=self%unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      end if
      if (ios /= 0) then
         call status%fail('cannot open '//trim(path)//': '//trim(msg))
         return
      end if
      self%is_open = .true.
      if (.not. continuing) call self%write_row(header)
   end subroutine csv_open

   subroutine csv_write_row(self, line)
      class(csv_writer_t), intent(inout) :: self
      character(len=*), intent(in) :: line
      if (.not. self%is_open) return
      write (self%unit, '(a)') line
      flush (self%unit)
   end subroutine csv_write_row

   subroutine csv_close(self)
      class(csv_writer_t), intent(inout) :: self
      if (self%is_open) close (self%unit)
      self%is_open = .false.
   end subroutine csv_close

   !> Keep the header of CSV file `path` and its leading rows whose integer in column `column` is
   !> <= `last`; drop the rest (rows of a run continued from an earlier point, a partial last row).
   !> The file is rewritten under a temporary name and renamed.
   subroutine keep_rows_until(path, column, last, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: column
      integer(i8), intent(in) :: last
      type(status_t), intent(inout) :: status
      call keep_leading_rows(path, column, real(last, rp), status)
   end subroutine keep_rows_until

   !> Keep the header, comments and leading rows of `path` whose time (column 1) is <= `last_time`.
   subroutine keep_rows_through_time(path, last_time, status)
      character(len=*), intent(in) :: path
      real(rp), intent(in) :: last_time
      type(status_t), intent(inout) :: status
      call keep_leading_rows(path, 1, last_time, status)
   end subroutine keep_rows_through_time

   !> Keep the header, the comment lines and the leading rows whose number in column `column` is <= last.
   subroutine keep_leading_rows(path, column, last, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: column
      real(rp), intent(in) :: last
      type(status_t), intent(inout) :: status
      integer :: input, output, ios, ios_read, first, k, fields
      real(rp) :: value
      character(len=max_line) :: line
      character(len=256) :: msg
      logical :: header_seen
      open (newunit=input, file=path, status='old', action='read', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call status%fail('cannot read '//path//' to continue it: '//trim(msg))
         return
      end if
      open (newunit=output, file=path//temporary_suffix, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         close (input)
         call status%fail('cannot write '//path//temporary_suffix//': '//trim(msg))
         return
      end if
      header_seen = .false.
      fields = 0
      do
         read (input, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:1) == '#') then
            write (output, '(a)') trim(line)
            cycle
         end if
         if (.not. header_seen) then
            header_seen = .true.
            fields = count_commas(line)
            write (output, '(a)') trim(line)
            cycle
         end if
         if (count_commas(line) /= fields) exit      ! a row cut short by a crash
         ! the field after the (column - 1)-th comma
         first = 1
         do k = 1, column - 1
            first = first + index(line(first:), ',')
         end do
         value = huge(value)
         k = index(line(first:), ',')
         if (k == 0) k = len_trim(line(first:)) + 1
         if (k > 1) read (line(first:first + k - 2), *, iostat=ios_read) value
         if (k > 1 .and. ios_read /= 0) value = huge(value)
         if (value > last) exit
         write (output, '(a)') trim(line)
      end do
      close (input)
      close (output)
      if (.not. rename_path(path//temporary_suffix, path)) call status%fail('cannot rename '//path//temporary_suffix)
   end subroutine keep_leading_rows

   pure integer function count_commas(line)
      character(len=*), intent(in) :: line
      integer :: i
      count_commas = 0
      do i = 1, len_trim(line)
         if (line(i:i) == ',') count_commas = count_commas + 1
      end do
   end function count_commas
end module csv_writer
