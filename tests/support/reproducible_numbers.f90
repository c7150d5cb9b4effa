!> Reproducible pseudo-random numbers for tests: the same on every compiler, rank and run.
module reproducible_numbers
   use kinds, only: rp, i8
   implicit none
   private

   !> A pseudo-random number in [0, 1) from an integer (the fractional part of a scaled sine), of a default
   !> or an 8-byte integer (a particle id): the same number for the same value.
   interface hash01
      module procedure hash01_default, hash01_i8
   end interface hash01

   public :: hash01

contains

   pure real(rp) function hash01_default(i)
      integer, intent(in) :: i
      hash01_default = hash01_i8(int(i, i8))
   end function hash01_default

   pure real(rp) function hash01_i8(i)
      integer(i8), intent(in) :: i
      hash01_i8 = modulo(sin(real(i, rp) * 12.9898_rp) * 43758.5453_rp, 1.0_rp)
   end function hash01_i8
end module reproducible_numbers
