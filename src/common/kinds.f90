!> Working precisions of Flotsam: one place decides them (style.md, lesson 3).
module kinds
   use, intrinsic :: iso_fortran_env, only: real64, int32, int64
   implicit none
   private

   !> Real kind of every floating-point quantity.
   integer, parameter, public :: rp = real64
   !> Integer kind for local counts and indices.
   integer, parameter, public :: ip = int32
   !> Integer kind for global particle counts, particle ids and HDF5 offsets.
   integer, parameter, public :: i8 = int64

   !> Length of file paths and of error messages.
   integer, parameter, public :: path_len = 512
   integer, parameter, public :: message_len = 1024
   !> Length of short identifiers (material names, model keywords).
   integer, parameter, public :: name_len = 32
end module kinds
