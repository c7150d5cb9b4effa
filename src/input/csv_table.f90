!> Numeric tables in CSV files that the scene points to (`&body points_file`, `&inlet velocity_file`):
!> a header line naming the columns (any order, any case; other columns ignored), then one row per line;
!> lines starting with '#' and blank lines are skipped, so pandas.read_csv(path, comment='#') reads the
!> same table. Also where such a file is (beside the scene file, its absolute path) and a checksum of the
!> numbers read, which the resolved scene records so that a restart notices a changed file.
module csv_table
   use, intrinsic :: iso_fortran_env, only: iostat_end, iostat_eor, int8
   use, intrinsic :: iso_c_binding, only: c_char, c_null_char, c_ptr, c_associated
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp, i8
   use error_status, only: status_t
   use input_text, only: int_text, lower_case
   implicit none
   private

   public :: read_csv_columns, numbers_checksum, beside, absolute_path

   interface
      !> POSIX realpath(3): the absolute path of an existing file, without '.', '..' or links.
      function c_realpath(path, resolved) bind(c, name='realpath') result(r)
         import :: c_char, c_ptr
         character(kind=c_char), intent(in) :: path(*)
         character(kind=c_char), intent(out) :: resolved(*)
         type(c_ptr) :: r
      end function c_realpath
   end interface

   !> Longest field of a line kept (a number or a column name; a longer field is cut and then not read).
   integer, parameter :: field_len = 128
   !> Longest path realpath may write (PATH_MAX of Linux) plus the terminating null.
   integer, parameter :: c_path_max = 4097

