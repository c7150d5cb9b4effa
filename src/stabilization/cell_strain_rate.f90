!> C0's cell-averaged rate of deformation taken from the grid (algorithms.md section 2.2, "2D identity"):
!>   d~_c = sum_p m_p sym(sum_i v_i (x) grad N_i(x_p)) / m_c = sym(sum_i v_i (x) Gbar_i),
!>   Gbar_i = sum_p m_p grad N_i(x_p) / m_c,
!> the same nodal velocities v_i G2P would use (MUSL's re-mapped ones). For multilinear N_i each component
!> of grad N_i is a product of the 1-D functions f_0(s) = 1 - s, f_1(s) = s of the other coordinates, so
!> Gbar_i needs only the cell's mean position in the cell (2-D: from its mass centre x_o^c, the "2D identity")
!> and, in 3-D, also the means of the products of two coordinates (cell_binning's local moments): exact, not
!> an approximation. Per cell instead of per particle, and G2P need not form the particles' velocity
!> gradients at all: a C0 step without its most expensive per-particle work (docs/performance-history.md, "C0's
!> rate from the grid"). The sums differ from the particle average's in round-off only.
module cell_strain_rate
   use kinds, only: rp
   use background_grid, only: grid_t
   use cell_binning, only: cell_list_t
   implicit none
   private

   public :: cell_rates_from_nodes

contains

   !> rates(:, c) := d~_c (tensor_layout order; d_zz = 0 in plane strain) for the listed cells with mass,
   !> from the nodal velocities velocity(1:dim, node) (further rows are not read) and the cells' means: in
   !> 2-D the mass centres x_o^c (cell_binning's bin_cell_mass_and_centre), in 3-D the local moments
   !> (bin_cell_mass_and_local_moments).
   subroutine cell_rates_from_nodes(grid, occupied, cell_mass, means, velocity, rates)
      type(grid_t), intent(in) :: grid
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: cell_mass(:)
      real(rp), intent(in), contiguous :: means(:, :), velocity(:, :)
      real(rp), intent(inout), contiguous :: rates(:, :)
      if (grid%dim == 2) then
         call rates_2d(grid, occupied, cell_mass, means, size(velocity, 1), velocity, rates)
      else
         call rates_3d(grid, occupied, cell_mass, means, velocity, rates)
      end if
   end subroutine cell_rates_from_nodes

   !> 2-D: Gbar_a = grad N_a at the mean position (xi, eta) = (x_o^c - origin) / h - lower corner, so
   !> L(:, 1) = ((v_2 - v_1)(1 - eta) + (v_4 - v_3) eta) / h and L(:, 2) = ((v_3 - v_1)(1 - xi) + (v_4 - v_2) xi) / h
   !> (corner a = 1 + o_1 + 2 o_2, the order of grid%stencil_stride). Arrays of literal leading sizes, and
   !> grid%cell_indices and grid%base_node_of_cell written out with the grid's numbers in locals: the loop is
   !> scalar and shared by only 4 particles a cell; calling the two (as rates_3d does) made the 2-D column's C0
   !> 3-4 % slower (scripts/bench_compare, best of 5 rounds).
   subroutine rates_2d(grid, occupied, cell_mass, centre, rows, velocity, rates)
      type(grid_t), intent(in) :: grid
      type(cell_list_t), intent(in) :: occupied
      integer, intent(in) :: rows
      real(rp), intent(in) :: cell_mass(:), centre(2, *), velocity(rows, *)
      real(rp), intent(inout) :: rates(4, *)
      real(rp) :: xi(2), v(2, 4), l(2, 2), origin(2), inv_h, inv_row
      integer :: i, c, a, g(2), base, stride(4), row_cells, node_offset
      origin = grid%origin(1:2)
      inv_h = grid%inv_h
      inv_row = grid%inv_row_cells(1)
      row_cells = grid%n_cells(1)
      stride = grid%stencil_stride(1:4)
      ! base node of the cell with local indices g: node_offset + g(1) + g(2) n_nodes(1)
      node_offset = 1 + (grid%cell_lo(1) - grid%node_lo(1)) + (grid%cell_lo(2) - grid%node_lo(2)) * grid%n_nodes(1)
      do i = 1, occupied%count
         c = occupied%cells(i)
         if (cell_mass(c) <= 0.0_rp) cycle
         ! local indices of the cell, as grid%cell_indices finds them
         g(2) = int((real(c - 1, rp) + 0.5_rp) * inv_row)
         g(1) = c - 1 - g(2) * row_cells
         xi = (centre(:, c) - origin) * inv_h - real(g + grid%cell_lo(1:2), rp)
         base = node_offset + g(1) + g(2) * grid%n_nodes(1)
         do a = 1, 4
            v(:, a) = velocity(1:2, base + stride(a))
         end do
         l(:, 1) = ((v(:, 2) - v(:, 1)) * (1.0_rp - xi(2)) + (v(:, 4) - v(:, 3)) * xi(2)) * inv_h
         l(:, 2) = ((v(:, 3) - v(:, 1)) * (1.0_rp - xi(1)) + (v(:, 4) - v(:, 2)) * xi(1)) * inv_h
         rates(:, c) = [l(1, 1), l(2, 2), 0.0_rp, 0.5_rp * (l(1, 2) + l(2, 1))]
      end do
   end subroutine rates_2d

   !> 3-D: component k of grad N_a is df(o_k) f(o_l, xi_l) f(o_m, xi_m) (l, m the other axes); its mean over
   !> the particles is df(o_k) times the mean of f(o_l, xi_l) f(o_m, xi_m), which the moments give:
   !> (1 - s)(1 - t) -> 1 - s - t + st, (1 - s) t -> t - st, s (1 - t) -> s - st, s t -> st.
   subroutine rates_3d(grid, occupied, cell_mass, moments, velocity, rates)
      type(grid_t), intent(in) :: grid
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: cell_mass(:), moments(:, :), velocity(:, :)
      real(rp), intent(inout) :: rates(:, :)
      ! the two axes other than k, and the row of moments holding the mean of their product
      integer, parameter :: other(2, 3) = reshape([2, 3, 1, 3, 1, 2], [2, 3]), product_row(3) = [4, 5, 6]
      real(rp) :: df(0:1), pair(0:1, 0:1, 3), gbar(3, 8), l(3, 3), v(3), s, t, st
      integer :: i, c, a, k, node, base, o(3)
      df = [-grid%inv_h, grid%inv_h]
      do i = 1, occupied%count
         c = occupied%cells(i)
         if (cell_mass(c) <= 0.0_rp) cycle
         base = grid%base_node_of_cell(grid%cell_indices(c))
         ! pair(o_l, o_m, k): the mean of f(o_l, xi_l) f(o_m, xi_m) over the cell's particles
         do k = 1, 3
            s = moments(other(1, k), c)
            t = moments(other(2, k), c)
            st = moments(product_row(k), c)
            pair(0, 0, k) = 1.0_rp - s - t + st
            pair(0, 1, k) = t - st
            pair(1, 0, k) = s - st
            pair(1, 1, k) = st
         end do
         do a = 1, 8
            o = [ibits(a - 1, 0, 1), ibits(a - 1, 1, 1), ibits(a - 1, 2, 1)]
            do k = 1, 3
               gbar(k, a) = df(o(k)) * pair(o(other(1, k)), o(other(2, k)), k)
            end do
         end do
         l = 0.0_rp
         do a = 1, 8
            node = base + grid%stencil_stride(a)
            v = velocity(1:3, node)
            do k = 1, 3
               l(:, k) = l(:, k) + v * gbar(k, a)
            end do
         end do
         rates(1:6, c) = [l(1, 1), l(2, 2), l(3, 3), 0.5_rp * (l(2, 3) + l(3, 2)), 0.5_rp * (l(1, 3) + l(3, 1)), &
                          0.5_rp * (l(1, 2) + l(2, 1))]
      end do
   end subroutine rates_3d
end module cell_strain_rate
