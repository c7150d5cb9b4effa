!> Particle arrays that cannot grow (src/particles/particle_set.f90): the failure is recorded with a
!> message, the particles held are kept, and later adds are dropped, instead of a runtime error. The
!> test caps its own address space (setrlimit RLIMIT_AS, as `ulimit -v` does) so that the growth fails
!> on any machine.
module test_particle_memory
   use, intrinsic :: iso_c_binding, only: c_int, c_long
   use kinds, only: rp, i8
   use particle_set, only: particle_set_t
   use process_memory, only: virtual_bytes
   use assertions, only: assertEqual, assertTrue, assertFalse
   implicit none
   private

   public :: test_growth_without_memory_is_reported

   integer(c_int), parameter :: rlimit_as = 9      ! Linux <sys/resource.h>

   type, bind(c) :: rlimit_t
      integer(c_long) :: current, maximum
   end type rlimit_t

   interface
      integer(c_int) function getrlimit(resource, limit) bind(c, name='getrlimit')
         import :: c_int, rlimit_t
         integer(c_int), value :: resource
         type(rlimit_t), intent(out) :: limit
      end function getrlimit
      integer(c_int) function setrlimit(resource, limit) bind(c, name='setrlimit')
         import :: c_int, rlimit_t
         integer(c_int), value :: resource
         type(rlimit_t), intent(in) :: limit
      end function setrlimit
   end interface

contains

   subroutine test_growth_without_memory_is_reported()
      type(particle_set_t) :: particles
      type(rlimit_t) :: limit
      integer :: p
      real(rp) :: sbar(4)
      sbar = 0.0_rp
      call particles%init(2, 1, 16)
      do p = 1, 10
         call particles%add([real(p, rp), 0.0_rp], [0.0_rp, 0.0_rp], 1.0_rp, 1000.0_rp, sbar, 1, int(p, i8))
      end do
      call assertTrue(particles%allocation%ok, 'room for 10 particles')

      ! 512 MB more address space than now: 100 million particles (about 10 GB of arrays) cannot fit
      call assertEqual(0, int(getrlimit(rlimit_as, limit)), 'getrlimit')
      limit%current = int(virtual_bytes() + 512_i8 * 1024_i8**2, c_long)
      call assertEqual(0, int(setrlimit(rlimit_as, limit)), 'setrlimit')
      call particles%reserve(100000000)
      call assertFalse(particles%allocation%ok, 'the failed growth is recorded')
      call assertTrue(index(particles%allocation%message, 'no memory for 100000000 particles') > 0, &
                      'the message names the count: '//trim(particles%allocation%message))
      call assertEqual(10, particles%count, 'the particles held are kept')
      call assertEqual(7.0_rp, particles%x(1, 7), 0.0_rp, 'their state is intact')
      call particles%add([1.0_rp, 0.0_rp], [0.0_rp, 0.0_rp], 1.0_rp, 1000.0_rp, sbar, 1, 11_i8)
      call assertEqual(10, particles%count, 'a later add is dropped')
   end subroutine test_growth_without_memory_is_reported
end module test_particle_memory
