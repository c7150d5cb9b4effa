!> Detection of a NaN or a blow-up in the particle state, run after every step (docs/output.md,
!> "When the solution blows up").
!>
!> A particle is unhealthy when a position, velocity, density or stress component is not finite, its
!> density is not positive or lies outside the run's density limits (a factor of 100 around the
!> materials' reference densities: a J that ran away at sane speeds), or its speed exceeds the run's
!> speed limit. The check that runs every step takes the velocities and densities from a scan of them
!> (scan_motion: the largest |v|^2, the lowest and highest density, NaN counts), which the time step makes
!> anyway and hands over, and reads the stresses once, as a flat array, in 8 independent partial sums (so
!> the loop vectorises without reordering the additions): a sum is finite only if every value is (a NaN
!> or an infinity propagates through a sum; the finite values of a sane state cannot overflow it).
!> Positions are not read: a position turns non-finite only with the velocity that moved it. Only when the
!> check fails does a second pass look for the first bad particle to name it. [R]
module health_check
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use world_frame, only: frame_t
   use input_text, only: int_text, real_text
   implicit none
   private

   public :: particles_healthy, describe_unhealthy_particle, scan_motion, merge_motion_scans

   !> What one pass over the velocities and densities of some particles found: what the time step needs
   !> (the largest |v|^2, the lowest density) and what the health check needs besides (the NaNs, the highest
   !> density). Maxima, minima and counts are exact: slices scanned apart and merged give what one scan of
   !> them all gives, so the step's scan serves the check and it need not read them again.
   type, public :: motion_scan_t
      real(rp) :: speed2 = 0.0_rp            !< largest |v|^2 [m^2/s^2] (a NaN |v|^2 need not be seen: nan_speeds)
      real(rp) :: lightest = huge(1.0_rp)    !< lowest density [kg/m^3], NaNs passed over (as minval does)
      real(rp) :: densest = 0.0_rp           !< highest density [kg/m^3] (a NaN need not be seen: nan_densities)
      integer :: nan_speeds = 0              !< particles whose |v|^2 is NaN
      integer :: nan_densities = 0           !< particles whose density is NaN
   end type motion_scan_t

   character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
   character(len=2), parameter :: components_2d(4) = ['xx', 'yy', 'zz', 'xy']
   character(len=2), parameter :: components_3d(6) = ['xx', 'yy', 'zz', 'yz', 'xz', 'xy']

