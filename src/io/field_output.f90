!> The fields file of one output time, written collectively by all ranks (docs/output.md):
!>
!>   /particles    one entry per particle, ranks concatenated in rank order (each rank's slab placed by
!>                 MPI_Exscan); positions, velocities and stresses in the world frame (world_frame)
!>   /grid/node    nodal mass and velocity on the nodes of the active box of cells
!>   /grid/cell    per material: cell averages of density and mean stress over the active box
!>
!> The active box is the smallest box of cells holding every particle; it lies inside the active region
!> of the decomposition (the cells allocated), so output cost follows the particles too. A state with a
!> particle outside the grid (a blow-up written for inspection) gets no grid fields. Nodal values are those of a
!> particle-to-grid transfer of the current state (the solver's next step repeats it, so writing does
!> not change the solution). A grid node belongs to the rank owning the cell of which it is the lower
!> corner; the nodes on the upper faces of the box belong to the ranks owning the last cells.
module field_output
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_is_finite
   use kinds, only: rp, i8, name_len
   use error_status, only: status_t
   use mpi_f08, only: MPI_Allreduce, MPI_IN_PLACE, MPI_INTEGER, MPI_LOGICAL, MPI_MIN, MPI_MAX, MPI_LAND
   use tensor_layout, only: mean_stress
   use background_grid, only: row_mass
   use grid_transfer, only: particles_to_grid
   use node_halo, only: sum_shared_nodes
   use mpm_solver, only: solver_t
   use hdf5_file, only: hdf5_file_t, slab_t, distributed_slab, to_single
   use scene_description, only: writes_particle_field
   use provenance, only: write_provenance_attributes, agreed_date
   use xdmf_writer, only: xdmf_attribute_t, output_entry_t
   use output_layout, only: fields_file, temporary_suffix
   use file_system, only: rename_path
   use status_broadcast, only: agree_on_status, broadcast_status
   implicit none
   private

   public :: write_fields, particle_xdmf_attributes, grid_xdmf_attributes

