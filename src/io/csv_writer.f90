!> A CSV file written row by row and flushed after each row, so a killed run leaves whole rows only.
module csv_writer
   use error_status, only: status_t
   implicit none
   private

   type, public :: csv_writer_t
      integer :: unit = 0
      logical :: is_open = .false.    !< newunit= numbers are negative: track the state separately
   contains
      procedure :: open => csv_open
      procedure :: write_row => csv_write_row
      procedure :: close => csv_close
   end type csv_writer_t

contains

   subroutine csv_open(self, path, header, status)
      class(csv_writer_t), intent(inout) :: self
      character(len=*), intent(in) :: path, header
      type(status_t), intent(inout) :: status
      integer :: ios
      character(len=256) :: msg
      open (newunit=self%unit, file=path, status='replace', action='write', iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call status%fail('cannot open '//trim(path)//': '//trim(msg))
         return
      end if
      self%is_open = .true.
      call self%write_row(header)
   end subroutine csv_open

   subroutine csv_write_row(self, line)
      class(csv_writer_t), intent(inout) :: self
      character(len=*), intent(in) :: line
      if (.not. self%is_open) return
      write (self%unit, '(a)') line
      flush (self%unit)
   end subroutine csv_write_row

   subroutine csv_close(self)
      class(csv_writer_t), intent(inout) :: self
      if (self%is_open) close (self%unit)
      self%is_open = .false.
   end subroutine csv_close
end module csv_writer
