!> The in-place permutation of the particle set (particle_set_t%permute, the sort's reorder) and its
!> growth: every persistent array follows its particle through fixed points, swaps and long cycles,
!> the destinations come back unchanged, and growth and fit keep the particles held.
module test_particle_permutation
   use kinds, only: rp, i8
   use particle_set, only: particle_set_t
   use assertions, only: assertEqual, assertTrue
   implicit none
   private

   public :: test_permute_in_place_2d_apic, test_permute_in_place_3d, test_growth_and_fit

contains

   subroutine test_permute_in_place_2d_apic()
      call check_permutation(2, .true.)
   end subroutine test_permute_in_place_2d_apic

   subroutine test_permute_in_place_3d()
      call check_permutation(3, .false.)
   end subroutine test_permute_in_place_3d

   !> Particle p carries values made from its id; after the permutation the particle in slot dest(p)
   !> must be particle p, whole.
   subroutine check_permutation(dim, affine)
      integer, intent(in) :: dim
      logical, intent(in) :: affine
      integer, parameter :: n = 50
      type(particle_set_t) :: particles
      integer :: p, dest(n), dest0(n), slot
      call particles%init(dim, 3, n, affine=affine, spin=.false.)
      call assertEqual(0, particles%n_spin, 'no spin when not asked for')
      do p = 1, n
         call add_particle(particles, dim, p)
         particles%cell(p) = 1000 + p
      end do
      ! fixed points (p = 1, 10, 20, ...), a swap (2 <-> 3) and one long cycle through the rest
      dest = [(p, p = 1, n)]
      dest(2) = 3
      dest(3) = 2
      call long_cycle(dest)
      dest0 = dest
      call particles%permute(dest)
      call assertTrue(all(dest == dest0), 'the destinations are restored')
      do p = 1, n
         slot = dest0(p)
         call assertEqual(int(p, i8), particles%id(slot), 'id follows its particle')
         call assertEqual(field_value(p, 1, dim), particles%x(:, slot), 0.0_rp, 'x')
         call assertEqual(field_value(p, 2, dim), particles%v(:, slot), 0.0_rp, 'v')
         call assertEqual(real(p, rp), particles%mass(slot), 0.0_rp, 'mass')
         call assertEqual(1000.0_rp + p, particles%density(slot), 0.0_rp, 'density')
         call assertEqual(field_value(p, 3, particles%n_sigma), particles%sbar(:, slot), 0.0_rp, 'sbar')
         call assertEqual(1 + mod(p, 3), particles%material(slot), 'material')
         call assertEqual(1000 + p, particles%cell(slot), 'cell')
         if (affine) call assertEqual(field_value(p, 4, dim * dim), particles%affine(:, slot), 0.0_rp, 'affine')
      end do
   end subroutine check_permutation

   !> The slots that are not fixed points (not 1, 2, 3 nor a multiple of 10) in one cycle, each to the next.
   subroutine long_cycle(dest)
      integer, intent(inout) :: dest(:)
      integer :: p, first, previous
      first = 0
      previous = 0
      do p = 4, size(dest)
         if (mod(p, 10) == 0) cycle
         if (previous > 0) dest(previous) = p
         if (first == 0) first = p
         previous = p
      end do
      dest(previous) = first
   end subroutine long_cycle

   subroutine test_growth_and_fit()
      type(particle_set_t) :: particles
      integer :: p
      call particles%init(2, 1, 16)
      call assertEqual(1, particles%n_spin, 'the spin by default')
      do p = 1, 1000
         call add_particle(particles, 2, p)
      end do
      call assertEqual(1000, particles%count, 'all added')
      call assertTrue(size(particles%mass) >= 1000 .and. size(particles%mass) <= 1000 + 1000 / 8 + 1, &
                      'growth by an eighth bounds the slack')
      call assertEqual(size(particles%mass), size(particles%spin, 2), 'the scratch arrays follow')
      call particles%reserve(1001)
      call assertTrue(size(particles%mass) >= 1001, 'reserve makes room')
      particles%count = 700
      call particles%fit()
      call assertEqual(700, size(particles%mass), 'fit to the particles held')
      call assertEqual(700, size(particles%strain_rate, 2), 'and the scratch arrays')
      do p = 1, 700
         call assertEqual(int(p, i8), particles%id(p), 'ids kept')
         call assertEqual(field_value(p, 3, 4), particles%sbar(:, p), 0.0_rp, 'sbar kept')
      end do
   end subroutine test_growth_and_fit

   subroutine add_particle(particles, dim, p)
      type(particle_set_t), intent(inout) :: particles
      integer, intent(in) :: dim, p
      call particles%add(field_value(p, 1, dim), field_value(p, 2, dim), real(p, rp), 1000.0_rp + p, &
                         field_value(p, 3, particles%n_sigma), 1 + mod(p, 3), int(p, i8), field_value(p, 4, dim * dim))
   end subroutine add_particle

   !> n distinct values of particle p for field f.
   pure function field_value(p, f, n) result(v)
      integer, intent(in) :: p, f, n
      real(rp) :: v(n)
      integer :: k
      v = [(real(100 * p + 10 * f + k, rp), k = 1, n)]
   end function field_value
end module test_particle_permutation
