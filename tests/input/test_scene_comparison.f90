!> Tests of src/input/scene_comparison.f90: two scene texts are compared as namelists (layout, comments,
!> order, number spelling do not count), each difference is named group%variable with both values, and
!> only the settings of restart_changeable are allowed.
module test_scene_comparison
   use assertions, only: assertEqual, assertTrue, assertFalse
   use error_status, only: status_t
   use scene_comparison, only: scene_change_t, compare_scene_texts, describe_changes, changeable_on_restart
   implicit none
   private

   public :: test_same_scene_in_other_words_is_unchanged, test_changed_physics_is_named, &
             test_run_settings_are_allowed, test_added_group_and_variable_are_named, &
             test_new_variable_at_its_default_is_unchanged

   character(len=*), parameter :: nl = new_line('a')

   !> A scene as a user might write it.
   character(len=*), parameter :: original = &
      "! a water column" // nl // &
      "&run end_time = 0.15, output_interval = 0.01, output_dir = 'column', checkpoint_interval_steps = 25 /" // nl // &
      "&grid dim = 2, cell_size = 0.02, extent = 2.0, 1.0 /" // nl // &
      "&gravity acceleration = 0.0, -9.81 /" // nl // &
      "&material name = 'water', model = 'newtonian_fluid', density = 1000.0, bulk_modulus = 2.0e6, " // &
      "cell_averaging = .true. /" // nl // &
      "&body material = 'water', lower = 0.0, 0.0, upper = 1.0, 0.5 /" // nl

