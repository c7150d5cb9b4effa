!> Reproducible pseudo-random numbers and particle orders for tests: the same on every compiler, rank and run.
module reproducible_numbers
   use kinds, only: rp, i8
   implicit none
   private

   !> A pseudo-random number in [0, 1) from an integer (the fractional part of a scaled sine), of a default
   !> or an 8-byte integer (a particle id): the same number for the same value.
   interface hash01
      module procedure hash01_default, hash01_i8
   end interface hash01

   public :: hash01, mirror_swaps

contains

   pure real(rp) function hash01_default(i)
      integer, intent(in) :: i
      hash01_default = hash01_i8(int(i, i8))
   end function hash01_default

   pure real(rp) function hash01_i8(i)
      integer(i8), intent(in) :: i
      hash01_i8 = modulo(sin(real(i, rp) * 12.9898_rp) * 43758.5453_rp, 1.0_rp)
   end function hash01_i8

   !> A permutation of 1..n (dest(p): the new place of p, as particle_set's permute takes it) that swaps every
   !> step-th place from `first` on in the first half with its mirror n + 1 - p: a set sorted by cell then
   !> meets some cells in several runs.
   pure function mirror_swaps(n, first, step) result(dest)
      integer, intent(in) :: n, first, step
      integer :: dest(n), p
      dest = [(p, p = 1, n)]
      do p = first, n / 2, step
         dest(p) = n + 1 - p
         dest(n + 1 - p) = p
      end do
   end function mirror_swaps
end module reproducible_numbers
