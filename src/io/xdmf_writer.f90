!> XDMF 3 files that describe the HDF5 fields files as time series for ParaView (docs/output.md).
!>
!> One file per kind of data, each a single `GridType="Collection" CollectionType="Temporal"` with one
!> member per output time (`<Time Value=.../>`):
!>   particles: `Polyvertex` topology with an explicit connectivity dataset 0..N-1 (without it ParaView
!>              shows no cells and meshio refuses the file; shared/docs/toolchain.md), XYZ geometry, and
!>              the positions also as the point array `position` (for meshio's time series reader);
!>   grid:      `3DCoRectMesh` of the active box of cells (one node layer in z in 2-D), ORIGIN_DXDYDZ,
!>              each inside a one-grid spatial collection: the box changes from output to output, and
!>              ParaView's Xdmf3 reader keeps the first step's extent for a series of plain structured
!>              grids (the render view then shows every step clipped to that box), while the blocks of
!>              a multiblock data set keep their own extents (docs/output.md).
!> XDMF lists dimensions slowest first (z y x), which is how a Fortran array a(x, y, z) appears in HDF5.
!> Only rank 0 calls these writers; the file is written under a temporary name and renamed.
module xdmf_writer
   use kinds, only: rp, i8
   use error_status, only: status_t
   use file_system, only: rename_path
   use output_layout, only: fields_file, temporary_suffix
   use input_text, only: int_text, real_text
   implicit none
   private

   !> One array of the fields files as XDMF presents it.
   type, public :: xdmf_attribute_t
      character(len=64) :: name = ''          !< array name shown in ParaView
      character(len=96) :: dataset = ''       !< HDF5 path inside the fields file
      character(len=4) :: center = 'Node'     !< 'Node' (per particle / grid node) or 'Cell'
      integer :: components = 1               !< 1 scalar, 3 vector, 9 tensor (row by row)
      logical :: is_integer = .false.
      integer :: precision = 8                !< bytes per value
   end type xdmf_attribute_t

   !> What one output step wrote (also kept in checkpoints, so a restarted run can list it again).
   type, public :: output_entry_t
      integer :: index = 0                    !< output number: fields file fields_<index>.h5
      real(rp) :: time = 0.0_rp              !< simulated time [s]
      integer(i8) :: step = 0
      integer(i8) :: particles = 0            !< particles in the file (0: no particle data)
      integer :: grid_cells(3) = 0            !< cells of the grid box along x, y, z (0: no grid data)
      real(rp) :: grid_origin(3) = 0.0_rp     !< world position of the box's lower corner [m]
   end type output_entry_t

   public :: write_particles_xdmf, write_grid_xdmf

contains

   !> Write the particle time series of `entries` with `attributes` to `path`.
   subroutine write_particles_xdmf(path, entries, attributes, status)
      character(len=*), intent(in) :: path
      type(output_entry_t), intent(in) :: entries(:)
      type(xdmf_attribute_t), intent(in) :: attributes(:)
      type(status_t), intent(inout) :: status
      type(xdmf_attribute_t), parameter :: position = xdmf_attribute_t('position', '/particles/position', 'Node', 3, &
                                                                        .false., 8)
      integer :: unit, e, a
      character(len=:), allocatable :: n, file
      call open_xdmf(path, 'particles', unit, status)
      if (.not. status%ok) return
      do e = 1, size(entries)
         if (entries(e)%particles <= 0) cycle
         n = int_text(entries(e)%particles)
         file = fields_file(entries(e)%index)
         call begin_step(unit, 'particles', entries(e))
         write (unit, '(a)') '        <Topology TopologyType="Polyvertex" NumberOfElements="'//n// &
            '" NodesPerElement="1">', &
            '          '//data_item(n, .true., 8, file//':/particles/connectivity'), &
            '        </Topology>', &
            '        <Geometry GeometryType="XYZ">', &
            '          '//data_item(n//' 3', .false., position%precision, file//':'//trim(position%dataset)), &
            '        </Geometry>'
         ! The positions once more as an array: meshio's TimeSeriesReader takes the points of the first
         ! step only and each step's arrays, and the particle count changes (inflow, particles leaving).
         call write_attribute(unit, position, n, file)
         do a = 1, size(attributes)
            call write_attribute(unit, attributes(a), n, file)
         end do
         write (unit, '(a)') '      </Grid>'
      end do
      call close_xdmf(path, unit, status)
   end subroutine write_particles_xdmf

   !> Write the grid time series of `entries` (grid box of each, spacing h) with `attributes` to `path`.
   !> With node_positions (a grid rotated against the world) the mesh is a 3DSMesh whose node positions
   !> are the dataset /grid/node/position.
   subroutine write_grid_xdmf(path, entries, attributes, dim, h, status, node_positions)
      character(len=*), intent(in) :: path
      type(output_entry_t), intent(in) :: entries(:)
      type(xdmf_attribute_t), intent(in) :: attributes(:)
      integer, intent(in) :: dim
      real(rp), intent(in) :: h
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: node_positions
      logical :: explicit
      integer :: unit, e, a, nodes(3)
      character(len=:), allocatable :: node_dims, cell_dims, file
      explicit = .false.
      if (present(node_positions)) explicit = node_positions
      call open_xdmf(path, 'grid', unit, status)
      if (.not. status%ok) return
      do e = 1, size(entries)
         associate (cells => entries(e)%grid_cells)
            if (any(cells(1:dim) <= 0)) cycle
            nodes = 1
            nodes(1:dim) = cells(1:dim) + 1
            node_dims = dims_text(nodes)
            cell_dims = dims_text(cells)
         end associate
         file = fields_file(entries(e)%index)
         ! the time on the member of the temporal collection, where the readers look for it
         write (unit, '(a)') '      <Grid Name="step" GridType="Collection" CollectionType="Spatial">', &
            '        <Time Value="'//real_text(entries(e)%time)//'"/>', &
            '        <Grid Name="grid" GridType="Uniform">'
         if (explicit) then
            write (unit, '(a)') '        <Topology TopologyType="3DSMesh" Dimensions="'//node_dims//'"/>', &
               '        <Geometry GeometryType="XYZ">', &
               '          '//data_item(node_dims//' 3', .false., 8, file//':/grid/node/position'), &
               '        </Geometry>'
         else
            write (unit, '(a)') '        <Topology TopologyType="3DCoRectMesh" Dimensions="'//node_dims//'"/>', &
            '        <Geometry GeometryType="ORIGIN_DXDYDZ">', &
            '          <DataItem Dimensions="3" NumberType="Float" Precision="8" Format="XML">'// &
            real_text(entries(e)%grid_origin(3))//' '//real_text(entries(e)%grid_origin(2))//' '// &
            real_text(entries(e)%grid_origin(1))//'</DataItem>', &
            '          <DataItem Dimensions="3" NumberType="Float" Precision="8" Format="XML">'// &
            real_text(h)//' '//real_text(h)//' '//real_text(h)//'</DataItem>', &
            '        </Geometry>'
         end if
         do a = 1, size(attributes)
            if (attributes(a)%center == 'Cell') then
               call write_attribute(unit, attributes(a), cell_dims, file)
            else
               call write_attribute(unit, attributes(a), node_dims, file)
            end if
         end do
         write (unit, '(a)') '        </Grid>', '      </Grid>'
      end do
      call close_xdmf(path, unit, status)
   end subroutine write_grid_xdmf

   subroutine open_xdmf(path, name, unit, status)
      character(len=*), intent(in) :: path, name
      integer, intent(out) :: unit
      type(status_t), intent(inout) :: status
      integer :: ios
      character(len=256) :: message
      open (newunit=unit, file=path//temporary_suffix, status='replace', action='write', iostat=ios, iomsg=message)
      if (ios /= 0) then
         call status%fail('cannot write '//path//temporary_suffix//': '//trim(message))
         return
      end if
      write (unit, '(a)') '<?xml version="1.0" ?>', &
         '<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>', &
         '<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">', &
         '  <Domain>', &
         '    <Grid Name="'//name//'" GridType="Collection" CollectionType="Temporal">'
   end subroutine open_xdmf

   subroutine close_xdmf(path, unit, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: unit
      type(status_t), intent(inout) :: status
      integer :: ios
      write (unit, '(a)') '    </Grid>', '  </Domain>', '</Xdmf>'
      close (unit, iostat=ios)
      if (ios /= 0) then
         call status%fail('cannot write '//path//temporary_suffix)
      else if (.not. rename_path(path//temporary_suffix, path)) then
         call status%fail('cannot rename '//path//temporary_suffix//' to '//path)
      end if
   end subroutine close_xdmf

   subroutine begin_step(unit, name, entry)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: name
      type(output_entry_t), intent(in) :: entry
      write (unit, '(a)') '      <Grid Name="'//name//'" GridType="Uniform">', &
         '        <Time Value="'//real_text(entry%time)//'"/>'
   end subroutine begin_step

   subroutine write_attribute(unit, attribute, dims, file)
      integer, intent(in) :: unit
      type(xdmf_attribute_t), intent(in) :: attribute
      character(len=*), intent(in) :: dims, file
      character(len=:), allocatable :: kind, item_dims
      select case (attribute%components)
      case (3)
         kind = 'Vector'
         item_dims = dims//' 3'
      case (9)
         kind = 'Tensor'
         item_dims = dims//' 9'
      case default
         kind = 'Scalar'
         item_dims = dims
      end select
      write (unit, '(a)') '        <Attribute Name="'//trim(attribute%name)//'" AttributeType="'//kind// &
         '" Center="'//trim(attribute%center)//'">', &
         '          '//data_item(item_dims, attribute%is_integer, attribute%precision, &
                                 file//':'//trim(attribute%dataset)), &
         '        </Attribute>'
   end subroutine write_attribute

   pure function data_item(dims, is_integer, precision, location) result(text)
      character(len=*), intent(in) :: dims, location
      logical, intent(in) :: is_integer
      integer, intent(in) :: precision
      character(len=:), allocatable :: text, number_type
      if (is_integer) then
         number_type = 'Int'
      else
         number_type = 'Float'
      end if
      text = '<DataItem Dimensions="'//dims//'" NumberType="'//number_type//'" Precision="'// &
             int_text(precision)//'" Format="HDF">'//location//'</DataItem>'
   end function data_item

   !> "nz ny nx" of the counts n(3) along x, y, z.
   pure function dims_text(n) result(text)
      integer, intent(in) :: n(3)
      character(len=:), allocatable :: text
      text = int_text(n(3))//' '//int_text(n(2))//' '//int_text(n(1))
   end function dims_text

end module xdmf_writer