contains

   !> `text` with the first `old` replaced by `new`.
   function edited(text, old, new) result(changed)
      character(len=*), intent(in) :: text, old, new
      character(len=:), allocatable :: changed
      integer :: at
      at = index(text, old)
      changed = text
      if (at > 0) changed = text(1:at - 1)//new//text(at + len(old):)
   end function edited

   subroutine compare(old_text, new_text, changes)
      character(len=*), intent(in) :: old_text, new_text
      type(scene_change_t), allocatable, intent(out) :: changes(:)
      type(status_t) :: status
      call compare_scene_texts(old_text, 'stored', new_text, 'scene', changes, status)
      call assertTrue(status%ok, 'compare_scene_texts: '//trim(status%message))
      if (.not. status%ok) allocate (changes(0))
   end subroutine compare

   !> Other blanks, line breaks, comments, order of variables and groups, case of names, and numbers,
   !> logicals and repeated values spelt otherwise: no change.
   subroutine test_same_scene_in_other_words_is_unchanged()
      type(scene_change_t), allocatable :: changes(:)
      character(len=*), parameter :: reworded = &
         "&Material  name='water',  model = 'newtonian_fluid' ! the fluid" // nl // &
         "   Bulk_Modulus = 2000000.0, density = 1e3," // nl // &
         "   cell_averaging = T /" // nl // &
         "! the box" // nl // &
         "&grid extent = 2, 1.0, cell_size = 2.0e-2, dim = 2 /" // nl // &
         "&run output_dir = 'column'" // nl // &
         "     end_time = 1.5d-1, output_interval = 0.010, checkpoint_interval_steps = +25 /" // nl // &
         "&gravity acceleration = 0, -9.810 /" // nl // &
         "&body material = 'water', lower = 2*0.0, upper = 1.0, 0.5 /" // nl
      call compare(original, reworded, changes)
      call assertEqual(0, size(changes), 'no change: '//describe_changes(changes, .false.)// &
                       describe_changes(changes, .true.))
   end subroutine test_same_scene_in_other_words_is_unchanged

   !> The bulk modulus and gravity changed: two differences, named with both values, not allowed.
   subroutine test_changed_physics_is_named()
      type(scene_change_t), allocatable :: changes(:)
      character(len=:), allocatable :: changed, refused
      changed = edited(edited(original, 'bulk_modulus = 2.0e6', 'bulk_modulus = 1.0e6'), '-9.81', '-5.0')
      call compare(original, changed, changes)
      call assertEqual(2, size(changes), 'two changes')
      if (size(changes) /= 2) return
      call assertEqual('gravity%acceleration', changes(1)%variable, 'in the order of the groups: gravity first')
      call assertEqual('0.0, -9.81', changes(1)%old_value, 'old gravity as written')
      call assertEqual('0.0, -5.0', changes(1)%new_value, 'new gravity as written')
      call assertEqual('material(1)%bulk_modulus', changes(2)%variable, 'a repeated group is numbered')
      call assertFalse(changes(1)%allowed .or. changes(2)%allowed, 'physics may not change')
      refused = describe_changes(changes, .false.)
      call assertEqual('gravity%acceleration: 0.0, -9.81 -> 0.0, -5.0; material(1)%bulk_modulus: 2.0e6 -> 1.0e6', &
                       refused, 'the description')
      call assertEqual('', describe_changes(changes, .true.), 'nothing allowed changed')
   end subroutine test_changed_physics_is_named

   !> end_time, the output folder and interval, checkpoint and field output settings may change; cfl,
   !> a material's or a body's values may not.
   subroutine test_run_settings_are_allowed()
      type(scene_change_t), allocatable :: changes(:)
      character(len=:), allocatable :: changed
      changed = edited(original, 'end_time = 0.15', 'end_time = 0.3, particle_output = F, load_interval = 0.01')
      changed = edited(changed, "'column'", "'column_2'")
      changed = edited(changed, 'checkpoint_interval_steps = 25', 'checkpoint_interval_steps = 50')
      call compare(original, changed, changes)
      call assertEqual(5, size(changes), 'five changes')
      call assertTrue(all(changes%allowed), 'all allowed: '//describe_changes(changes, .true.))
      call assertEqual('', describe_changes(changes, .false.), 'none refused')
      call assertTrue(changeable_on_restart('run%end_time'), 'end_time')
      call assertTrue(changeable_on_restart('Run%Checkpoints_Kept'), 'checkpoints_kept, any case')
      call assertTrue(changeable_on_restart('run%rebalance_interval'), 'rebalance_interval')
      call assertFalse(changeable_on_restart('run%cfl'), 'cfl')
      call assertFalse(changeable_on_restart('run%dt'), 'dt')
      call assertFalse(changeable_on_restart('run%update_scheme'), 'update_scheme')
      call assertFalse(changeable_on_restart('material(1)%bulk_modulus'), 'bulk_modulus')
      call assertFalse(changeable_on_restart('inlet(2)%end_time'), 'an inlet''s end_time is not the run''s')
      call assertFalse(changeable_on_restart('gauge(1)%point'), 'a gauge')
   end subroutine test_run_settings_are_allowed

   !> Another body and a variable given on one side only are differences too.
   subroutine test_added_group_and_variable_are_named()
      type(scene_change_t), allocatable :: changes(:)
      character(len=:), allocatable :: changed
      changed = edited(original, 'density = 1000.0,', 'density = 1000.0, viscosity = 1.0e-3,')// &
                "&body material = 'water', lower = 1.5, 0.0, upper = 1.7, 0.2 /"
      call compare(original, changed, changes)
      call assertEqual(2, size(changes), 'two changes: '//describe_changes(changes, .false.))
      if (size(changes) /= 2) return
      call assertEqual('material(1)%viscosity: (not given) -> 1.0e-3; body groups: 1 -> 2', &
                       describe_changes(changes, .false.), 'the description')
   end subroutine test_added_group_and_variable_are_named

   !> A checkpoint written before a variable existed lacks it: the new scene giving its default is no
   !> change (a restart of an older checkpoint is not refused), another value is.
   subroutine test_new_variable_at_its_default_is_unchanged()
      type(scene_change_t), allocatable :: changes(:)
      character(len=:), allocatable :: changed
      changed = edited(edited(original, 'density = 1000.0,', 'density = 1000.0, viscosity = 0.0,'), &
                       'upper = 1.0, 0.5 /', 'upper = 1.0, 0.5, angular_velocity = 3*0.0 /')
      call compare(original, changed, changes)
      call assertEqual(0, size(changes), 'defaults are no change: '//describe_changes(changes, .false.))
      changed = edited(original, 'upper = 1.0, 0.5 /', 'upper = 1.0, 0.5, angular_velocity = 0.0, 0.0, 1.0 /')
      call compare(original, changed, changes)
      call assertEqual('body(1)%angular_velocity: (not given) -> 0.0, 0.0, 1.0', describe_changes(changes, .false.), &
                       'another value is')
   end subroutine test_new_variable_at_its_default_is_unchanged

end module test_scene_comparison