contains

   !> True if every particle is healthy (see the module). `speed_limit` in m/s; `density_limits` the
   !> lowest and highest density allowed [kg/m^3] (without: any positive density). `motion`: the time
   !> step's scan of every particle's velocity and density (scan_motion, merged over the materials); without
   !> it they are scanned here.
   logical function particles_healthy(particles, speed_limit, density_limits, motion) result(healthy)
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(in) :: speed_limit
      real(rp), intent(in), optional :: density_limits(2)
      type(motion_scan_t), intent(in), optional :: motion
      type(motion_scan_t) :: scan
      real(rp) :: total
      integer :: n
      n = particles%count
      healthy = .true.
      if (n == 0) return
      if (present(motion)) then
         scan = motion
      else
         call scan_motion(particles%v(:, 1:n), particles%density(1:n), scan)
      end if
      total = stress_sum(particles%sbar, particles%n_sigma * n)
      ! |v|^2 is finite only if every component is: an infinity makes it infinite, a NaN is counted
      healthy = ieee_is_finite(total) .and. scan%nan_speeds == 0 .and. scan%nan_densities == 0 .and. &
                ieee_is_finite(scan%speed2) .and. ieee_is_finite(scan%densest) .and. scan%lightest > 0.0_rp
      if (healthy .and. present(density_limits)) healthy = scan%lightest >= density_limits(1) .and. &
                                                           scan%densest <= density_limits(2)
      if (healthy) healthy = sqrt(scan%speed2) <= speed_limit     ! the limit may be huge: not squared
   end function particles_healthy

   !> The sum of the first n values of `values` (8 partial sums). Explicit shape: the stresses of the
   !> particle set are passed whole, as their first n elements.
   pure real(rp) function stress_sum(values, n) result(total)
      integer, intent(in) :: n
      real(rp), intent(in) :: values(n)
      integer, parameter :: width = 8
      real(rp) :: sums(width)
      integer :: i, tail
      tail = n - mod(n, width)
      sums = 0.0_rp
      do i = 1, tail, width
         sums = sums + values(i:i + width - 1)
      end do
      total = sum(sums) + sum(values(tail + 1:n))
   end function stress_sum

   !> The scan of velocities v(:, p) and densities density(p) of a slice of particles, in loops the compiler
   !> vectorises (one scalar loop for both was 4 % of a 2-D step). The velocities of a known leading
   !> dimension; |v|^2 summed from 0 as sum() does, so that the compiler fuses the same multiplications into
   !> its additions and the time step is the same bit for bit (v1^2 + v2^2 fused the other one). NaNs
   !> counted in integers (a logical reduction keeps a loop scalar); a NaN density is passed over by the
   !> lowest density as minval does, which a vectorised min need not do, so then a scalar pass.
   pure subroutine scan_motion(v, density, scan)
      real(rp), intent(in), contiguous :: v(:, :), density(:)
      type(motion_scan_t), intent(out) :: scan
      real(rp) :: lightest, densest
      integer :: n, p, nans
      n = size(density)
      if (size(v, 1) == 2) then
         call fastest_2d(v, scan%speed2, scan%nan_speeds)
      else
         call fastest_3d(v, scan%speed2, scan%nan_speeds)
      end if
      lightest = huge(1.0_rp)
      densest = 0.0_rp
      nans = 0
      do p = 1, n
         lightest = min(lightest, density(p))
         densest = max(densest, density(p))
         nans = nans + merge(1, 0, ieee_is_nan(density(p)))
      end do
      if (nans > 0) then
         lightest = huge(1.0_rp)
         do p = 1, n
            if (density(p) < lightest) lightest = density(p)
         end do
      end if
      scan%lightest = lightest
      scan%densest = densest
      scan%nan_densities = nans
   contains
      pure subroutine fastest_2d(v, largest, nans)
         real(rp), intent(in) :: v(2, n)
         real(rp), intent(out) :: largest
         integer, intent(out) :: nans
         real(rp) :: v2
         integer :: p
         largest = 0.0_rp
         nans = 0
         do p = 1, n
            v2 = 0.0_rp
            v2 = v2 + v(1, p)**2
            v2 = v2 + v(2, p)**2
            largest = max(largest, v2)
            nans = nans + merge(1, 0, ieee_is_nan(v2))
         end do
      end subroutine fastest_2d
      pure subroutine fastest_3d(v, largest, nans)
         real(rp), intent(in) :: v(3, n)
         real(rp), intent(out) :: largest
         integer, intent(out) :: nans
         real(rp) :: v2
         integer :: p
         largest = 0.0_rp
         nans = 0
         do p = 1, n
            v2 = 0.0_rp
            v2 = v2 + v(1, p)**2
            v2 = v2 + v(2, p)**2
            v2 = v2 + v(3, p)**2
            largest = max(largest, v2)
            nans = nans + merge(1, 0, ieee_is_nan(v2))
         end do
      end subroutine fastest_3d
   end subroutine scan_motion

   !> The scan of two sets of particles together.
   pure subroutine merge_motion_scans(total, part)
      type(motion_scan_t), intent(inout) :: total
      type(motion_scan_t), intent(in) :: part
      total%speed2 = max(total%speed2, part%speed2)
      total%lightest = min(total%lightest, part%lightest)
      total%densest = max(total%densest, part%densest)
      total%nan_speeds = total%nan_speeds + part%nan_speeds
      total%nan_densities = total%nan_densities + part%nan_densities
   end subroutine merge_motion_scans

   !> The first unhealthy particle (local index; 0 if none) and what is wrong with it, e.g.
   !> "particle 1234 (material 'water') at x = (0.5, 0.25): velocity y = NaN". The position is given in
   !> the world frame (through `frame`) when it is finite; the quantities in the grid's frame.
   subroutine describe_unhealthy_particle(particles, frame, speed_limit, material_names, particle, description, &
                                          density_limits)
      type(particle_set_t), intent(in) :: particles
      type(frame_t), intent(in) :: frame
      real(rp), intent(in) :: speed_limit
      character(len=*), intent(in) :: material_names(:)
      integer, intent(out) :: particle
      character(len=:), allocatable, intent(out) :: description
      real(rp), intent(in), optional :: density_limits(2)
      character(len=:), allocatable :: problem, where
      real(rp) :: limits(2)
      integer :: p
      description = ''
      limits = [0.0_rp, huge(1.0_rp)]
      if (present(density_limits)) limits = density_limits
      do p = 1, particles%count
         call find_problem(particles, p, speed_limit, limits, problem)
         if (len(problem) == 0) cycle
         particle = p
         if (all(ieee_is_finite(particles%x(:, p)))) then
            where = vector_text(frame%world_point(particles%x(:, p)))
         else
            where = vector_text(particles%x(:, p))
         end if
         description = 'particle '//int_text(particles%id(p))//" (material '"// &
                       trim(material_names(particles%material(p)))//"') at x = "//where//': '//problem
         return
      end do
      particle = 0
   end subroutine describe_unhealthy_particle

   !> What is wrong with particle p ('' if nothing): the first non-finite quantity (velocity, density,
   !> stress, position), else a non-positive density, else one outside the limits, else a speed above the limit.
   subroutine find_problem(particles, p, speed_limit, density_limits, problem)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: p
      real(rp), intent(in) :: speed_limit, density_limits(2)
      character(len=:), allocatable, intent(out) :: problem
      integer :: k
      real(rp) :: speed
      problem = ''
      do k = 1, particles%dim
         if (.not. ieee_is_finite(particles%v(k, p))) problem = 'velocity '//axis(k)//' = '//real_text(particles%v(k, p))
         if (len(problem) > 0) return
      end do
      if (.not. ieee_is_finite(particles%density(p))) then
         problem = 'density = '//real_text(particles%density(p))
         return
      end if
      do k = 1, particles%n_sigma
         if (.not. ieee_is_finite(particles%sbar(k, p))) then
            problem = 'stress '//component_name(particles%dim, k)//' = '// &
                      real_text(particles%density(p) * particles%sbar(k, p))
            return
         end if
      end do
      do k = 1, particles%dim
         if (.not. ieee_is_finite(particles%x(k, p))) problem = 'position '//axis(k)//' = '//real_text(particles%x(k, p))
         if (len(problem) > 0) return
      end do
      if (.not. particles%density(p) > 0.0_rp) then
         problem = 'density = '//real_text(particles%density(p))//' kg/m^3 (must be > 0)'
         return
      end if
      if (particles%density(p) < density_limits(1) .or. particles%density(p) > density_limits(2)) then
         problem = 'density = '//real_text(particles%density(p))//' kg/m^3, outside ['// &
                   real_text(density_limits(1))//', '//real_text(density_limits(2))//'] (100 times the '// &
                   'materials'' reference densities either way)'
         return
      end if
      speed = norm2(particles%v(:, p))
      if (speed > speed_limit) problem = 'speed = '//real_text(speed)//' m/s exceeds &run speed_limit = '// &
                                         real_text(speed_limit)//' m/s'
   end subroutine find_problem

   pure function component_name(dim, k) result(name)
      integer, intent(in) :: dim, k
      character(len=2) :: name
      if (dim == 2) then
         name = components_2d(k)
      else
         name = components_3d(k)
      end if
   end function component_name

   function vector_text(x) result(text)
      real(rp), intent(in) :: x(:)
      character(len=:), allocatable :: text
      integer :: k
      text = '('
      do k = 1, size(x)
         text = text//real_text(x(k))
         if (k < size(x)) text = text//', '
      end do
      text = text//')'
   end function vector_text
end module health_check
