!> Bodies read from files of points (`&body points_file`, docs/input.md): real debris geometry as one
!> particle per point, with its world position and volume.
!>
!> Formats, chosen by the file name's ending:
!>   .csv        a header line naming the columns (x, y[, z] and volume, in any order; other columns
!>               are ignored), then one point per line; lines starting with '#' and blank lines are
!>               skipped (pandas.read_csv(path, comment='#') reads the same table)
!>   .h5, .hdf5  datasets `position` (h5py shape (n, dim) or (n, 3), Fortran (dim, n); a third
!>               component is ignored in 2-D) and `volume` (n), at the root or in the group
!>               `particles` (so a Flotsam fields file can be read back)
!> Rank 0 reads the files while it checks the scene (load_body_points); the points travel to the other
!> ranks with the scene, so every rank seeds from the same numbers.
module point_file
   use, intrinsic :: iso_fortran_env, only: iostat_end, iostat_eor, int8
   use, intrinsic :: iso_c_binding, only: c_char, c_null_char, c_ptr, c_associated
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use hdf5, only: hid_t, hsize_t, h5open_f, h5fopen_f, h5fclose_f, h5dopen_f, h5dclose_f, h5dread_f, &
                   h5dget_space_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5sclose_f, &
                   h5lexists_f, h5fis_hdf5_f, h5eset_auto_f, H5F_ACC_RDONLY_F, H5T_NATIVE_DOUBLE
   use kinds, only: rp, i8, path_len
   use error_status, only: status_t
   use scene_description, only: scene_t, body_points_t
   use input_text, only: int_text, real_text, lower_case, group_context
   use body_lattice, only: has_points_file
   implicit none
   private

   public :: read_point_file, points_checksum, load_body_points

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

   !> Rank 0, after validate_scene: read the points file of every `&body points_file` into
   !> scene%body_points, check every point (finite, volume > 0, inside the scene box), set the body's
   !> points_file to the absolute path of the file read and its points_checksum (a given checksum must
   !> match). `label` names the scene in messages; a relative points_file is relative to the folder of
   !> the scene file.
   subroutine load_body_points(scene, label, status)
      type(scene_t), intent(inout) :: scene
      character(len=*), intent(in) :: label
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, path, absolute, checksum
      real(rp) :: box_lower(3), box_upper(3), tolerance
      integer :: b, dim

      dim = scene%grid%dim
      ! allocated before the loop (gfortran 12 warns falsely about a first assignment inside it)
      allocate (character(len=0) :: where, path, absolute, checksum)
      if (.not. allocated(scene%bodies)) return
      if (allocated(scene%body_points)) deallocate (scene%body_points)
      allocate (scene%body_points(size(scene%bodies)))
      tolerance = 1.0e-9_rp * scene%grid%cell_size
      box_lower = scene%grid%origin
      box_upper = scene%grid%origin + scene%grid%extent
      do b = 1, size(scene%bodies)
         associate (body => scene%bodies(b), points => scene%body_points(b))
            if (.not. has_points_file(body)) cycle
            where = group_context(label, 'body', b, body_detail(body%name, body%material))// &
                    ": variable points_file = '"//trim(body%points_file)//"'"
            path = beside(scene%source_file, trim(body%points_file))
            absolute = absolute_path(path)
            if (len(absolute) == 0) then
               call status%fail(where//': '//path//': file not found')
               return
            else if (len(absolute) > path_len) then
               call status%fail(where//': '//absolute//': the path is longer than '//int_text(path_len)//' characters')
               return
            end if
            call read_point_file(absolute, dim, box_lower(1:dim), box_upper(1:dim), tolerance, points%position, &
                                 points%volume, status)
            if (.not. status%ok) then
               status%message = where//': '//trim(status%message)
               return
            end if
            checksum = points_checksum(points%position, points%volume)
            if (len_trim(body%points_checksum) > 0 .and. trim(body%points_checksum) /= checksum) then
               call status%fail(where//': '//absolute//": the points do not match points_checksum = '"// &
                                trim(body%points_checksum)//"' (the file gives '"//checksum// &
                                "'): the file changed since the scene was written")
               return
            end if
            body%points_file = absolute
            body%points_checksum = checksum
         end associate
      end do
   end subroutine load_body_points

   !> "name 'log', material 'wood'", or "material 'wood'" for an unnamed body.
   pure function body_detail(name, material) result(detail)
      character(len=*), intent(in) :: name, material
      character(len=:), allocatable :: detail
      detail = "material '"//trim(material)//"'"
      if (len_trim(name) > 0) detail = "name '"//trim(name)//"', "//detail
   end function body_detail

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

   !> Read the points of `path` (CSV or HDF5, by its ending) in a `dim`-dimensional scene: positions
   !> (dim, n) and volumes (n), every point inside lower..upper (to `tolerance`). Messages start with the path.
   subroutine read_point_file(path, dim, lower, upper, tolerance, position, volume, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: dim
      real(rp), intent(in) :: lower(dim), upper(dim), tolerance
      real(rp), allocatable, intent(out) :: position(:, :), volume(:)
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: ending
      integer :: dot

      dot = index(path, '.', back=.true.)
      ending = ''
      if (dot > index(path, '/', back=.true.)) ending = lower_case(path(dot + 1:))
      select case (ending)
      case ('csv')
         call read_csv_points(path, dim, lower, upper, tolerance, position, volume, status)
      case ('h5', 'hdf5')
         call read_hdf5_points(path, dim, lower, upper, tolerance, position, volume, status)
      case default
         call status%fail(path//": the name must end in .csv (a table) or .h5 / .hdf5 (datasets 'position' and "// &
                          "'volume')")
      end select
   end subroutine read_point_file

   !> A table of points: header line, then x, y[, z], volume per line (docs/input.md).
   subroutine read_csv_points(path, dim, lower, upper, tolerance, position, volume, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: dim
      real(rp), intent(in) :: lower(dim), upper(dim), tolerance
      real(rp), allocatable, intent(out) :: position(:, :), volume(:)
      type(status_t), intent(inout) :: status
      character(len=*), parameter :: axis_names(3) = ['x', 'y', 'z']
      character(len=:), allocatable :: line, where
      character(len=field_len), allocatable :: fields(:)
      character(len=512) :: message
      real(rp), allocatable :: grown(:, :)
      real(rp) :: values(dim + 1)
      integer :: unit, ios, line_number, columns(dim + 1), c, k, n
      logical :: header_read

      allocate (position(dim, 0), volume(0))
      allocate (character(len=0) :: where, line)
      open (newunit=unit, file=path, status='old', action='read', form='formatted', access='sequential', &
            iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail(path//': cannot open the file: '//trim(message))
         return
      end if
      allocate (grown(dim + 1, 1024))
      n = 0
      line_number = 0
      header_read = .false.
      do
         call read_line(unit, line, ios, message)
         if (ios == iostat_end) exit
         line_number = line_number + 1
         where = path//': line '//int_text(line_number)
         if (ios /= 0) then
            call status%fail(where//': cannot read the file: '//trim(message))
            exit
         end if
         if (len_trim(line) == 0) cycle
         if (line(verify(line, ' '):verify(line, ' ')) == '#') cycle
         call split_fields(line, fields)
         if (.not. header_read) then
            header_read = .true.
            do k = 1, dim + 1
               if (k <= dim) then
                  columns(k) = find_column(fields, axis_names(k))
               else
                  columns(k) = find_column(fields, 'volume')
               end if
               if (columns(k) == 0) then
                  call status%fail(where//': the header names no column '//trim(header_name(k, dim))// &
                                   ' (it must name x, y'//trim(merge(', z', '   ', dim == 3))//' and volume)')
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
         do k = 1, dim + 1
            c = columns(k)
            if (.not. read_number(fields(c), values(k))) then
               call status%fail(where//': column '//trim(header_name(k, dim))//": '"//trim(fields(c))// &
                                "' is not a finite number")
               exit
            end if
         end do
         if (.not. status%ok) exit
         call check_point(where, values(1:dim), values(dim + 1), lower, upper, tolerance, status)
         if (.not. status%ok) exit
         if (n == size(grown, 2)) call grow(grown)
         n = n + 1
         grown(:, n) = values
      end do
      close (unit)
      if (.not. status%ok) return
      if (.not. header_read) then
         call status%fail(path//': no header line (x, y'//trim(merge(', z', '   ', dim == 3))//', volume) and no points')
      else if (n == 0) then
         call status%fail(path//': no points after the header line')
      end if
      if (.not. status%ok) return
      deallocate (position, volume)
      allocate (position(dim, n), volume(n))
      position = grown(1:dim, 1:n)
      volume = grown(dim + 1, 1:n)
   end subroutine read_csv_points

   pure function header_name(k, dim) result(name)
      integer, intent(in) :: k, dim
      character(len=6) :: name
      character(len=*), parameter :: axis_names(3) = ['x', 'y', 'z']
      if (k <= dim) then
         name = axis_names(k)
      else
         name = 'volume'
      end if
   end function header_name

   !> Double the capacity of the points read so far.
   subroutine grow(values)
      real(rp), allocatable, intent(inout) :: values(:, :)
      real(rp), allocatable :: larger(:, :)
      allocate (larger(size(values, 1), 2 * size(values, 2)))
      larger(:, 1:size(values, 2)) = values
      call move_alloc(larger, values)
   end subroutine grow

   !> A point must be finite, of positive volume and inside the scene box lower..upper.
   subroutine check_point(where, x, volume, lower, upper, tolerance, status)
      character(len=*), intent(in) :: where
      real(rp), intent(in) :: x(:), volume, lower(:), upper(:), tolerance
      type(status_t), intent(inout) :: status
      character(len=*), parameter :: axis_names(3) = ['x', 'y', 'z']
      integer :: k
      if (.not. volume > 0.0_rp) then
         call status%fail(where//': volume must be > 0, got '//real_text(volume))
         return
      end if
      do k = 1, size(x)
         if (x(k) < lower(k) - tolerance .or. x(k) > upper(k) + tolerance) then
            call status%fail(where//': the point lies outside the scene box of &grid: '//axis_names(k)//' = '// &
                             real_text(x(k))//', the box spans '//real_text(lower(k))//' .. '//real_text(upper(k)))
            return
         end if
      end do
   end subroutine check_point

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

   !> Datasets `position` and `volume` of an HDF5 file (at the root or in group `particles`).
   subroutine read_hdf5_points(path, dim, lower, upper, tolerance, position, volume, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: dim
      real(rp), intent(in) :: lower(dim), upper(dim), tolerance
      real(rp), allocatable, intent(out) :: position(:, :), volume(:)
      type(status_t), intent(inout) :: status
      integer(hid_t) :: file
      integer :: error, p
      logical :: is_hdf5, found
      character(len=:), allocatable :: group
      real(rp), allocatable :: stored(:, :), flat(:, :)
      integer(hsize_t) :: dims(2)

      allocate (position(dim, 0), volume(0))
      call h5open_f(error)
      call h5eset_auto_f(0, error)          ! our messages, not the library's error stack
      call h5fis_hdf5_f(path, is_hdf5, error)
      if (error /= 0 .or. .not. is_hdf5) then
         call status%fail(path//': not an HDF5 file')
         return
      end if
      call h5fopen_f(path, H5F_ACC_RDONLY_F, file, error)
      if (error /= 0) then
         call status%fail(path//': cannot open the HDF5 file')
         return
      end if
      group = ''
      call h5lexists_f(file, 'position', found, error)
      if (.not. found) then
         call h5lexists_f(file, 'particles', found, error)
         if (found) call h5lexists_f(file, 'particles/position', found, error)
         if (found) group = 'particles/'
      end if
      if (.not. found) then
         call status%fail(path//": no dataset 'position' (nor 'particles/position')")
      else
         call read_dataset(file, path, group//'position', stored, dims, status)
      end if
      if (status%ok) then
         if (dims(1) /= dim .and. dims(1) /= 3) then
            call status%fail(path//': dataset '//group//'position must hold '//int_text(dim)// &
                             ' (or 3) components per point (h5py shape (n, '//int_text(dim)//')), got '// &
                             int_text(int(dims(1), i8)))
         end if
      end if
      if (status%ok) then
         call read_dataset(file, path, group//'volume', flat, dims, status)
         if (status%ok .and. dims(1) /= 1) then
            call status%fail(path//': dataset '//group//'volume must hold one value per point, got h5py shape ('// &
                             int_text(int(dims(2), i8))//', '//int_text(int(dims(1), i8))//')')
         end if
         if (status%ok .and. size(flat) /= size(stored, 2)) then
            call status%fail(path//': dataset '//group//'volume holds '//int_text(size(flat))//' values, '// &
                             group//'position '//int_text(size(stored, 2))//' points')
         end if
      end if
      call h5fclose_f(file, error)
      if (.not. status%ok) return
      if (size(stored, 2) == 0) then
         call status%fail(path//': no points in dataset '//group//'position')
         return
      end if
      do p = 1, size(stored, 2)
         if (.not. all(ieee_is_finite(stored(1:dim, p))) .or. .not. ieee_is_finite(flat(1, p))) then
            call status%fail(path//': point '//int_text(p - 1)//' (0-based) is not finite')
            return
         end if
         call check_point(path//': point '//int_text(p - 1)//' (0-based)', stored(1:dim, p), flat(1, p), lower, upper, &
                          tolerance, status)
         if (.not. status%ok) return
      end do
      deallocate (position, volume)
      allocate (position(dim, size(stored, 2)), volume(size(stored, 2)))
      position = stored(1:dim, :)
      volume = flat(1, :)
   end subroutine read_hdf5_points

   !> A 1-D or 2-D dataset as doubles (m, n) in Fortran order: 1-D gives m = 1.
   subroutine read_dataset(file, path, name, values, dims, status)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path, name
      real(rp), allocatable, intent(out) :: values(:, :)
      integer(hsize_t), intent(out) :: dims(2)
      type(status_t), intent(inout) :: status
      integer(hid_t) :: dataset, space
      integer(hsize_t) :: found(2), maxdims(2)
      integer :: error, rank
      logical :: exists

      dims = 0
      allocate (values(0, 0))
      call h5lexists_f(file, name, exists, error)
      if (.not. exists) then
         call status%fail(path//': no dataset '//name)
         return
      end if
      call h5dopen_f(file, name, dataset, error)
      if (error /= 0) then
         call status%fail(path//': cannot open dataset '//name)
         return
      end if
      call h5dget_space_f(dataset, space, error)
      call h5sget_simple_extent_ndims_f(space, rank, error)
      if (rank < 1 .or. rank > 2) then
         call status%fail(path//': dataset '//name//' must have 1 or 2 dimensions, has '//int_text(rank))
      else
         ! the Fortran interface gives the dimensions fastest first: h5py's (n, 2) is (2, n) here
         call h5sget_simple_extent_dims_f(space, found(1:rank), maxdims(1:rank), error)
         if (rank == 1) then
            dims = [1_hsize_t, found(1)]
         else
            dims = found
         end if
         deallocate (values)
         allocate (values(dims(1), dims(2)))
         if (size(values) > 0) then
            call h5dread_f(dataset, H5T_NATIVE_DOUBLE, values, dims, error)
            if (error /= 0) call status%fail(path//': cannot read dataset '//name//' as numbers')
         end if
      end if
      call h5sclose_f(space, error)
      call h5dclose_f(dataset, error)
   end subroutine read_dataset

   !> 16 hex digits of two 32-bit FNV-1a hashes (different offsets) over the bytes of the positions and
   !> volumes: a file whose points change gets another checksum (a change detector, not a signature).
   function points_checksum(position, volume) result(text)
      real(rp), intent(in) :: position(:, :), volume(:)
      character(len=16) :: text
      integer(i8), parameter :: prime = 16777619_i8, modulus = 4294967296_i8
      integer(i8) :: h(2)
      integer :: p
      h = [2166136261_i8, 3735928559_i8]
      do p = 1, size(volume)
         call add_values(position(:, p))
         call add_values([volume(p)])
      end do
      write (text, '(2z8.8)') h(1), h(2)
      text = lower_case(text)

   contains

      subroutine add_values(values)
         real(rp), intent(in) :: values(:)
         integer(int8) :: bytes(8)
         integer :: v, k
         do v = 1, size(values)
            bytes = transfer(values(v), bytes)
            do k = 1, 8
               ! h < 2^32 and prime < 2^25: the product fits 64 bits
               h = mod(ieor(h, iand(int(bytes(k), i8), 255_i8)) * prime, modulus)
            end do
         end do
      end subroutine add_values
   end function points_checksum
end module point_file
