!> The piston stroke of periodic and irregular waves (`&wall motion = 'regular_wave'`, `'irregular_wave'`;
!> docs/theory.md section 3.8): the displacement X(t) of a piston wavemaker as a sum of sines,
!>    X(t) = r(t - t_s) sum_i A_i sin(w_i (t - t_s) + phi_i),   X = 0 before t_s,
!> with a ramp r(tau) = (1 - cos(pi tau / t_r)) / 2 over the first t_r seconds (1 after; X and dX/dt
!> start from 0).
!>  - Linear waves: w^2 = g k tanh(k h) (dispersion), and a piston of stroke S = 2 A makes waves of height
!>    H = m1 S, m1 = 2 (cosh 2kh - 1) / (sinh 2kh + 2kh) (Biesel's transfer function; Dean & Dalrymple
!>    1991, chapter 6).
!>  - Regular waves of second order (Madsen 1971): the piston's first-order motion (S0 / 2) sin(w t) with
!>    S0 = H / m1 also makes a free second harmonic, a wave of frequency 2w that travels at its own speed
!>    and beats against the bound Stokes harmonic along the flume. The stroke
!>       X2 = H^2 / (32 h) (3 cosh(kh) / sinh^3(kh) - 2 / m1) sin(2 w t)
!>    added to it cancels that free wave (Madsen 1971; as in DualSPHysics, Altomare et al. 2017).
!>  - Irregular waves: components at f_i = i / D (D the record's duration: the signal repeats after D)
!>    over [0.5, 3] f_p of a JONSWAP spectrum (Hasselmann et al. 1973; gamma = 1: Pierson-Moskowitz in its
!>    Hs-Tp form), amplitudes a_i = sqrt(2 S(f_i) df) scaled so that 4 sqrt(sum a_i^2 / 2) = Hs exactly,
!>    random phases from `seed` (the Park-Miller generator: the same signal on every compiler and rank),
!>    each component's stroke a_i / m1(k_i) (the linear transfer function per component).
module wave_paddle
   use kinds, only: rp
   implicit none
   private

   real(rp), parameter :: pi = acos(-1.0_rp)
   !> The irregular record's frequency band in units of the peak frequency [R]: below 0.5 f_p lies 2e-9 of
   !> m0 (the density there is below 3e-7 of its peak), and above 3 f_p 1.5 % of m0 (Pierson-Moskowitz; less for
   !> gamma > 1), on waves nine times shorter than the peak's in deep water, which a grid resolving the peak
   !> does not carry.
   real(rp), parameter, public :: band_low = 0.5_rp, band_high = 3.0_rp
   !> The JONSWAP peak width sigma below and above the peak frequency (Hasselmann et al. 1973).
   real(rp), parameter :: sigma_below = 0.07_rp, sigma_above = 0.09_rp

   !> A piston's displacement along its direction as a sum of sines with a start-up ramp.
   type, public :: paddle_signal_t
      real(rp) :: start = 0.0_rp                  !< t_s [s]
      real(rp) :: ramp = 0.0_rp                   !< t_r [s] (0: none)
      real(rp), allocatable :: amplitude(:)       !< A_i [m]
      real(rp), allocatable :: frequency(:)       !< w_i [rad/s]
      real(rp), allocatable :: phase(:)           !< phi_i [rad]
   contains
      procedure :: displacement => signal_displacement
      procedure :: speed_bound => signal_speed_bound
      procedure :: extent => signal_extent
   end type paddle_signal_t

   public :: wavenumber, biesel_transfer, second_order_stroke, stokes_second_harmonic, regular_signal, &
             irregular_signal, jonswap_density, park_miller

contains

   !> The wavenumber k of linear waves of angular frequency w in water h deep under gravity g: the root of
   !> w^2 = g k tanh(k h), by Newton from Eckart's approximation (to round-off).
   pure real(rp) function wavenumber(omega, depth, g) result(k)
      real(rp), intent(in) :: omega, depth, g
      real(rp) :: f, slope, deep
      integer :: iteration
      deep = omega**2 / g
      k = deep / sqrt(tanh(deep * depth))
      do iteration = 1, 50
         f = g * k * tanh(k * depth) - omega**2
         ! d/dk of g k tanh(kh); sech^2(kh) below round-off beyond kh = 20 (cosh would overflow)
         slope = g * tanh(k * depth)
         if (k * depth < 20.0_rp) slope = slope + g * k * depth / cosh(k * depth)**2
         if (abs(f) <= 8.0_rp * epsilon(1.0_rp) * omega**2) exit
         k = k - f / slope
      end do
   end function wavenumber

   !> Biesel's piston transfer function H / S = 2 (cosh 2kh - 1) / (sinh 2kh + 2kh).
   pure real(rp) function biesel_transfer(kh) result(m1)
      real(rp), intent(in) :: kh
      ! beyond kh = 20 m1 = 2 to round-off (and sinh 2kh overflows from kh = 355)
      m1 = 2.0_rp
      if (kh < 20.0_rp) m1 = 4.0_rp * sinh(kh)**2 / (sinh(2.0_rp * kh) + 2.0_rp * kh)
   end function biesel_transfer

   !> Madsen's (1971) second-order stroke amplitude of the sin(2 w t) term for waves of height H, wavenumber
   !> k in water h deep [m].
   pure real(rp) function second_order_stroke(height, k, depth) result(x2)
      real(rp), intent(in) :: height, k, depth
      real(rp) :: kh
      kh = k * depth
      ! cosh / sinh^3 below round-off against 2 / m1 beyond kh = 20 (and overflowing from kh = 237)
      x2 = -2.0_rp / biesel_transfer(kh)
      if (kh < 20.0_rp) x2 = x2 + 3.0_rp * cosh(kh) / sinh(kh)**3
      x2 = height**2 / (32.0_rp * depth) * x2
   end function second_order_stroke

   !> The bound second harmonic of a Stokes wave of height H: eta = H/2 cos(theta) + a2 cos(2 theta),
   !> a2 = (H^2 k / 16) cosh(kh) (2 + cosh 2kh) / sinh^3(kh) (Dean & Dalrymple 1991, chapter 11) [m].
   pure real(rp) function stokes_second_harmonic(height, k, depth) result(a2)
      real(rp), intent(in) :: height, k, depth
      real(rp) :: kh
      kh = k * depth
      ! cosh(kh) (2 + cosh 2kh) / sinh^3(kh) = 2 to round-off beyond kh = 20 (and overflows from kh = 178)
      a2 = 2.0_rp
      if (kh < 20.0_rp) a2 = cosh(kh) * (2.0_rp + cosh(2.0_rp * kh)) / sinh(kh)**3
      a2 = height**2 * k / 16.0_rp * a2
   end function stokes_second_harmonic

   !> The stroke of regular waves of height H and period T in water h deep (g), of `order` 1 or 2, from
   !> `start` with a ramp of `ramp` seconds.
   pure function regular_signal(height, period, depth, g, order, start, ramp) result(signal)
      real(rp), intent(in) :: height, period, depth, g, start, ramp
      integer, intent(in) :: order
      type(paddle_signal_t) :: signal
      real(rp) :: omega, k
      omega = 2.0_rp * pi / period
      k = wavenumber(omega, depth, g)
      signal%start = start
      signal%ramp = ramp
      if (order >= 2) then
         signal%amplitude = [0.5_rp * height / biesel_transfer(k * depth), second_order_stroke(height, k, depth)]
         signal%frequency = [omega, 2.0_rp * omega]
         signal%phase = [0.0_rp, 0.0_rp]
      else
         signal%amplitude = [0.5_rp * height / biesel_transfer(k * depth)]
         signal%frequency = [omega]
         signal%phase = [0.0_rp]
      end if
   end function regular_signal

   !> The JONSWAP spectral density S(f) [m^2 s] of peak frequency fp and peak enhancement gamma, with the
   !> Phillips constant `alpha` in S = alpha g^2 (2 pi)^-4 f^-5 exp(-5/4 (fp/f)^4) gamma^r.
   pure real(rp) function jonswap_density(f, fp, gamma, alpha, g) result(s)
      real(rp), intent(in) :: f, fp, gamma, alpha, g
      real(rp) :: sigma, r
      s = 0.0_rp
      if (f <= 0.0_rp) return
      sigma = merge(sigma_below, sigma_above, f <= fp)
      r = exp(-(f - fp)**2 / (2.0_rp * sigma**2 * fp**2))
      s = alpha * g**2 * (2.0_rp * pi)**(-4) * f**(-5) * exp(-1.25_rp * (fp / f)**4) * gamma**r
   end function jonswap_density

   !> The stroke of irregular waves of significant height Hs and peak period Tp (JONSWAP, `gamma`) in water h
   !> deep (g): components f_i = i / D in [band_low, band_high] f_p with phases from `seed`, from `start`
   !> with a ramp of `ramp` seconds.
   pure function irregular_signal(hs, tp, gamma, duration, seed, depth, g, start, ramp) result(signal)
      real(rp), intent(in) :: hs, tp, gamma, duration, depth, g, start, ramp
      integer, intent(in) :: seed
      type(paddle_signal_t) :: signal
      real(rp), allocatable :: eta(:)
      real(rp) :: fp, df, f, m0, u
      integer :: first, last, i, n, state
      fp = 1.0_rp / tp
      df = 1.0_rp / duration
      first = max(1, ceiling(band_low * fp / df))
      last = floor(band_high * fp / df)
      n = max(0, last - first + 1)
      allocate (eta(n), signal%amplitude(n), signal%frequency(n), signal%phase(n))
      state = seed
      do i = 1, n
         f = (first + i - 1) * df
         eta(i) = sqrt(2.0_rp * jonswap_density(f, fp, gamma, 1.0_rp, g) * df)
         signal%frequency(i) = 2.0_rp * pi * f
         call park_miller(state, u)
         signal%phase(i) = 2.0_rp * pi * u
      end do
      ! Hs = 4 sqrt(m0), m0 = sum a_i^2 / 2 of the discrete record
      m0 = 0.5_rp * sum(eta**2)
      if (m0 > 0.0_rp) eta = eta * hs / (4.0_rp * sqrt(m0))
      do i = 1, n
         signal%amplitude(i) = eta(i) / biesel_transfer(wavenumber(signal%frequency(i), depth, g) * depth)
      end do
      signal%start = start
      signal%ramp = ramp
   end function irregular_signal

   !> `u`: the next uniform number in (0, 1) of the minimal standard generator x := 16807 x mod (2^31 - 1)
   !> (Park & Miller 1988; exact in 64-bit integers), `state` in 1 .. 2^31 - 2.
   pure subroutine park_miller(state, u)
      integer, intent(inout) :: state
      real(rp), intent(out) :: u
      integer, parameter :: i8 = selected_int_kind(18)
      integer(i8), parameter :: modulus = 2147483647_i8
      state = int(mod(16807_i8 * int(state, i8), modulus))
      u = real(state, rp) / real(modulus, rp)
   end subroutine park_miller

   !> The ramp r(tau) and its rate dr/dtau.
   pure subroutine ramp_of(self, tau, r, rate)
      type(paddle_signal_t), intent(in) :: self
      real(rp), intent(in) :: tau
      real(rp), intent(out) :: r, rate
      r = 1.0_rp
      rate = 0.0_rp
      if (tau <= 0.0_rp) then
         r = 0.0_rp
      else if (tau < self%ramp) then
         r = 0.5_rp * (1.0_rp - cos(pi * tau / self%ramp))
         rate = 0.5_rp * pi / self%ramp * sin(pi * tau / self%ramp)
      end if
   end subroutine ramp_of

   !> X(t) [m].
   pure real(rp) function signal_displacement(self, t) result(x)
      class(paddle_signal_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp) :: tau, r, rate
      x = 0.0_rp
      tau = t - self%start
      if (tau <= 0.0_rp .or. .not. allocated(self%amplitude)) return
      call ramp_of(self, tau, r, rate)
      x = r * sum(self%amplitude * sin(self%frequency * tau + self%phase))
   end function signal_displacement

   !> A bound of |dX/dt| at any time [m/s]: sum A_i w_i plus the ramp's part max(r') sum A_i.
   pure real(rp) function signal_speed_bound(self) result(speed)
      class(paddle_signal_t), intent(in) :: self
      speed = 0.0_rp
      if (.not. allocated(self%amplitude)) return
      speed = sum(abs(self%amplitude) * self%frequency)
      if (self%ramp > 0.0_rp) speed = speed + 0.5_rp * pi / self%ramp * sum(abs(self%amplitude))
   end function signal_speed_bound

   !> The largest |X| the signal reaches [m]: for one or two components their sum of amplitudes (reached
   !> or nearly: a bound); for more, the largest of |X| sampled over the ramp and one repeat of the record
   !> (`record` seconds) at 20 samples per period of the fastest component, plus 2 % (between two samples
   !> |X| exceeds the larger by at most 1 - cos(pi / 20) = 1.2 % of the amplitude).
   pure real(rp) function signal_extent(self, record) result(extent)
      class(paddle_signal_t), intent(in) :: self
      real(rp), intent(in) :: record
      real(rp) :: dt, t
      integer :: i, samples
      extent = 0.0_rp
      if (.not. allocated(self%amplitude)) return
      if (size(self%amplitude) <= 2) then
         extent = sum(abs(self%amplitude))
         return
      end if
      dt = 2.0_rp * pi / maxval(self%frequency) / 20.0_rp
      samples = ceiling((record + self%ramp) / dt)
      do i = 0, samples
         t = self%start + i * dt
         extent = max(extent, abs(self%displacement(t)))
      end do
      extent = 1.02_rp * extent
   end function signal_extent
end module wave_paddle
