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
   !> neighbours smaller than this fraction of the largest |q| of the three cells counts as zero. Without
   !> it, a field that is flat along an axis (a tank at rest, across its width) has its oscillation flags
   !> decided by round-off, which then opens faces with O(1) jumps at random and makes the result depend
   !> on the order of floating-point sums (for instance on the number of MPI ranks).
   real(rp), parameter :: noise_guard = 1.0e-10_rp

   public :: limited_flux_increments

contains

   !> dq(:, c) for every owned padded cell c (zero elsewhere). `exists` marks cells holding this material
   !> (owned and ghost); q(:, c), mass(c), centre(:, c) are read only where exists(c).
   subroutine limited_flux_increments(box, h, exists, mass, centre, q, options, dq)
      type(padded_cells_t), intent(in) :: box
      real(rp), intent(in) :: h
      logical, intent(in) :: exists(:)
      real(rp), intent(in) :: mass(:), centre(:, :), q(:, :)
      type(flux_options_t), intent(in) :: options
      real(rp), intent(out) :: dq(:, :)
      real(rp), allocatable :: slope(:, :)
      logical, allocatable :: oscillating(:, :)
      integer :: k, nq, c, stride, along, j
      real(rp) :: n_faces, flux, jump, limited_jump, x_m, allowed, d_min
      logical :: active

      nq = size(q, 1)
      n_faces = real(2 * box%dim, rp)
      d_min = min_centre_distance * h
      dq = 0.0_rp
      allocate (slope(nq, box%count), oscillating(nq, box%count))
      do k = 1, box%dim
         stride = box%stride(k)
         ! slopes and oscillation flags of every cell that has both neighbours inside the padded box
         do c = 1, box%count
            along = position_along(box, c, k)
            if (.not. exists(c) .or. along == 1 .or. along == box%n(k)) then
               slope(:, c) = 0.0_rp
               oscillating(:, c) = .false.
               cycle
            end if
            call cell_slope(exists(c - stride), exists(c + stride), centre(k, c - stride), centre(k, c), &
                            centre(k, c + stride), q(:, c - stride), q(:, c), q(:, c + stride), d_min, &
                            slope(:, c), oscillating(:, c))
         end do
         ! faces (c, c + stride) with both cells present and at least one owned
         do c = 1, box%count
            along = position_along(box, c, k)
            if (along < 2 .or. along > box%n(k) - 2) cycle
            if (.not. (exists(c) .and. exists(c + stride))) cycle
            if (.not. (box%owned(c) .or. box%owned(c + stride))) cycle
            associate (m_minus => mass(c), m_plus => mass(c + stride), &
                       x_minus => centre(k, c), x_plus => centre(k, c + stride))
               x_m = (m_minus * x_plus + m_plus * x_minus) / (m_minus + m_plus)         ! eq. 8
               do j = 1, nq
                  ! oscillation limiter (eq. 6): gamma_o = gamma_max on an active face, else no flux
                  if (options%both_cells_oscillate) then
                     active = oscillating(j, c) .and. oscillating(j, c + stride)
                  else
                     active = oscillating(j, c) .or. oscillating(j, c + stride)
                  end if
                  if (.not. active) cycle
                  jump = q(j, c) - q(j, c + stride)
                  allowed = (x_m - x_minus) * slope(j, c) - (x_m - x_plus) * slope(j, c + stride)   ! e_- - e_+
                  limited_jump = sign0(jump) * min(max(sign0(jump) * (jump + allowed), 0.0_rp), abs(jump))  ! eq. 12
                  flux = options%gamma_max * limited_jump / (n_faces * (m_minus + m_plus))   ! eqs. 5, 11, 1/n
                  if (box%owned(c + stride)) dq(j, c + stride) = dq(j, c + stride) + m_minus * flux
                  if (box%owned(c)) dq(j, c) = dq(j, c) - m_plus * flux
               end do
            end associate
         end do
      end do
   end subroutine limited_flux_increments

   !> Eq. 7 slope and eq. 6 oscillation flag of a cell with values qc from its lower (l) and upper (r)
   !> neighbours along one axis. A cell missing a neighbour cannot oscillate [?] (default of the spec).
   pure subroutine cell_slope(has_l, has_r, xl, xc, xr, ql, qc, qr, d_min, slope, oscillating)
      logical, intent(in) :: has_l, has_r
      real(rp), intent(in) :: xl, xc, xr, ql(:), qc(:), qr(:), d_min
      real(rp), intent(out) :: slope(:)
      logical, intent(out) :: oscillating(:)
      real(rp) :: noise(size(qc))
      if (has_l .and. has_r) then
         slope = (qr - ql) / max(xr - xl, d_min)
         noise = noise_guard * max(abs(ql), abs(qc), abs(qr))
         oscillating = (abs(qr - qc) > noise .and. abs(qc - ql) > noise) .and. (qr - qc) * (qc - ql) < 0.0_rp
      else if (has_l) then
         slope = (qc - ql) / max(xc - xl, d_min)
         oscillating = .false.
      else if (has_r) then
         slope = (qr - qc) / max(xr - xc, d_min)
         oscillating = .false.
      else
         slope = 0.0_rp
         oscillating = .false.
      end if
   end subroutine cell_slope

   !> 1-based position of padded cell c along axis k.
   pure integer function position_along(box, c, k)
      type(padded_cells_t), intent(in) :: box
      integer, intent(in) :: c, k
      position_along = 1 + mod((c - 1) / box%stride(k), box%n(k))
   end function position_along

   !> sign returning -1, 0 or +1 ([Y17] section 3.5).
   elemental real(rp) function sign0(x)
      real(rp), intent(in) :: x
      sign0 = 0.0_rp
      if (x > 0.0_rp) sign0 = 1.0_rp
      if (x < 0.0_rp) sign0 = -1.0_rp
   end function sign0
end module limited_flux_smoothing
