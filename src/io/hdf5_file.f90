!> One HDF5 file opened by all ranks of a communicator through MPI-IO (style.md, lesson 10).
!>
!> Particle-like data are global 1-D datasets (or 2-D with a leading component axis): every rank owns
!> a contiguous slab of the global index range, placed by an `MPI_Exscan` of the local counts
!> (`distributed_slab`). Grid data are 1- to 4-D blocks placed by their global offset. All writes and
!> reads are collective; a rank with nothing to write selects nothing but still takes part.
!> A Fortran array `a(n_components, n)` appears in the file as shape (n, n_components) in C order.
!>
!> Every procedure is collective over the file's communicator and must be called by every rank in the
!> same order with the same names and global shapes. Failures are recorded in `status` with the file
!> and object named; HDF5's own error stack printing is switched off.
module hdf5_file
   use, intrinsic :: iso_c_binding, only: c_loc, c_ptr, c_char
   use, intrinsic :: iso_fortran_env, only: int32, int64, real32, real64
   use, intrinsic :: ieee_exceptions, only: ieee_flag_type, ieee_invalid, ieee_divide_by_zero, ieee_overflow, &
                                            ieee_get_halting_mode, ieee_set_halting_mode, ieee_set_flag
   use hdf5, only: hid_t, hsize_t, size_t, h5open_f, h5eset_auto_f, h5pcreate_f, h5pclose_f, h5pset_fapl_mpio_f, &
                   h5pset_dxpl_mpio_f, h5fcreate_f, h5fopen_f, h5fclose_f, h5fflush_f, h5gcreate_f, h5gclose_f, &
                   h5screate_simple_f, h5screate_f, h5sclose_f, h5sselect_hyperslab_f, h5sselect_none_f, &
                   h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5dcreate_f, h5dopen_f, h5dclose_f, &
                   h5dwrite_f, h5dread_f, h5dget_space_f, h5acreate_f, h5aopen_f, h5aclose_f, h5awrite_f, h5aread_f, &
                   h5aexists_f, h5aget_type_f, h5aget_space_f, h5tget_size_f, h5tcopy_f, h5tset_size_f, h5tclose_f, h5lexists_f, &
                   h5oopen_f, h5oclose_f, &
                   h5kind_to_type, H5_REAL_KIND, H5_INTEGER_KIND, H5P_FILE_ACCESS_F, H5P_DATASET_XFER_F, &
                   H5FD_MPIO_COLLECTIVE_F, H5F_ACC_TRUNC_F, H5F_ACC_RDONLY_F, H5F_SCOPE_GLOBAL_F, H5S_SCALAR_F, &
                   H5S_SELECT_SET_F, H5T_FORTRAN_S1
   use mpi_f08, only: MPI_Comm, MPI_Exscan, MPI_Allreduce, MPI_Comm_rank, MPI_IN_PLACE, MPI_INTEGER8, MPI_SUM, &
                      MPI_INFO_NULL
   use kinds, only: rp, i8
   use error_status, only: status_t
   implicit none
   private

   !> A rank's contiguous share [offset, offset + count) of a global index range of `total` entries.
   type, public :: slab_t
      integer(i8) :: offset = 0, count = 0, total = 0
   end type slab_t

   type, public :: hdf5_file_t
      integer(hid_t) :: id = -1
      integer(hid_t) :: transfer = -1            !< collective data-transfer property list
      type(MPI_Comm) :: comm
      character(len=:), allocatable :: path
      logical :: is_open = .false.
   contains
      procedure :: create => file_create
      procedure :: open => file_open
      procedure :: close => file_close
      procedure :: create_group => file_create_group
      procedure :: has => file_has
      procedure :: dataset_dims => file_dataset_dims
      procedure :: has_attribute => file_has_attribute
      generic :: write_slab => write_slab_real1, write_slab_real2, write_slab_int1, write_slab_i81, write_slab_single1, &
         write_slab_single2
      generic :: read_slab => read_slab_real1, read_slab_real2, read_slab_int1, read_slab_i81
      generic :: write_block => file_write_block, file_write_block_single
      procedure :: read_block => file_read_block
      generic :: write_attribute => attribute_write_real, attribute_write_int, attribute_write_i8, &
         attribute_write_string, attribute_write_real_array, attribute_write_int_array, attribute_write_i8_array
      generic :: read_attribute => attribute_read_real, attribute_read_int, attribute_read_i8, attribute_read_string, &
         attribute_read_real_array, attribute_read_int_array
      !> string attributes of a dataset or group (units, description, material names)
      generic :: write_object_attribute => object_attribute_write_string, object_attribute_write_strings
      procedure, private :: write_slab_real1, write_slab_real2, write_slab_int1, write_slab_i81, write_slab_single1, &
         write_slab_single2, file_write_block, file_write_block_single
      procedure, private :: object_attribute_write_string, object_attribute_write_strings
      procedure, private :: read_slab_real1, read_slab_real2, read_slab_int1, read_slab_i81
      procedure, private :: attribute_write_real, attribute_write_int, attribute_write_i8, attribute_write_string, &
         attribute_write_real_array, attribute_write_int_array, attribute_write_i8_array
      procedure, private :: attribute_read_real, attribute_read_int, attribute_read_i8, attribute_read_string, &
         attribute_read_real_array, attribute_read_int_array
   end type hdf5_file_t

   public :: distributed_slab, even_slab, to_single

   logical, save :: library_open = .false.

