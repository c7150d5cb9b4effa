!> A text pre-scan of a namelist file. gfortran silently skips every group it is not asked for, so a
!> misspelt group (`&materal`) or text outside any group would be ignored; the scan finds every group
!> with its lines, rejects unknown group names, and splits each group into its `name = value` items,
!> which the reader uses to name the variable behind a read error and to see which variables a group
!> assigns. Comments (`!`) and quoted strings are honoured as the namelist reader does.
module namelist_scan
   use, intrinsic :: iso_fortran_env, only: iostat_end, iostat_eor
   use error_status, only: status_t
   use input_text, only: lower_case, int_text, keyword_index
   implicit none
   private

   public :: scan_namelist_file, scan_namelist_text

   !> One `designator = values` of a group, comments removed.
   type, public :: namelist_item_t
      character(len=:), allocatable :: name        !< variable name in lower case, without subscript
      character(len=:), allocatable :: designator  !< as written, e.g. `origin(2)`; '' for stray text
      character(len=:), allocatable :: value       !< value text as written
      integer :: line = 0                          !< line of the designator
   contains
      procedure :: text => item_text
   end type namelist_item_t

   !> One occurrence of a group: `&name ... /`.
   type, public :: namelist_group_t
      character(len=:), allocatable :: name        !< group name in lower case
      integer :: first_line = 0
      integer :: last_line = 0
      type(namelist_item_t), allocatable :: items(:)
   contains
      procedure :: assigns => group_assigns
      procedure :: text => group_text
   end type namelist_group_t

   !> All groups of a file, in file order.
   type, public :: namelist_file_t
      character(len=:), allocatable :: path
      type(namelist_group_t), allocatable :: groups(:)
   contains
      procedure :: count => file_count
      procedure :: find => file_find
   end type namelist_file_t

   type :: line_t
      character(len=:), allocatable :: text
   end type line_t

   !> Text of the group being collected, with the line of every character.
   type :: group_text_t
      character(len=:), allocatable :: text
      integer, allocatable :: line_of(:)
      integer :: length = 0
   end type group_text_t

