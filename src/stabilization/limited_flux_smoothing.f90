!> The limited constant-flux smoothing of [Y17] section 3 (FOAL1's smoothing step), on cell data.
!>
!> Given per-cell mass m_c, mass centre x_o^c and values q_c of one material, it returns the increments
!> dq_c of the owned cells such that q^_c = q_c + dq_c (eq. 13). Splitting q into n = 2 dim partitions
!> that each smooth across one face and gathering them back (eqs. 10, 13) equals evaluating every face
!> flux from the same unsmoothed field and scaling it by 1/n [D] (algorithms.md section 3.3), which is
!> what is done here, axis by axis:
!>   slope S_c along k (eq. 7), oscillation flag (eq. 6), face activation gamma_o (OR / AND rule [?]),
!>   interface x_m and allowable errors e (eq. 8), limited jump DM (eq. 12), flux (eqs. 5, 11).
!> A face flux is computed once from the face's two cells and applied to both sides, so a face shared
!> by two ranks gets bitwise the same flux on both and the sum of m q is conserved.
!> Works on the padded cell box of cell_halo (two ghost layers); the same code serves 2-D and 3-D.
module limited_flux_smoothing
   use kinds, only: rp
   use cell_halo, only: padded_cells_t
   implicit none
   private

   !> Options of the smoothing (per material, `&material` in docs/input.md).
   type, public :: flux_options_t
      real(rp) :: gamma_max = 1.0_rp           !< flux tuning coefficient in [0, 1]
      logical :: both_cells_oscillate = .false. !< AND rule; default OR: one oscillating cell opens the face [?]
   end type flux_options_t

   !> Guard of one-sided slope denominators: mass centres of adjacent cells closer than this fraction
   !> of h are treated as this far apart [R] (algorithms.md section 3.3, step 1).
   real(rp), parameter :: min_centre_distance = 1.0e-3_rp
   !> Noise guard of the oscillation test [R] (algorithms.md section 3.3, step 2): a difference between
   !> neighbours smaller than this fraction of the largest |q| (any component) of the three cells counts
   !> as zero. The scale is the largest component because a component that is zero in exact arithmetic
   !> (the shear stress of a fluid at rest) carries noise at the scale of the others. Without
   !> it, a field that is flat along an axis (a tank at rest, across its width) has its oscillation flags
   !> decided by round-off, which then opens faces with O(1) jumps at random and makes the result depend
   !> on the order of floating-point sums (for instance on the number of MPI ranks).
   real(rp), parameter :: noise_guard = 1.0e-10_rp
   !> Most values smoothed per cell (the 3-D stress).
   integer, parameter :: max_values = 6

   !> Work arrays of the flux increments, kept between calls (a step must not page in fresh memory).
   !> A workspace belongs to one dq array: it remembers which part of dq the last call may have made
   !> non-zero, and the next call clears only that part (the rest of the box is air in a tank).
   type, public :: flux_workspace_t
      integer, allocatable :: oscillating(:)   !< bit j - 1 set: component j oscillates along the current axis
      real(rp), allocatable :: scale(:)
      !> eq. 7 slopes along the current axis: (cells, values) in 2-D, (values, cells) in 3-D
      real(rp), allocatable :: slope(:)
      real(rp), allocatable :: columns(:)      !< 2-D: q_c, x_o^c and the flag one array each, (cells, values + 3)
      integer :: written_lo(3) = 1, written_hi(3) = 0   !< box of cells of dq the last call may have written
   end type flux_workspace_t

   public :: limited_flux_increments, field_flux_increments

contains

   !> dq(:, c) for every owned padded cell c (zero elsewhere). `exists` marks cells holding this material
   !> (owned and ghost); q(:, c), mass(c), centre(:, c) are read only where exists(c). `workspace` keeps
   !> the work arrays between calls; a new one (or one last used with another dq) makes the call zero all
   !> of dq first. The separate arrays are packed into one cell field for field_flux_increments.
   subroutine limited_flux_increments(box, h, exists, mass, centre, q, options, dq, workspace)
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(in) :: h
      logical, intent(in) :: exists(:)
      real(rp), intent(in) :: mass(:), centre(:, :), q(:, :)
      type(flux_options_t), intent(in) :: options
      real(rp), contiguous, intent(inout) :: dq(:, :)      ! as field_flux_increments' (else gfortran copies it)
      type(flux_workspace_t), intent(inout) :: workspace
      real(rp), allocatable :: field(:, :)
      integer :: dim
      dim = size(centre, 1)
      allocate (field(2 + dim + size(q, 1), box%count))
      field(1, :) = merge(1.0_rp, 0.0_rp, exists)
      field(2, :) = mass
      field(3:2 + dim, :) = centre
      field(3 + dim:, :) = q
      call field_flux_increments(box, h, exists, field, options, dq, workspace)
   end subroutine limited_flux_increments

   !> As limited_flux_increments, on the cell field of cell_halo's exchange: field(:, c) = [flag, m_c,
   !> x_o^c (box%dim values), q_c], one column per padded cell; dq is (size(q_c), box%count).
   !> The loops run over the bounding box of the existing cells row by row, with the limits along the axis
   !> in the loop bounds (no per-cell position tests). Faces are visited axis by axis in flat cell order,
   !> which fixes the order of the sums into dq.
   subroutine field_flux_increments(box, h, exists, field, options, dq, workspace)
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(in) :: h
      logical, intent(in) :: exists(:)
      real(rp), contiguous, intent(in) :: field(:, :)
      type(flux_options_t), intent(in) :: options
      real(rp), contiguous, intent(inout) :: dq(:, :)
      type(flux_workspace_t), intent(inout) :: workspace
      integer :: nq, lo(3), hi(3)

      nq = size(field, 1) - 2 - box%dim
      if (.not. ((box%dim == 2 .and. nq == 4) .or. (box%dim == 3 .and. nq == 6))) then
         call increments_any(box, h, exists, field(2, :), field(3:2 + box%dim, :), field(3 + box%dim:, :), options, &
                             dq, workspace)
         return
      end if
      call start_workspace(nq, box, exists, dq, workspace, lo, hi)
      if (any(hi < lo)) return
      ! literal sizes for the 2-D and 3-D stress: the compiler unrolls the components and the centre
      if (box%dim == 2) then
         call flux_increments(2, 4, box, h, exists, field, options, lo, hi, workspace%oscillating, workspace%scale, &
                              workspace%slope, workspace%columns, dq)
      else
         call flux_increments(3, 6, box, h, exists, field, options, lo, hi, workspace%oscillating, workspace%scale, &
                              workspace%slope, workspace%columns, dq)
      end if
   end subroutine field_flux_increments

   !> The work of field_flux_increments on the bounding box lo:hi of the existing cells, with the
   !> dimension and the number of values as arguments (literals at the calls that matter). In 2-D the
   !> flags and slopes of a row are formed in vector lanes from `columns`, the cells' values one array per
   !> quantity (`(box%count, nq + 3)`: q_c, x_o^c, the flag 1 or 0), and the slopes are (cells, values);
   !> 3-D keeps the cell-by-cell loop and the slopes (values, cells), a cell's slopes one vector: its rows
   !> are short, and in lanes it was slower.
   subroutine flux_increments(dim, nq, box, h, exists, field, options, lo, hi, oscillating, scale, slope, columns, dq)
      integer, intent(in) :: dim, nq, lo(3), hi(3)
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(in) :: h
      logical, intent(in) :: exists(*)
      real(rp), intent(in) :: field(2 + dim + nq, *)
      type(flux_options_t), intent(in) :: options
      integer, intent(inout) :: oscillating(*)
      real(rp), intent(inout) :: scale(*), slope(*), columns(box%count, merge(nq + 3, 0, dim == 2)), &
                                 dq(nq, *)
      integer :: k, c, stride, i1, i2, i3, flo(3), fhi(3)
      real(rp) :: d_min
      d_min = min_centre_distance * h
      if (dim == 2) then
         ! lo:hi and the cells around it, which the rows read as neighbours (their flags 0)
         flo(1:2) = max(lo(1:2) - 1, 1)
         fhi(1:2) = min(hi(1:2) + 1, box%n(1:2))
         do i2 = flo(2), fhi(2)
            call row_columns(nq, box%count, exists, field, flat_index(box, flo(1), i2, 1), fhi(1) - flo(1) + 1, &
                             columns, scale)
         end do
      else
         do i3 = lo(3), hi(3)
            do i2 = lo(2), hi(2)
               c = flat_index(box, lo(1), i2, i3)
               do i1 = lo(1), hi(1)
                  if (exists(c)) scale(c) = round_off_scale(nq, field(3 + dim:2 + dim + nq, c))
                  c = c + 1
               end do
            end do
         end do
      end if
      do k = 1, dim
         stride = box%stride(k)
         ! oscillation flags (eq. 6) and slopes (eq. 7) of the cells with both neighbours along k inside
         ! the padded box
         flo = lo
         fhi = hi
         flo(k) = max(lo(k), 2)
         fhi(k) = min(hi(k), box%n(k) - 1)
         do i3 = flo(3), fhi(3)
            do i2 = flo(2), fhi(2)
               c = flat_index(box, flo(1), i2, i3)
               if (dim == 2) then
                  call row_flags_in_lanes(nq, box%count, columns(:, nq + 3), scale, columns(:, 1:nq), columns(:, nq + k), &
                                          c, fhi(1) - flo(1) + 1, stride, d_min, oscillating, slope)
               else
                  call row_oscillation_bits(dim, nq, k, exists, scale, field, c, fhi(1) - flo(1) + 1, stride, d_min, &
                                            oscillating, slope)
               end if
            end do
         end do
         ! faces (c, c + stride) with c two or more layers inside the box and c + stride in the bounding box
         flo(k) = max(lo(k), 2)
         fhi(k) = min(hi(k) - 1, box%n(k) - 2)
         do i3 = flo(3), fhi(3)
            do i2 = flo(2), fhi(2)
               c = flat_index(box, flo(1), i2, i3)
               do i1 = flo(1), fhi(1)
                  if (ior(oscillating(c), oscillating(c + stride)) /= 0) &
                     call face_flux(dim, nq, box, exists, field, options, oscillating, slope, c, k, dq)
                  c = c + 1
               end do
            end do
         end do
      end do
   end subroutine flux_increments

   !> The work arrays for nq values per cell (kept while the box and nq stay), dq zero on the box (only the
   !> cells the last call wrote, when the arrays are kept), and the bounding box lo:hi of the existing
   !> cells, which every face flux of this call writes into (hi < lo: none).
   subroutine start_workspace(nq, box, exists, dq, workspace, lo, hi)
      integer, intent(in) :: nq
      type(padded_cells_t), intent(in) :: box
      logical, intent(in) :: exists(:)
      real(rp), contiguous, intent(inout) :: dq(:, :)
      type(flux_workspace_t), intent(inout) :: workspace
      integer, intent(out) :: lo(3), hi(3)
      if (allocated(workspace%oscillating)) then
         if (size(workspace%oscillating) /= box%count .or. size(workspace%slope) /= nq * box%count) &
            deallocate (workspace%oscillating, workspace%scale, workspace%slope, workspace%columns)
      end if
      if (allocated(workspace%oscillating)) then
         call clear_box(nq, box, workspace%written_lo, workspace%written_hi, dq)
      else
         ! columns: 2-D only (one element otherwise)
         allocate (workspace%oscillating(box%count), workspace%scale(box%count), workspace%slope(nq * box%count), &
                   workspace%columns(merge((nq + 3) * box%count, 1, box%dim == 2)))
         dq = 0.0_rp
      end if
      call existing_bounds(box, exists, lo, hi)
      workspace%written_lo = lo
      workspace%written_hi = hi
   end subroutine start_workspace

   !> Bounding box lo:hi (padded coordinates) of the existing cells; hi < lo if there are none.
   subroutine existing_bounds(box, exists, lo, hi)
      type(padded_cells_t), intent(in) :: box
      logical, intent(in) :: exists(:)
      integer, intent(out) :: lo(3), hi(3)
      integer :: i1, i2, i3, c
      lo = box%n
      hi = 1
      hi(1:box%dim) = 0
      c = 0
      do i3 = 1, box%n(3)
         do i2 = 1, box%n(2)
            if (.not. any(exists(c + 1:c + box%n(1)))) then
               c = c + box%n(1)
               cycle
            end if
            lo(2:3) = min(lo(2:3), [i2, i3])
            hi(2:3) = max(hi(2:3), [i2, i3])
            do i1 = 1, box%n(1)
               c = c + 1
               if (.not. exists(c)) cycle
               lo(1) = min(lo(1), i1)
               hi(1) = max(hi(1), i1)
            end do
         end do
      end do
   end subroutine existing_bounds

   !> dq := 0 on the cells lo..hi (padded coordinates), row by row (not the flat range between its
   !> corners: that covers whole rows of the padded box, most of it air beside a column of water).
   !> dq is read flat (nq values per cell): a row is one contiguous range.
   subroutine clear_box(nq, box, lo, hi, dq)
      integer, intent(in) :: nq
      type(padded_cells_t), intent(in) :: box
      integer, intent(in) :: lo(3), hi(3)
      real(rp), intent(inout) :: dq(*)
      integer :: i2, i3, c
      if (any(hi < lo)) return
      do i3 = lo(3), hi(3)
         do i2 = lo(2), hi(2)
            c = flat_index(box, lo(1), i2, i3)
            dq(nq * (c - 1) + 1:nq * (c + hi(1) - lo(1))) = 0.0_rp
         end do
      end do
   end subroutine clear_box

   pure integer function flat_index(box, i1, i2, i3)
      type(padded_cells_t), intent(in) :: box
      integer, intent(in) :: i1, i2, i3
      flat_index = 1 + (i1 - 1) + (i2 - 1) * box%stride(2) + (i3 - 1) * box%stride(3)
   end function flat_index

   !> Eq. 6 per component for the cells first..first + count - 1 along the axis k of `stride`, as bits
   !> (bit j - 1: component j), with the noise guard: both differences above round-off and of opposite
   !> sign (3-D; in 2-D row_flags_in_lanes). 0 if the cell or a neighbour is missing (a cell missing a
   !> neighbour cannot be tested [?]). The components are tested without branches: in a flow that has
   !> just been set in motion half the cells oscillate, at random, and a branch per test was mispredicted
   !> half the time (measured on the collapsing water column). Cells without the material are not read
   !> (their values are anything).
   !> Also the eq. 7 slope along k of every existing cell of the row: central with both neighbours,
   !> one-sided with one, else 0. Most faces of a flow in motion are active, and a cell's slope serves
   !> both of its faces: once per cell here rather than twice per face.
   subroutine row_oscillation_bits(dim, nq, k, exists, scale, field, first, count, stride, d_min, oscillating, slope)
      integer, intent(in) :: dim, nq, k, first, count, stride
      logical, intent(in) :: exists(*)
      real(rp), intent(in) :: scale(*), field(2 + dim + nq, *), d_min
      integer, intent(inout) :: oscillating(*)
      real(rp), intent(inout) :: slope(nq, *)
      real(rp) :: noise, left, right, distance
      integer :: j, c, bits, lower, upper
      do c = first, first + count - 1
         oscillating(c) = 0
         if (.not. exists(c)) cycle
         if (exists(c - stride) .and. exists(c + stride)) then
            noise = max(scale(c - stride), scale(c), scale(c + stride))
            bits = 0
            do j = 1, nq
               left = field(2 + dim + j, c) - field(2 + dim + j, c - stride)
               right = field(2 + dim + j, c + stride) - field(2 + dim + j, c)
               bits = ior(bits, merge(ishft(1, j - 1), 0, (abs(right) > noise) .and. (abs(left) > noise) .and. &
                                                          (right * left < 0.0_rp)))
            end do
            oscillating(c) = bits
            lower = c - stride
            upper = c + stride
         else if (exists(c - stride)) then
            lower = c - stride
            upper = c
         else if (exists(c + stride)) then
            lower = c
            upper = c + stride
         else
            slope(:, c) = 0.0_rp
            cycle
         end if
         distance = max(field(2 + k, upper) - field(2 + k, lower), d_min)
         slope(:, c) = (field(3 + dim:2 + dim + nq, upper) - field(3 + dim:2 + dim + nq, lower)) / distance
      end do
   end subroutine row_oscillation_bits

   !> The cells first..first + count - 1 of a row (2-D) one array per quantity, (n, nq + 3): q_c (nq),
   !> x_o^c (2), the flag (1 or 0); and their round-off scale. row_flags_in_lanes computes with every cell
   !> of a row and its neighbours and drops what a missing cell gave, so a missing cell's values are 0
   !> here (its field entry may hold anything).
   subroutine row_columns(nq, n, exists, field, first, count, columns, scale)
      integer, intent(in) :: nq, n, first, count
      logical, intent(in) :: exists(*)
      real(rp), intent(in) :: field(4 + nq, *)
      real(rp), intent(inout) :: columns(n, nq + 3), scale(*)
      integer :: c, j
      real(rp) :: largest
      do c = first, first + count - 1
         do j = 1, nq
            columns(c, j) = merge(field(4 + j, c), 0.0_rp, exists(c))
         end do
         columns(c, nq + 1) = merge(field(3, c), 0.0_rp, exists(c))
         columns(c, nq + 2) = merge(field(4, c), 0.0_rp, exists(c))
         columns(c, nq + 3) = merge(1.0_rp, 0.0_rp, exists(c))
      end do
      ! round_off_scale's maximum written out: a cell's values lie a column apart here, which that function's
      ! explicit-shape dummy takes through a temporary copy at every call (a debug build warns at each one:
      ! millions of lines per run). Two ways of calling it measured slower on flotsam_flux_bench's dense
      ! field: an assumed-shape dummy (641-911 against 624-637 us) and the call on the packed field's
      ! contiguous values behind a test of `exists` (684-696 against 663-684 us); written out, the loop runs
      ! across the cells in vector lanes
      do c = first, first + count - 1
         largest = abs(columns(c, 1))
         do j = 2, nq
            largest = max(largest, abs(columns(c, j)))
         end do
         scale(c) = noise_guard * largest
      end do
   end subroutine row_columns

   !> A cell's round-off scale (see noise_guard) from its values q_c; max, not maxval: no NaN tests.
   pure real(rp) function round_off_scale(nq, q)
      integer, intent(in) :: nq
      real(rp), intent(in) :: q(nq)
      real(rp) :: largest
      integer :: j
      largest = abs(q(1))
      do j = 2, nq
         largest = max(largest, abs(q(j)))
      end do
      round_off_scale = noise_guard * largest
   end function round_off_scale

   !> row_oscillation_bits in vector lanes (2-D), from the cells' values one array per quantity: q(:, j),
   !> the centres along the axis x, and `flag`, 1 where the cell holds the material and else 0. Every cell
   !> of the row is computed, its neighbours selected by products with the flags rather than by branches or
   !> merge (which gcc 12 does not vectorise here), and what a missing cell gave is dropped. With finite
   !> values a product by 1 or 0 and a sum with a zero are exact, so the flags and slopes are those of
   !> row_oscillation_bits (a zero's sign aside). A missing cell's slope is not read.
   subroutine row_flags_in_lanes(nq, n, flag, scale, q, x, first, count, stride, d_min, oscillating, slope)
      integer, intent(in) :: nq, n, first, count, stride
      real(rp), intent(in) :: flag(n), scale(n), q(n, nq), x(n), d_min
      integer, intent(inout) :: oscillating(n)
      real(rp), intent(inout) :: slope(n, nq)
      real(rp) :: noise, left, right, distance, lower, upper, below, above, opposite
      integer :: j, c, bits
      do c = first, first + count - 1
         below = flag(c - stride)
         above = flag(c + stride)
         noise = max(scale(c - stride), scale(c), scale(c + stride))
         bits = 0
         do j = 1, nq
            left = q(c, j) - q(c - stride, j)
            right = q(c + stride, j) - q(c, j)
            opposite = merge(1.0_rp, 0.0_rp, min(abs(right), abs(left)) > noise) * &
                       merge(1.0_rp, 0.0_rp, right * left < 0.0_rp)
            bits = bits + int(opposite) * 2**(j - 1)
         end do
         oscillating(c) = int(flag(c) * below * above) * bits
         lower = below * x(c - stride) + (1.0_rp - below) * x(c)
         upper = above * x(c + stride) + (1.0_rp - above) * x(c)
         distance = max(upper - lower, d_min)
         do j = 1, nq
            lower = below * q(c - stride, j) + (1.0_rp - below) * q(c, j)
            upper = above * q(c + stride, j) + (1.0_rp - above) * q(c, j)
            slope(c, j) = max(below, above) * ((upper - lower) / distance)
         end do
      end do
   end subroutine row_flags_in_lanes

   !> The limited flux across the face (c, c + stride of axis k), if both cells exist, at least one is
   !> owned, and the face is active for some component; added to dq of the owned side(s).
   !> One division per face: 1 / (m_- + m_+) serves x_m (eq. 8) and every value's flux (eq. 11), which
   !> the general code below divides by one at a time (a division per value on the store's critical path;
   !> the results differ by round-off, docs/performance-history.md "FOAL1's face flux with one division").
   subroutine face_flux(dim, nq, box, exists, field, options, oscillating, slope, c, k, dq)
      integer, intent(in) :: dim, nq
      type(padded_cells_t), intent(in) :: box
      logical, intent(in) :: exists(*)
      real(rp), intent(in) :: field(2 + dim + nq, *), slope(*)
      type(flux_options_t), intent(in) :: options
      integer, intent(in) :: oscillating(*), c, k
      real(rp), intent(inout) :: dq(nq, *)
      integer :: j, right, active, cell_step, value_step
      real(rp) :: n_faces, flux, jump, limited_jump, x_m, allowed, inv_mass, flux_per_jump
      logical :: owned_minus, owned_plus
      ! slope of value j of cell c: slope(1 + (c - 1) cell_step + (j - 1) value_step) (layouts: flux_increments)
      cell_step = merge(1, nq, dim == 2)
      value_step = merge(box%count, 1, dim == 2)
      right = c + box%stride(k)
      if (.not. (exists(c) .and. exists(right))) return
      owned_minus = box%owned(c)
      owned_plus = box%owned(right)
      if (.not. (owned_minus .or. owned_plus)) return
      ! oscillation limiter (eq. 6): gamma_o = gamma_max on an active face, else no flux
      if (options%both_cells_oscillate) then
         active = iand(oscillating(c), oscillating(right))
      else
         active = ior(oscillating(c), oscillating(right))
      end if
      if (active == 0) return
      n_faces = real(2 * dim, rp)
      associate (m_minus => field(2, c), m_plus => field(2, right), x_minus => field(2 + k, c), &
                 x_plus => field(2 + k, right))
         inv_mass = 1.0_rp / (m_minus + m_plus)
         x_m = (m_minus * x_plus + m_plus * x_minus) * inv_mass   ! eq. 8
         flux_per_jump = options%gamma_max / n_faces * inv_mass   ! eqs. 5, 11, 1/n: gamma / (n (m_- + m_+))
         do j = 1, nq
            if (.not. btest(active, j - 1)) cycle
            jump = field(2 + dim + j, c) - field(2 + dim + j, right)
            allowed = (x_m - x_minus) * slope(1 + (c - 1) * cell_step + (j - 1) * value_step) &
                      - (x_m - x_plus) * slope(1 + (right - 1) * cell_step + (j - 1) * value_step)   ! e_- - e_+
            limited_jump = sign0(jump) * min(max(sign0(jump) * (jump + allowed), 0.0_rp), abs(jump))  ! eq. 12
            flux = flux_per_jump * limited_jump
            if (owned_plus) dq(j, right) = dq(j, right) + m_minus * flux
            if (owned_minus) dq(j, c) = dq(j, c) - m_plus * flux
         end do
      end associate
   end subroutine face_flux


   ! --- Other numbers of values per cell (FOAL1 on the pressure alone: one): the code of before the
   ! compile-time kernels, kept as it was. Rewritten like the kernels it gave results that differ
   ! in the last bits (the compiler fuses a different set of multiply-adds), and results must stay
   ! bitwise the same. ---

   subroutine increments_any(box, h, exists, mass, centre, q, options, dq, workspace)
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(in) :: h
      logical, intent(in) :: exists(:)
      real(rp), intent(in) :: mass(:), centre(:, :), q(:, :)
      type(flux_options_t), intent(in) :: options
      real(rp), contiguous, intent(inout) :: dq(:, :)      ! as start_workspace's (else gfortran copies it)
      type(flux_workspace_t), intent(inout) :: workspace
      integer :: k, nq, c, stride, i1, i2, i3, lo(3), hi(3), flo(3), fhi(3)

      nq = size(q, 1)
      call start_workspace(nq, box, exists, dq, workspace, lo, hi)
      if (any(hi < lo)) return
      associate (oscillating => workspace%oscillating, scale => workspace%scale)
         do i3 = lo(3), hi(3)
            do i2 = lo(2), hi(2)
               c = flat_index(box, lo(1), i2, i3)
               do i1 = lo(1), hi(1)
                  if (exists(c)) scale(c) = noise_guard * maxval(abs(q(:, c)))     ! round-off scale (see noise_guard)
                  c = c + 1
               end do
            end do
         end do
         do k = 1, box%dim
            stride = box%stride(k)
            ! oscillation flags (eq. 6) of the cells with both neighbours along k inside the padded box
            flo = lo
            fhi = hi
            flo(k) = max(lo(k), 2)
            fhi(k) = min(hi(k), box%n(k) - 1)
            do i3 = flo(3), fhi(3)
               do i2 = flo(2), fhi(2)
                  c = flat_index(box, flo(1), i2, i3)
                  if (nq == 4) then     ! a literal count unrolls the components (2-D stress)
                     call oscillation_bits_any(4, exists, scale, q, c, fhi(1) - flo(1) + 1, stride, oscillating)
                  else
                     call oscillation_bits_any(nq, exists, scale, q, c, fhi(1) - flo(1) + 1, stride, oscillating)
                  end if
               end do
            end do
            ! faces (c, c + stride) with c two or more layers inside the box and c + stride in the bounding box
            flo(k) = max(lo(k), 2)
            fhi(k) = min(hi(k) - 1, box%n(k) - 2)
            do i3 = flo(3), fhi(3)
               do i2 = flo(2), fhi(2)
                  c = flat_index(box, flo(1), i2, i3)
                  do i1 = flo(1), fhi(1)
                     if (ior(oscillating(c), oscillating(c + stride)) /= 0) &
                        call face_flux_any(box, h, exists, mass, centre, q, options, oscillating, c, k, dq)
                     c = c + 1
                  end do
               end do
            end do
         end do
      end associate
   end subroutine increments_any

   !> Eq. 6 per component for the cells first..first + count - 1 along the axis of `stride`, as bits
   !> (bit j - 1: component j), with the noise guard: both differences above round-off and of opposite
   !> sign. 0 if the cell or a neighbour is missing (a cell missing a neighbour cannot be tested [?]).
   !> The components are tested without branches: in a flow that has just been set in motion half the
   !> cells oscillate, at random, and a branch per test was mispredicted half the time (measured on the
   !> collapsing water column). Cells without the material are not read (their values are anything).
   subroutine oscillation_bits_any(nq, exists, scale, q, first, count, stride, oscillating)
      integer, intent(in) :: nq, first, count, stride
      logical, intent(in) :: exists(:)
      real(rp), intent(in) :: scale(:), q(:, :)
      integer, intent(inout) :: oscillating(:)
      real(rp) :: noise, left, right
      integer :: j, c, bits
      do c = first, first + count - 1
         oscillating(c) = 0
         if (.not. (exists(c) .and. exists(c - stride) .and. exists(c + stride))) cycle
         noise = max(scale(c - stride), scale(c), scale(c + stride))
         bits = 0
         do j = 1, nq
            left = q(j, c) - q(j, c - stride)
            right = q(j, c + stride) - q(j, c)
            bits = ior(bits, merge(ishft(1, j - 1), 0, (abs(right) > noise) .and. (abs(left) > noise) .and. &
                                                       (right * left < 0.0_rp)))
         end do
         oscillating(c) = bits
      end do
   end subroutine oscillation_bits_any

   !> The limited flux across the face (c, c + stride of axis k), if both cells exist, at least one is
   !> owned, and the face is active for some component; added to dq of the owned side(s).
   subroutine face_flux_any(box, h, exists, mass, centre, q, options, oscillating, c, k, dq)
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(in) :: h
      logical, intent(in) :: exists(:)
      real(rp), intent(in) :: mass(:), centre(:, :), q(:, :)
      type(flux_options_t), intent(in) :: options
      integer, intent(in) :: oscillating(:), c, k
      real(rp), intent(inout) :: dq(:, :)
      integer :: j, right, active
      ! fixed size (nq <= 6): an automatic array of size(q, 1) is a malloc per face with gfortran
      real(rp) :: n_faces, flux, jump, limited_jump, x_m, allowed, d_min, slope_minus(max_values), &
                  slope_plus(max_values)
      right = c + box%stride(k)
      if (.not. (exists(c) .and. exists(right))) return
      if (.not. (box%owned(c) .or. box%owned(right))) return
      ! oscillation limiter (eq. 6): gamma_o = gamma_max on an active face, else no flux
      if (options%both_cells_oscillate) then
         active = iand(oscillating(c), oscillating(right))
      else
         active = ior(oscillating(c), oscillating(right))
      end if
      if (active == 0) return
      n_faces = real(2 * box%dim, rp)
      d_min = min_centre_distance * h
      ! slopes (eq. 7) of the two cells, only for the faces that can carry a flux
      call cell_slope_any(box, exists, centre, q, c, k, d_min, active, slope_minus)
      call cell_slope_any(box, exists, centre, q, right, k, d_min, active, slope_plus)
      associate (m_minus => mass(c), m_plus => mass(right), x_minus => centre(k, c), x_plus => centre(k, right))
         x_m = (m_minus * x_plus + m_plus * x_minus) / (m_minus + m_plus)         ! eq. 8
         do j = 1, size(q, 1)
            if (.not. btest(active, j - 1)) cycle
            jump = q(j, c) - q(j, right)
            allowed = (x_m - x_minus) * slope_minus(j) - (x_m - x_plus) * slope_plus(j)   ! e_- - e_+
            limited_jump = sign0(jump) * min(max(sign0(jump) * (jump + allowed), 0.0_rp), abs(jump))  ! eq. 12
            flux = options%gamma_max * limited_jump / (n_faces * (m_minus + m_plus))   ! eqs. 5, 11, 1/n
            if (box%owned(right)) dq(j, right) = dq(j, right) + m_minus * flux
            if (box%owned(c)) dq(j, c) = dq(j, c) - m_plus * flux
         end do
      end associate
   end subroutine face_flux_any


   !> Eq. 7 slope along axis k of cell c (of a face that lies inside the padded box, so both of c's
   !> neighbours along k are inside it too): central with both neighbours, one-sided with one, else 0.
   !> Only the components whose bit is set in `active` are computed (a division each); the others are
   !> left undefined.
   pure subroutine cell_slope_any(box, exists, centre, q, c, k, d_min, active, slope)
      type(padded_cells_t), intent(in) :: box
      logical, intent(in) :: exists(:)
      real(rp), intent(in) :: centre(:, :), q(:, :), d_min
      integer, intent(in) :: c, k, active
      real(rp), intent(inout) :: slope(:)
      integer :: l, r, lower, upper, j
      real(rp) :: distance
      l = c - box%stride(k)
      r = c + box%stride(k)
      if (exists(l) .and. exists(r)) then
         lower = l
         upper = r
      else if (exists(l)) then
         lower = l
         upper = c
      else if (exists(r)) then
         lower = c
         upper = r
      else
         slope(1:size(q, 1)) = 0.0_rp
         return
      end if
      distance = max(centre(k, upper) - centre(k, lower), d_min)
      do j = 1, size(q, 1)
         if (btest(active, j - 1)) slope(j) = (q(j, upper) - q(j, lower)) / distance
      end do
   end subroutine cell_slope_any


   !> sign returning -1, 0 or +1 ([Y17] section 3.5).
   elemental real(rp) function sign0(x)
      real(rp), intent(in) :: x
      sign0 = 0.0_rp
      if (x > 0.0_rp) sign0 = 1.0_rp
      if (x < 0.0_rp) sign0 = -1.0_rp
   end function sign0
end module limited_flux_smoothing
