!> Memory of this process as the Linux kernel reports it in /proc/self/status (0 where it cannot be
!> read: another OS, or a restricted /proc).
module process_memory
   use kinds, only: i8
   implicit none
   private

   public :: resident_bytes, peak_resident_bytes

contains

   !> Resident set now (VmRSS) [bytes].
   integer(i8) function resident_bytes()
      resident_bytes = status_field_bytes('VmRSS:')
   end function resident_bytes

   !> Largest resident set so far (VmHWM, the high-water mark) [bytes].
   integer(i8) function peak_resident_bytes()
      peak_resident_bytes = status_field_bytes('VmHWM:')
   end function peak_resident_bytes

   !> The value of a `Name:   1234 kB` line of /proc/self/status, in bytes.
   integer(i8) function status_field_bytes(field) result(bytes)
      character(len=*), intent(in) :: field
      integer :: unit, ios
      character(len=256) :: line
      integer(i8) :: kib
      bytes = 0
      open (newunit=unit, file='/proc/self/status', action='read', iostat=ios)
      if (ios /= 0) return
      do
         read (unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:len(field)) == field) then
            read (line(len(field) + 1:), *, iostat=ios) kib
            if (ios == 0) bytes = 1024_i8 * kib
            exit
         end if
      end do
      close (unit)
   end function status_field_bytes
end module process_memory
