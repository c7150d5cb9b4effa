!> Memory of this process as the Linux kernel reports it in /proc/self/status (0 where it cannot be
!> read: another OS, or a restricted /proc), and the memory still available to it: the node's
!> MemAvailable (/proc/meminfo), the room left under a cgroup limit (v2 memory.max - memory.current,
!> v1 memory.limit_in_bytes - memory.usage_in_bytes) and under the address-space limit of `ulimit -v`
!> (/proc/self/limits, minus VmSize). -1 stands for "no such limit" or "cannot be read".
module process_memory
   use kinds, only: i8
   implicit none
   private

   public :: resident_bytes, peak_resident_bytes, virtual_bytes
   public :: meminfo_available_bytes, cgroup_room_bytes, address_space_room_bytes, file_number, field_bytes

   !> Limits at or above this mean "no limit" (cgroup v1 writes 2^63 - 4096 for none).
   integer(i8), parameter :: no_limit = 2_i8**60

contains

   !> Resident set now (VmRSS) [bytes].
   integer(i8) function resident_bytes()
      resident_bytes = status_field_bytes('VmRSS:')
   end function resident_bytes

   !> Largest resident set so far (VmHWM, the high-water mark) [bytes].
   integer(i8) function peak_resident_bytes()
      peak_resident_bytes = status_field_bytes('VmHWM:')
   end function peak_resident_bytes

   !> Address space in use (VmSize) [bytes].
   integer(i8) function virtual_bytes()
      virtual_bytes = status_field_bytes('VmSize:')
   end function virtual_bytes

   !> The value of a `Name:   1234 kB` line of /proc/self/status, in bytes.
   integer(i8) function status_field_bytes(field) result(bytes)
      character(len=*), intent(in) :: field
      bytes = max(0_i8, field_bytes('/proc/self/status', field))
   end function status_field_bytes

   !> The value of a `Name:   1234 kB` line of file `path` in bytes; -1 if there is none.
   integer(i8) function field_bytes(path, field) result(bytes)
      character(len=*), intent(in) :: path, field
      character(len=:), allocatable :: value
      integer(i8) :: kib
      integer :: ios
      bytes = -1
      if (.not. line_after(path, field, value)) return
      read (value, *, iostat=ios) kib
      if (ios == 0) bytes = 1024_i8 * kib
   end function field_bytes

   !> The rest of the first line of file `path` that starts with `field`; false if the file cannot be
   !> read or has no such line.
   logical function line_after(path, field, value) result(found)
      character(len=*), intent(in) :: path, field
      character(len=:), allocatable, intent(out) :: value
      integer :: unit, ios
      character(len=256) :: line
      found = .false.
      value = ''
      open (newunit=unit, file=path, action='read', status='old', iostat=ios)
      if (ios /= 0) return
      do
         read (unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:len(field)) == field) then
            value = trim(line(len(field) + 1:))
            found = .true.
            exit
         end if
      end do
      close (unit)
   end function line_after

   !> The number a file holds on its first line (as cgroup files do); -1 if it holds none ('max').
   integer(i8) function file_number(path) result(number)
      character(len=*), intent(in) :: path
      integer :: unit, ios
      character(len=64) :: line
      number = -1
      open (newunit=unit, file=path, action='read', status='old', iostat=ios)
      if (ios /= 0) return
      read (unit, '(a)', iostat=ios) line
      close (unit)
      if (ios /= 0) return
      read (line, *, iostat=ios) number
      if (ios /= 0) number = -1
   end function file_number

   !> MemAvailable of `meminfo` (default /proc/meminfo): what the node can give without swapping [bytes].
   integer(i8) function meminfo_available_bytes(meminfo) result(bytes)
      character(len=*), intent(in), optional :: meminfo
      if (present(meminfo)) then
         bytes = field_bytes(meminfo, 'MemAvailable:')
      else
         bytes = field_bytes('/proc/meminfo', 'MemAvailable:')
      end if
   end function meminfo_available_bytes

   !> Room left under the cgroup memory limit of `root` (default /sys/fs/cgroup: the process's own
   !> group inside a container or a batch job's cgroup namespace): v2 memory.max - memory.current, else v1
   !> memory/memory.limit_in_bytes - memory/memory.usage_in_bytes; -1 without a limit [bytes].
   integer(i8) function cgroup_room_bytes(root) result(bytes)
      character(len=*), intent(in), optional :: root
      character(len=:), allocatable :: dir
      integer(i8) :: limit
      dir = '/sys/fs/cgroup'
      if (present(root)) dir = root
      bytes = -1
      limit = file_number(dir//'/memory.max')
      if (limit >= 0 .and. limit < no_limit) then
         bytes = max(0_i8, limit - max(0_i8, file_number(dir//'/memory.current')))
         return
      end if
      limit = file_number(dir//'/memory/memory.limit_in_bytes')
      if (limit >= 0 .and. limit < no_limit) &
         bytes = max(0_i8, limit - max(0_i8, file_number(dir//'/memory/memory.usage_in_bytes')))
   end function cgroup_room_bytes

   !> Room left under this process's address-space limit (`ulimit -v`, the soft `Max address space` of
   !> `limits`, default /proc/self/limits) minus its VmSize; -1 when unlimited [bytes].
   integer(i8) function address_space_room_bytes(limits) result(bytes)
      character(len=*), intent(in), optional :: limits
      character(len=:), allocatable :: path, value
      character(len=32) :: soft
      integer :: ios
      integer(i8) :: limit
      path = '/proc/self/limits'
      if (present(limits)) path = limits
      bytes = -1
      if (.not. line_after(path, 'Max address space', value)) return
      read (value, *, iostat=ios) soft
      if (ios /= 0 .or. soft == 'unlimited') return
      read (soft, *, iostat=ios) limit
      if (ios == 0 .and. limit < no_limit) bytes = max(0_i8, limit - virtual_bytes())
   end function address_space_room_bytes
end module process_memory
