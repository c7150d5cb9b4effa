!> Prescribed rigid translations of walls (`&wall motion`, docs/input.md; docs/theory.md section 3.6).
!>
!> The displacement d(t) of a wall from its position in the scene is a function of time alone: a
!> restart needs no state. Kinds:
!>  - none: d = 0.
!>  - solitary_wave: the piston stroke of Goring (1978) that makes a solitary wave of height A in water
!>    of depth h, eta = A sech^2(theta), theta = k (c (t - t_s) - x) - theta_0, k = sqrt(3 A / (4 h^3)),
!>    c = sqrt(g (h + A)), x measured along the wall's normal from its position in the scene. The paddle
!>    follows dX/dt = c eta(X, t) / (h + eta(X, t)). Along the paddle's path dtheta/dt = k c h / (h + eta)
!>    and dX/dtheta = eta / (k h), which integrate in closed form [D]:
!>       X(theta) = (A / (k h)) (tanh theta + tanh theta_0)
!>       t(theta) = t_s + (theta + theta_0 + (A / h) (tanh theta + tanh theta_0)) / (k c)
!>    so t -> theta is one monotonic scalar equation (t'(theta) >= 1 / (k c)), solved by safeguarded
!>    Newton to round-off: no ODE integration error at all. The stroke runs over theta in
!>    [-theta_0, theta_0], theta_0 = 3.8 (Goring's choice: its duration is his 2 (3.8 + A/h) / (k c)); the
!>    paddle starts at 0.2 % of the wave's height (velocity 0.002 c A / h) and stops after the stroke
!>    S = (2 A / (k h)) tanh(3.8) = 0.99900 x 2 A / (k h).
!> A wall moves by mean_velocity over a step: its nodes are constrained to that velocity, and a
!> particle that moves with it lands where the wall is at the end of the step.
module wall_motion
   use kinds, only: rp
   use scene_description, only: wall_spec_t, motion_solitary_wave
   implicit none
   private

   integer, parameter, public :: motion_kind_none = 0, motion_kind_solitary = 1

   !> theta_0 of the solitary stroke (Goring 1978): the paddle starts where eta = A sech^2(3.8) = 0.002 A.
   real(rp), parameter, public :: solitary_theta0 = 3.8_rp

   type, public :: wall_motion_t
      integer :: kind = motion_kind_none
      real(rp) :: direction(3) = 0.0_rp  !< world unit vector the wall moves along (solitary: its normal)
      real(rp) :: start = 0.0_rp         !< t_s [s]
      real(rp) :: amplitude = 0.0_rp     !< A [m]
      real(rp) :: depth = 0.0_rp         !< h [m]
      real(rp) :: wavenumber = 0.0_rp    !< k [1/m]
      real(rp) :: celerity = 0.0_rp      !< c [m/s]
   contains
      procedure :: displacement => motion_displacement
      procedure :: mean_velocity => motion_mean_velocity
      procedure :: max_speed => motion_max_speed
      procedure :: moving => motion_moving
      procedure :: stroke => motion_stroke
      procedure :: end_time => motion_end_time
   end type wall_motion_t

   public :: solitary_motion, motion_of_wall

contains

   !> The stroke of a solitary wave of height `amplitude` in water `depth` deep under gravity `g`, along
   !> the world unit vector `direction` (the wall's normal), starting at `start`.
   pure function solitary_motion(direction, start, amplitude, depth, g) result(motion)
      real(rp), intent(in) :: direction(3), start, amplitude, depth, g
      type(wall_motion_t) :: motion
      motion%kind = motion_kind_solitary
      motion%direction = direction / norm2(direction)
      motion%start = start
      motion%amplitude = amplitude
      motion%depth = depth
      motion%wavenumber = sqrt(3.0_rp * amplitude / (4.0_rp * depth**3))
      motion%celerity = sqrt(g * (depth + amplitude))
   end function solitary_motion

   !> The motion of a `&wall` (validated) under the world gravity vector `gravity` of a `dim`-D scene.
   pure function motion_of_wall(spec, gravity, dim) result(motion)
      type(wall_spec_t), intent(in) :: spec
      real(rp), intent(in) :: gravity(3)
      integer, intent(in) :: dim
      type(wall_motion_t) :: motion
      real(rp) :: normal(3)
      if (spec%motion /= motion_solitary_wave) return
      normal = 0.0_rp
      normal(1:dim) = spec%normal(1:dim) / norm2(spec%normal(1:dim))
      motion = solitary_motion(normal, spec%motion_start, spec%wave_height, spec%water_depth, norm2(gravity(1:dim)))
   end function motion_of_wall

   !> The wall moves at all (a fixed wall keeps its nodes and its arithmetic).
   pure logical function motion_moving(self)
      class(wall_motion_t), intent(in) :: self
      motion_moving = self%kind /= motion_kind_none
   end function motion_moving

   !> Length of the whole motion along `direction` [m] (solitary: S).
   pure real(rp) function motion_stroke(self) result(stroke)
      class(wall_motion_t), intent(in) :: self
      stroke = 0.0_rp
      if (self%kind == motion_kind_solitary) stroke = paddle_position(self, solitary_theta0)
   end function motion_stroke

   !> The time the motion ends [s] (the wall is at rest after it).
   pure real(rp) function motion_end_time(self) result(t)
      class(wall_motion_t), intent(in) :: self
      t = self%start
      if (self%kind == motion_kind_solitary) &
         t = self%start + time_of_theta(self, solitary_theta0)
   end function motion_end_time

   !> Displacement from the scene position at time t, world frame [m].
   pure function motion_displacement(self, t) result(d)
      class(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp) :: d(3)
      d = 0.0_rp
      if (self%kind == motion_kind_solitary) d = paddle_position(self, theta_at(self, t)) * self%direction
   end function motion_displacement

   !> Mean velocity over [t0, t1] (t1 > t0), world frame [m/s].
   pure function motion_mean_velocity(self, t0, t1) result(v)
      class(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: t0, t1
      real(rp) :: v(3)
      v = 0.0_rp
      if (self%kind == motion_kind_none) return
      v = (self%displacement(t1) - self%displacement(t0)) / (t1 - t0)
   end function motion_mean_velocity

   !> An upper bound of the wall's speed over [t0, t1] [m/s] (the time step's and the active region's):
   !> solitary, the paddle's speed c eta / (h + eta) at the largest eta it meets in the interval.
   pure real(rp) function motion_max_speed(self, t0, t1) result(speed)
      class(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: t0, t1
      real(rp) :: a, b, eta
      speed = 0.0_rp
      if (self%kind /= motion_kind_solitary) return
      if (t1 <= self%start .or. t0 >= self%end_time()) return
      a = theta_at(self, t0)
      b = theta_at(self, t1)
      ! eta = A sech^2(theta) peaks at theta = 0
      if (a <= 0.0_rp .and. b >= 0.0_rp) then
         eta = self%amplitude
      else
         eta = self%amplitude / cosh(min(abs(a), abs(b)))**2
      end if
      speed = self%celerity * eta / (self%depth + eta)
   end function motion_max_speed

   !> X(theta) = (A / (k h)) (tanh theta + tanh theta_0).
   pure real(rp) function paddle_position(self, theta) result(x)
      type(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: theta
      x = self%amplitude / (self%wavenumber * self%depth) * (tanh(theta) + tanh(solitary_theta0))
   end function paddle_position

   !> t(theta) - t_s = (theta + theta_0 + (A/h) (tanh theta + tanh theta_0)) / (k c).
   pure real(rp) function time_of_theta(self, theta) result(t)
      type(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: theta
      t = (theta + solitary_theta0 + self%amplitude / self%depth * (tanh(theta) + tanh(solitary_theta0))) / &
          (self%wavenumber * self%celerity)
   end function time_of_theta

   !> The phase theta of the paddle at time t, clipped to [-theta_0, theta_0]: Newton on t(theta) = t,
   !> kept inside a bracket that shrinks with every iterate (t' >= 1/(k c) > 0: one root).
   pure real(rp) function theta_at(self, t) result(theta)
      type(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp) :: tau, lo, hi, f, slope, next, ratio
      integer :: iteration
      ratio = self%amplitude / self%depth
      tau = (t - self%start) * self%wavenumber * self%celerity
      theta = -solitary_theta0
      if (tau <= 0.0_rp) return
      theta = solitary_theta0
      if (t - self%start >= time_of_theta(self, solitary_theta0)) return
      lo = -solitary_theta0
      hi = solitary_theta0
      ! the linear part alone as the first guess (tau = theta + theta_0 when A << h)
      theta = max(lo, min(hi, tau - solitary_theta0))
      do iteration = 1, 100
         f = theta + solitary_theta0 + ratio * (tanh(theta) + tanh(solitary_theta0)) - tau
         if (f > 0.0_rp) then
            hi = theta
         else
            lo = theta
         end if
         slope = 1.0_rp + ratio / cosh(theta)**2
         next = theta - f / slope
         if (next <= lo .or. next >= hi) next = 0.5_rp * (lo + hi)
         if (abs(next - theta) <= 4.0_rp * epsilon(1.0_rp) * max(1.0_rp, abs(theta))) then
            theta = next
            exit
         end if
         theta = next
      end do
   end function theta_at
end module wall_motion
