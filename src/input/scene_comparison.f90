!> Which variables differ between two scenes given as namelist text (the one a checkpoint stores and
!> the one a restart reads), and whether a restart may change them (docs/output.md, "Checkpoints and
!> restart").
!>
!> The texts are compared as namelists, not as text: group by group (the k-th occurrence of a repeated
!> group with the k-th), variable by variable whatever their order, each value as the list of values it
!> assigns: numbers by value (1e3 and 1000.0 are the same), logicals by truth (.true. and T), strings by
!> their text. Blanks, line breaks and comments do not count.
module scene_comparison
   use kinds, only: rp, i8
   use error_status, only: status_t
   use namelist_scan, only: namelist_file_t, namelist_group_t, scan_namelist_text
   use scene_reader, only: known_groups, repeated_groups
   use scene_description, only: scene_t
   use scene_record, only: scene_namelist_text
   use input_text, only: lower_case, int_text
   implicit none
   private

   public :: compare_scene_texts, describe_changes, changeable_on_restart

   !> What a restart may change without --allow-scene-change: when the run ends, what it writes where and
   !> how often, the blow-up speed limit and the load balancing; nothing of the physics or the particles.
   !> `&body points_file`, `&inlet velocity_file` and `&wall` / `&structure motion_file` may name another path (the scene
   !> records it as an absolute path, so a moved folder changes it): their numbers are compared through
   !> `points_checksum`, `velocity_checksum` and `motion_checksum`, which may not change.
   !> Load balancing changes the order of sums, so a continuation that changes it equals an
   !> uninterrupted run to round-off (as one on another number of ranks), not bit for bit. [R]
   character(len=*), parameter, public :: restart_changeable(*) = [character(len=29) :: &
      'run%end_time', 'run%max_steps', 'run%output_interval', 'run%output_dir', 'run%overwrite', &
      'run%particle_output', 'run%grid_output', 'run%progress_interval', 'run%floor_size', 'run%load_interval', &
      'run%checkpoint_interval_steps', 'run%checkpoint_interval_wall', 'run%checkpoints_kept', 'run%speed_limit', &
      'run%rebalance_threshold', 'run%rebalance_interval', 'body%points_file', 'inlet%velocity_file', &
      'wall%motion_file', 'structure%motion_file']

   !> One difference: `material(1)%bulk_modulus: 2000000.0 -> 1000000.0`.
   type, public :: scene_change_t
      character(len=:), allocatable :: variable   !< group%variable; group(k)%variable for a repeated group
      character(len=:), allocatable :: old_value  !< as the first text writes it; '(not given)' if absent
      character(len=:), allocatable :: new_value
      logical :: allowed = .false.                !< a restart may make it (restart_changeable)
   end type scene_change_t

   type :: token_t
      character(len=:), allocatable :: text
   end type token_t

   !> The values a value text assigns, one token each.
   type :: token_list_t
      type(token_t), allocatable :: tokens(:)
      integer :: n = 0
   end type token_list_t

   !> Longest description describe_changes returns (it must fit a status message with its context).
   integer, parameter :: description_limit = 640

contains

   !> The differences from scene text `old_text` (named `old_label` in messages) to `new_text`, in the
   !> order of the groups and of the variables of `old_text`. A variable `old_text` lacks that `new_text`
   !> gives its default value is no change: a checkpoint written before the variable existed had it at
   !> that default. Fails only if a text cannot be scanned.
   subroutine compare_scene_texts(old_text, old_label, new_text, new_label, changes, status)
      character(len=*), intent(in) :: old_text, old_label, new_text, new_label
      type(scene_change_t), allocatable, intent(out) :: changes(:)
      type(status_t), intent(inout) :: status
      type(namelist_file_t) :: old_file, new_file, defaults
      character(len=:), allocatable :: group, label
      integer :: g, k, n_old, n_new

      allocate (changes(0))
      call scan_namelist_text(old_text, old_label, known_groups, old_file, status)
      call scan_namelist_text(new_text, new_label, known_groups, new_file, status)
      call scan_namelist_text(default_text(), 'the defaults', known_groups, defaults, status)
      if (.not. status%ok) return
      do g = 1, size(known_groups)
         group = trim(known_groups(g))
         n_old = old_file%count(group)
         n_new = new_file%count(group)
         if (n_old /= n_new) call add_change(changes, group//' groups', int_text(n_old), int_text(n_new))
         do k = 1, min(n_old, n_new)
            label = group
            if (any(repeated_groups == group)) label = group//'('//int_text(k)//')'
            call compare_groups(old_file%groups(old_file%find(group, k)), new_file%groups(new_file%find(group, k)), &
                                defaults%groups(defaults%find(group, 1)), label, changes)
         end do
      end do
   end subroutine compare_scene_texts

   !> May a restart change `variable` (group%variable, group(k)%variable)?
   pure logical function changeable_on_restart(variable)
      character(len=*), intent(in) :: variable
      character(len=:), allocatable :: key
      integer :: open, close
      key = lower_case(variable)
      open = index(key, '(')
      close = index(key, ')')
      if (open > 0 .and. close > open) key = key(1:open - 1)//key(close + 1:)
      changeable_on_restart = any(restart_changeable == key)
   end function changeable_on_restart

   !> "a: 1.0 -> 2.0; b: ..." for the changes whose `allowed` is `allowed`, cut after description_limit
   !> characters with the number of the others.
   function describe_changes(changes, allowed) result(text)
      type(scene_change_t), intent(in) :: changes(:)
      logical, intent(in) :: allowed
      character(len=:), allocatable :: text
      character(len=:), allocatable :: one
      integer :: c, left
      text = ''
      left = count(changes%allowed .eqv. allowed)
      do c = 1, size(changes)
         if (changes(c)%allowed .neqv. allowed) cycle
         one = changes(c)%variable//': '//changes(c)%old_value//' -> '//changes(c)%new_value
         if (len(text) > 0 .and. len(text) + len(one) > description_limit) then
            text = text//'; and '//int_text(left)//' more'
            return
         end if
         if (len(text) > 0) text = text//'; '
         text = text//one
         left = left - 1
      end do
   end function describe_changes

   !> The variables of two occurrences of a group, matched by designator (the last one wins, as in a
   !> namelist read).
   subroutine compare_groups(old_group, new_group, default_group, label, changes)
      type(namelist_group_t), intent(in) :: old_group, new_group, default_group
      character(len=*), intent(in) :: label
      type(scene_change_t), allocatable, intent(inout) :: changes(:)
      character(len=*), parameter :: absent = '(not given)'
      integer :: i, j, d
      do i = 1, size(old_group%items)
         if (last_item(old_group, key(old_group%items(i)%designator)) /= i) cycle
         j = last_item(new_group, key(old_group%items(i)%designator))
         if (j == 0) then
            call add_change(changes, item_label(label, old_group%items(i)%designator), old_group%items(i)%value, absent)
         else if (.not. same_values(old_group%items(i)%value, new_group%items(j)%value)) then
            call add_change(changes, item_label(label, old_group%items(i)%designator), old_group%items(i)%value, &
                            new_group%items(j)%value)
         end if
      end do
      do j = 1, size(new_group%items)
         if (last_item(new_group, key(new_group%items(j)%designator)) /= j) cycle
         if (last_item(old_group, key(new_group%items(j)%designator)) /= 0) cycle
         d = last_item(default_group, key(new_group%items(j)%designator))
         if (d > 0) then
            if (same_values(default_group%items(d)%value, new_group%items(j)%value)) cycle
         end if
         call add_change(changes, item_label(label, new_group%items(j)%designator), absent, new_group%items(j)%value)
      end do
   end subroutine compare_groups

   !> The scene record of the defaults: a scene of default values with one entry of every group.
   function default_text() result(text)
      character(len=:), allocatable :: text
      type(scene_t) :: defaults
      allocate (defaults%materials(1), defaults%bodies(1), defaults%walls(1), defaults%structures(1), &
                defaults%inlets(1), defaults%gauges(1), defaults%contacts(1))
      text = scene_namelist_text(defaults)
   end function default_text

   !> Index of the last item of `group` whose designator has `wanted` as key; 0 if there is none.
   pure integer function last_item(group, wanted) result(found)
      type(namelist_group_t), intent(in) :: group
      character(len=*), intent(in) :: wanted
      integer :: i
      found = 0
      do i = 1, size(group%items)
         if (key(group%items(i)%designator) == wanted) found = i
      end do
   end function last_item

   !> A designator in lower case without blanks: `Origin( 2 )` and `origin(2)` are the same.
   pure function key(designator) result(text)
      character(len=*), intent(in) :: designator
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, len(designator)
         if (designator(i:i) /= ' ' .and. designator(i:i) /= achar(9)) text = text//lower_case(designator(i:i))
      end do
   end function key

   pure function item_label(group_label, designator) result(text)
      character(len=*), intent(in) :: group_label, designator
      character(len=:), allocatable :: text
      text = group_label//'%'//key(designator)
      if (len(designator) == 0) text = group_label//'%(text without a variable)'
   end function item_label

   subroutine add_change(changes, variable, old_value, new_value)
      type(scene_change_t), allocatable, intent(inout) :: changes(:)
      character(len=*), intent(in) :: variable, old_value, new_value
      type(scene_change_t), allocatable :: grown(:)
      integer :: n
      n = size(changes)
      allocate (grown(n + 1))
      grown(1:n) = changes
      grown(n + 1)%variable = variable
      grown(n + 1)%old_value = old_value
      grown(n + 1)%new_value = new_value
      grown(n + 1)%allowed = changeable_on_restart(variable)
      call move_alloc(grown, changes)
   end subroutine add_change

   !> Do two value texts assign the same values? `2*0.0` is `0.0, 0.0`.
   logical function same_values(a, b) result(same)
      character(len=*), intent(in) :: a, b
      type(token_list_t) :: left, right
      integer :: t
      call split_values(a, left)
      call split_values(b, right)
      same = left%n == right%n
      if (.not. same) return
      do t = 1, left%n
         same = same_value(left%tokens(t)%text, right%tokens(t)%text)
         if (.not. same) return
      end do
   end function same_values

   !> Two single values: strings by their text (trailing blanks do not count), logicals by truth,
   !> integers exactly, other numbers as reals, anything else by its lower-case text.
   logical function same_value(a, b) result(same)
      character(len=*), intent(in) :: a, b
      integer(i8) :: i, j
      real(rp) :: x, y
      integer :: ios_a, ios_b
      if (is_quoted(a) .or. is_quoted(b)) then
         same = is_quoted(a) .and. is_quoted(b)
         if (same) same = unquoted(a) == unquoted(b)
      else if (is_logical(a) .or. is_logical(b)) then
         same = is_logical(a) .and. is_logical(b)
         if (same) same = logical_value(a) .eqv. logical_value(b)
      else
         ios_a = 1
         ios_b = 1
         if (verify(a, '+-0123456789') == 0 .and. verify(b, '+-0123456789') == 0) then
            read (a, *, iostat=ios_a) i
            read (b, *, iostat=ios_b) j
            if (ios_a == 0 .and. ios_b == 0) then
               same = i == j
               return
            end if
         end if
         read (a, *, iostat=ios_a) x
         read (b, *, iostat=ios_b) y
         if (ios_a == 0 .and. ios_b == 0) then
            same = .not. (x < y .or. x > y)      ! exactly equal, without -Wcompare-reals
         else
            same = lower_case(a) == lower_case(b)
         end if
      end if
   end function same_value

   pure logical function is_quoted(token)
      character(len=*), intent(in) :: token
      is_quoted = .false.
      if (len(token) > 0) is_quoted = token(1:1) == "'" .or. token(1:1) == '"'
   end function is_quoted

   !> The text of a quoted string: quotes removed, a doubled quote read as one.
   pure function unquoted(token) result(text)
      character(len=*), intent(in) :: token
      character(len=:), allocatable :: text
      character(len=1) :: quote
      integer :: i
      text = ''
      quote = token(1:1)
      i = 2
      do while (i <= len(token))
         if (token(i:i) == quote) then
            if (i == len(token)) exit
            if (token(i + 1:i + 1) /= quote) exit
            i = i + 1
         end if
         text = text//token(i:i)
         i = i + 1
      end do
   end function unquoted

   !> A namelist logical: T, F, .true., .False., true ...: an optional point, then t or f.
   pure logical function is_logical(token)
      character(len=*), intent(in) :: token
      character(len=:), allocatable :: word
      word = lower_case(token)
      if (len(word) > 1 .and. word(1:1) == '.') word = word(2:)
      is_logical = .false.
      if (len(word) > 0) is_logical = word(1:1) == 't' .or. word(1:1) == 'f'
   end function is_logical

   pure logical function logical_value(token)
      character(len=*), intent(in) :: token
      character(len=:), allocatable :: word
      word = lower_case(token)
      if (len(word) > 1 .and. word(1:1) == '.') word = word(2:)
      logical_value = word(1:1) == 't'
   end function logical_value

   !> The values of a value text, split at commas and blanks outside quotes, `r*c` expanded.
   subroutine split_values(text, list)
      character(len=*), intent(in) :: text
      type(token_list_t), intent(out) :: list
      character(len=1) :: quote
      integer :: i, start
      allocate (list%tokens(8))
      quote = ' '
      start = 0
      do i = 1, len(text)
         if (quote /= ' ') then
            if (text(i:i) == quote) quote = ' '      ! a doubled quote closes and reopens: the same token
         else if (text(i:i) == "'" .or. text(i:i) == '"') then
            quote = text(i:i)
            if (start == 0) start = i
         else if (text(i:i) == ',' .or. text(i:i) == ' ' .or. text(i:i) == achar(9)) then
            if (start > 0) call add_token(list, text(start:i - 1))
            start = 0
         else if (start == 0) then
            start = i
         end if
      end do
      if (start > 0) call add_token(list, text(start:))
   end subroutine split_values

   !> Append `token`, or `r` copies of `c` for `r*c`.
   subroutine add_token(list, token)
      type(token_list_t), intent(inout) :: list
      character(len=*), intent(in) :: token
      integer :: star, repeats, ios, r
      star = index(token, '*')
      repeats = 1
      if (star > 1 .and. .not. is_quoted(token)) then
         if (verify(token(1:star - 1), '0123456789') == 0) then
            read (token(1:star - 1), *, iostat=ios) repeats
            if (ios == 0) then
               do r = 1, repeats
                  call push(list, token(star + 1:))
               end do
               return
            end if
         end if
      end if
      call push(list, token)
   end subroutine add_token

   subroutine push(list, token)
      type(token_list_t), intent(inout) :: list
      character(len=*), intent(in) :: token
      type(token_t), allocatable :: grown(:)
      if (list%n == size(list%tokens)) then
         allocate (grown(2*list%n))
         grown(1:list%n) = list%tokens(1:list%n)
         call move_alloc(grown, list%tokens)
      end if
      list%n = list%n + 1
      list%tokens(list%n)%text = token
   end subroutine push
end module scene_comparison
