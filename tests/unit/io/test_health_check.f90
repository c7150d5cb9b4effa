!> Tests of src/solver/health_check.f90: a sane state passes; a NaN or infinity in any quantity, a
!> non-positive density, a density outside the run's limits or a speed above the limit fails, and the
!> report names the particle (its global id, material and position) and the quantity. Every verdict is also
!> reached from the time step's scan of velocities and densities (scan_motion, two slices merged), which
!> then reads only the stresses.
module test_health_check
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use, intrinsic :: ieee_exceptions, only: ieee_get_halting_mode, ieee_set_halting_mode, ieee_invalid
   use kinds, only: rp, i8
   use assertions, only: assertTrue, assertFalse, assertEqual
   use particle_set, only: particle_set_t
   use health_check, only: particles_healthy, describe_unhealthy_particle, motion_scan_t, scan_motion, merge_motion_scans
   use world_frame, only: frame_t
   implicit none
   private

   public :: test_sane_state_is_healthy, test_nan_stress_is_named, test_infinite_position_is_named, &
             test_negative_density_is_named, test_speed_above_limit_is_named, test_runaway_density_is_named, &
             test_nan_velocity_and_density_are_named

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

   !> The scan the solver hands the check: one per material slice (1:30 and 31:50), merged.
   function motion_of(particles) result(motion)
      type(particle_set_t), intent(in) :: particles
      type(motion_scan_t) :: motion, part
      call scan_motion(particles%v(:, 1:30), particles%density(1:30), motion)
      call scan_motion(particles%v(:, 31:50), particles%density(31:50), part)
      call merge_motion_scans(motion, part)
   end function motion_of

   !> particles_healthy with and without the scan: the same verdict, which is returned.
   logical function healthy_both_ways(particles, density_limits) result(healthy)
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(in), optional :: density_limits(2)
      logical :: from_scan
      healthy = particles_healthy(particles, limit, density_limits)
      from_scan = particles_healthy(particles, limit, density_limits, motion_of(particles))
      call assertTrue(healthy .eqv. from_scan, 'the same verdict from the time step''s scan')
   end function healthy_both_ways

   subroutine check_report(particles, expected_particle, expected_text)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: expected_particle
      character(len=*), intent(in) :: expected_text
      integer :: particle
      character(len=:), allocatable :: description
      type(frame_t) :: frame       ! the grid frame is the world frame
      call assertFalse(healthy_both_ways(particles), 'detected by the fast check')
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
      call assertTrue(healthy_both_ways(particles), 'sane state')
      ! a scene without waves (rigid bodies only) has no speed limit: huge, which must not overflow (Debug traps)
      call assertTrue(particles_healthy(particles, huge(1.0_rp), motion=motion_of(particles)), 'speed limit huge')
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
      call assertTrue(healthy_both_ways(particles), 'at the limit: still healthy')
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
      call assertTrue(healthy_both_ways(particles, limits), 'at the limits: still healthy')
      particles%density(50) = 1.01e5_rp
      call assertTrue(healthy_both_ways(particles), 'no limits: any positive density')
      call assertFalse(healthy_both_ways(particles, limits), 'above the limit: detected')
      call describe_unhealthy_particle(particles, frame, limit, names, particle, description, limits)
      call assertEqual(50, particle, 'the dense particle')
      call assertTrue(index(description, 'density = 101000.0 kg/m^3, outside [10.0, 100000.0]') > 0, &
                      'report "'//description//'"')
      particles%density(50) = 1000.0_rp
      particles%density(17) = 9.9_rp
      call assertFalse(healthy_both_ways(particles, limits), 'below the limit: detected')
      call describe_unhealthy_particle(particles, frame, limit, names, particle, description, limits)
      call assertEqual(17, particle, 'the light particle')
   end subroutine test_runaway_density_is_named

   !> NaNs the scan counts (a vectorised max or min need not see them): a velocity component, a density,
   !> an infinite density; each past the 8-wide blocks too. Both checks compare NaNs (max, min), which the
   !> Debug build's trap on invalid operations would stop: halting is off for this test.
   subroutine test_nan_velocity_and_density_are_named()
      type(particle_set_t) :: particles
      logical :: halting
      call ieee_get_halting_mode(ieee_invalid, halting)
      call ieee_set_halting_mode(ieee_invalid, .false.)
      particles = sane_particles()
      particles%v(1, 21) = ieee_value(1.0_rp, ieee_quiet_nan)
      call check_report(particles, 21, 'velocity x = NaN')
      particles = sane_particles()
      particles%v(2, 49) = ieee_value(1.0_rp, ieee_quiet_nan)
      call check_report(particles, 49, 'velocity y = NaN')
      particles = sane_particles()
      particles%density(8) = ieee_value(1.0_rp, ieee_quiet_nan)
      call check_report(particles, 8, 'density = NaN')
      particles = sane_particles()
      particles%density(50) = ieee_value(1.0_rp, ieee_positive_inf)
      call check_report(particles, 50, 'density = +Infinity')
      call ieee_set_halting_mode(ieee_invalid, halting)
   end subroutine test_nan_velocity_and_density_are_named
end module test_health_check
