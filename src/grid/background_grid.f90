!> The part of the background grid a rank works on: the nodes of its owned cells.
!>
!> The local nodes are those of the owned cells and, with a stencil wider than a cell's corners (bspline2),
!> `ghost` more layers on each side (shape_functions: ghost_node_layers); node_lo = cell_lo - ghost.
!> Nodes are numbered locally in one flat index, x fastest:
!>   node(i, j, k) = 1 + (i - node_lo(1)) + n_nodes(1) * ((j - node_lo(2)) + n_nodes(2) * (k - node_lo(3)))
!> with global 0-based node indices i, j, k. Cells use the same rule with their own counts. Nodal
!> quantities that particles accumulate (P2G) live in one array `accumulated(:, node)` so that the
!> ghost-node sum exchanges them all in one message.
module background_grid
   use kinds, only: rp, i8
   use error_status, only: status_t
   use memory_budget, only: byte_text
   use input_text, only: int_text
   use shape_functions, only: shape_linear, stencil_nodes, stencil_offset, ghost_node_layers
   use domain_decomposition, only: domain_t
   use world_frame, only: frame_t
   implicit none
   private

   !> Rows of `accumulated`: mass, then momentum (dim), then force (dim) of all particles; then, with contact
   !> (src/solver/body_contact.f90), `field_rows` rows of the bodies' own velocity fields.
   integer, parameter, public :: row_mass = 1

   type, public :: grid_t
      integer :: dim = 2
      real(rp) :: h = 1.0_rp, inv_h = 1.0_rp       !< cell edge and its inverse
      real(rp) :: origin(3) = 0.0_rp               !< lower corner of the whole grid (grid frame)
      type(frame_t) :: frame                       !< the grid frame's placement in the world
      integer :: global_cells(3) = 1
      integer :: node_lo(3) = 0, node_hi(3) = 0    !< global index range of the local nodes
      integer :: n_nodes(3) = 1, node_count = 0
      integer :: cell_lo(3) = 0, cell_hi(3) = 0    !< owned cells (global, 0-based)
      integer :: n_cells(3) = 1, cell_count = 0
      real(rp) :: inv_row_cells(2) = 1.0_rp        !< 1 / cells of a row along x, 1 / cells of a layer (cell_indices)
      integer :: shape = shape_linear               !< shape function kind (set before init, kept by init)
      integer :: ghost = 0                          !< node layers beyond the cells' corners on each side
      integer :: stencil_size = 4                   !< nodes a particle touches (shape_functions: stencil_nodes)
      integer :: stencil_stride(27) = 0             !< local node offset of stencil node a from the base node
      !> along axis k the rank's cells end where the active region does: it owns its upper node layers too
      logical :: owns_upper(3) = .true.
      !> along axis k the rank's cells start where the active region does: it owns its lower ghost layers
      logical :: owns_lower(3) = .true.
      integer :: row_momentum = 2, row_force = 4, n_rows = 5
      integer :: field_rows = 0                    !< rows of the contact fields after the force (kept by init)
      real(rp), allocatable :: accumulated(:, :)   !< (n_rows, node): mass, momentum, force
      real(rp), allocatable :: velocity(:, :)      !< v_i^{n+theta} used for kinematics and positions
      real(rp), allocatable :: velocity_increment(:, :)  !< dv_i = v_i^{n+1} - v_i^n (FLIP increment)
   contains
      procedure :: init => grid_init
      procedure :: local_node => grid_local_node
      procedure :: node_indices => grid_node_indices
      procedure :: owns_node => grid_owns_node
      procedure :: local_cell => grid_local_cell
      procedure :: base_node_of_cell => grid_base_node_of_cell
      procedure :: cell_indices => grid_cell_indices
      procedure :: cell_of_position => grid_cell_of_position
      procedure :: cell_along => grid_cell_along
      procedure :: owned_local_cell => grid_owned_local_cell
      procedure :: owned_local_cells => grid_owned_local_cells
   end type grid_t