contains

   !> The slab of a rank holding `local_count` entries: offset = sum of the counts of lower ranks
   !> (MPI_Exscan), total = sum over all ranks. Collective.
   function distributed_slab(comm, local_count) result(slab)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: local_count
      type(slab_t) :: slab
      integer :: rank
      slab%count = local_count
      slab%offset = 0
      call MPI_Exscan(slab%count, slab%offset, 1, MPI_INTEGER8, MPI_SUM, comm)
      call MPI_Comm_rank(comm, rank)
      if (rank == 0) slab%offset = 0      ! MPI_Exscan leaves rank 0's result undefined
      slab%total = slab%count
      call MPI_Allreduce(MPI_IN_PLACE, slab%total, 1, MPI_INTEGER8, MPI_SUM, comm)
   end function distributed_slab

   !> Rank `rank` of `n_ranks`' share of `total` entries split as evenly as possible (for reading).
   pure function even_slab(total, rank, n_ranks) result(slab)
      integer(i8), intent(in) :: total
      integer, intent(in) :: rank, n_ranks
      type(slab_t) :: slab
      slab%total = total
      slab%offset = (total * rank) / n_ranks
      slab%count = (total * (rank + 1)) / n_ranks - slab%offset
   end function even_slab

   !> Open the HDF5 library once per process, without its error-stack printing (we report our own).
   !> The floating-point traps of the Debug build are masked while the library initialises: some HDF5
   !> builds probe the native float types with operations that raise IEEE flags (Debian's 1.10.8 does
   !> not, but a trap there would end every Debug run); the flags it raises are cleared afterwards.
   subroutine open_library(status)
      type(status_t), intent(inout) :: status
      type(ieee_flag_type), parameter :: traps(3) = [ieee_invalid, ieee_divide_by_zero, ieee_overflow]
      logical :: halting(3)
      integer :: error
      if (library_open) return
      call ieee_get_halting_mode(traps, halting)
      call ieee_set_halting_mode(traps, .false.)
      call h5open_f(error)
      call ieee_set_flag(traps, .false.)
      call ieee_set_halting_mode(traps, halting)
      if (error < 0) then
         call status%fail('cannot initialise the HDF5 library')
         return
      end if
      call h5eset_auto_f(0, error)
      library_open = .true.
   end subroutine open_library

   !> Create (or truncate) `path` for writing by every rank of `comm`. Collective.
   subroutine file_create(self, path, comm, status)
      class(hdf5_file_t), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      type(status_t), intent(inout) :: status
      call open_or_create(self, path, comm, .true., status)
   end subroutine file_create

   !> Open an existing `path` read-only on every rank of `comm`. Collective.
   subroutine file_open(self, path, comm, status)
      class(hdf5_file_t), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      type(status_t), intent(inout) :: status
      call open_or_create(self, path, comm, .false., status)
   end subroutine file_open

   subroutine open_or_create(self, path, comm, create, status)
      class(hdf5_file_t), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(MPI_Comm), intent(in) :: comm
      logical, intent(in) :: create
      type(status_t), intent(inout) :: status
      integer(hid_t) :: access
      integer :: error, e
      if (.not. status%ok) return
      call open_library(status)
      if (.not. status%ok) return
      self%path = trim(path)
      self%comm = comm
      call h5pcreate_f(H5P_FILE_ACCESS_F, access, error)
      call h5pset_fapl_mpio_f(access, comm%MPI_VAL, MPI_INFO_NULL%MPI_VAL, e)
      error = min(error, e)
      if (create) then
         call h5fcreate_f(self%path, H5F_ACC_TRUNC_F, self%id, e, access_prp=access)
      else
         call h5fopen_f(self%path, H5F_ACC_RDONLY_F, self%id, e, access_prp=access)
      end if
      error = min(error, e)
      call h5pclose_f(access, e)
      if (error < 0) then
         if (create) then
            call status%fail('cannot create HDF5 file '//self%path)
         else
            call status%fail('cannot open HDF5 file '//self%path//' (missing, truncated or not an HDF5 file)')
         end if
         return
      end if
      call h5pcreate_f(H5P_DATASET_XFER_F, self%transfer, error)
      call h5pset_dxpl_mpio_f(self%transfer, H5FD_MPIO_COLLECTIVE_F, e)
      if (min(error, e) < 0) call status%fail('cannot set up collective transfers for '//self%path)
      self%is_open = .true.
   end subroutine open_or_create

   !> Close the file; with `flush`, first push every rank's data to the storage device (MPI_File_sync),
   !> so a completed file survives a crash of the machine. Collective.
   subroutine file_close(self, status, flush)
      class(hdf5_file_t), intent(inout) :: self
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: flush
      integer :: error
      if (.not. self%is_open) return
      error = 0
      if (present(flush)) then
         if (flush) call h5fflush_f(self%id, H5F_SCOPE_GLOBAL_F, error)
      end if
      if (error < 0) call status%fail('cannot flush HDF5 file '//self%path)
      call h5pclose_f(self%transfer, error)
      call h5fclose_f(self%id, error)
      if (error < 0) call status%fail('cannot close HDF5 file '//self%path)
      self%is_open = .false.
   end subroutine file_close

   subroutine file_create_group(self, name, status)
      class(hdf5_file_t), intent(inout) :: self
      character(len=*), intent(in) :: name
      type(status_t), intent(inout) :: status
      integer(hid_t) :: group
      integer :: error
      if (.not. status%ok) return
      call h5gcreate_f(self%id, name, group, error)
      if (error < 0) then
         call status%fail('cannot create group '//name//' in '//self%path)
         return
      end if
      call h5gclose_f(group, error)
   end subroutine file_create_group

   !> True if the file has an object (group or dataset) at `name`; every parent must exist.
   logical function file_has(self, name)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer :: error
      call h5lexists_f(self%id, name, file_has, error)
      if (error < 0) file_has = .false.
   end function file_has

   !> True if the root group has attribute `name`.
   logical function file_has_attribute(self, name)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer :: error
      call h5aexists_f(self%id, name, file_has_attribute, error)
      if (error < 0) file_has_attribute = .false.
   end function file_has_attribute

   !> Fortran-order dimensions of dataset `name` (rank-sized array; empty if it cannot be read).
   function file_dataset_dims(self, name, status) result(dims)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(status_t), intent(inout) :: status
      integer(i8), allocatable :: dims(:)
      integer(hid_t) :: dataset, space
      integer(hsize_t) :: extent(7), max_extent(7)
      integer :: error, n
      allocate (dims(0))
      if (.not. status%ok) return
      call h5dopen_f(self%id, name, dataset, error)
      if (error < 0) then
         call status%fail(self%path//' has no dataset '//name)
         return
      end if
      call h5dget_space_f(dataset, space, error)
      call h5sget_simple_extent_ndims_f(space, n, error)
      call h5sget_simple_extent_dims_f(space, extent(1:n), max_extent(1:n), error)
      if (error >= 0) dims = int(extent(1:n), i8)
      call h5sclose_f(space, error)
      call h5dclose_f(dataset, error)
   end function file_dataset_dims

   ! --- datasets -----------------------------------------------------------------------------------

   !> Create dataset `name` of Fortran shape `global` and write this rank's block of shape `local` at
   !> 0-based `offset` from `buffer` (contiguous, Fortran order; size >= 1 even when the block is empty).
   subroutine write_block_ptr(self, name, type_id, global, offset, local, buffer, status)
      type(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: type_id
      integer(i8), intent(in) :: global(:), offset(:), local(:)
      type(c_ptr), intent(in) :: buffer
      type(status_t), intent(inout) :: status
      integer(hid_t) :: file_space, memory_space, dataset
      integer :: error, e, n
      if (.not. status%ok) return
      n = size(global)
      call h5screate_simple_f(n, int(global, hsize_t), file_space, error)
      call h5dcreate_f(self%id, name, type_id, file_space, dataset, e)
      error = min(error, e)
      if (error < 0) then
         call status%fail('cannot create dataset '//name//' in '//self%path)
         return
      end if
      if (product(global) == 0) then     ! an empty dataset: nothing to write (HDF5 refuses the transfer)
         call h5sclose_f(file_space, e)
         call h5dclose_f(dataset, e)
         return
      end if
      call select_block(file_space, offset, local, memory_space, error)
      call h5dwrite_f(dataset, type_id, buffer, e, memory_space, file_space, self%transfer)
      error = min(error, e)
      call h5sclose_f(memory_space, e)
      call h5sclose_f(file_space, e)
      call h5dclose_f(dataset, e)
      if (error < 0) call status%fail('cannot write dataset '//name//' of '//self%path)
   end subroutine write_block_ptr

   !> Read this rank's block of shape `local` at 0-based `offset` of dataset `name` into `buffer`,
   !> after checking that the dataset has the Fortran shape `global`.
   subroutine read_block_ptr(self, name, type_id, global, offset, local, buffer, status)
      type(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: type_id
      integer(i8), intent(in) :: global(:), offset(:), local(:)
      type(c_ptr), intent(in) :: buffer
      type(status_t), intent(inout) :: status
      integer(hid_t) :: file_space, memory_space, dataset
      integer(i8), allocatable :: dims(:)
      type(c_ptr) :: destination
      integer :: error, e
      character(len=200) :: shape_text
      if (.not. status%ok) return
      destination = buffer                ! h5dread_f takes the address intent(inout)
      dims = self%dataset_dims(name, status)
      if (.not. status%ok) return
      if (size(dims) /= size(global)) then
         call status%fail('dataset '//name//' of '//self%path//' has the wrong number of dimensions')
         return
      else if (any(dims /= global)) then
         write (shape_text, '(a,*(i0,:,","))') 'expected shape ', global
         call status%fail('dataset '//name//' of '//self%path//' has the wrong shape ('//trim(shape_text)//')')
         return
      end if
      if (product(global) == 0) return
      call h5dopen_f(self%id, name, dataset, error)
      call h5dget_space_f(dataset, file_space, e)
      error = min(error, e)
      call select_block(file_space, offset, local, memory_space, e)
      error = min(error, e)
      call h5dread_f(dataset, type_id, destination, e, memory_space, file_space, self%transfer)
      error = min(error, e)
      call h5sclose_f(memory_space, e)
      call h5sclose_f(file_space, e)
      call h5dclose_f(dataset, e)
      if (error < 0) call status%fail('cannot read dataset '//name//' of '//self%path//' (truncated file?)')
   end subroutine read_block_ptr

   !> Select the block in the file space and make the matching memory space (none for an empty block).
   subroutine select_block(file_space, offset, local, memory_space, error)
      integer(hid_t), intent(in) :: file_space
      integer(i8), intent(in) :: offset(:), local(:)
      integer(hid_t), intent(out) :: memory_space
      integer, intent(out) :: error
      integer :: e
      if (product(local) > 0) then
         call h5screate_simple_f(size(local), int(local, hsize_t), memory_space, error)
         call h5sselect_hyperslab_f(file_space, H5S_SELECT_SET_F, int(offset, hsize_t), int(local, hsize_t), e)
      else
         call h5screate_simple_f(1, [1_hsize_t], memory_space, error)
         call h5sselect_none_f(memory_space, e)
         error = min(error, e)
         call h5sselect_none_f(file_space, e)
      end if
      error = min(error, e)
   end subroutine select_block

   !> Write a global grid dataset of Fortran shape `global` (e.g. (3, nx, ny, nz) for a nodal vector),
   !> this rank contributing the block `local` at `offset` (leading component axis included).
   subroutine file_write_block(self, name, global, offset, local, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: global(:), offset(:), local(:)
      real(rp), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_block_ptr(self, name, real_type(), global, offset, local, c_loc(values), status)
   end subroutine file_write_block

   !> The same in single precision (a float32 dataset).
   subroutine file_write_block_single(self, name, global, offset, local, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: global(:), offset(:), local(:)
      real(real32), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_block_ptr(self, name, single_type(), global, offset, local, c_loc(values), status)
   end subroutine file_write_block_single

   !> Read this rank's block `local` at `offset` of the grid dataset `name` of Fortran shape `global`.
   subroutine file_read_block(self, name, global, offset, local, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in) :: global(:), offset(:), local(:)
      real(rp), intent(inout), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call read_block_ptr(self, name, real_type(), global, offset, local, c_loc(values), status)
   end subroutine file_read_block

   !> Write `values(1:slab%count)` as this rank's part of the global 1-D dataset `name` (slab%total).
   subroutine write_slab_real1(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      real(rp), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_block_ptr(self, name, real_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine write_slab_real1

   !> Write `values(:, 1:slab%count)` as this rank's rows of the global dataset (size(values, 1), total).
   subroutine write_slab_real2(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      real(rp), intent(in), target, contiguous :: values(:, :)
      type(status_t), intent(inout) :: status
      integer(i8) :: n
      n = size(values, 1)
      call write_block_ptr(self, name, real_type(), [n, slab%total], [0_i8, slab%offset], [n, slab%count], &
                           c_loc(values), status)
   end subroutine write_slab_real2

   !> Single precision: `values(1:slab%count)` into the float32 1-D dataset `name`.
   subroutine write_slab_single1(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      real(real32), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_block_ptr(self, name, single_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine write_slab_single1

   !> Single precision: `values(:, 1:slab%count)` as this rank's rows of the float32 dataset `name`.
   subroutine write_slab_single2(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      real(real32), intent(in), target, contiguous :: values(:, :)
      type(status_t), intent(inout) :: status
      integer(i8) :: n
      n = size(values, 1)
      call write_block_ptr(self, name, single_type(), [n, slab%total], [0_i8, slab%offset], [n, slab%count], &
                           c_loc(values), status)
   end subroutine write_slab_single2

   !> `values` rounded to single precision (nearest). A value beyond its range becomes an infinity (the
   !> state of a blow-up written for inspection): the Debug build's overflow trap is masked meanwhile.
   function to_single(values) result(single)
      real(rp), intent(in) :: values(:)
      real(real32), allocatable :: single(:)
      type(ieee_flag_type), parameter :: traps(1) = [ieee_overflow]
      logical :: halting(1)
      allocate (single(size(values)))
      call ieee_get_halting_mode(traps, halting)
      call ieee_set_halting_mode(traps, .false.)
      single(:) = real(values, real32)
      call ieee_set_flag(traps, .false.)
      call ieee_set_halting_mode(traps, halting)
   end function to_single

   subroutine write_slab_int1(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      integer, intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_block_ptr(self, name, int_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine write_slab_int1

   subroutine write_slab_i81(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      integer(i8), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_block_ptr(self, name, i8_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine write_slab_i81

   !> Read this rank's slab of the global 1-D dataset `name`, which must hold slab%total entries.
   subroutine read_slab_real1(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      real(rp), intent(inout), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call read_block_ptr(self, name, real_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine read_slab_real1

   !> Read this rank's rows of the global dataset (size(values, 1), slab%total).
   subroutine read_slab_real2(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      real(rp), intent(inout), target, contiguous :: values(:, :)
      type(status_t), intent(inout) :: status
      integer(i8) :: n
      n = size(values, 1)
      call read_block_ptr(self, name, real_type(), [n, slab%total], [0_i8, slab%offset], [n, slab%count], &
                          c_loc(values), status)
   end subroutine read_slab_real2

   subroutine read_slab_int1(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      integer, intent(inout), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call read_block_ptr(self, name, int_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine read_slab_int1

   subroutine read_slab_i81(self, name, slab, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      type(slab_t), intent(in) :: slab
      integer(i8), intent(inout), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call read_block_ptr(self, name, i8_type(), [slab%total], [slab%offset], [slab%count], c_loc(values), status)
   end subroutine read_slab_i81

   ! --- attributes of the root group ---------------------------------------------------------------

   !> Create attribute `name` of the root group holding the `n` values of type `type_id` at `buffer`
   !> (scalar: a scalar attribute of one value).
   !> With `location`, the attribute goes to that object (a dataset or group) instead of the root group.
   subroutine write_attribute_ptr(self, name, type_id, n, scalar, buffer, status, location)
      type(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: type_id
      integer, intent(in) :: n
      logical, intent(in) :: scalar
      type(c_ptr), intent(in) :: buffer
      type(status_t), intent(inout) :: status
      integer(hid_t), intent(in), optional :: location
      integer(hid_t) :: space, attribute, owner
      integer :: error, e
      if (.not. status%ok) return
      owner = self%id
      if (present(location)) owner = location
      if (scalar) then
         call h5screate_f(H5S_SCALAR_F, space, error)
      else
         call h5screate_simple_f(1, [int(n, hsize_t)], space, error)
      end if
      call h5acreate_f(owner, name, type_id, space, attribute, e)
      call h5sclose_f(space, error)
      if (e < 0) then
         call status%fail('cannot create attribute '//name//' in '//self%path)
         return
      end if
      call h5awrite_f(attribute, type_id, buffer, error)
      call h5aclose_f(attribute, e)
      if (error < 0) call status%fail('cannot write attribute '//name//' of '//self%path)
   end subroutine write_attribute_ptr

   subroutine attribute_write_real(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      real(rp), intent(in), target :: value
      type(status_t), intent(inout) :: status
      call write_attribute_ptr(self, name, real_type(), 1, .true., c_loc(value), status)
   end subroutine attribute_write_real

   subroutine attribute_write_int(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer, intent(in), target :: value
      type(status_t), intent(inout) :: status
      call write_attribute_ptr(self, name, int_type(), 1, .true., c_loc(value), status)
   end subroutine attribute_write_int

   subroutine attribute_write_i8(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in), target :: value
      type(status_t), intent(inout) :: status
      call write_attribute_ptr(self, name, i8_type(), 1, .true., c_loc(value), status)
   end subroutine attribute_write_i8

   subroutine attribute_write_real_array(self, name, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      real(rp), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_attribute_ptr(self, name, real_type(), size(values), .false., c_loc(values), status)
   end subroutine attribute_write_real_array

   subroutine attribute_write_int_array(self, name, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer, intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_attribute_ptr(self, name, int_type(), size(values), .false., c_loc(values), status)
   end subroutine attribute_write_int_array

   subroutine attribute_write_i8_array(self, name, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(in), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call write_attribute_ptr(self, name, i8_type(), size(values), .false., c_loc(values), status)
   end subroutine attribute_write_i8_array

   !> A fixed-length string attribute (trailing blanks removed; at least one character).
   subroutine attribute_write_string(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name, value
      type(status_t), intent(inout) :: status
      integer(hid_t) :: string_type
      integer :: error, n
      character(kind=c_char), allocatable, target :: text(:)
      if (.not. status%ok) return
      n = max(1, len_trim(value))
      allocate (text(n))
      text = ' '
      text(1:len_trim(value)) = transfer(value(1:len_trim(value)), text, len_trim(value))
      call h5tcopy_f(H5T_FORTRAN_S1, string_type, error)
      call h5tset_size_f(string_type, int(n, size_t), error)
      call write_attribute_ptr(self, name, string_type, 1, .true., c_loc(text), status)
      call h5tclose_f(string_type, error)
   end subroutine attribute_write_string

   !> String attribute `name` of the dataset or group `object` (e.g. units of /particles/velocity).
   subroutine object_attribute_write_string(self, object, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: object, name, value
      type(status_t), intent(inout) :: status
      call object_attribute_write_strings(self, object, name, [value], status, scalar=.true.)
   end subroutine object_attribute_write_string

   !> Attribute `name` of `object` holding the strings `values` (fixed length: the longest, blank-padded);
   !> h5py shows it as an array of bytes, e.g. material_names [b'water', b'wood block'].
   subroutine object_attribute_write_strings(self, object, name, values, status, scalar)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: object, name, values(:)
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: scalar
      integer(hid_t) :: string_type, owner
      integer :: error, n, k, width
      logical :: one
      character(kind=c_char), allocatable, target :: text(:)
      if (.not. status%ok) return
      one = .false.
      if (present(scalar)) one = scalar .and. size(values) == 1
      width = 1
      do k = 1, size(values)
         width = max(width, len_trim(values(k)))
      end do
      n = size(values)
      allocate (text(max(1, n) * width))
      text = ' '
      do k = 1, n
         if (len_trim(values(k)) > 0) text((k - 1) * width + 1:(k - 1) * width + len_trim(values(k))) = &
            transfer(values(k)(1:len_trim(values(k))), text, len_trim(values(k)))
      end do
      call h5oopen_f(self%id, object, owner, error)
      if (error < 0) then
         call status%fail('cannot open '//object//' of '//self%path//' to write its attribute '//name)
         return
      end if
      call h5tcopy_f(H5T_FORTRAN_S1, string_type, error)
      call h5tset_size_f(string_type, int(width, size_t), error)
      call write_attribute_ptr(self, name, string_type, max(1, n), one, c_loc(text), status, owner)
      call h5tclose_f(string_type, error)
      call h5oclose_f(owner, error)
   end subroutine object_attribute_write_strings

   !> Open root attribute `name`; fails with a message naming it if it is missing or, when `n` is
   !> given, does not hold exactly n values (n = 1 also accepts a scalar).
   subroutine open_attribute(self, name, attribute, status, n)
      type(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(out) :: attribute
      type(status_t), intent(inout) :: status
      integer, intent(in), optional :: n
      integer(hid_t) :: space
      integer(hsize_t) :: extent(7), max_extent(7)
      integer :: error, e, rank
      attribute = -1
      if (.not. status%ok) return
      if (.not. self%has_attribute(name)) then
         call status%fail(self%path//' has no attribute '//name)
         return
      end if
      call h5aopen_f(self%id, name, attribute, error)
      if (error < 0) then
         call status%fail('cannot open attribute '//name//' of '//self%path)
         return
      end if
      if (.not. present(n)) return
      call h5aget_space_f(attribute, space, error)
      call h5sget_simple_extent_ndims_f(space, rank, e)
      extent = 1
      if (rank > 0) call h5sget_simple_extent_dims_f(space, extent(1:rank), max_extent(1:rank), e)
      call h5sclose_f(space, e)
      if (product(extent(1:max(rank, 1))) /= int(n, hsize_t)) then
         call status%fail('attribute '//name//' of '//self%path//' has the wrong number of values')
         call h5aclose_f(attribute, e)
         attribute = -1
      end if
   end subroutine open_attribute

   !> Read the n values of attribute `name` (n = 1: also a scalar) as type `type_id` into `buffer`.
   subroutine read_attribute_ptr(self, name, type_id, n, buffer, status)
      type(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(hid_t), intent(in) :: type_id
      integer, intent(in) :: n
      type(c_ptr), intent(in) :: buffer
      type(status_t), intent(inout) :: status
      integer(hid_t) :: attribute
      type(c_ptr) :: destination
      integer :: error, e
      call open_attribute(self, name, attribute, status, n)
      if (.not. status%ok) return
      destination = buffer                ! h5aread_f takes the address intent(inout)
      call h5aread_f(attribute, type_id, destination, error)
      call h5aclose_f(attribute, e)
      if (error < 0) call status%fail('cannot read attribute '//name//' of '//self%path)
   end subroutine read_attribute_ptr

   subroutine attribute_read_real(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      real(rp), intent(inout), target :: value
      type(status_t), intent(inout) :: status
      call read_attribute_ptr(self, name, real_type(), 1, c_loc(value), status)
   end subroutine attribute_read_real

   subroutine attribute_read_int(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout), target :: value
      type(status_t), intent(inout) :: status
      call read_attribute_ptr(self, name, int_type(), 1, c_loc(value), status)
   end subroutine attribute_read_int

   subroutine attribute_read_i8(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer(i8), intent(inout), target :: value
      type(status_t), intent(inout) :: status
      call read_attribute_ptr(self, name, i8_type(), 1, c_loc(value), status)
   end subroutine attribute_read_i8

   !> Read an array attribute of exactly size(values) reals.
   subroutine attribute_read_real_array(self, name, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      real(rp), intent(inout), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call read_attribute_ptr(self, name, real_type(), size(values), c_loc(values), status)
   end subroutine attribute_read_real_array

   !> Read an array attribute of exactly size(values) default integers.
   subroutine attribute_read_int_array(self, name, values, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer, intent(inout), target, contiguous :: values(:)
      type(status_t), intent(inout) :: status
      call read_attribute_ptr(self, name, int_type(), size(values), c_loc(values), status)
   end subroutine attribute_read_int_array

   !> Read a string attribute into `value` (blank-padded; cut if longer than len(value)).
   subroutine attribute_read_string(self, name, value, status)
      class(hdf5_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      character(len=*), intent(inout) :: value
      type(status_t), intent(inout) :: status
      integer(hid_t) :: attribute, file_type, memory_type
      integer(size_t) :: n
      integer :: error, e
      character(len=:), allocatable :: buffer
      call open_attribute(self, name, attribute, status)
      if (.not. status%ok) return
      call h5aget_type_f(attribute, file_type, error)
      call h5tget_size_f(file_type, n, e)
      error = min(error, e)
      call h5tclose_f(file_type, e)
      allocate (character(len=max(1_size_t, n)) :: buffer)
      call h5tcopy_f(H5T_FORTRAN_S1, memory_type, e)
      call h5tset_size_f(memory_type, int(len(buffer), size_t), e)
      call h5aread_f(attribute, memory_type, buffer, [1_hsize_t], e)
      error = min(error, e)
      call h5tclose_f(memory_type, e)
      call h5aclose_f(attribute, e)
      if (error < 0) then
         call status%fail('cannot read attribute '//name//' of '//self%path)
         return
      end if
      value = buffer
   end subroutine attribute_read_string

   ! --- types ---------------------------------------------------------------------------------------

   integer(hid_t) function real_type()
      real_type = h5kind_to_type(real64, H5_REAL_KIND)
   end function real_type

   integer(hid_t) function single_type()
      single_type = h5kind_to_type(real32, H5_REAL_KIND)
   end function single_type

   integer(hid_t) function int_type()
      int_type = h5kind_to_type(int32, H5_INTEGER_KIND)
   end function int_type

   integer(hid_t) function i8_type()
      i8_type = h5kind_to_type(int64, H5_INTEGER_KIND)
   end function i8_type
end module hdf5_file
