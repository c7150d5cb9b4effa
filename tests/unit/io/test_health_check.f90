!> Tests of src/solver/health_check.f90: a sane state passes; a NaN or infinity in any quantity, a
!> non-positive density, a density outside the run's limits or a speed above the limit fails, and the
!> report names the particle (its global id, material and position) and the quantity.
module test_health_check
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use kinds, only: rp, i8
   use assertions, only: assertTrue, assertFalse, assertEqual
   use particle_set, only: particle_set_t
   use health_check, only: particles_healthy, describe_unhealthy_particle
   use world_frame, only: frame_t
   implicit none
   private

   public :: test_sane_state_is_healthy, test_nan_stress_is_named, test_infinite_position_is_named, &
             test_negative_density_is_named, test_speed_above_limit_is_named, test_runaway_density_is_named

   real(rp), parameter :: limit = 100.0_rp
   character(len=8), parameter :: names(2) = ['water   ', 'block   ']

contains

   !> 50 particles of 2 materials in 2-D with ids 1000 + p, at rest under a hydrostatic stress.
   function sane_particles() result(particles)
      type(particle_set_t) :: particles
      integer :: p
      call particles%init(2, 2, 64)
      do p = 1, 50
         call particles%add([0.01_rp * p, 0.5_rp], [1.0_rp, -2.0_rp], 0.25_rp, 1000.0_rp, &
                            [-10.0_rp, -10.0_rp, -10.0_rp, 0.0_rp], merge(1, 2, p <= 30), 1000_i8 + p)
      end do
   end function sane_particles

   subroutine check_report(particles, expected_particle, expected_text)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: expected_particle
      character(len=*), intent(in) :: expected_text
      integer :: particle
      character(len=:), allocatable :: description
      type(frame_t) :: frame       ! the grid frame is the world frame
      call assertFalse(particles_healthy(particles, limit), 'detected by the fast check')
      call describe_unhealthy_particle(particles, frame, limit, names, particle, description)
      call assertEqual(expected_particle, particle, 'the first bad particle')
      call assertTrue(index(description, expected_text) > 0, 'report "'//description//'" contains "'// &
                      expected_text//'"')
   end subroutine check_report

   subroutine test_sane_state_is_healthy()
      type(particle_set_t) :: particles
      integer :: particle
      character(len=:), allocatable :: description
      type(frame_t) :: frame
      particles = sane_particles()
      call assertTrue(particles_healthy(particles, limit), 'sane state')
      call describe_unhealthy_particle(particles, frame, limit, names, particle, description)
      call assertEqual(0, particle, 'no particle named')
   end subroutine test_sane_state_is_healthy

   subroutine test_nan_stress_is_named()
      type(particle_set_t) :: particles
      particles = sane_particles()
      particles%sbar(4, 37) = ieee_value(1.0_rp, ieee_quiet_nan)
      particles%sbar(1, 40) = ieee_value(1.0_rp, ieee_quiet_nan)
      call check_report(particles, 37, "particle 1037 (material 'block') at x = (0.37, 0.5): stress xy = NaN")
   end subroutine test_nan_stress_is_named

   !> A position becomes infinite only with the velocity that moved it: the fast check reads velocities.
   subroutine test_infinite_position_is_named()
      type(particle_set_t) :: particles
      particles = sane_particles()
      particles%x(2, 3) = ieee_value(1.0_rp, ieee_positive_inf)
      particles%v(2, 3) = ieee_value(1.0_rp, ieee_positive_inf)
      call check_report(particles, 3, "particle 1003 (material 'water') at x = (0.03, +Infinity): velocity y = +Infinity")
   end subroutine test_infinite_position_is_named

   subroutine test_negative_density_is_named()
      type(particle_set_t) :: particles
      particles = sane_particles()
      particles%density(12) = -5.0_rp
      call check_report(particles, 12, 'particle 1012 (material ''water'') at x = (0.12, 0.5): density = -5.0 kg/m^3 (must be > 0)')
      ! the last particles fall outside the 8-wide blocks of the fast check
      particles%density(12) = 1000.0_rp
      particles%density(50) = 0.0_rp
      call check_report(particles, 50, 'density = 0.0 kg/m^3 (must be > 0)')
   end subroutine test_negative_density_is_named

   subroutine test_speed_above_limit_is_named()
      type(particle_set_t) :: particles
      particles = sane_particles()
      particles%v(:, 50) = [60.0_rp, 80.0_rp]
      call assertTrue(particles_healthy(particles, limit), 'at the limit: still healthy')
      particles%v(:, 50) = [60.0_rp, 80.1_rp]
      call check_report(particles, 50, "particle 1050 (material 'block') at x = (0.5, 0.5): speed = 100.08")
      call check_report(particles, 50, 'm/s exceeds &run speed_limit = 100.0 m/s')
   end subroutine test_speed_above_limit_is_named

   !> A J that ran away at sane speeds: 100 times the reference density passes, more fails, either way;
   !> without limits any positive density passes.
   subroutine test_runaway_density_is_named()
      type(particle_set_t) :: particles
      real(rp), parameter :: limits(2) = [10.0_rp, 1.0e5_rp]
      integer :: particle
      character(len=:), allocatable :: description
      type(frame_t) :: frame
      particles = sane_particles()
      particles%density(50) = 1.0e5_rp
      particles%density(3) = 10.0_rp
      call assertTrue(particles_healthy(particles, limit, limits), 'at the limits: still healthy')
      particles%density(50) = 1.01e5_rp
      call assertTrue(particles_healthy(particles, limit), 'no limits: any positive density')
      call assertFalse(particles_healthy(particles, limit, limits), 'above the limit: detected')
      call describe_unhealthy_particle(particles, frame, limit, names, particle, description, limits)
      call assertEqual(50, particle, 'the dense particle')
      call assertTrue(index(description, 'density = 101000.0 kg/m^3, outside [10.0, 100000.0]') > 0, &
                      'report "'//description//'"')
      particles%density(50) = 1000.0_rp
      particles%density(17) = 9.9_rp
      call assertFalse(particles_healthy(particles, limit, limits), 'below the limit: detected')
      call describe_unhealthy_particle(particles, frame, limit, names, particle, description, limits)
      call assertEqual(17, particle, 'the light particle')
   end subroutine test_runaway_density_is_named
end module test_health_check
