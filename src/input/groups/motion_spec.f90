!> The prescribed rigid translation a `&wall` or a `&structure` may make (docs/input.md; wall_motion
!> computes it): its keywords, its type and defaults (motion_spec_t), and what both groups' readers and
!> scene.nml do with its variables (motion, motion_start, wave_height, water_depth, motion_direction,
!> motion_file, motion_checksum).
module motion_spec
   use kinds, only: rp, name_len, path_len
   use input_text, only: real_text, real_list_text, quoted
   use scene_variables, only: take_text
   implicit none
   private

   public :: motion_to_locals, take_motion, motion_value

   !> `&wall motion=` and `&structure motion=` keywords: fixed, the piston stroke of a solitary wave (Goring 1978), a
   !> displacement read from a time table (docs/input.md).
   character(len=*), parameter, public :: motion_none = 'none'
   character(len=*), parameter, public :: motion_solitary_wave = 'solitary_wave'
   character(len=*), parameter, public :: motion_table = 'table'

   !> Accepted `&wall motion=` keywords (stored lower case).
   character(len=*), parameter, public :: motion_keywords(*) = [character(len=13) :: motion_none, &
                                                                motion_solitary_wave, motion_table]
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
   end type motion_spec_t

contains

   !> The variables of a prescribed motion (`&wall`, `&structure`) as namelist variables.
   pure subroutine motion_to_locals(spec, motion, motion_start, wave_height, water_depth, motion_direction, &
                                    motion_file, motion_checksum)
      type(motion_spec_t), intent(in) :: spec
      character(len=*), intent(out) :: motion, motion_file, motion_checksum
      real(rp), intent(out) :: motion_start, wave_height, water_depth, motion_direction(3)
      motion = spec%kind
      motion_start = spec%start
      wave_height = spec%wave_height
      water_depth = spec%water_depth
      motion_direction = spec%direction
      motion_file = spec%file
      motion_checksum = spec%checksum
   end subroutine motion_to_locals

   !> The namelist variables read back into the motion (see motion_to_locals; take_text for the strings).
   subroutine take_motion(motion, motion_start, wave_height, water_depth, motion_direction, motion_file, &
                          motion_checksum, spec, ios, message)
      character(len=*), intent(in) :: motion, motion_file, motion_checksum
      real(rp), intent(in) :: motion_start, wave_height, water_depth, motion_direction(3)
      type(motion_spec_t), intent(inout) :: spec
      integer, intent(inout) :: ios
      character(len=*), intent(inout) :: message
      call take_text('motion', motion, spec%kind, ios, message, fold='lower')
      call take_text('motion_file', motion_file, spec%file, ios, message)
      call take_text('motion_checksum', motion_checksum, spec%checksum, ios, message, fold='lower')
      if (ios /= 0) return
      spec%start = motion_start
      spec%wave_height = wave_height
      spec%water_depth = water_depth
      spec%direction = motion_direction
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
      case default
         text = ''
      end select
   end function motion_value
end module motion_spec
