!> The prescribed rigid translation a `&wall` or a `&structure` may make (docs/input.md; wall_motion
!> computes it): its keywords, its type and defaults (motion_spec_t), and what both groups' readers and
!> scene.nml do with its variables (motion, motion_start, wave_height, water_depth, motion_direction,
!> motion_file, motion_checksum; the piston waves' wave_period, wave_order, ramp_time, spectrum,
!> significant_wave_height, peak_period, gamma, wave_seed, wave_duration).
module motion_spec
   use kinds, only: rp, name_len, path_len
   use input_text, only: real_text, real_list_text, quoted, int_text
   use scene_variables, only: take_text
   implicit none
   private

   public :: motion_to_locals, take_motion, motion_value

   !> `&wall motion=` and `&structure motion=` keywords: fixed, the piston stroke of a solitary wave (Goring 1978), a
   !> displacement read from a time table (docs/input.md).
   character(len=*), parameter, public :: motion_none = 'none'
   character(len=*), parameter, public :: motion_solitary_wave = 'solitary_wave'
   character(len=*), parameter, public :: motion_table = 'table'
   !> periodic waves from a piston (Biesel's transfer function, Madsen's second order; wave_paddle)
   character(len=*), parameter, public :: motion_regular_wave = 'regular_wave'
   !> irregular waves of a JONSWAP spectrum from a piston (wave_paddle)
   character(len=*), parameter, public :: motion_irregular_wave = 'irregular_wave'

   !> Accepted `&wall motion=` keywords (stored lower case).
   character(len=*), parameter, public :: motion_keywords(*) = [character(len=14) :: motion_none, &
                                                                motion_solitary_wave, motion_table, &
                                                                motion_regular_wave, motion_irregular_wave]
   !> Accepted `spectrum=` keywords of an irregular wave: JONSWAP (with `gamma`), Pierson-Moskowitz (gamma = 1).
   character(len=*), parameter, public :: spectrum_jonswap = 'jonswap', spectrum_pierson_moskowitz = 'pierson_moskowitz'
   character(len=*), parameter, public :: spectrum_keywords(*) = [character(len=17) :: spectrum_jonswap, &
                                                                  spectrum_pierson_moskowitz]
   !> JONSWAP's mean peak enhancement factor (Hasselmann et al. 1973), the default `gamma`.
   real(rp), parameter, public :: jonswap_gamma = 3.3_rp
   !> A prescribed rigid translation of a `&wall` or a `&structure` (wall_motion; docs/input.md): the
   !> namelist variables motion, motion_start, wave_height, water_depth, motion_file, motion_checksum and
   !> (a structure's solitary wave) motion_direction.
   type, public :: motion_spec_t
      character(len=name_len) :: kind = motion_none   !< `motion`: 'none', 'solitary_wave' or 'table'
      real(rp) :: start = 0.0_rp              !< `motion_start`, solitary_wave: the stroke starts [s]
      real(rp) :: wave_height = 0.0_rp        !< solitary_wave: wave height A [m]
      real(rp) :: water_depth = 0.0_rp        !< solitary_wave: still-water depth h [m]
      !> `motion_file`, table: CSV of the displacement (t, x, y[, z]); resolved to an absolute path
      character(len=path_len) :: file = ''
      !> `motion_checksum`, table: checksum of the numbers read from the file (16 hex digits); given: must match
      character(len=16) :: checksum = ''
      !> `motion_direction`, a structure's solitary_wave: the direction of the stroke, any length (a wall
      !> moves along its normal)
      real(rp) :: direction(3) = 0.0_rp
      real(rp) :: wave_period = 0.0_rp        !< regular_wave: period T [s]
      integer :: wave_order = 2               !< regular_wave: 1 (linear) or 2 (Madsen's second-order stroke)
      !> regular_wave, irregular_wave: the ramp of the stroke's amplitude [s]; < 0 (not given): resolved to 2
      !> periods (2 peak periods) by resolve_scene
      real(rp) :: ramp_time = -1.0_rp
      character(len=name_len) :: spectrum = spectrum_jonswap   !< irregular_wave: 'jonswap' or 'pierson_moskowitz'
      real(rp) :: significant_wave_height = 0.0_rp            !< irregular_wave: Hs = 4 sqrt(m0) [m]
      real(rp) :: peak_period = 0.0_rp                        !< irregular_wave: Tp [s]
      real(rp) :: gamma = jonswap_gamma                       !< irregular_wave, jonswap: peak enhancement [-]
      integer :: wave_seed = 1                                !< irregular_wave: seed of the phases, 1 .. 2^31 - 2
      !> irregular_wave: the record's duration D [s] (frequency spacing 1/D; the signal repeats after D); 0
      !> (not given): resolved to 200 peak periods by resolve_scene
      real(rp) :: wave_duration = 0.0_rp
   end type motion_spec_t


contains

   !> The variables of a prescribed motion (`&wall`, `&structure`) as namelist variables.
   pure subroutine motion_to_locals(spec, motion, motion_start, wave_height, water_depth, motion_direction, &
                                    motion_file, motion_checksum, wave_period, wave_order, ramp_time, spectrum, &
                                    significant_wave_height, peak_period, gamma, wave_seed, wave_duration)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(out) :: motion, motion_file, motion_checksum, spectrum
      real(rp), intent(out) :: motion_start, wave_height, water_depth, motion_direction(3), wave_period, ramp_time, &
                               significant_wave_height, peak_period, gamma, wave_duration
      integer, intent(out) :: wave_order, wave_seed
      motion = spec%kind
      motion_start = spec%start
      wave_height = spec%wave_height
      water_depth = spec%water_depth
      motion_direction = spec%direction
      motion_file = spec%file
      motion_checksum = spec%checksum
      wave_period = spec%wave_period
      wave_order = spec%wave_order
      ramp_time = spec%ramp_time
      spectrum = spec%spectrum
      significant_wave_height = spec%significant_wave_height
      peak_period = spec%peak_period
      gamma = spec%gamma
      wave_seed = spec%wave_seed
      wave_duration = spec%wave_duration
   end subroutine motion_to_locals

   !> The namelist variables read back into the motion (see motion_to_locals; take_text for the strings).
   subroutine take_motion(motion, motion_start, wave_height, water_depth, motion_direction, motion_file, &
                          motion_checksum, wave_period, wave_order, ramp_time, spectrum, significant_wave_height, &
                          peak_period, gamma, wave_seed, wave_duration, spec, ios, message)
      character(len=*), intent(in) :: motion, motion_file, motion_checksum, spectrum
      real(rp), intent(in) :: motion_start, wave_height, water_depth, motion_direction(3), wave_period, ramp_time, &
                              significant_wave_height, peak_period, gamma, wave_duration
      integer, intent(in) :: wave_order, wave_seed
      type(motion_spec_t), intent(inout) :: spec
      integer, intent(inout) :: ios
      character(len=*), intent(inout) :: message
      call take_text('motion', motion, spec%kind, ios, message, fold='lower')
      call take_text('motion_file', motion_file, spec%file, ios, message)
      call take_text('motion_checksum', motion_checksum, spec%checksum, ios, message, fold='lower')
      call take_text('spectrum', spectrum, spec%spectrum, ios, message, fold='lower')
      if (ios /= 0) return
      spec%start = motion_start
      spec%wave_height = wave_height
      spec%water_depth = water_depth
      spec%direction = motion_direction
      spec%wave_period = wave_period
      spec%wave_order = wave_order
      spec%ramp_time = ramp_time
      spec%significant_wave_height = significant_wave_height
      spec%peak_period = peak_period
      spec%gamma = gamma
      spec%wave_seed = wave_seed
      spec%wave_duration = wave_duration
   end subroutine take_motion

   !> A variable of the prescribed motion of a `&wall` or a `&structure`; '' for another variable.
   function motion_value(motion, name) result(text)
      type(motion_spec_t), intent(in) :: motion
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('motion')
         text = quoted(motion%kind)
      case ('motion_start')
         text = real_text(motion%start)
      case ('wave_height')
         text = real_text(motion%wave_height)
      case ('water_depth')
         text = real_text(motion%water_depth)
      case ('motion_direction')
         text = real_list_text(motion%direction)
      case ('motion_file')
         text = quoted(motion%file)
      case ('motion_checksum')
         text = quoted(motion%checksum)
      case ('wave_period')
         text = real_text(motion%wave_period)
      case ('wave_order')
         text = int_text(motion%wave_order)
      case ('ramp_time')
         text = real_text(motion%ramp_time)
      case ('spectrum')
         text = quoted(motion%spectrum)
      case ('significant_wave_height')
         text = real_text(motion%significant_wave_height)
      case ('peak_period')
         text = real_text(motion%peak_period)
      case ('gamma')
         text = real_text(motion%gamma)
      case ('wave_seed')
         text = int_text(motion%wave_seed)
      case ('wave_duration')
         text = real_text(motion%wave_duration)
      case default
         text = ''
      end select
   end function motion_value
end module motion_spec
