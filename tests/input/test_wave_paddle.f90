!> Tests of src/input/wave_paddle.f90: the dispersion relation's root, Biesel's transfer function in its
!> shallow and deep limits, the JONSWAP density against the closed-form integral of its Pierson-Moskowitz
!> shape, the Park-Miller generator against its published check value, the irregular record's Hs and peak,
!> and the stroke's ramp, speed bound and extent.
module test_wave_paddle
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use wave_paddle, only: paddle_signal_t, wavenumber, biesel_transfer, regular_signal, irregular_signal, &
                          jonswap_density, park_miller, second_order_stroke, band_low, band_high
   implicit none
   private

   public :: test_dispersion_root, test_biesel_limits, test_jonswap_integral, test_park_miller_check_value, &
             test_irregular_record, test_stroke_ramp_and_bounds

   real(rp), parameter :: g = 9.81_rp, pi = acos(-1.0_rp)

contains

   !> w^2 = g k tanh(kh) to round-off from shallow to deep water; the limits k h -> w / sqrt(g h) and
   !> k -> w^2 / g.
   subroutine test_dispersion_root()
      real(rp) :: periods(5) = [0.3_rp, 0.7_rp, 1.5_rp, 4.0_rp, 20.0_rp], omega, k, depth
      integer :: i
      depth = 0.4_rp
      do i = 1, size(periods)
         omega = 2.0_rp * pi / periods(i)
         k = wavenumber(omega, depth, g)
         call assertEqual(omega**2, g * k * tanh(k * depth), 1.0e-13_rp * omega**2, 'w^2 = g k tanh(kh)')
      end do
      ! shallow: a 200 s wave in 0.4 m of water, c = sqrt(g h) within (kh)^2 / 6
      omega = 2.0_rp * pi / 200.0_rp
      k = wavenumber(omega, depth, g)
      call assertEqual(sqrt(g * depth), omega / k, 1.0e-5_rp * sqrt(g * depth), 'shallow water: c = sqrt(g h)')
      ! deep: a 0.3 s wave in 10 m
      omega = 2.0_rp * pi / 0.3_rp
      call assertEqual(omega**2 / g, wavenumber(omega, 10.0_rp, g), 1.0e-12_rp * omega**2 / g, 'deep water: k = w^2 / g')
   end subroutine test_dispersion_root

   !> H / S -> kh in shallow water and -> 2 in deep water; at kh = 1 the
   !> form 2 (cosh 2kh - 1) / (sinh 2kh + 2kh).
   subroutine test_biesel_limits()
      call assertEqual(1.0e-3_rp, biesel_transfer(1.0e-3_rp), 1.0e-9_rp, 'shallow: H/S = kh')
      call assertEqual(2.0_rp, biesel_transfer(20.0_rp), 1.0e-12_rp, 'deep: H/S = 2')
      call assertEqual(2.0_rp * (cosh(2.0_rp) - 1.0_rp) / (sinh(2.0_rp) + 2.0_rp), biesel_transfer(1.0_rp), 1.0e-15_rp, &
                       'kh = 1: Biesel')
   end subroutine test_biesel_limits

   !> With gamma = 1 the density is alpha g^2 (2 pi)^-4 f^-5 exp(-5/4 (fp/f)^4), whose integral over all f is
   !> alpha g^2 (2 pi)^-4 / (5 fp^4) in closed form; the trapezoid rule over 0.3 .. 40 fp gives it within
   !> 1e-5 (the tail above 40 fp holds 5e-7 of it). With gamma = 3.3 the density peaks at fp.
   subroutine test_jonswap_integral()
      real(rp) :: fp, df, total, exact, f, peak_f, peak_s, s
      integer :: i, n
      fp = 0.8_rp
      n = 400000
      df = (40.0_rp - 0.3_rp) * fp / n
      total = 0.0_rp
      do i = 0, n
         f = 0.3_rp * fp + i * df
         total = total + merge(0.5_rp, 1.0_rp, i == 0 .or. i == n) * jonswap_density(f, fp, 1.0_rp, 1.0_rp, g) * df
      end do
      exact = g**2 * (2.0_rp * pi)**(-4) / (5.0_rp * fp**4)
      call assertEqual(exact, total, 1.0e-5_rp * exact, 'Pierson-Moskowitz: integral in closed form')
      peak_s = 0.0_rp
      peak_f = 0.0_rp
      do i = 1, 2000
         f = 0.5_rp * fp + i * 1.0e-3_rp * fp
         s = jonswap_density(f, fp, 3.3_rp, 1.0_rp, g)
         if (s > peak_s) then
            peak_s = s
            peak_f = f
         end if
      end do
      call assertEqual(fp, peak_f, 1.0e-3_rp * fp, 'JONSWAP peaks at fp')
      call assertEqual(3.3_rp, peak_s / jonswap_density(fp, fp, 1.0_rp, 1.0_rp, g), 1.0e-12_rp, &
                       'JONSWAP at fp: gamma times Pierson-Moskowitz')
   end subroutine test_jonswap_integral

   !> Park & Miller (1988): from seed 1 the 10 000th state is 1043618065.
   subroutine test_park_miller_check_value()
      integer :: state, i
      real(rp) :: u
      state = 1
      do i = 1, 10000
         call park_miller(state, u)
         call assertTrue(u > 0.0_rp .and. u < 1.0_rp, 'uniform in (0, 1)')
      end do
      call assertEqual(1043618065, state, 'the 10 000th state from seed 1')
   end subroutine test_park_miller_check_value

   !> The record's components: spaced 1 / D within the band, the surface's 4 sqrt(m0) = Hs exactly (the
   !> stroke times Biesel's H/S of each component), the largest component at fp, the same phases from the
   !> same seed and others from another.
   subroutine test_irregular_record()
      type(paddle_signal_t) :: signal, again, other
      real(rp) :: hs, tp, depth, duration, eta2, m1, fp
      real(rp), allocatable :: eta(:)
      integer :: i
      hs = 0.05_rp
      tp = 1.2_rp
      depth = 0.5_rp
      duration = 200.0_rp * tp
      fp = 1.0_rp / tp
      signal = irregular_signal(hs, tp, 3.3_rp, duration, 7, depth, g, 0.0_rp, 2.0_rp * tp)
      call assertTrue(size(signal%amplitude) == floor(band_high * fp * duration + 1.0e-9_rp) - &
                      ceiling(band_low * fp * duration - 1.0e-9_rp) + 1, 'one component per 1/D in the band')
      call assertEqual(2.0_rp * pi / duration, signal%frequency(2) - signal%frequency(1), 1.0e-12_rp, 'spacing 1/D')
      allocate (eta(size(signal%amplitude)))
      do i = 1, size(eta)
         m1 = biesel_transfer(wavenumber(signal%frequency(i), depth, g) * depth)
         eta(i) = signal%amplitude(i) * m1
      end do
      eta2 = 0.5_rp * sum(eta**2)
      call assertEqual(hs, 4.0_rp * sqrt(eta2), 1.0e-13_rp, 'Hs = 4 sqrt(m0) of the record')
      call assertEqual(2.0_rp * pi * fp, signal%frequency(maxloc(eta, 1)), 2.0_rp * pi / duration, &
                       'the largest component at fp')
      again = irregular_signal(hs, tp, 3.3_rp, duration, 7, depth, g, 0.0_rp, 2.0_rp * tp)
      call assertTrue(all(again%phase == signal%phase), 'same seed, same phases')
      other = irregular_signal(hs, tp, 3.3_rp, duration, 8, depth, g, 0.0_rp, 2.0_rp * tp)
      call assertTrue(count(other%phase == signal%phase) == 0, 'another seed, other phases')
   end subroutine test_irregular_record

   !> A regular stroke: 0 before and at the start, (S0/2) sin + X2 sin(2 .) after the ramp with S0 = H / m1,
   !> its finite-difference speed within speed_bound, its mean over a period 0, |X| within extent; an
   !> irregular one: |X| sampled 4 times finer than extent samples stays within it and reaches 0.97 of it.
   subroutine test_stroke_ramp_and_bounds()
      type(paddle_signal_t) :: signal
      real(rp) :: height, period, depth, omega, k, t, x, expected, fastest, dt, mean, largest
      integer :: i
      height = 0.02_rp
      period = 1.0_rp
      depth = 0.3_rp
      signal = regular_signal(height, period, depth, g, 2, 0.5_rp, 2.0_rp)
      omega = 2.0_rp * pi / period
      k = wavenumber(omega, depth, g)
      call assertEqual(0.0_rp, signal%displacement(0.2_rp), 0.0_rp, 'at rest before the start')
      call assertEqual(0.0_rp, signal%displacement(0.5_rp), 0.0_rp, 'at rest at the start')
      t = 3.7_rp
      expected = 0.5_rp * height / biesel_transfer(k * depth) * sin(omega * (t - 0.5_rp)) + &
                 second_order_stroke(height, k, depth) * sin(2.0_rp * omega * (t - 0.5_rp))
      call assertEqual(expected, signal%displacement(t), 1.0e-15_rp, 'after the ramp: first and second order')
      fastest = 0.0_rp
      mean = 0.0_rp
      dt = period / 1000.0_rp
      do i = 0, 6000
         t = 0.5_rp + i * dt
         fastest = max(fastest, abs(signal%displacement(t + 1.0e-6_rp) - signal%displacement(t - 1.0e-6_rp)) / 2.0e-6_rp)
         if (i >= 3000 .and. i < 4000) mean = mean + signal%displacement(t) / 1000.0_rp
         call assertTrue(abs(signal%displacement(t)) <= signal%extent(period), '|X| within the extent')
      end do
      call assertTrue(fastest <= signal%speed_bound(), 'speed within its bound')
      call assertTrue(fastest >= 0.8_rp * signal%speed_bound(), 'the bound is not loose (regular)')
      call assertEqual(0.0_rp, mean, 1.0e-12_rp, 'no mean displacement over a period')
      signal = irregular_signal(0.03_rp, 1.0_rp, 3.3_rp, 40.0_rp, 3, depth, g, 0.0_rp, 2.0_rp)
      largest = 0.0_rp
      dt = 2.0_rp * pi / maxval(signal%frequency) / 80.0_rp
      do i = 0, ceiling(42.0_rp / dt)
         x = abs(signal%displacement(i * dt))
         largest = max(largest, x)
      end do
      call assertTrue(largest <= signal%extent(40.0_rp), 'irregular: |X| within the extent')
      call assertTrue(largest >= 0.97_rp * signal%extent(40.0_rp), 'irregular: the extent is not loose')
   end subroutine test_stroke_ramp_and_bounds
end module test_wave_paddle