contains

   !> Write fields file number `index` of the solver's current state into `dir` (particles and/or grid as
   !> the run's particle_output / grid_output ask) and describe it in `entry`. Collective.
   subroutine write_fields(solver, dir, index, entry, status)
      type(solver_t), intent(inout) :: solver
      character(len=*), intent(in) :: dir
      integer, intent(in) :: index
      type(output_entry_t), intent(out) :: entry
      type(status_t), intent(inout) :: status
      type(hdf5_file_t) :: file
      character(len=:), allocatable :: path

      entry%index = index
      entry%time = solver%time
      entry%step = solver%step
      path = trim(dir)//'/'//fields_file(index)
      call file%create(path//temporary_suffix, solver%domain%comm, status)
      call file%write_attribute('time', solver%time, status)
      call file%write_attribute('step', solver%step, status)
      call file%write_attribute('output_index', index, status)
      call file%write_attribute('dim', solver%grid%dim, status)
      call write_provenance_attributes(file, solver%scene, agreed_date(solver%domain%comm), status, &
                                       solver%domain%nranks)
      if (solver%run%particle_output) call write_particle_fields(solver, file, entry, status)
      ! the state of a blow-up written for inspection may have particles nowhere: then no grid
      if (solver%run%grid_output) then
         if (positions_in_grid(solver)) call write_grid_fields(solver, file, entry, status)
      end if
      call file%close(status)
      call agree_on_status(status, solver%domain%comm)
      if (.not. status%ok) return
      if (solver%domain%rank == 0) then
         if (.not. rename_path(path//temporary_suffix, path)) call status%fail('cannot rename '//path//temporary_suffix)
      end if
      call broadcast_status(status, solver%domain%comm, 0)
   end subroutine write_fields

   !> /particles: every particle's state in the world frame and a Polyvertex connectivity 0..N-1; the
   !> datasets `&run particle_fields` chooses (position and connectivity always), each with its units and
   !> description, reals in `&run field_precision` (positions always double: the geometry).
   subroutine write_particle_fields(solver, file, entry, status)
      type(solver_t), intent(in) :: solver
      type(hdf5_file_t), intent(inout) :: file
      type(output_entry_t), intent(inout) :: entry
      type(status_t), intent(inout) :: status
      type(slab_t) :: slab
      real(rp), allocatable :: vectors(:, :), tensors(:, :), scalars(:), sigma(:, :)
      integer, allocatable :: integers(:)
      integer(i8), allocatable :: ids(:)
      integer :: n, p, m
      logical :: single
      character(len=:), allocatable :: per_depth
      character(len=name_len), allocatable :: names(:)

      n = solver%particles%count
      single = solver%run%field_precision == 'single'
      slab = distributed_slab(solver%domain%comm, n)
      entry%particles = slab%total
      per_depth = ''
      if (solver%grid%dim == 2) per_depth = ' per metre of thickness (2-D plane strain)'
      call file%create_group('particles', status)
      associate (particles => solver%particles, run => solver%run)
         allocate (vectors(3, max(n, 1)), tensors(9, max(n, 1)), scalars(max(n, 1)), integers(max(n, 1)), &
                   ids(max(n, 1)))
         call solver%grid%frame%to_world_points(particles%x(:, 1:n), vectors)
         call file%write_slab('particles/position', slab, vectors, status)
         call describe(file, 'particles/position', 'm', 'position in the world frame (x, y, z; z = 0 in 2-D)', status)
         if (writes_particle_field(run, 'velocity')) then
            call solver%grid%frame%to_world_vectors(particles%v(:, 1:n), vectors)
            call put_reals(file, 'particles/velocity', slab, vectors, single, 'm/s', &
                           'velocity in the world frame (x, y, z; z = 0 in 2-D)', status)
         end if
         if (writes_particle_field(run, 'mass')) then
            scalars(1:n) = particles%mass(1:n)
            call put_real(file, 'particles/mass', slab, scalars, single, merge('kg/m', 'kg  ', solver%grid%dim == 2), &
                          'mass (constant)'//per_depth, status)
         end if
         if (writes_particle_field(run, 'density')) then
            scalars(1:n) = particles%density(1:n)
            call put_real(file, 'particles/density', slab, scalars, single, 'kg/m^3', 'current density rho', status)
         end if
         if (writes_particle_field(run, 'volume')) then
            scalars(1:n) = particles%mass(1:n) / particles%density(1:n)
            call put_real(file, 'particles/volume', slab, scalars, single, merge('m^2', 'm^3', solver%grid%dim == 2), &
                          'current volume m / rho'//per_depth, status)
         end if
         do p = 1, n
            scalars(p) = particles%density(p) * mean_stress(particles%sbar(:, p))
         end do
         if (writes_particle_field(run, 'mean_stress')) &
            call put_real(file, 'particles/mean_stress', slab, scalars, single, 'Pa', &
                          'mean stress (sxx + syy + szz) / 3 = -pressure (negative in compression)', status)
         if (writes_particle_field(run, 'pressure')) then
            scalars(1:n) = -scalars(1:n)
            call put_real(file, 'particles/pressure', slab, scalars, single, 'Pa', &
                          'pressure p = -(sxx + syy + szz) / 3 = -mean_stress (positive in compression; the fluid '// &
                          'pressure of docs/theory.md)', status)
         end if
         if (writes_particle_field(run, 'stress')) then
            allocate (sigma(particles%n_sigma, max(n, 1)))
            do p = 1, n
               sigma(:, p) = particles%density(p) * particles%sbar(:, p)
            end do
            call solver%grid%frame%to_world_tensors(sigma(:, 1:n), particles%dim, tensors)
            call put_reals(file, 'particles/stress', slab, tensors, single, 'Pa', 'Cauchy stress in the world frame, '// &
                           'row by row: xx, xy, xz, yx, yy, yz, zx, zy, zz (tension positive; 2-D: szz of plane strain)', &
                           status)
         end if
         if (writes_particle_field(run, 'material')) then
            integers(1:n) = particles%material(1:n)
            call file%write_slab('particles/material', slab, integers, status)
            allocate (names(size(solver%materials)))
            do m = 1, size(solver%materials)
               names(m) = solver%materials(m)%model%name
            end do
            call describe(file, 'particles/material', '-', 'material number k = 1, 2, ...: the k-th &material '// &
                          'group, named material_names[k-1]', status)
            call file%write_object_attribute('particles/material', 'material_names', names, status)
         end if
         if (writes_particle_field(run, 'rank')) then
            integers(1:n) = solver%domain%rank
            call file%write_slab('particles/rank', slab, integers, status)
            call describe(file, 'particles/rank', '-', 'rank that owned the particle', status)
         end if
         if (writes_particle_field(run, 'id')) then
            ids(1:n) = particles%id(1:n)
            call file%write_slab('particles/id', slab, ids, status)
            call describe(file, 'particles/id', '-', 'globally unique particle id, the same in every output '// &
                          'and for any number of ranks', status)
         end if
         do p = 1, n
            ids(p) = slab%offset + p - 1
         end do
         call file%write_slab('particles/connectivity', slab, ids, status)
         call describe(file, 'particles/connectivity', '-', '0 .. N-1: one vertex cell per particle (XDMF '// &
                       'Polyvertex topology)', status)
      end associate
   end subroutine write_particle_fields

   !> The attributes `units` and `description` of dataset `name`.
   subroutine describe(file, name, units, description, status)
      type(hdf5_file_t), intent(inout) :: file
      character(len=*), intent(in) :: name, units, description
      type(status_t), intent(inout) :: status
      call file%write_object_attribute(name, 'units', trim(units), status)
      call file%write_object_attribute(name, 'description', description, status)
   end subroutine describe

   !> A 1-D particle dataset in double or single precision, described.
   subroutine put_real(file, name, slab, values, single, units, description, status)
      type(hdf5_file_t), intent(inout) :: file
      character(len=*), intent(in) :: name, units, description
      type(slab_t), intent(in) :: slab
      real(rp), intent(in), contiguous :: values(:)
      logical, intent(in) :: single
      type(status_t), intent(inout) :: status
      if (single) then
         call file%write_slab(name, slab, to_single(values), status)
      else
         call file%write_slab(name, slab, values, status)
      end if
      call describe(file, name, units, description, status)
   end subroutine put_real

   !> A particle dataset of vectors or tensors (one column per particle) in double or single precision.
   subroutine put_reals(file, name, slab, values, single, units, description, status)
      type(hdf5_file_t), intent(inout) :: file
      character(len=*), intent(in) :: name, units, description
      type(slab_t), intent(in) :: slab
      real(rp), intent(in), contiguous :: values(:, :)
      logical, intent(in) :: single
      type(status_t), intent(inout) :: status
      if (single) then
         call file%write_slab(name, slab, reshape(to_single(reshape(values, [size(values)])), shape(values)), status)
      else
         call file%write_slab(name, slab, values, status)
      end if
      call describe(file, name, units, description, status)
   end subroutine put_reals

   !> A grid dataset (a block of the active box) in double or single precision, described.
   subroutine put_block(file, name, global, offset, local, values, single, units, description, status)
      type(hdf5_file_t), intent(inout) :: file
      character(len=*), intent(in) :: name, units, description
      integer(i8), intent(in) :: global(:), offset(:), local(:)
      real(rp), intent(in), contiguous :: values(:)
      logical, intent(in) :: single
      type(status_t), intent(inout) :: status
      if (single) then
         call file%write_block(name, global, offset, local, to_single(values), status)
      else
         call file%write_block(name, global, offset, local, values, status)
      end if
      call describe(file, name, units, description, status)
   end subroutine put_block

   !> /grid: nodal mass and velocity, and per material the cell averages of density and mean stress
   !> (volume weighted: sum m / sum V, and sum V sigma_m / sum V) on the active box.
   subroutine write_grid_fields(solver, file, entry, status)
      type(solver_t), intent(inout) :: solver
      type(hdf5_file_t), intent(inout) :: file
      type(output_entry_t), intent(inout) :: entry
      type(status_t), intent(inout) :: status
      integer :: box_lo(3), box_hi(3), cell_lo(3), cell_hi(3), node_hi(3), dim, m, k
      integer(i8) :: cells(3), nodes(3), local_cells(3), local_nodes(3), offset(3)
      real(rp), allocatable :: node_mass(:), node_velocity(:, :), density(:), stress(:), corner(:, :), &
                               node_position(:, :)
      real(rp) :: world_corner(3, 1)
      character(len=:), allocatable :: name, per_depth
      logical :: single

      dim = solver%grid%dim
      allocate (corner(dim, 1))
      call active_box(solver, box_lo, box_hi)
      cells = 1
      nodes = 1
      cells(1:dim) = box_hi(1:dim) - box_lo(1:dim) + 1
      nodes(1:dim) = cells(1:dim) + 1
      entry%grid_cells = int(cells)
      entry%grid_origin = 0.0_rp
      entry%grid_origin(1:dim) = solver%grid%origin(1:dim) + box_lo(1:dim) * solver%grid%h
      corner(:, 1) = entry%grid_origin(1:dim)
      call solver%grid%frame%to_world_points(corner, world_corner)
      entry%grid_origin = world_corner(:, 1)

      ! this rank's cells and nodes inside the box
      cell_lo = 0
      cell_hi = 0
      node_hi = 0
      cell_lo(1:dim) = max(solver%grid%cell_lo(1:dim), box_lo(1:dim))
      cell_hi(1:dim) = min(solver%grid%cell_hi(1:dim), box_hi(1:dim))
      do k = 1, dim
         node_hi(k) = cell_hi(k) + merge(1, 0, cell_hi(k) == box_hi(k))
      end do
      local_cells = max(0_i8, int(cell_hi - cell_lo + 1, i8))
      local_nodes = max(0_i8, int(node_hi - cell_lo + 1, i8))
      if (any(local_cells == 0)) then
         local_cells = 0
         local_nodes = 0
      end if
      offset = int(cell_lo - box_lo, i8)
      offset(dim + 1:) = 0

      call particles_to_grid(solver%grid, solver%particles, solver%gravity)
      call sum_shared_nodes(solver%domain, solver%grid, solver%grid%accumulated)
      call nodal_fields(solver, cell_lo, node_hi, local_nodes, node_mass, node_velocity, node_position)

      single = solver%run%field_precision == 'single'
      name = ''
      per_depth = ''
      if (dim == 2) per_depth = ' per metre of thickness (2-D plane strain)'
      call file%create_group('grid', status)
      call file%create_group('grid/node', status)
      call file%create_group('grid/cell', status)
      call put_block(file, 'grid/node/mass', nodes, offset, local_nodes, node_mass, single, &
                     merge('kg/m', 'kg  ', dim == 2), 'nodal mass sum N_ip m_p'//per_depth, status)
      call put_block(file, 'grid/node/velocity', [3_i8, nodes], [0_i8, offset], [3_i8, local_nodes], &
                     reshape(node_velocity, [size(node_velocity)]), single, 'm/s', &
                     'nodal velocity (sum N_ip m_p v_p) / m_i in the world frame; 0 on empty nodes', status)
      ! a rotated grid is not a rectilinear mesh in the world: its node positions go into the file (always
      ! double: the geometry)
      if (solver%grid%frame%rotated) then
         call file%write_block('grid/node/position', [3_i8, nodes], [0_i8, offset], [3_i8, local_nodes], &
                               reshape(node_position, [size(node_position)]), status)
         call describe(file, 'grid/node/position', 'm', 'world position of each node (the grid is rotated)', status)
      end if
      do m = 1, size(solver%materials)
         call cell_averages(solver, m, cell_lo, local_cells, density, stress)
         name = material_field_name(solver, m)
         call put_block(file, 'grid/cell/density_'//name, cells, offset, local_cells, density, single, 'kg/m^3', &
                        "cell average of the density of material '"//trim(solver%materials(m)%model%name)// &
                        "', sum m_p / sum V_p; NaN where the cell holds none of it", status)
         call put_block(file, 'grid/cell/mean_stress_'//name, cells, offset, local_cells, stress, single, 'Pa', &
                        "volume-weighted cell average of the mean stress (-pressure) of material '"// &
                        trim(solver%materials(m)%model%name)//"', sum V_p s_m,p / sum V_p; NaN where absent", status)
      end do
   end subroutine write_grid_fields

   !> True if every particle of every rank has a finite position inside the grid. Collective.
   logical function positions_in_grid(solver) result(inside)
      type(solver_t), intent(in) :: solver
      integer :: p, k
      real(rp) :: s
      inside = .true.
      do p = 1, solver%particles%count
         do k = 1, solver%grid%dim
            if (.not. ieee_is_finite(solver%particles%x(k, p))) then
               inside = .false.
            else
               s = (solver%particles%x(k, p) - solver%grid%origin(k)) * solver%grid%inv_h
               inside = s >= 0.0_rp .and. s <= real(solver%grid%global_cells(k), rp) * (1.0_rp + epsilon(s))
            end if
            if (.not. inside) exit
         end do
         if (.not. inside) exit
      end do
      call MPI_Allreduce(MPI_IN_PLACE, inside, 1, MPI_LOGICAL, MPI_LAND, solver%domain%comm)
   end function positions_in_grid

   !> Smallest box of global cells holding every particle (the decomposition's active region when there
   !> are none: no other cells are allocated). Collective.
   subroutine active_box(solver, box_lo, box_hi)
      type(solver_t), intent(in) :: solver
      integer, intent(out) :: box_lo(3), box_hi(3)
      integer :: p, c(3), dim
      dim = solver%grid%dim
      box_lo = huge(1)
      box_hi = -1
      do p = 1, solver%particles%count
         c = solver%grid%cell_of_position(solver%particles%x(:, p))
         box_lo = min(box_lo, c)
         box_hi = max(box_hi, c)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, box_lo, 3, MPI_INTEGER, MPI_MIN, solver%domain%comm)
      call MPI_Allreduce(MPI_IN_PLACE, box_hi, 3, MPI_INTEGER, MPI_MAX, solver%domain%comm)
      if (box_hi(1) < 0) call solver%domain%region(box_lo, box_hi)
      box_lo(dim + 1:) = 0
      box_hi(dim + 1:) = 0
   end subroutine active_box

   !> Mass and velocity P/m (0 on empty nodes) of the nodes cell_lo..node_hi, x fastest, and with
   !> `position` their world positions (a rotated grid writes them).
   subroutine nodal_fields(solver, cell_lo, node_hi, local_nodes, mass, velocity, position)
      type(solver_t), intent(in) :: solver
      integer, intent(in) :: cell_lo(3), node_hi(3)
      integer(i8), intent(in) :: local_nodes(3)
      real(rp), allocatable, intent(out) :: mass(:), velocity(:, :)
      real(rp), allocatable, intent(out), optional :: position(:, :)
      real(rp), allocatable :: grid_velocity(:, :), grid_position(:, :)
      integer :: i, j, l, n, node, dim, mom
      dim = solver%grid%dim
      mom = solver%grid%row_momentum
      n = int(product(local_nodes))
      allocate (mass(max(n, 1)), velocity(3, max(n, 1)), grid_velocity(dim, max(n, 1)), grid_position(dim, max(n, 1)))
      mass = 0.0_rp
      grid_velocity = 0.0_rp
      grid_position = 0.0_rp
      if (n > 0) then
         n = 0
         do l = cell_lo(3), node_hi(3)
            do j = cell_lo(2), node_hi(2)
               do i = cell_lo(1), node_hi(1)
                  n = n + 1
                  node = solver%grid%local_node([i, j, l])
                  mass(n) = solver%grid%accumulated(row_mass, node)
                  if (mass(n) > solver%mass_tolerance) &
                     grid_velocity(:, n) = solver%grid%accumulated(mom:mom + dim - 1, node) / mass(n)
                  grid_position(:, n) = solver%grid%origin(1:dim) + [i, j, l] * solver%grid%h
               end do
            end do
         end do
      end if
      call solver%grid%frame%to_world_vectors(grid_velocity, velocity)
      if (present(position)) then
         allocate (position(3, max(n, 1)))
         call solver%grid%frame%to_world_points(grid_position, position)
      end if
   end subroutine nodal_fields

   !> Volume-weighted cell averages of material m over the local_cells from cell_lo (x fastest): density
   !> sum m / sum V and mean stress sum V sigma_m / sum V; NaN where the cell has none of the material.
   subroutine cell_averages(solver, m, cell_lo, local_cells, density, stress)
      type(solver_t), intent(in) :: solver
      integer, intent(in) :: m, cell_lo(3)
      integer(i8), intent(in) :: local_cells(3)
      real(rp), allocatable, intent(out) :: density(:), stress(:)
      real(rp), allocatable :: mass(:), volume(:)
      integer :: p, n, c(3), k, dim, index
      real(rp) :: v
      dim = solver%grid%dim
      n = int(product(local_cells))
      allocate (density(max(n, 1)), stress(max(n, 1)), mass(max(n, 1)), volume(max(n, 1)))
      mass = 0.0_rp
      volume = 0.0_rp
      stress = 0.0_rp
      if (n > 0) then
         associate (particles => solver%particles)
            do p = particles%material_first(m), particles%material_last(m)
               c = solver%grid%cell_of_position(particles%x(:, p))
               index = 0
               do k = dim, 1, -1
                  index = index * int(local_cells(k)) + (c(k) - cell_lo(k))
               end do
               index = index + 1
               v = particles%mass(p) / particles%density(p)
               mass(index) = mass(index) + particles%mass(p)
               volume(index) = volume(index) + v
               stress(index) = stress(index) + v * particles%density(p) * mean_stress(particles%sbar(:, p))
            end do
         end associate
      end if
      do p = 1, n
         if (volume(p) > 0.0_rp) then
            density(p) = mass(p) / volume(p)
            stress(p) = stress(p) / volume(p)
         else
            density(p) = ieee_value(1.0_rp, ieee_quiet_nan)
            stress(p) = density(p)
         end if
      end do
   end subroutine cell_averages

   !> The material's name as it appears in dataset and array names: letters, digits, '-' and '_' kept,
   !> anything else replaced by '_'; the material number is appended if two materials would clash.
   function material_field_name(solver, m) result(name)
      type(solver_t), intent(in) :: solver
      integer, intent(in) :: m
      character(len=:), allocatable :: name
      integer :: other
      character(len=12) :: number
      name = safe_name(solver%materials(m)%model%name)
      do other = 1, size(solver%materials)
         if (other /= m .and. safe_name(solver%materials(other)%model%name) == name) then
            write (number, '(i0)') m
            name = name//'_'//trim(number)
            return
         end if
      end do
   end function material_field_name

   pure function safe_name(text) result(name)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: name
      integer :: i
      name = trim(text)
      do i = 1, len(name)
         select case (name(i:i))
         case ('a':'z', 'A':'Z', '0':'9', '-', '_')
         case default
            name(i:i) = '_'
         end select
      end do
      if (len(name) == 0) name = 'material'
   end function safe_name

   !> The XDMF description of /particles: the datasets `&run particle_fields` chose, reals in the
   !> precision of `&run field_precision` (4 or 8 bytes, as written).
   function particle_xdmf_attributes(solver) result(attributes)
      type(solver_t), intent(in) :: solver
      type(xdmf_attribute_t), allocatable :: attributes(:)
      type(xdmf_attribute_t) :: every(10)
      integer :: bytes, k
      bytes = merge(4, 8, solver%run%field_precision == 'single')
      every = [xdmf_attribute_t('velocity', '/particles/velocity', 'Node', 3, .false., bytes), &
             xdmf_attribute_t('mass', '/particles/mass', 'Node', 1, .false., bytes), &
             xdmf_attribute_t('volume', '/particles/volume', 'Node', 1, .false., bytes), &
             xdmf_attribute_t('density', '/particles/density', 'Node', 1, .false., bytes), &
             xdmf_attribute_t('stress', '/particles/stress', 'Node', 9, .false., bytes), &
             xdmf_attribute_t('mean_stress', '/particles/mean_stress', 'Node', 1, .false., bytes), &
             xdmf_attribute_t('pressure', '/particles/pressure', 'Node', 1, .false., bytes), &
             xdmf_attribute_t('material', '/particles/material', 'Node', 1, .true., 4), &
             xdmf_attribute_t('id', '/particles/id', 'Node', 1, .true., 8), &
             xdmf_attribute_t('rank', '/particles/rank', 'Node', 1, .true., 4)]
      allocate (attributes(0))
      do k = 1, size(every)
         if (writes_particle_field(solver%run, trim(every(k)%name))) attributes = [attributes, every(k)]
      end do
   end function particle_xdmf_attributes

   !> The XDMF description of /grid for the solver's materials, reals in the precision written.
   function grid_xdmf_attributes(solver) result(attributes)
      type(solver_t), intent(in) :: solver
      type(xdmf_attribute_t), allocatable :: attributes(:)
      character(len=:), allocatable :: name
      integer :: m, bytes
      bytes = merge(4, 8, solver%run%field_precision == 'single')
      attributes = [xdmf_attribute_t('mass', '/grid/node/mass', 'Node', 1, .false., bytes), &
                    xdmf_attribute_t('velocity', '/grid/node/velocity', 'Node', 3, .false., bytes)]
      do m = 1, size(solver%materials)
         name = material_field_name(solver, m)
         attributes = [attributes, xdmf_attribute_t('density_'//name, '/grid/cell/density_'//name, 'Cell', 1, .false., &
                                                    bytes), &
                       xdmf_attribute_t('mean_stress_'//name, '/grid/cell/mean_stress_'//name, 'Cell', 1, .false., bytes)]
      end do
   end function grid_xdmf_attributes
end module field_output
