!> Checks of a piston's waves (`&wall` / `&structure` motion = 'regular_wave' or 'irregular_wave';
!> docs/input.md, docs/theory.md section 3.8): the variables in range, and refused what the theory or the
!> grid cannot carry: a wave steeper than it can stand (Miche's breaking limit), a second-order wave whose
!> second harmonic puts a hump in its trough, a wavelength of fewer than min_cells_per_wavelength cells.
module wave_validation
   use kinds, only: rp
   use error_status, only: status_t
   use scene_description, only: motion_spec_t
   use motion_spec, only: motion_regular_wave, motion_irregular_wave, spectrum_keywords, spectrum_jonswap, &
                          jonswap_gamma
   use input_text, only: int_text, real_text, quoted_list
   use input_checks, only: check_real
   use wave_paddle, only: wavenumber, stokes_second_harmonic
   implicit none
   private

   public :: validate_wave_motion, stray_wave_variable

   real(rp), parameter :: pi = acos(-1.0_rp)
   !> Fewest cells per wavelength a piston's wave may have [R]: at 10 cells a wave of linear shape functions
   !> is carried by 10 nodes per period of its shape; docs/theory.md section 3.8 recommends 20 or more.
   real(rp), parameter, public :: min_cells_per_wavelength = 10.0_rp
   !> Miche's (1944) limit of a wave's steepness before it breaks: H / L <= 0.142 tanh(kh).
   real(rp), parameter :: miche_steepness = 0.142_rp
   !> Largest ratio of the second harmonic to the first of a second-order Stokes wave: beyond 1/4,
   !> a cos(theta) + a2 cos(2 theta) has a second crest in its trough, and the expansion fails.
   real(rp), parameter :: max_harmonic_ratio = 0.25_rp
   !> Fewest peak periods in an irregular wave's record (50 components over 0.5 .. 3 f_p).
   real(rp), parameter :: min_record_periods = 20.0_rp
   !> The largest seed of the Park-Miller generator (2^31 - 2).
   integer, parameter :: max_seed = 2147483646

contains

   !> A variable that belongs to the piston waves given without its motion (`variable`, '' if none; of
   !> several, the last in the order below) and the motions it belongs to (`owner`): wave_period,
   !> wave_order with regular_wave, ramp_time with either wave, spectrum .. wave_duration with irregular_wave.
   subroutine stray_wave_variable(spec, variable, owner)
      type(motion_spec_t), intent(in) :: spec
      character(len=:), allocatable, intent(out) :: variable, owner
      type(motion_spec_t) :: defaults
      character(len=*), parameter :: regular = "motion = '"//motion_regular_wave//"'", &
                                     irregular = "motion = '"//motion_irregular_wave//"'"
      variable = ''
      owner = regular
      if (spec%kind /= motion_regular_wave) then
         if (spec%wave_period /= defaults%wave_period) variable = 'wave_period'
         if (spec%wave_order /= defaults%wave_order) variable = 'wave_order'
         if (len(variable) > 0) return
      end if
      owner = regular//' or '//irregular
      if (spec%kind /= motion_regular_wave .and. spec%kind /= motion_irregular_wave .and. &
          spec%ramp_time /= defaults%ramp_time) variable = 'ramp_time'
      if (len(variable) > 0 .or. spec%kind == motion_irregular_wave) return
      owner = irregular
      if (spec%spectrum /= defaults%spectrum) variable = 'spectrum'
      if (spec%significant_wave_height /= defaults%significant_wave_height) variable = 'significant_wave_height'
      if (spec%peak_period /= defaults%peak_period) variable = 'peak_period'
      if (spec%gamma /= defaults%gamma) variable = 'gamma'
      if (spec%wave_seed /= defaults%wave_seed) variable = 'wave_seed'
      if (spec%wave_duration /= defaults%wave_duration) variable = 'wave_duration'
   end subroutine stray_wave_variable

   !> A regular or irregular wave of `spec` (its variables known to belong to it; its start, depth and
   !> gravity checked by the caller) at `where`, under gravity `g` on cells of `cell` m.
   subroutine validate_wave_motion(spec, where, g, cell, status)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(in) :: where
      real(rp), intent(in) :: g, cell
      type(status_t), intent(inout) :: status
      real(rp) :: height, period
      character(len=:), allocatable :: height_name, period_name
      ! ramp_time < 0: not given (two periods)
      if (spec%ramp_time /= -1.0_rp) call check_real(where, 'ramp_time', spec%ramp_time, status, at_least=0.0_rp)
      if (spec%kind == motion_regular_wave) then
         height_name = 'wave_height'
         period_name = 'wave_period'
         height = spec%wave_height
         period = spec%wave_period
         if (status%ok .and. spec%wave_order /= 1 .and. spec%wave_order /= 2) &
            call status%fail(where//': variable wave_order must be 1 (linear) or 2 (Madsen''s second order), got '// &
                             int_text(spec%wave_order))
      else
         height_name = 'significant_wave_height'
         period_name = 'peak_period'
         height = spec%significant_wave_height
         period = spec%peak_period
         call check_irregular(spec, where, status)
      end if
      call check_real(where, height_name, height, status, greater_than=0.0_rp)
      call check_real(where, period_name, period, status, greater_than=0.0_rp)
      if (.not. status%ok) return
      call check_wave_shape(spec, where, height_name, height, period_name, period, g, cell, status)
   end subroutine validate_wave_motion

   !> An irregular wave's spectrum, gamma, seed and record.
   subroutine check_irregular(spec, where, status)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(in) :: where
      type(status_t), intent(inout) :: status
      if (.not. status%ok) return
      if (all(spec%spectrum /= spectrum_keywords)) then
         call status%fail(where//': variable spectrum must be one of '//quoted_list(spectrum_keywords)//", got '"// &
                          trim(spec%spectrum)//"'")
         return
      end if
      if (spec%spectrum == spectrum_jonswap) then
         call check_real(where, 'gamma', spec%gamma, status, at_least=1.0_rp)
      else if (spec%gamma /= jonswap_gamma) then
         call status%fail(where//": variable gamma belongs to spectrum = '"//spectrum_jonswap//"' (Pierson-Moskowitz "// &
                          "is gamma = 1), got spectrum = '"//trim(spec%spectrum)//"'")
      end if
      if (status%ok .and. (spec%wave_seed < 1 .or. spec%wave_seed > max_seed)) &
         call status%fail(where//': variable wave_seed must be in 1 .. '//int_text(max_seed)//', got '// &
                          int_text(spec%wave_seed))
      ! wave_duration = 0: not given (200 peak periods)
      if (spec%wave_duration /= 0.0_rp .and. spec%peak_period > 0.0_rp) &
         call check_real(where, 'wave_duration', spec%wave_duration, status, &
                         at_least=min_record_periods * spec%peak_period)
   end subroutine check_irregular

   !> The wave of height `height` and period `period` (the peak period of an irregular one) against
   !> Miche's limit, a second order's trough and the grid's cells per wavelength.
   subroutine check_wave_shape(spec, where, height_name, height, period_name, period, g, cell, status)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(in) :: where, height_name, period_name
      real(rp), intent(in) :: height, period, g, cell
      type(status_t), intent(inout) :: status
      real(rp) :: k, length, limit, ratio
      k = wavenumber(2.0_rp * pi / period, spec%water_depth, g)
      length = 2.0_rp * pi / k
      if (length < min_cells_per_wavelength * cell) then
         call status%fail(where//': variable '//period_name//' = '//real_text(period)//' s makes waves '// &
                          brief(length)//' m long in water '//real_text(spec%water_depth)//' m deep, '// &
                          brief(length / cell)//' cells of &grid cell_size = '//real_text(cell)// &
                          ': the grid cannot carry them (at least '//int_text(nint(min_cells_per_wavelength))// &
                          ' cells per wavelength; 20 or more recommended)')
         return
      end if
      limit = miche_steepness * length * tanh(k * spec%water_depth)
      if (height > limit) then
         call status%fail(where//': variable '//height_name//' = '//real_text(height)//' m is too steep for a '// &
                          'wave '//brief(length)//' m long in water '//real_text(spec%water_depth)// &
                          ' m deep: it breaks above '//brief(limit)//' m (Miche: H/L <= 0.142 tanh(kh))')
         return
      end if
      if (spec%kind /= motion_regular_wave .or. spec%wave_order /= 2) return
      ratio = stokes_second_harmonic(height, k, spec%water_depth) / (0.5_rp * height)
      if (ratio > max_harmonic_ratio) &
         call status%fail(where//': variable wave_height = '//real_text(height)//' m: second-order (Stokes) theory '// &
                          'does not hold for this wave (kh = '//brief(k * spec%water_depth)// &
                          '): its second harmonic is '//brief(ratio)//' of the first, above 1/4, which puts a '// &
                          'second crest in its trough; use a smaller height, deeper water or wave_order = 1')
   end subroutine check_wave_shape

   !> A derived number in a message, to 4 significant digits.
   pure function brief(x) result(text)
      real(rp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=32) :: buffer
      write (buffer, '(g0.4)') x
      text = trim(adjustl(buffer))
   end function brief
end module wave_validation