contains

   !> Read the columns `names` (lower case) of the CSV file `path`: values(k, r) is column names(k) of
   !> row r, line(r) the row's line number in the file (for the caller's messages). `rows` names the rows
   !> in messages ('points', 'rows'). Fails on a missing column, a row with too few fields or a field that
   !> is not a finite number; a file without rows is left to the caller (n = 0). Messages start with the path.
   subroutine read_csv_columns(path, names, rows, values, line, status)
      character(len=*), intent(in) :: path, names(:), rows
      real(rp), allocatable, intent(out) :: values(:, :)
      integer, allocatable, intent(out) :: line(:)
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: text, where
      character(len=field_len), allocatable :: fields(:)
      character(len=512) :: message
      real(rp), allocatable :: grown(:, :)
      integer, allocatable :: grown_line(:)
      integer :: unit, ios, line_number, columns(size(names)), c, k, n, m
      logical :: header_read

      m = size(names)
      allocate (values(m, 0), line(0))
      allocate (character(len=0) :: where, text)
      open (newunit=unit, file=path, status='old', action='read', form='formatted', access='sequential', &
            iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail(path//': cannot open the file: '//trim(message))
         return
      end if
      allocate (grown(m, 1024), grown_line(1024))
      n = 0
      line_number = 0
      header_read = .false.
      do
         call read_line(unit, text, ios, message)
         if (ios == iostat_end) exit
         line_number = line_number + 1
         where = path//': line '//int_text(line_number)
         if (ios /= 0) then
            call status%fail(where//': cannot read the file: '//trim(message))
            exit
         end if
         if (len_trim(text) == 0) cycle
         if (text(verify(text, ' '):verify(text, ' ')) == '#') cycle
         call split_fields(text, fields)
         if (.not. header_read) then
            header_read = .true.
            do k = 1, m
               columns(k) = find_column(fields, trim(names(k)))
               if (columns(k) == 0) then
                  call status%fail(where//': the header names no column '//trim(names(k))//' (it must name '// &
                                   name_list(names)//')')
                  exit
               end if
            end do
            if (.not. status%ok) exit
            cycle
         end if
         if (size(fields) < maxval(columns)) then
            call status%fail(where//': '//int_text(size(fields))//' values, the header names '// &
                             int_text(maxval(columns))//' columns')
            exit
         end if
         if (n == size(grown, 2)) call grow(grown, grown_line)
         n = n + 1
         do k = 1, m
            c = columns(k)
            if (.not. read_number(fields(c), grown(k, n))) then
               call status%fail(where//': column '//trim(names(k))//": '"//trim(fields(c))// &
                                "' is not a finite number")
               exit
            end if
         end do
         if (.not. status%ok) exit
         grown_line(n) = line_number
      end do
      close (unit)
      if (.not. status%ok) return
      if (.not. header_read) then
         call status%fail(path//': no header line ('//name_list(names, ', ')//') and no '//rows)
         return
      end if
      deallocate (values, line)
      allocate (values(m, n), line(n))
      values = grown(:, 1:n)
      line = grown_line(1:n)
   end subroutine read_csv_columns

   !> 'x, y and volume' (or with `last` in place of ' and ').
   pure function name_list(names, last) result(text)
      character(len=*), intent(in) :: names(:)
      character(len=*), intent(in), optional :: last
      character(len=:), allocatable :: text
      integer :: k
      text = trim(names(1))
      do k = 2, size(names)
         if (k < size(names)) then
            text = text//', '//trim(names(k))
         else if (present(last)) then
            text = text//last//trim(names(k))
         else
            text = text//' and '//trim(names(k))
         end if
      end do
   end function name_list

   !> Double the capacity of the rows read so far.
   pure subroutine grow(values, line)
      real(rp), allocatable, intent(inout) :: values(:, :)
      integer, allocatable, intent(inout) :: line(:)
      real(rp), allocatable :: larger(:, :)
      integer, allocatable :: longer(:)
      allocate (larger(size(values, 1), 2 * size(values, 2)), longer(2 * size(line)))
      larger(:, 1:size(values, 2)) = values
      longer(1:size(line)) = line
      call move_alloc(larger, values)
      call move_alloc(longer, line)
   end subroutine grow

   !> One line of any length (without its line break; a trailing carriage return removed).
   subroutine read_line(unit, line, ios, message)
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: line
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=256) :: chunk
      integer :: nread
      line = ''
      do
         read (unit, '(a)', advance='no', iostat=ios, iomsg=message, size=nread) chunk
         if (ios == 0 .or. ios == iostat_eor) line = line//chunk(1:nread)
         if (ios == 0) cycle
         if (ios == iostat_eor) ios = 0
         ! end of file after a last line without a line break: that line still counts
         if (ios == iostat_end .and. len(line) > 0) ios = 0
         exit
      end do
      if (len(line) > 0) then
         if (line(len(line):len(line)) == achar(13)) line = line(1:len(line) - 1)
      end if
   end subroutine read_line

   !> The comma-separated fields of a line, blanks and one pair of double quotes around each removed.
   pure subroutine split_fields(line, fields)
      character(len=*), intent(in) :: line
      character(len=field_len), allocatable, intent(out) :: fields(:)
      integer :: n, start, comma, k
      character(len=:), allocatable :: field
      n = count([(line(k:k) == ',', k=1, len(line))]) + 1
      allocate (fields(n))
      start = 1
      do k = 1, n
         comma = index(line(start:), ',')
         if (comma == 0) then
            field = trim(adjustl(line(start:)))
         else
            field = trim(adjustl(line(start:start + comma - 2)))
            start = start + comma
         end if
         if (len(field) >= 2) then
            if (field(1:1) == '"' .and. field(len(field):len(field)) == '"') field = field(2:len(field) - 1)
         end if
         fields(k) = field
      end do
   end subroutine split_fields

   !> Position of the column called `name` (any case); 0 if none.
   pure integer function find_column(fields, name) result(found)
      character(len=*), intent(in) :: fields(:), name
      integer :: k
      found = 0
      do k = 1, size(fields)
         if (lower_case(trim(fields(k))) == name) then
            found = k
            return
         end if
      end do
   end function find_column

   !> A decimal number as pandas writes it (digits, sign, point, exponent e), and finite.
   logical function read_number(text, value) result(ok)
      character(len=*), intent(in) :: text
      real(rp), intent(out) :: value
      integer :: ios
      value = 0.0_rp
      ok = len_trim(text) > 0 .and. verify(trim(text), '0123456789+-.eE') == 0 .and. &
           scan(trim(text), '0123456789') > 0
      if (.not. ok) return
      read (text, *, iostat=ios) value
      ok = ios == 0
      if (ok) ok = ieee_is_finite(value)
   end function read_number

   !> `path` as seen from the folder of `scene_file` (unchanged if absolute).
   pure function beside(scene_file, path) result(joined)
      character(len=*), intent(in) :: scene_file, path
      character(len=:), allocatable :: joined
      integer :: slash
      joined = path
      if (path(1:1) == '/') return
      slash = index(scene_file, '/', back=.true.)
      if (slash > 0) joined = scene_file(1:slash)//path
   end function beside

   !> The absolute path of an existing file; '' if it does not exist.
   function absolute_path(path) result(absolute)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: absolute
      character(kind=c_char) :: buffer(c_path_max)
      integer :: i
      absolute = ''
      buffer = c_null_char
      if (.not. c_associated(c_realpath(path//c_null_char, buffer))) return
      do i = 1, c_path_max
         if (buffer(i) == c_null_char) exit
         absolute = absolute//buffer(i)
      end do
   end function absolute_path

   !> 16 hex digits of two 32-bit FNV-1a hashes (different offsets) over the bytes of `values` in array
   !> order: other numbers get another checksum (a change detector, not a signature).
   function numbers_checksum(values) result(text)
      real(rp), intent(in) :: values(:, :)
      character(len=16) :: text
      integer(i8), parameter :: prime = 16777619_i8, modulus = 4294967296_i8
      integer(i8) :: h(2)
      integer(int8) :: bytes(8)
      integer :: r, v, k
      h = [2166136261_i8, 3735928559_i8]
      do r = 1, size(values, 2)
         do v = 1, size(values, 1)
            bytes = transfer(values(v, r), bytes)
            do k = 1, 8
               ! h < 2^32 and prime < 2^25: the product fits 64 bits
               h = mod(ieor(h, iand(int(bytes(k), i8), 255_i8)) * prime, modulus)
            end do
         end do
      end do
      write (text, '(2z8.8)') h(1), h(2)
      text = lower_case(text)
   end function numbers_checksum
end module csv_table
