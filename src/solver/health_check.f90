!> Detection of a NaN or a blow-up in the particle state, run after every step (docs/output.md,
!> "When the solution blows up").
!>
!> A particle is unhealthy when a position, velocity, density or stress component is not finite, its
!> density is not positive, or its speed exceeds the run's speed limit. The check that runs every
!> step is one streaming pass per array: the plain sum of all values is finite only if every value is
!> (a NaN or an infinity propagates through a sum; finite values of a sane state cannot overflow it),
!> plus the minimum density and the maximum squared speed. Only when that fails does a second pass
!> look for the first bad particle to name it. [R]
module health_check
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use input_text, only: int_text, real_text
   implicit none
   private

   public :: particles_healthy, describe_unhealthy_particle

   character(len=1), parameter :: axis(3) = ['x', 'y', 'z']
   character(len=2), parameter :: components_2d(4) = ['xx', 'yy', 'zz', 'xy']
   character(len=2), parameter :: components_3d(6) = ['xx', 'yy', 'zz', 'yz', 'xz', 'xy']

contains

   !> True if every particle is healthy (see the module). `speed_limit` in m/s.
   logical function particles_healthy(particles, speed_limit) result(healthy)
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(in) :: speed_limit
      real(rp) :: total, max_speed2, min_density
      integer :: n, p
      n = particles%count
      healthy = .true.
      if (n == 0) return
      total = sum(particles%x(:, 1:n)) + sum(particles%v(:, 1:n)) + sum(particles%density(1:n)) + &
              sum(particles%sbar(:, 1:n))
      if (.not. ieee_is_finite(total)) then
         healthy = .false.
         return
      end if
      ! every value is finite from here: the comparisons below cannot meet a NaN
      min_density = minval(particles%density(1:n))
      max_speed2 = 0.0_rp
      do p = 1, n
         max_speed2 = max(max_speed2, sum(particles%v(:, p)**2))
      end do
      healthy = min_density > 0.0_rp .and. max_speed2 <= speed_limit**2
   end function particles_healthy

   !> The first unhealthy particle (local index; 0 if none) and what is wrong with it, e.g.
   !> "particle 1234 (material 'water') at x = (0.5, 0.25): velocity y = NaN".
   subroutine describe_unhealthy_particle(particles, speed_limit, material_names, particle, description)
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(in) :: speed_limit
      character(len=*), intent(in) :: material_names(:)
      integer, intent(out) :: particle
      character(len=:), allocatable, intent(out) :: description
      character(len=:), allocatable :: problem
      integer :: p
      description = ''
      do p = 1, particles%count
         call find_problem(particles, p, speed_limit, problem)
         if (len(problem) == 0) cycle
         particle = p
         description = 'particle '//int_text(particles%id(p))//" (material '"// &
                       trim(material_names(particles%material(p)))//"') at x = "//vector_text(particles%x(:, p))// &
                       ': '//problem
         return
      end do
      particle = 0
   end subroutine describe_unhealthy_particle

   !> What is wrong with particle p ('' if nothing): the first non-finite quantity, else a non-positive
   !> density, else a speed above the limit.
   subroutine find_problem(particles, p, speed_limit, problem)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: p
      real(rp), intent(in) :: speed_limit
      character(len=:), allocatable, intent(out) :: problem
      integer :: k
      real(rp) :: speed
      problem = ''
      do k = 1, particles%dim
         if (.not. ieee_is_finite(particles%x(k, p))) problem = 'position '//axis(k)//' = '//real_text(particles%x(k, p))
         if (len(problem) > 0) return
      end do
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
      if (.not. particles%density(p) > 0.0_rp) then
         problem = 'density = '//real_text(particles%density(p))//' kg/m^3 (must be > 0)'
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
