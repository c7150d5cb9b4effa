!> Tests of src/input/wall_motion.f90: the closed-form solitary-wave stroke against Goring's ODE
!> dX/dt = c eta(X, t) / (h + eta(X, t)) integrated by RK4, its total stroke, its speed bound, and the
!> motion of a table.
module test_wall_motion
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use wall_motion, only: wall_motion_t, solitary_motion, solitary_theta0
   use time_table, only: time_table_t
   implicit none
   private

   public :: test_solitary_stroke_solves_the_ode, test_solitary_stroke_length, test_speed_bound, test_table_motion

   real(rp), parameter :: g = 9.81_rp, depth = 0.1_rp

contains

   !> dX/dt of Goring's paddle at (X, t): eta taken at the paddle.
   pure real(rp) function paddle_speed(motion, x, t) result(v)
      type(wall_motion_t), intent(in) :: motion
      real(rp), intent(in) :: x, t
      real(rp) :: eta
      eta = motion%amplitude / cosh(motion%wavenumber * (motion%celerity * (t - motion%start) - x) - &
                                    solitary_theta0)**2
      v = motion%celerity * eta / (motion%depth + eta)
   end function paddle_speed

   !> RK4 with 20 000 steps over the stroke against the closed form, at A/h = 0.1, 0.3, 0.6: the same
   !> position to 1e-12 m all along (RK4's own error at this step), the start within 0.4 % of the peak
   !> speed (0.2 % (h + A) / h: sech^2(3.8) = 0.002).
   subroutine test_solitary_stroke_solves_the_ode()
      type(wall_motion_t) :: motion
      real(rp) :: ratios(3) = [0.1_rp, 0.3_rp, 0.6_rp], t, dt, x, k1, k2, k3, k4, d(3), worst
      integer :: r, n, i
      do r = 1, size(ratios)
         motion = solitary_motion([1.0_rp, 0.0_rp, 0.0_rp], 0.5_rp, ratios(r) * depth, depth, g)
         n = 20000
         dt = (motion%end_time() - motion%start) / n
         t = motion%start
         x = 0.0_rp
         worst = 0.0_rp
         do i = 1, n
            k1 = paddle_speed(motion, x, t)
            k2 = paddle_speed(motion, x + 0.5_rp * dt * k1, t + 0.5_rp * dt)
            k3 = paddle_speed(motion, x + 0.5_rp * dt * k2, t + 0.5_rp * dt)
            k4 = paddle_speed(motion, x + dt * k3, t + dt)
            x = x + dt * (k1 + 2.0_rp * k2 + 2.0_rp * k3 + k4) / 6.0_rp
            t = t + dt
            d = motion%displacement(t)
            worst = max(worst, abs(d(1) - x))
         end do
         call assertTrue(worst < 1.0e-12_rp, 'closed form = RK4 of the ODE to 1e-12 m')
         d = motion%displacement(motion%start - 1.0_rp)
         call assertEqual(0.0_rp, d(1), 0.0_rp, 'at rest before the start')
         d = motion%displacement(motion%end_time() + 1.0_rp)
         call assertEqual(motion%stroke(), d(1), 1.0e-15_rp, 'at rest after the stroke')
         call assertTrue(paddle_speed(motion, 0.0_rp, motion%start) < 0.004_rp * motion%celerity * ratios(r) / &
                         (1.0_rp + ratios(r)), 'the stroke starts within 0.4 % of the peak speed')
      end do
   end subroutine test_solitary_stroke_solves_the_ode

   !> S = (2 A / (k h)) tanh(3.8), 0.1 % short of Goring's 2 A / (k h); along the normal only.
   subroutine test_solitary_stroke_length()
      type(wall_motion_t) :: motion
      real(rp) :: d(3), n(3)
      n = [3.0_rp, 4.0_rp, 0.0_rp] / 5.0_rp
      motion = solitary_motion(n, 0.0_rp, 0.03_rp, depth, g)
      call assertEqual(2.0_rp * 0.03_rp / (motion%wavenumber * depth) * tanh(solitary_theta0), motion%stroke(), &
                       1.0e-15_rp, 'S = (2 A / (k h)) tanh(3.8)')
      call assertTrue(abs(motion%stroke() / (2.0_rp * 0.03_rp / (motion%wavenumber * depth)) - 1.0_rp) < 1.01e-3_rp, &
                      'within 0.1 % of 2 A / (k h)')
      call assertEqual(sqrt(3.0_rp * 0.03_rp / (4.0_rp * depth**3)), motion%wavenumber, 1.0e-15_rp, 'k')
      call assertEqual(sqrt(g * (depth + 0.03_rp)), motion%celerity, 1.0e-15_rp, 'c')
      d = motion%displacement(motion%end_time())
      call assertEqual(motion%stroke() * n, d, 1.0e-15_rp, 'moves along its normal')
   end subroutine test_solitary_stroke_length

   !> max_speed bounds the mean velocity of every step (the time step's wall speed) and reaches c A / (h + A).
   subroutine test_speed_bound()
      type(wall_motion_t) :: motion
      real(rp) :: t, dt, v(3), peak
      integer :: i
      motion = solitary_motion([1.0_rp, 0.0_rp, 0.0_rp], 0.0_rp, 0.03_rp, depth, g)
      dt = motion%end_time() / 1000.0_rp
      peak = 0.0_rp
      do i = 0, 999
         t = i * dt
         v = motion%mean_velocity(t, t + dt)
         call assertTrue(v(1) <= motion%max_speed(t, t + dt) * (1.0_rp + 1.0e-12_rp), 'bound holds')
         peak = max(peak, motion%max_speed(t, t + dt))
      end do
      call assertEqual(motion%celerity * 0.03_rp / (depth + 0.03_rp), peak, 1.0e-12_rp, 'peak c A / (h + A)')
      call assertEqual(0.0_rp, motion%max_speed(motion%end_time() + 1.0_rp, motion%end_time() + 2.0_rp), 0.0_rp, &
                       'at rest after the stroke')
   end subroutine test_speed_bound

   !> A table: displacement linear between rows, held outside; the mean velocity of a step across a row;
   !> the speed bound of the steepest interval met.
   subroutine test_table_motion()
      type(wall_motion_t) :: motion
      real(rp) :: d(3), v(3)
      motion%kind = 2
      motion%table%time = [0.0_rp, 1.0_rp, 3.0_rp]
      motion%table%values = reshape([0.0_rp, 0.0_rp, 0.1_rp, 0.0_rp, 0.1_rp, 0.4_rp], [2, 3])
      motion%table%columns = ['x', 'y']
      call assertTrue(motion%moving(), 'a table moves')
      d = motion%displacement(0.5_rp)
      call assertEqual([0.05_rp, 0.0_rp, 0.0_rp], d, 1.0e-15_rp, 'halfway along the first row interval')
      d = motion%displacement(5.0_rp)
      call assertEqual([0.1_rp, 0.4_rp, 0.0_rp], d, 1.0e-15_rp, 'the last row held')
      v = motion%mean_velocity(0.5_rp, 1.5_rp)
      call assertEqual([0.05_rp, 0.1_rp, 0.0_rp], v, 1.0e-15_rp, 'mean velocity across a row')
      call assertEqual(0.2_rp, motion%max_speed(0.5_rp, 1.5_rp), 1.0e-15_rp, 'steepest interval met')
      call assertEqual(0.1_rp, motion%max_speed(0.2_rp, 0.4_rp), 1.0e-15_rp, 'first interval only')
      call assertEqual(0.0_rp, motion%max_speed(3.5_rp, 4.0_rp), 0.0_rp, 'at rest after the last row')
   end subroutine test_table_motion
end module test_wall_motion
