!> The memory figures of src/common/process_memory.f90, read from files written here in the layout of
!> /proc/meminfo, a cgroup v2 or v1 folder and /proc/self/limits.
module test_process_memory
   use kinds, only: i8
   use process_memory, only: meminfo_available_bytes, cgroup_room_bytes, address_space_room_bytes, virtual_bytes
   use assertions, only: assertEqual, assertTrue
   implicit none
   private

   public :: test_meminfo_available, test_cgroup_v2_room, test_cgroup_v1_room, test_no_cgroup_limit, &
             test_address_space_limit

contains

   subroutine write_lines(path, lines)
      character(len=*), intent(in) :: path, lines(:)
      integer :: unit, i
      open (newunit=unit, file=path, status='replace', action='write')
      do i = 1, size(lines)
         write (unit, '(a)') trim(lines(i))
      end do
      close (unit)
   end subroutine write_lines

   subroutine test_meminfo_available()
      call write_lines('meminfo', [character(len=40) :: 'MemTotal:       24683620 kB', &
                                   'MemFree:        22757952 kB', 'MemAvailable:   24095916 kB'])
      call assertEqual(24095916_i8 * 1024_i8, meminfo_available_bytes('meminfo'), 'MemAvailable in bytes')
      call assertEqual(-1_i8, meminfo_available_bytes('no_such_meminfo'), 'no file: unknown')
      call assertTrue(meminfo_available_bytes() > 0, 'this machine has some')
   end subroutine test_meminfo_available

   subroutine test_cgroup_v2_room()
      call execute_command_line('mkdir -p cgroup_v2')
      call write_lines('cgroup_v2/memory.max', ['4294967296'])
      call write_lines('cgroup_v2/memory.current', ['1073741824'])
      call assertEqual(3221225472_i8, cgroup_room_bytes('cgroup_v2'), 'memory.max - memory.current')
   end subroutine test_cgroup_v2_room

   subroutine test_cgroup_v1_room()
      call execute_command_line('mkdir -p cgroup_v1/memory')
      call write_lines('cgroup_v1/memory/memory.limit_in_bytes', ['2147483648'])
      call write_lines('cgroup_v1/memory/memory.usage_in_bytes', ['536870912'])
      call assertEqual(1610612736_i8, cgroup_room_bytes('cgroup_v1'), 'limit_in_bytes - usage_in_bytes')
   end subroutine test_cgroup_v1_room

   subroutine test_no_cgroup_limit()
      call execute_command_line('mkdir -p cgroup_max cgroup_none/memory')
      call write_lines('cgroup_max/memory.max', ['max'])
      call write_lines('cgroup_max/memory.current', ['1073741824'])
      call assertEqual(-1_i8, cgroup_room_bytes('cgroup_max'), "v2 'max': no limit")
      call write_lines('cgroup_none/memory/memory.limit_in_bytes', ['9223372036854771712'])
      call assertEqual(-1_i8, cgroup_room_bytes('cgroup_none'), 'v1 2^63 - 4096: no limit')
      call assertEqual(-1_i8, cgroup_room_bytes('no_such_cgroup'), 'no files: no limit')
   end subroutine test_no_cgroup_limit

   subroutine test_address_space_limit()
      character(len=100) :: line
      call write_lines('limits_unlimited', [character(len=80) :: &
                       'Limit                     Soft Limit           Hard Limit           Units', &
                       'Max address space         unlimited            unlimited            bytes'])
      call assertEqual(-1_i8, address_space_room_bytes('limits_unlimited'), 'unlimited')
      write (line, '(a,i0,a)') 'Max address space         ', virtual_bytes() + 1000000000_i8, '           unlimited  bytes'
      call write_lines('limits_set', [character(len=80) :: &
                       'Limit                     Soft Limit           Hard Limit           Units', line])
      ! the limit less what the process uses (which grows a little between the two readings)
      call assertTrue(abs(address_space_room_bytes('limits_set') - 1000000000_i8) < 50000000_i8, &
                      'limit - VmSize')
   end subroutine test_address_space_limit
end module test_process_memory
