!> The few POSIX file-system calls Fortran lacks (existence of a folder, creating one, renaming and
!> removing files), via the C library.
module file_system
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
   implicit none
   private

   public :: path_exists, make_directory, rename_path, remove_file

   interface
      function c_access(path, mode) bind(c, name='access') result(r)
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: mode
         integer(c_int) :: r
      end function c_access
      function c_mkdir(path, mode) bind(c, name='mkdir') result(r)
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: mode
         integer(c_int) :: r
      end function c_mkdir
      function c_rename(old_path, new_path) bind(c, name='rename') result(r)
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: old_path(*), new_path(*)
         integer(c_int) :: r
      end function c_rename
      function c_remove(path) bind(c, name='remove') result(r)
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: r
      end function c_remove
   end interface

   integer(c_int), parameter :: f_ok = 0, w_ok = 2

contains

   !> True if a file or folder exists at `path`.
   logical function path_exists(path)
      character(len=*), intent(in) :: path
      path_exists = c_access(trim(path)//c_null_char, f_ok) == 0
   end function path_exists

   !> Create `path` and any missing parents (like mkdir -p). Returns .false. on failure or if the
   !> result is not writable.
   logical function make_directory(path) result(ok)
      character(len=*), intent(in) :: path
      integer :: i, r
      character(len=len_trim(path)) :: p
      p = trim(path)
      do i = 2, len(p)
         if (p(i:i) == '/' .and. p(i - 1:i - 1) /= '/') then
            if (.not. path_exists(p(1:i - 1))) r = c_mkdir(p(1:i - 1)//c_null_char, int(o'755', c_int))
         end if
      end do
      if (.not. path_exists(p)) r = c_mkdir(p//c_null_char, int(o'755', c_int))
      ok = c_access(p//c_null_char, w_ok) == 0
   end function make_directory

   !> Rename `old_path` to `new_path`, replacing it atomically if it exists (POSIX rename). True on success.
   logical function rename_path(old_path, new_path) result(ok)
      character(len=*), intent(in) :: old_path, new_path
      ok = c_rename(trim(old_path)//c_null_char, trim(new_path)//c_null_char) == 0
   end function rename_path

   !> Remove the file `path`; true if it is gone afterwards (also when it did not exist).
   logical function remove_file(path) result(ok)
      character(len=*), intent(in) :: path
      integer(c_int) :: r
      if (.not. path_exists(path)) then
         ok = .true.
         return
      end if
      r = c_remove(trim(path)//c_null_char)
      ok = .not. path_exists(path)
   end function remove_file
end module file_system