contains

   !> `designator = value`, as it can be fed back to a namelist read on its own.
   function item_text(self) result(text)
      class(namelist_item_t), intent(in) :: self
      character(len=:), allocatable :: text
      if (len(self%designator) > 0) then
         text = self%designator//' = '//self%value
      else
         text = self%value
      end if
   end function item_text

   !> The group as one line `&name item, item, /` (comments removed), as a namelist read of an
   !> internal file takes it.
   function group_text(self) result(text)
      class(namelist_group_t), intent(in) :: self
      character(len=:), allocatable :: text
      integer :: i
      text = '&'//self%name
      do i = 1, size(self%items)
         text = text//' '//self%items(i)%text()//','
      end do
      text = text//' /'
   end function group_text

   !> Does this group assign variable `name` (whole or in part)?
   logical function group_assigns(self, name) result(assigns)
      class(namelist_group_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer :: i
      assigns = .false.
      do i = 1, size(self%items)
         if (self%items(i)%name == lower_case(name)) assigns = .true.
      end do
   end function group_assigns

   !> Number of occurrences of group `name`.
   integer function file_count(self, name) result(n)
      class(namelist_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer :: g
      n = 0
      do g = 1, size(self%groups)
         if (self%groups(g)%name == lower_case(name)) n = n + 1
      end do
   end function file_count

   !> Index in `groups` of the `occurrence`-th group `name`; 0 if there are fewer.
   integer function file_find(self, name, occurrence) result(found)
      class(namelist_file_t), intent(in) :: self
      character(len=*), intent(in) :: name
      integer, intent(in) :: occurrence
      integer :: g, seen
      found = 0
      seen = 0
      do g = 1, size(self%groups)
         if (self%groups(g)%name /= lower_case(name)) cycle
         seen = seen + 1
         if (seen == occurrence) then
            found = g
            return
         end if
      end do
   end function file_find

   !> Read the whole file open on `unit` (rewound before and after) and list its groups.
   !> Fails, naming `path` and the line, on an unknown group name, a group without its closing `/`,
   !> or text outside any group that is not a `!` comment.
   subroutine scan_namelist_file(unit, path, known_groups, file, status)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: known_groups(:)
      type(namelist_file_t), intent(out) :: file
      type(status_t), intent(inout) :: status
      type(line_t), allocatable :: lines(:)
      integer :: nlines

      file%path = path
      allocate (file%groups(0))
      call read_lines(unit, path, lines, nlines, status)
      if (.not. status%ok) return
      call find_groups(lines(1:nlines), path, known_groups, file, status)
      rewind (unit)
   end subroutine scan_namelist_file

   !> The same scan of namelist text held in memory, lines separated by new_line('a') (e.g. the scene
   !> stored in a checkpoint); `label` names it in messages.
   subroutine scan_namelist_text(text, label, known_groups, file, status)
      character(len=*), intent(in) :: text
      character(len=*), intent(in) :: label
      character(len=*), intent(in) :: known_groups(:)
      type(namelist_file_t), intent(out) :: file
      type(status_t), intent(inout) :: status
      type(line_t), allocatable :: lines(:)
      integer :: start, break, l

      file%path = label
      allocate (file%groups(0))
      allocate (lines(count([(text(l:l) == new_line('a'), l = 1, len(text))]) + 1))
      start = 1
      do l = 1, size(lines)
         break = index(text(start:), new_line('a'))
         if (break == 0) then
            lines(l)%text = text(start:)
         else
            lines(l)%text = text(start:start + break - 2)
            start = start + break
         end if
      end do
      call find_groups(lines, label, known_groups, file, status)
   end subroutine scan_namelist_text

   subroutine read_lines(unit, path, lines, nlines, status)
      integer, intent(in) :: unit
      character(len=*), intent(in) :: path
      type(line_t), allocatable, intent(out) :: lines(:)
      integer, intent(out) :: nlines
      type(status_t), intent(inout) :: status
      type(line_t), allocatable :: grown(:)
      character(len=256) :: chunk
      character(len=:), allocatable :: line
      character(len=512) :: message
      integer :: ios, nread

      allocate (lines(64))
      nlines = 0
      rewind (unit)
      line = ''
      do
         read (unit, '(a)', advance='no', iostat=ios, iomsg=message, size=nread) chunk
         if (ios == 0 .or. ios == iostat_eor) line = line//chunk(1:nread)
         if (ios == 0) cycle
         if (ios > 0) then
            call status%fail(trim(path)//': line '//int_text(nlines + 1)//': cannot read the scene file: '//trim(message))
            return
         end if
         ! End of a record, or end of file after a last line without a line break.
         if (ios == iostat_eor .or. len(line) > 0) then
            if (nlines == size(lines)) then
               allocate (grown(2*nlines))
               grown(1:nlines) = lines
               call move_alloc(grown, lines)
            end if
            nlines = nlines + 1
            lines(nlines)%text = line
            line = ''
         end if
         if (ios == iostat_end) exit
      end do
   end subroutine read_lines

   subroutine find_groups(lines, path, known_groups, file, status)
      type(line_t), intent(in) :: lines(:)
      character(len=*), intent(in) :: path
      character(len=*), intent(in) :: known_groups(:)
      type(namelist_file_t), intent(inout) :: file
      type(status_t), intent(inout) :: status
      type(group_text_t) :: body
      character(len=:), allocatable :: name, where
      character(len=1) :: c, quote
      logical :: inside
      integer :: l, i, n, name_end

      inside = .false.
      quote = ' '
      do l = 1, size(lines)
         associate (text => lines(l)%text)
            n = len(text)
            where = trim(path)//': line '//int_text(l)//': '
            i = 1
            do while (i <= n)
               c = text(i:i)
               if (quote /= ' ') then
                  ! Inside a quoted string: a doubled quote stands for one quote character.
                  call append(body, c, l)
                  if (c == quote) then
                     if (i < n) then
                        if (text(i + 1:i + 1) == quote) then
                           call append(body, quote, l)
                           i = i + 2
                           cycle
                        end if
                     end if
                     quote = ' '
                  else if (c == '&' .or. c == '$') then
                     ! gfortran looks for a group start character by character, strings included.
                     name_end = name_length(text(i + 1:))
                     if (name_end > 0) then
                        if (keyword_index(text(i + 1:i + name_end), known_groups) > 0) then
                           call status%fail(where//"'"//text(i:i + name_end)//"' inside a quoted string would be "// &
                                            'taken for the start of a group; remove the '//c)
                           return
                        end if
                     end if
                  end if
               else if (c == '!') then
                  exit
               else if (is_blank(c)) then
                  if (inside) call append_blank(body, l)
               else if (c == '&' .or. c == '$') then
                  name_end = name_length(text(i + 1:))
                  name = lower_case(text(i + 1:i + name_end))
                  if (inside .and. name == 'end') then
                     if (.not. ends_name(text, i + 1 + name_end)) then
                        call status%fail(where//"unexpected '"//text(i:min(n, i + 1 + name_end))//"'")
                        return
                     end if
                     call close_group(file, body, l)
                     inside = .false.
                     i = i + 1 + name_end
                     cycle
                  else if (inside) then
                     call status%fail(where//'group &'//file%groups(size(file%groups))%name// &
                                      ' (line '//int_text(file%groups(size(file%groups))%first_line)// &
                                      ') is not closed with / before '//text(i:i + name_end))
                     return
                  else if (name_end == 0) then
                     call status%fail(where//"'"//c//"' not followed by a group name")
                     return
                  else if (keyword_index(name, known_groups) == 0) then
                     call status%fail(where//'unknown group &'//text(i + 1:i + name_end)//' (known groups: '// &
                                      known_list(known_groups)//')')
                     return
                  else if (.not. ends_name(text, i + 1 + name_end)) then
                     call status%fail(where//'group name &'//name//' must be followed by a blank or a line break')
                     return
                  end if
                  call open_group(file, body, name, l)
                  inside = .true.
                  i = i + 1 + name_end
                  cycle
               else if (.not. inside) then
                  call status%fail(where//"text outside of any group: '"//trim(adjustl(text(i:)))// &
                                   "' (comments start with !)")
                  return
               else if (c == '/') then
                  call close_group(file, body, l)
                  inside = .false.
               else
                  if (c == '''' .or. c == '"') quote = c
                  call append(body, c, l)
               end if
               i = i + 1
            end do
            if (inside .and. quote == ' ') call append_blank(body, l)
         end associate
      end do
      if (inside) then
         call status%fail(trim(path)//': group &'//file%groups(size(file%groups))%name//' (line '// &
                          int_text(file%groups(size(file%groups))%first_line)//') is not closed with /')
      end if
   end subroutine find_groups

   pure logical function is_blank(c)
      character(len=1), intent(in) :: c
      is_blank = c == ' ' .or. c == achar(9) .or. c == achar(13)
   end function is_blank

   pure logical function is_name_character(c)
      character(len=1), intent(in) :: c
      is_name_character = verify(lower_case(c), 'abcdefghijklmnopqrstuvwxyz0123456789_') == 0
   end function is_name_character

   !> Length of the name that starts `text` (a letter, then letters, digits, underscores).
   pure integer function name_length(text) result(n)
      character(len=*), intent(in) :: text
      n = 0
      if (len(text) == 0) return
      if (verify(lower_case(text(1:1)), 'abcdefghijklmnopqrstuvwxyz') /= 0) return
      do n = 1, len(text)
         if (.not. is_name_character(text(n:n))) exit
      end do
      n = n - 1
   end function name_length

   !> Is position `after` of `text` past a name's end: a blank, a comment or the end of the line?
   pure logical function ends_name(text, after)
      character(len=*), intent(in) :: text
      integer, intent(in) :: after
      ends_name = after > len(text)
      if (.not. ends_name) ends_name = is_blank(text(after:after)) .or. text(after:after) == '!'
   end function ends_name

   function known_list(known_groups) result(text)
      character(len=*), intent(in) :: known_groups(:)
      character(len=:), allocatable :: text
      integer :: g
      text = ''
      do g = 1, size(known_groups)
         if (g > 1) text = text//', '
         text = text//'&'//trim(known_groups(g))
      end do
   end function known_list

   subroutine append(body, c, line)
      type(group_text_t), intent(inout) :: body
      character(len=1), intent(in) :: c
      integer, intent(in) :: line
      character(len=:), allocatable :: text
      integer, allocatable :: line_of(:)
      if (body%length == len(body%text)) then
         allocate (character(len=2*body%length + 64) :: text)
         allocate (line_of(2*body%length + 64))
         text(1:body%length) = body%text(1:body%length)
         line_of(1:body%length) = body%line_of(1:body%length)
         call move_alloc(text, body%text)
         call move_alloc(line_of, body%line_of)
      end if
      body%length = body%length + 1
      body%text(body%length:body%length) = c
      body%line_of(body%length) = line
   end subroutine append

   !> A separator blank; runs of blanks, comments and line breaks between values become one blank.
   subroutine append_blank(body, line)
      type(group_text_t), intent(inout) :: body
      integer, intent(in) :: line
      if (body%length > 0) then
         if (body%text(body%length:body%length) == ' ') return
      end if
      call append(body, ' ', line)
   end subroutine append_blank

   subroutine open_group(file, body, name, line)
      type(namelist_file_t), intent(inout) :: file
      type(group_text_t), intent(out) :: body
      character(len=*), intent(in) :: name
      integer, intent(in) :: line
      type(namelist_group_t), allocatable :: grown(:)
      integer :: n
      n = size(file%groups)
      allocate (grown(n + 1))
      grown(1:n) = file%groups
      grown(n + 1)%name = name
      grown(n + 1)%first_line = line
      call move_alloc(grown, file%groups)
      allocate (character(len=64) :: body%text)
      allocate (body%line_of(64))
      body%length = 0
   end subroutine open_group

   subroutine close_group(file, body, line)
      type(namelist_file_t), intent(inout) :: file
      type(group_text_t), intent(in) :: body
      integer, intent(in) :: line
      associate (group => file%groups(size(file%groups)))
         group%last_line = line
         call split_items(body, group%items)
      end associate
   end subroutine close_group

   !> Split a group's text into `designator = values` items. A designator is the name (with an
   !> optional subscript) in front of an `=` that is outside quotes and parentheses.
   subroutine split_items(body, items)
      type(group_text_t), intent(in) :: body
      type(namelist_item_t), allocatable, intent(out) :: items(:)
      integer, allocatable :: starts(:), equals(:)
      character(len=1) :: c, quote
      logical :: doubled
      integer :: i, j, depth, n, last, start

      associate (text => body%text(1:body%length))
         n = len(text)
         allocate (starts(0), equals(0))
         quote = ' '
         depth = 0
         i = 1
         do while (i <= n)
            c = text(i:i)
            if (quote /= ' ') then
               if (c == quote) then
                  doubled = .false.
                  if (i < n) doubled = text(i + 1:i + 1) == quote
                  if (doubled) then
                     i = i + 1
                  else
                     quote = ' '
                  end if
               end if
            else if (c == '''' .or. c == '"') then
               quote = c
            else if (c == '(') then
               depth = depth + 1
            else if (c == ')') then
               depth = max(0, depth - 1)
            else if (c == '=' .and. depth == 0) then
               starts = [starts, designator_start(text, i)]
               equals = [equals, i]
            end if
            i = i + 1
         end do

         allocate (items(0))
         ! Text in front of the first designator is not an assignment.
         last = n
         if (size(starts) > 0) last = starts(1) - 1
         if (len_trim(text(1:last)) > 0) then
            start = verify(text(1:last), ' ')
            call add_item(items, '', trim_value(text(start:last)), body%line_of(start))
         end if
         do j = 1, size(starts)
            last = n
            if (j < size(starts)) last = starts(j + 1) - 1
            call add_item(items, trim(adjustl(text(starts(j):equals(j) - 1))), trim_value(text(equals(j) + 1:last)), &
                          body%line_of(starts(j)))
         end do
      end associate
   end subroutine split_items

   subroutine add_item(items, designator, value, line)
      type(namelist_item_t), allocatable, intent(inout) :: items(:)
      character(len=*), intent(in) :: designator, value
      integer, intent(in) :: line
      type(namelist_item_t), allocatable :: grown(:)
      integer :: n
      n = size(items)
      allocate (grown(n + 1))
      grown(1:n) = items
      grown(n + 1)%designator = designator
      grown(n + 1)%name = lower_case(base_name(designator))
      grown(n + 1)%value = value
      grown(n + 1)%line = line
      call move_alloc(grown, items)
   end subroutine add_item

   !> Start of the designator that ends in front of the `=` at `equals`: blanks, an optional
   !> parenthesised subscript, then name characters and `%`, read backwards.
   pure integer function designator_start(text, equals) result(start)
      character(len=*), intent(in) :: text
      integer, intent(in) :: equals
      integer :: i, depth
      i = equals - 1
      do while (i >= 1)
         if (text(i:i) /= ' ') exit
         i = i - 1
      end do
      if (i >= 1) then
         if (text(i:i) == ')') then
            depth = 0
            do while (i >= 1)
               if (text(i:i) == ')') depth = depth + 1
               if (text(i:i) == '(') depth = depth - 1
               i = i - 1
               if (depth == 0) exit
            end do
         end if
      end if
      do while (i >= 1)
         if (.not. (is_name_character(text(i:i)) .or. text(i:i) == '%')) exit
         i = i - 1
      end do
      start = i + 1
   end function designator_start

   pure function base_name(designator) result(name)
      character(len=*), intent(in) :: designator
      character(len=:), allocatable :: name
      integer :: cut
      name = trim(adjustl(designator))
      cut = scan(name, '(%')
      if (cut > 0) name = trim(name(1:cut - 1))
   end function base_name

   !> Value text without surrounding blanks and without the separating comma in front of the next item.
   pure function trim_value(text) result(value)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: value
      value = trim(adjustl(text))
      if (len(value) > 0) then
         if (value(len(value):len(value)) == ',') value = trim(value(1:len(value) - 1))
      end if
   end function trim_value
end module namelist_scan
