!> The `&run` group (docs/input.md): the time stepping, output, checkpoints and health limits of a run.
!> Here: the type and defaults of its variables (run_control_t), the particle datasets it may name, the
!> reader's rows (run_variables), the namelist read, the scene.nml text (run_value) and which particle
!> datasets a run writes (writes_particle_field), and the checks of its values (validate_run).
module run_group
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp, i8, name_len, path_len
   use input_text, only: lower_case, int_text, real_text, quoted, logical_text, quoted_list, group_context
   use scene_variables, only: variable_info_t, text_len, take_text
   use error_status, only: status_t
   use input_checks, only: check_real
   implicit none
   private

   public :: validate_run, read_run_group, run_value, writes_particle_field

   !> The particle datasets `&run particle_fields` may name (position and connectivity are always written).
   character(len=*), parameter, public :: particle_field_names(*) = [character(len=11) :: 'velocity', 'mass', &
      'volume', 'density', 'stress', 'mean_stress', 'pressure', 'material', 'id', 'rank']
   !> `&run field_precision` keywords.
   character(len=*), parameter, public :: field_precision_keywords(*) = [character(len=6) :: 'double', 'single']

   !> Accepted `&run update_scheme=` keywords (stored upper case).
   character(len=*), parameter, public :: update_scheme_keywords(*) = [character(len=4) :: 'USL', 'MUSL']
   !> Accepted `&run transfer=` keywords (stored lower case).
   character(len=*), parameter, public :: transfer_keywords(*) = [character(len=8) :: 'flip_pic', 'apic']
   !> `&run`: time stepping, update scheme and output control.
   type, public :: run_control_t
      real(rp) :: end_time = -1.0_rp          !< simulated time to reach [s] (required)
      !> Courant number of the automatic time step; 0: the default of each material (the solver's
      !> material_courant_numbers: 0.75 h / c for a fluid on multilinear functions but with C0, else 0.5)
      real(rp) :: cfl = 0.0_rp
      real(rp) :: fixed_dt = 0.0_rp           !< fixed time step [s]; 0 selects the CFL step
      real(rp) :: output_interval = 0.0_rp    !< simulated time between diagnostics rows [s]; 0: end_time/100
      character(len=path_len) :: output_dir = 'output'
      logical :: overwrite = .false.          !< allow replacing a previous run in output_dir
      character(len=name_len) :: update_scheme = 'MUSL'  !< 'MUSL' (default) or 'USL'
      !> velocity transfer: 'flip_pic' (the FLIP/PIC blend, default) or 'apic' (affine, docs/theory.md)
      character(len=name_len) :: transfer = 'flip_pic'
      real(rp) :: flip_fraction = 0.95_rp     !< 1: pure FLIP, 0: pure PIC (default: docs/theory.md)
      !> the scene file or an override assigns flip_fraction: refused with 'apic', which has no blend
      logical :: flip_fraction_given = .false.
      real(rp) :: theta = 1.0_rp              !< theta of the nodal velocity used for kinematics
      integer(i8) :: max_steps = huge(1_i8)   !< stop after this many steps
      real(rp) :: progress_interval = 5.0_rp  !< wall seconds between progress lines on stderr; <= 0: none
      real(rp) :: floor_size = 0.0_rp         !< tank floor width (2-D) / area (3-D) for h_eq; 0: from grid
      logical :: particle_output = .true.     !< write particle fields (HDF5 + XDMF) at every output time
      logical :: grid_output = .true.         !< write grid fields of the active box at every output time
      !> precision of the real datasets of the fields files: 'double' or 'single' (positions stay double)
      character(len=name_len) :: field_precision = 'double'
      !> particle datasets written: comma-separated names of particle_field_names, or 'all'; position always
      character(len=path_len) :: particle_fields = 'all'
      integer(i8) :: checkpoint_interval_steps = 0   !< steps between checkpoints; 0: not by steps
      real(rp) :: checkpoint_interval_wall = 3600.0_rp  !< wall seconds between checkpoints; 0: not by time
      integer :: checkpoints_kept = 2         !< newest checkpoints kept on disk
      real(rp) :: speed_limit = 0.0_rp        !< particle speed taken as a blow-up [m/s]; 0: 10 x fastest wave
      !> rebalance when the largest rank holds more than this multiple of the mean particles per rank; 0: never
      real(rp) :: rebalance_threshold = 1.02_rp
      integer :: rebalance_interval = 20      !< steps between balance checks (also at every output time)
      !> simulated time between rows of loads.csv, gauges.csv and bodies.csv [s]; 0: every step. Loads are
      !> averages over the interval (impulse / length), gauges and body states samples at the row's time.
      real(rp) :: load_interval = 1.0e-3_rp
   end type run_control_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: run_variables(*) = [ &
      variable_info_t('run', 'end_time', 'real', .true.), &
      variable_info_t('run', 'cfl', 'real', .false.), &
      variable_info_t('run', 'dt', 'real', .false.), &
      variable_info_t('run', 'output_interval', 'real', .false.), &
      variable_info_t('run', 'output_dir', 'string', .false.), &
      variable_info_t('run', 'overwrite', 'logical', .false.), &
      variable_info_t('run', 'update_scheme', 'string', .false.), &
      variable_info_t('run', 'transfer', 'string', .false.), &
      variable_info_t('run', 'flip_fraction', 'real', .false.), &
      variable_info_t('run', 'theta', 'real', .false.), &
      variable_info_t('run', 'max_steps', 'integer', .false.), &
      variable_info_t('run', 'progress_interval', 'real', .false.), &
      variable_info_t('run', 'floor_size', 'real', .false.), &
      variable_info_t('run', 'particle_output', 'logical', .false.), &
      variable_info_t('run', 'grid_output', 'logical', .false.), &
      variable_info_t('run', 'field_precision', 'string', .false.), &
      variable_info_t('run', 'particle_fields', 'string', .false.), &
      variable_info_t('run', 'checkpoint_interval_steps', 'integer', .false.), &
      variable_info_t('run', 'checkpoint_interval_wall', 'real', .false.), &
      variable_info_t('run', 'checkpoints_kept', 'integer', .false.), &
      variable_info_t('run', 'speed_limit', 'real', .false.), &
      variable_info_t('run', 'rebalance_threshold', 'real', .false.), &
      variable_info_t('run', 'rebalance_interval', 'integer', .false.), &
      variable_info_t('run', 'load_interval', 'real', .false.)]

