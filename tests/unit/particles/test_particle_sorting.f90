!> The solver's decision to leave arrivals unsorted until the periodic sort (particle_sorting's
!> in_material_order): it holds exactly when the appended particles keep every material's particles
!> contiguous, and then set_material_ranges gives the ranges a full sort would.
module test_particle_sorting
   use kinds, only: rp, i8
   use particle_set, only: particle_set_t
   use particle_sorting, only: in_material_order, set_material_ranges
   use assertions, only: assertEqual, assertTrue, assertFalse
   implicit none
   private

   public :: test_appended_in_material_order, test_appended_out_of_material_order

contains

   !> 12 particles sorted by material (1 1 1 1 2 2 2 2 3 3 3 3), then `appended` added at the end.
   function sorted_then(appended) result(particles)
      integer, intent(in) :: appended(:)
      type(particle_set_t) :: particles
      integer :: p
      call particles%init(2, 3, 32)
      do p = 1, 12
         call add(1 + (p - 1) / 4)
      end do
      do p = 1, size(appended)
         call add(appended(p))
      end do
   contains
      subroutine add(material)
         integer, intent(in) :: material
         call particles%add([0.1_rp * particles%count, 0.5_rp], [0.0_rp, 0.0_rp], 1.0_rp, 1000.0_rp, &
                            [0.0_rp, 0.0_rp, 0.0_rp, 0.0_rp], material, int(particles%count + 1, i8))
      end subroutine add
   end function sorted_then

   !> Arrivals of the last material, or of it and none after, keep the slices: the ranges are those of
   !> the materials' particles, counted here independently.
   subroutine test_appended_in_material_order()
      type(particle_set_t) :: particles
      particles = sorted_then([3, 3])
      call assertTrue(in_material_order(particles, 12), 'two arrivals of the last material')
      call set_material_ranges(particles)
      call check_ranges(particles)
      ! the check may start before the arrivals (the solver starts at count - arrived)
      call assertTrue(in_material_order(particles, 1), 'the whole set in order')
      particles = sorted_then([integer ::])
      call assertTrue(in_material_order(particles, 12), 'no arrivals')
      call assertTrue(in_material_order(particles, 0), 'no arrivals, from before the start')
   end subroutine test_appended_in_material_order

   !> An arrival of an earlier material, or arrivals out of order among themselves, would split a slice.
   subroutine test_appended_out_of_material_order()
      type(particle_set_t) :: particles
      particles = sorted_then([2])
      call assertFalse(in_material_order(particles, 12), 'an arrival of material 2 after material 3')
      particles = sorted_then([3, 3, 1])
      call assertFalse(in_material_order(particles, 12), 'material 1 after the arrivals of 3')
      call assertFalse(in_material_order(particles, 13), 'the descent after the first arrival')
      call assertTrue(in_material_order(particles, 15), 'from the last particle: nothing to check')
   end subroutine test_appended_out_of_material_order

   subroutine check_ranges(particles)
      type(particle_set_t), intent(in) :: particles
      integer :: m, p, first, last
      do m = 1, 3
         first = huge(1)
         last = 0
         do p = 1, particles%count
            if (particles%material(p) /= m) cycle
            first = min(first, p)
            last = max(last, p)
         end do
         call assertEqual(first, particles%material_first(m), 'first of a material')
         call assertEqual(last, particles%material_last(m), 'last of a material')
         call assertEqual(last - first + 1, count(particles%material(1:particles%count) == m), 'contiguous')
      end do
   end subroutine check_ranges
end module test_particle_sorting