contains

   !> Size the local node box from the owned cells of `domain`.
   subroutine grid_init(self, domain, origin, h, frame, status)
      class(grid_t), intent(inout) :: self
      type(domain_t), intent(in) :: domain
      real(rp), intent(in) :: origin(3), h
      type(frame_t), intent(in), optional :: frame
      type(status_t), intent(inout), optional :: status   !< fails if the node arrays cannot be allocated
      integer :: a, k, stride(3), stat

      self%dim = domain%dim
      self%h = h
      self%inv_h = 1.0_rp / h
      self%origin = origin
      if (present(frame)) self%frame = frame
      self%global_cells = domain%global_cells
      self%cell_lo = domain%cell_lo
      self%cell_hi = domain%cell_hi
      self%owns_upper = .true.
      self%owns_lower = .true.
      if (allocated(domain%cuts)) then
         do k = 1, self%dim
            self%owns_upper(k) = domain%cell_hi(k) == domain%cuts(domain%dims(k), k) - 1
            self%owns_lower(k) = domain%cell_lo(k) == domain%cuts(0, k)
         end do
      end if
      self%ghost = ghost_node_layers(self%shape)
      self%n_cells = 1
      self%n_cells(1:self%dim) = self%cell_hi(1:self%dim) - self%cell_lo(1:self%dim) + 1
      self%cell_count = product(self%n_cells)
      self%inv_row_cells = 1.0_rp / real([self%n_cells(1), self%n_cells(1) * self%n_cells(2)], rp)
      self%node_lo = self%cell_lo
      self%node_hi = self%cell_hi
      self%node_lo(1:self%dim) = self%cell_lo(1:self%dim) - self%ghost
      self%node_hi(1:self%dim) = self%cell_hi(1:self%dim) + 1 + self%ghost
      self%n_nodes = 1
      self%n_nodes(1:self%dim) = self%n_cells(1:self%dim) + 1 + 2 * self%ghost
      self%node_count = product(self%n_nodes)

      stride = [1, self%n_nodes(1), self%n_nodes(1) * self%n_nodes(2)]
      self%stencil_size = stencil_nodes(self%shape, self%dim)
      self%stencil_stride = 0
      do a = 1, self%stencil_size
         do k = 1, self%dim
            self%stencil_stride(a) = self%stencil_stride(a) + stencil_offset(self%shape, a, k) * stride(k)
         end do
      end do

      self%row_momentum = row_mass + 1
      self%row_force = self%row_momentum + self%dim
      self%n_rows = 1 + 2 * self%dim + self%field_rows
      if (allocated(self%accumulated)) deallocate (self%accumulated, self%velocity, self%velocity_increment)
      allocate (self%accumulated(self%n_rows, self%node_count), self%velocity(self%dim, self%node_count), &
                self%velocity_increment(self%dim, self%node_count), stat=stat)
      if (stat /= 0) then
         ! no memory for this block: the caller stops; empty arrays keep the grid a valid object until then
         if (allocated(self%accumulated)) deallocate (self%accumulated)
         if (allocated(self%velocity)) deallocate (self%velocity)
         if (allocated(self%velocity_increment)) deallocate (self%velocity_increment)
         allocate (self%accumulated(self%n_rows, 0), self%velocity(self%dim, 0), self%velocity_increment(self%dim, 0))
         if (present(status)) call status%fail('no memory for the grid: '//byte_text(8_i8 * (self%n_rows + 2 * self%dim) * &
                                                                                      int(self%node_count, i8))// &
                                               ' for '//int_text(self%node_count)//' nodes on one rank')
         return
      end if
      self%accumulated = 0.0_rp
      self%velocity = 0.0_rp
      self%velocity_increment = 0.0_rp
   end subroutine grid_init

   !> Local flat index of the node with global indices g (0-based).
   pure integer function grid_local_node(self, g)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: g(:)
      integer :: k
      grid_local_node = 0
      do k = self%dim, 1, -1
         grid_local_node = grid_local_node * self%n_nodes(k) + (g(k) - self%node_lo(k))
      end do
      grid_local_node = grid_local_node + 1
   end function grid_local_node

   !> Global indices (0-based) of the local node with flat index `node` (the inverse of local_node).
   pure function grid_node_indices(self, node) result(g)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: node
      integer :: g(self%dim), k, rest
      rest = node - 1
      do k = 1, self%dim
         g(k) = self%node_lo(k) + mod(rest, self%n_nodes(k))
         rest = rest / self%n_nodes(k)
      end do
   end function grid_node_indices

   !> True if this rank is the one that counts the local node g (global indices) in sums over nodes: a
   !> node shared with the rank above along an axis belongs to that rank (the lower corner of its cells),
   !> a ghost node below the rank's cells to the rank below.
   pure logical function grid_owns_node(self, g) result(owns)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: g(:)
      integer :: k
      owns = .true.
      do k = 1, self%dim
         if (g(k) > self%cell_hi(k) .and. .not. self%owns_upper(k)) owns = .false.
         if (g(k) < self%cell_lo(k) .and. .not. self%owns_lower(k)) owns = .false.
      end do
   end function grid_owns_node

   !> Local flat index of the owned cell with global indices c (0-based).
   pure integer function grid_local_cell(self, c)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: c(:)
      integer :: k
      grid_local_cell = 0
      do k = self%dim, 1, -1
         grid_local_cell = grid_local_cell * self%n_cells(k) + (c(k) - self%cell_lo(k))
      end do
      grid_local_cell = grid_local_cell + 1
   end function grid_local_cell

   !> Global indices (0-based) of the owned cell with local flat index `cell`, the inverse of local_cell. The
   !> quotients by the row and layer sizes are taken in floating point from the middle of the cell's slot,
   !> (cell - 1 + 1/2) / n, whose integer part is exact while (cell - 1) n < 2e15: an integer division is several
   !> times dearer, and C0 takes the indices of every occupied cell at every step (cell_strain_rate).
   pure function grid_cell_indices(self, cell) result(g)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: cell
      integer :: g(3), rest, layer, row
      rest = cell - 1
      g = self%cell_lo
      if (self%dim == 3) then
         layer = int((real(rest, rp) + 0.5_rp) * self%inv_row_cells(2))
         rest = rest - layer * self%n_cells(1) * self%n_cells(2)
         g(3) = g(3) + layer
      end if
      row = int((real(rest, rp) + 0.5_rp) * self%inv_row_cells(1))
      g(2) = g(2) + row
      g(1) = g(1) + rest - row * self%n_cells(1)
   end function grid_cell_indices

   !> Local index of the lower corner node of the cell with global indices c (in the local node box).
   pure integer function grid_base_node_of_cell(self, c)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: c(:)
      grid_base_node_of_cell = self%local_node(c)
   end function grid_base_node_of_cell

   !> Global cell (0-based) holding position x: floor((x - origin)/h), a particle on a face going to
   !> the upper cell, except on the upper face of the whole grid, which belongs to the last cell.
   pure function grid_cell_of_position(self, x) result(c)
      class(grid_t), intent(in) :: self
      real(rp), intent(in) :: x(:)
      integer :: c(3), k
      c = 0
      do k = 1, self%dim
         c(k) = self%cell_along(x(k), k)
      end do
   end function grid_cell_of_position

   !> Global cell index along axis k of coordinate xk (rule of cell_of_position: the last face belongs to the
   !> last cell). Without branches (integer flags), so that the loops calling it vectorise
   !> (owned_local_cells).
   pure integer function grid_cell_along(self, xk, k) result(c)
      class(grid_t), intent(in) :: self
      real(rp), intent(in) :: xk
      integer, intent(in) :: k
      real(rp) :: s
      s = (xk - self%origin(k)) * self%inv_h
      c = floor(s)
      c = c - merge(1, 0, c == self%global_cells(k)) * merge(1, 0, s <= real(self%global_cells(k), rp) * (1 + epsilon(s)))
   end function grid_cell_along

   !> Local index of the owned cell holding x, or 0 if x lies outside the owned cells.
   !> (cell_along followed by local_cell, in one pass: this runs for every particle every step.)
   pure integer function grid_owned_local_cell(self, x) result(cell)
      class(grid_t), intent(in) :: self
      real(rp), intent(in) :: x(:)
      integer :: k, c, stride
      cell = 1
      stride = 1
      do k = 1, self%dim
         c = grid_cell_along(self, x(k), k)
         if (c < self%cell_lo(k) .or. c > self%cell_hi(k)) then
            cell = 0
            return
         end if
         cell = cell + (c - self%cell_lo(k)) * stride
         stride = stride * self%n_cells(k)
      end do
   end function grid_owned_local_cell

   !> owned_local_cell of the positions x(:, 1:n) into cell(1:n), and the number of them outside the owned
   !> cells (cell 0). The same integers in one pass that the compiler vectorises: per dimension, positions
   !> of a known leading dimension, no early exit (one particle at a time, every particle and every step,
   !> this was 4 % of a 2-D step).
   pure subroutine grid_owned_local_cells(self, n, x, cell, outside)
      class(grid_t), intent(in) :: self
      integer, intent(in) :: n
      real(rp), intent(in), contiguous :: x(:, :)
      integer, intent(inout), contiguous :: cell(:)
      integer, intent(out) :: outside
      if (self%dim == 2) then
         call cells_2d(x, cell, outside)
      else
         call cells_3d(x, cell, outside)
      end if
   contains
      ! integer flags (1 inside, 0 outside) instead of logicals: gfortran's .and. and logical merges put
      ! branches into the loop; the grid's bounds and the count in local variables: the stores to cell(:)
      ! could otherwise change them for all the compiler knows. Either keeps the loop from vectorising.
      pure subroutine cells_2d(x, cell, outside)
         real(rp), intent(in) :: x(2, n)
         integer, intent(inout) :: cell(n)
         integer, intent(out) :: outside
         integer :: p, c1, c2, inside, lo(3), hi(3), n1, missing
         lo = self%cell_lo
         hi = self%cell_hi
         n1 = self%n_cells(1)
         missing = 0
         do p = 1, n
            c1 = grid_cell_along(self, x(1, p), 1)
            c2 = grid_cell_along(self, x(2, p), 2)
            inside = merge(1, 0, min(c1 - lo(1), hi(1) - c1, c2 - lo(2), hi(2) - c2) >= 0)
            cell(p) = inside * (1 + (c1 - lo(1)) + (c2 - lo(2)) * n1)
            missing = missing + (1 - inside)
         end do
         outside = missing
      end subroutine cells_2d
      pure subroutine cells_3d(x, cell, outside)
         real(rp), intent(in) :: x(3, n)
         integer, intent(inout) :: cell(n)
         integer, intent(out) :: outside
         integer :: p, c1, c2, c3, inside, lo(3), hi(3), n1, n2, missing
         lo = self%cell_lo
         hi = self%cell_hi
         n1 = self%n_cells(1)
         n2 = self%n_cells(2)
         missing = 0
         do p = 1, n
            c1 = grid_cell_along(self, x(1, p), 1)
            c2 = grid_cell_along(self, x(2, p), 2)
            c3 = grid_cell_along(self, x(3, p), 3)
            inside = merge(1, 0, min(c1 - lo(1), hi(1) - c1, c2 - lo(2), hi(2) - c2, c3 - lo(3), hi(3) - c3) >= 0)
            cell(p) = inside * (1 + (c1 - lo(1)) + ((c2 - lo(2)) + (c3 - lo(3)) * n2) * n1)
            missing = missing + (1 - inside)
         end do
         outside = missing
      end subroutine cells_3d
   end subroutine grid_owned_local_cells
end module background_grid