contains

   !> Read one `&run ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_run_group(control, ios, message, text)
      type(run_control_t), intent(inout) :: control
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      real(rp) :: end_time, cfl, dt, output_interval, flip_fraction, theta, progress_interval, floor_size, &
                  checkpoint_interval_wall, speed_limit, rebalance_threshold, load_interval
      character(len=text_len) :: output_dir, update_scheme, field_precision, particle_fields, transfer
      logical :: overwrite, particle_output, grid_output
      integer(i8) :: max_steps, checkpoint_interval_steps
      integer :: checkpoints_kept, rebalance_interval
      namelist /run/ end_time, cfl, dt, output_interval, output_dir, overwrite, update_scheme, transfer, &
         flip_fraction, theta, max_steps, progress_interval, floor_size, particle_output, grid_output, &
         checkpoint_interval_steps, checkpoint_interval_wall, checkpoints_kept, speed_limit, rebalance_threshold, &
         rebalance_interval, load_interval, field_precision, particle_fields

      end_time = control%end_time
      cfl = control%cfl
      dt = control%fixed_dt
      output_interval = control%output_interval
      output_dir = control%output_dir
      overwrite = control%overwrite
      update_scheme = control%update_scheme
      transfer = control%transfer
      ! huge marks "not assigned here": with APIC a flip_fraction the scene gives is refused, not ignored
      flip_fraction = huge(1.0_rp)
      theta = control%theta
      max_steps = control%max_steps
      progress_interval = control%progress_interval
      floor_size = control%floor_size
      particle_output = control%particle_output
      grid_output = control%grid_output
      field_precision = control%field_precision
      particle_fields = control%particle_fields
      checkpoint_interval_steps = control%checkpoint_interval_steps
      checkpoint_interval_wall = control%checkpoint_interval_wall
      checkpoints_kept = control%checkpoints_kept
      speed_limit = control%speed_limit
      rebalance_threshold = control%rebalance_threshold
      rebalance_interval = control%rebalance_interval
      load_interval = control%load_interval
      read (text, nml=run, iostat=ios, iomsg=message)
      call take_text('output_dir', output_dir, control%output_dir, ios, message)
      call take_text('update_scheme', update_scheme, control%update_scheme, ios, message, fold='upper')
      call take_text('transfer', transfer, control%transfer, ios, message, fold='lower')
      call take_text('field_precision', field_precision, control%field_precision, ios, message, fold='lower')
      call take_text('particle_fields', particle_fields, control%particle_fields, ios, message)
      if (ios /= 0) return
      control%end_time = end_time
      control%cfl = cfl
      control%fixed_dt = dt
      control%output_interval = output_interval
      control%overwrite = overwrite
      if (flip_fraction < huge(1.0_rp) .or. .not. ieee_is_finite(flip_fraction)) then
         control%flip_fraction = flip_fraction
         control%flip_fraction_given = .true.
      end if
      control%theta = theta
      control%max_steps = max_steps
      control%progress_interval = progress_interval
      control%floor_size = floor_size
      control%particle_output = particle_output
      control%grid_output = grid_output
      control%particle_fields = without_blanks(lower_case(control%particle_fields))
      control%checkpoint_interval_steps = checkpoint_interval_steps
      control%checkpoint_interval_wall = checkpoint_interval_wall
      control%checkpoints_kept = checkpoints_kept
      control%speed_limit = speed_limit
      control%rebalance_threshold = rebalance_threshold
      control%rebalance_interval = rebalance_interval
      control%load_interval = load_interval
   end subroutine read_run_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function run_value(run, name) result(text)
      type(run_control_t), intent(in) :: run
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('end_time')
         text = real_text(run%end_time)
      case ('cfl')
         text = real_text(run%cfl)
      case ('dt')
         text = real_text(run%fixed_dt)
      case ('output_interval')
         text = real_text(run%output_interval)
      case ('output_dir')
         text = quoted(run%output_dir)
      case ('update_scheme')
         text = quoted(run%update_scheme)
      case ('transfer')
         text = quoted(run%transfer)
      case ('flip_fraction')
         text = real_text(run%flip_fraction)
      case ('theta')
         text = real_text(run%theta)
      case ('max_steps')
         text = int_text(run%max_steps)
      case ('progress_interval')
         text = real_text(run%progress_interval)
      case ('floor_size')
         text = real_text(run%floor_size)
      case ('particle_output')
         text = logical_text(run%particle_output)
      case ('grid_output')
         text = logical_text(run%grid_output)
      case ('field_precision')
         text = quoted(run%field_precision)
      case ('particle_fields')
         text = quoted(run%particle_fields)
      case ('checkpoint_interval_steps')
         text = int_text(run%checkpoint_interval_steps)
      case ('checkpoint_interval_wall')
         text = real_text(run%checkpoint_interval_wall)
      case ('checkpoints_kept')
         text = int_text(run%checkpoints_kept)
      case ('speed_limit')
         text = real_text(run%speed_limit)
      case ('rebalance_threshold')
         text = real_text(run%rebalance_threshold)
      case ('rebalance_interval')
         text = int_text(run%rebalance_interval)
      case ('load_interval')
         text = real_text(run%load_interval)
      case default
         text = ''
      end select
   end function run_value

   !> `&run particle_fields` asks for particle dataset `name` ('all' asks for every one).
   pure logical function writes_particle_field(run, name)
      type(run_control_t), intent(in) :: run
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: item
      integer :: start, comma
      writes_particle_field = .false.
      start = 1
      do
         comma = index(run%particle_fields(start:), ',')
         if (comma == 0) then
            item = trim(adjustl(run%particle_fields(start:)))
         else
            item = trim(adjustl(run%particle_fields(start:start + comma - 2)))
         end if
         if (item == 'all' .or. item == name) then
            writes_particle_field = .true.
            return
         end if
         if (comma == 0) return
         start = start + comma
      end do
   end function writes_particle_field

   !> `text` with every blank removed (a list of names reads the same with or without them).
   pure function without_blanks(text) result(packed)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: packed
      integer :: i, n
      packed = ''
      n = 0
      do i = 1, len_trim(text)
         if (text(i:i) == ' ') cycle
         n = n + 1
         packed(n:n) = text(i:i)
      end do
   end function without_blanks

   subroutine validate_run(run, path, status)
      type(run_control_t), intent(in) :: run
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where

      where = group_context(path, 'run', 0)
      call check_real(where, 'end_time', run%end_time, status, greater_than=0.0_rp)
      ! at most the largest critical step of any shape function (bspline2 in 3-D: 2.67); the grid's own limit
      ! is checked with the grid (scene_validation); 0 (not given) is the default of each material
      if (run%cfl /= 0.0_rp) call check_real(where, 'cfl', run%cfl, status, greater_than=0.0_rp, at_most=3.0_rp)
      call check_real(where, 'dt', run%fixed_dt, status, at_least=0.0_rp)
      call check_real(where, 'output_interval', run%output_interval, status, at_least=0.0_rp)
      if (len_trim(run%output_dir) == 0) call status%fail(where//': variable output_dir must not be empty')
      if (all(run%update_scheme /= update_scheme_keywords)) then
         call status%fail(where//': variable update_scheme must be one of '//quoted_list(update_scheme_keywords)// &
                          ", got '"//trim(run%update_scheme)//"'")
      end if
      if (all(run%transfer /= transfer_keywords)) then
         call status%fail(where//': variable transfer must be one of '//quoted_list(transfer_keywords)// &
                          ", got '"//trim(run%transfer)//"'")
      else if (run%transfer == 'apic' .and. run%flip_fraction_given) then
         ! a blend the user asked for must not be dropped without a word
         call status%fail(where//": variable flip_fraction has no effect with transfer = 'apic' (APIC has no FLIP/PIC "// &
                          "blend); remove it")
      end if
      call check_real(where, 'flip_fraction', run%flip_fraction, status, at_least=0.0_rp, at_most=1.0_rp)
      call check_real(where, 'theta', run%theta, status, greater_than=0.0_rp, at_most=1.0_rp)
      if (run%max_steps <= 0_i8) then
         call status%fail(where//': variable max_steps must be > 0, got '//int_text(run%max_steps))
      end if
      call check_real(where, 'progress_interval', run%progress_interval, status)
      call check_real(where, 'floor_size', run%floor_size, status, at_least=0.0_rp)
      if (run%checkpoint_interval_steps < 0_i8) then
         call status%fail(where//': variable checkpoint_interval_steps must be >= 0, got '// &
                          int_text(run%checkpoint_interval_steps))
      end if
      call check_real(where, 'checkpoint_interval_wall', run%checkpoint_interval_wall, status, at_least=0.0_rp)
      if (run%checkpoints_kept < 1) then
         call status%fail(where//': variable checkpoints_kept must be >= 1, got '//int_text(run%checkpoints_kept))
      end if
      call check_real(where, 'speed_limit', run%speed_limit, status, at_least=0.0_rp)
      ! below 1 even a perfect balance would exceed the threshold (NaN fails the finiteness test first)
      if (.not. ieee_is_finite(run%rebalance_threshold)) then
         call check_real(where, 'rebalance_threshold', run%rebalance_threshold, status)
      else if (run%rebalance_threshold < 0.0_rp .or. &
               (run%rebalance_threshold > 0.0_rp .and. run%rebalance_threshold < 1.0_rp)) then
         call status%fail(where//': variable rebalance_threshold must be 0 (off) or >= 1, got '// &
                          real_text(run%rebalance_threshold))
      end if
      if (run%rebalance_interval < 1) then
         call status%fail(where//': variable rebalance_interval must be >= 1, got '//int_text(run%rebalance_interval))
      end if
      call check_real(where, 'load_interval', run%load_interval, status, at_least=0.0_rp)
      if (status%ok .and. all(run%field_precision /= field_precision_keywords)) then
         call status%fail(where//': variable field_precision must be one of '//quoted_list(field_precision_keywords)// &
                          ", got '"//trim(run%field_precision)//"'")
      end if
      if (status%ok) call check_particle_fields(where, run%particle_fields, status)
   end subroutine validate_run

   !> `&run particle_fields` is a comma-separated list of particle datasets (or 'all'; 'position' is
   !> always written and may be named).
   subroutine check_particle_fields(where, fields, status)
      character(len=*), intent(in) :: where, fields
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: item
      integer :: start, comma
      start = 1
      do
         comma = index(fields(start:), ',')
         if (comma == 0) then
            item = trim(fields(start:))
         else
            item = fields(start:start + comma - 2)
         end if
         if (item /= 'all' .and. item /= 'position' .and. all(particle_field_names /= item)) then
            if (len(item) == 0) then
               call status%fail(where//": variable particle_fields has an empty name in '"//trim(fields)// &
                                "' (a comma-separated list of "//quoted_list(particle_field_names)//", or 'all')")
            else
               call status%fail(where//": variable particle_fields: unknown field '"//item//"' (fields: "// &
                                quoted_list(particle_field_names)//", or 'all'; position is always written)")
            end if
            return
         end if
         if (comma == 0) return
         start = start + comma
      end do
   end subroutine check_particle_fields
end module run_group
