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
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use hdf5, only: hid_t, hsize_t, h5open_f, h5fopen_f, h5fclose_f, h5dopen_f, h5dclose_f, h5dread_f, &
                   h5dget_space_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5sclose_f, &
                   h5lexists_f, h5fis_hdf5_f, h5eset_auto_f, H5F_ACC_RDONLY_F, H5T_NATIVE_DOUBLE
   use kinds, only: rp, i8, path_len
   use error_status, only: status_t
   use scene_description, only: scene_t, body_points_t
   use input_text, only: int_text, real_text, lower_case, group_context
   use body_lattice, only: has_points_file
   use csv_table, only: read_csv_columns, numbers_checksum, beside, absolute_path
   implicit none
   private

   public :: read_point_file, points_checksum, load_body_points

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
      character(len=*), parameter :: names(4) = ['x     ', 'y     ', 'z     ', 'volume']
      real(rp), allocatable :: values(:, :)
      integer, allocatable :: line(:)
      integer :: p

      allocate (position(dim, 0), volume(0))
      call read_csv_columns(path, [names(1:dim), names(4)], 'points', values, line, status)
      if (.not. status%ok) return
      if (size(values, 2) == 0) then
         call status%fail(path//': no points after the header line')
         return
      end if
      do p = 1, size(values, 2)
         call check_point(path//': line '//int_text(line(p)), values(1:dim, p), values(dim + 1, p), lower, upper, &
                          tolerance, status)
         if (.not. status%ok) return
      end do
      deallocate (position, volume)
      allocate (position(dim, size(values, 2)), volume(size(values, 2)))
      position = values(1:dim, :)
      volume = values(dim + 1, :)
   end subroutine read_csv_points

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

   !> The checksum (csv_table numbers_checksum) of the points in the order x, y[, z], volume per point.
   function points_checksum(position, volume) result(text)
      real(rp), intent(in) :: position(:, :), volume(:)
      character(len=16) :: text
      real(rp), allocatable :: rows(:, :)
      allocate (rows(size(position, 1) + 1, size(volume)))
      rows(1:size(position, 1), :) = position(:, 1:size(volume))
      rows(size(position, 1) + 1, :) = volume
      text = numbers_checksum(rows)
   end function points_checksum
end module point_file
