!> Prescribed rigid translations of walls and structures (`&wall motion`, `&structure motion`,
!> docs/input.md; docs/theory.md section 3.6).
!>
!> The displacement d(t) of a wall or a structure from its position in the scene is a function of time
!> alone: a restart needs no state. Kinds:
!>  - none: d = 0.
!>  - solitary_wave: the piston stroke of Goring (1978) that makes a solitary wave of height A in water
!>    of depth h, eta = A sech^2(theta), theta = k (c (t - t_s) - x) - theta_0, k = sqrt(3 A / (4 h^3)),
!>    c = sqrt(g (h + A)), x measured along the wall's normal (a structure: its motion_direction) from its
!>    position in the scene. The paddle
!>    follows dX/dt = c eta(X, t) / (h + eta(X, t)). Along the paddle's path dtheta/dt = k c h / (h + eta)
!>    and dX/dtheta = eta / (k h), which integrate in closed form [D]:
!>       X(theta) = (A / (k h)) (tanh theta + tanh theta_0)
!>       t(theta) = t_s + (theta + theta_0 + (A / h) (tanh theta + tanh theta_0)) / (k c)
!>    so t -> theta is one monotonic scalar equation (t'(theta) >= 1 / (k c)), solved by safeguarded
!>    Newton to round-off: no ODE integration error at all. The stroke runs over theta in
!>    [-theta_0, theta_0], theta_0 = 3.8 (Goring's choice: its duration is his 2 (3.8 + A/h) / (k c)); the
!>    paddle starts at 0.2 % of the wave's height (velocity 0.002 c A / h) and stops after the stroke
!>    S = (2 A / (k h)) tanh(3.8) = 0.99900 x 2 A / (k h).
!>  - regular_wave, irregular_wave: a piston's periodic or irregular stroke along the wall's normal (a
!>    structure: its motion_direction), a sum of sines with a start-up ramp (wave_paddle).
!>  - table: the displacement (x, y[, z]) of a CSV time table (`motion_file`, time_table: linear between
!>    rows, the first / last row held outside them), read by rank 0 when the scene is read
!>    (load_wall_tables) and broadcast with it; its velocity is piecewise constant.
!> A wall moves by mean_velocity over a step: its nodes are constrained to that velocity, and a
!> particle that moves with it lands where the wall is at the end of the step.
module wall_motion
   use kinds, only: rp, path_len
   use error_status, only: status_t
   use scene_description, only: scene_t, grid_spec_t, motion_spec_t, motion_solitary_wave, motion_table, structure_shape
   use motion_spec, only: motion_regular_wave, motion_irregular_wave, spectrum_pierson_moskowitz
   use wave_paddle, only: paddle_signal_t, regular_signal, irregular_signal
   use shape_geometry, only: shape_bounds
   use time_table, only: time_table_t, read_time_table
   use csv_table, only: beside
   use input_text, only: group_context, int_text, real_text
   implicit none
   private

   integer, parameter, public :: motion_kind_none = 0, motion_kind_solitary = 1, motion_kind_table = 2, &
                                 motion_kind_waves = 3

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
      type(time_table_t) :: table        !< table: the displacement, columns x, y[, z] (world frame)
      type(paddle_signal_t) :: signal    !< waves: the stroke along `direction` [m]
      real(rp) :: record = 0.0_rp        !< waves: the time after which the stroke repeats [s]
   contains
      procedure :: displacement => motion_displacement
      procedure :: mean_velocity => motion_mean_velocity
      procedure :: max_speed => motion_max_speed
      procedure :: moving => motion_moving
      procedure :: stroke => motion_stroke
      procedure :: end_time => motion_end_time
      procedure :: oscillates => motion_oscillates
   end type wall_motion_t

   public :: solitary_motion, prescribed_motion, load_motion_tables, box_excursion

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

   !> The motion `spec` of a `&wall` or a `&structure` (validated) under the world gravity vector `gravity`
   !> of a `dim`-D scene; `direction` (world, any length) the solitary stroke's (a wall's normal, a
   !> structure's motion_direction); `table` the table of its motion_file (load_motion_tables).
   pure function prescribed_motion(spec, direction, gravity, dim, table) result(motion)
      type(motion_spec_t), intent(in) :: spec
      real(rp), intent(in) :: direction(3), gravity(3)
      integer, intent(in) :: dim
      type(time_table_t), intent(in), optional :: table
      type(wall_motion_t) :: motion
      real(rp) :: unit(3), g
      if (spec%kind == motion_table .and. present(table)) then
         motion%kind = motion_kind_table
         motion%table = table
         return
      end if
      ! the other motions have no direction of their own (it may be zero)
      if (spec%kind /= motion_solitary_wave .and. spec%kind /= motion_regular_wave .and. &
          spec%kind /= motion_irregular_wave) return
      unit = 0.0_rp
      unit(1:dim) = direction(1:dim) / norm2(direction(1:dim))
      g = norm2(gravity(1:dim))
      select case (spec%kind)
      case (motion_solitary_wave)
         motion = solitary_motion(unit, spec%start, spec%wave_height, spec%water_depth, g)
      case (motion_regular_wave)
         call waves_along(unit, spec%wave_period)
         motion%signal = regular_signal(spec%wave_height, spec%wave_period, spec%water_depth, g, spec%wave_order, &
                                        spec%start, spec%ramp_time)
      case (motion_irregular_wave)
         call waves_along(unit, spec%wave_duration)
         motion%signal = irregular_signal(spec%significant_wave_height, spec%peak_period, &
                                          merge(1.0_rp, spec%gamma, spec%spectrum == spectrum_pierson_moskowitz), &
                                          spec%wave_duration, spec%wave_seed, spec%water_depth, g, spec%start, &
                                          spec%ramp_time)
      end select

   contains

      !> A piston's waves along `along`, repeating after `record` seconds.
      pure subroutine waves_along(along, record)
         real(rp), intent(in) :: along(3), record
         motion%kind = motion_kind_waves
         motion%direction = along
         motion%start = spec%start
         motion%record = record
      end subroutine waves_along
   end function prescribed_motion

   !> The wall goes back and forth (a piston's waves): its stroke reaches `stroke` either way.
   pure logical function motion_oscillates(self)
      class(wall_motion_t), intent(in) :: self
      motion_oscillates = self%kind == motion_kind_waves
   end function motion_oscillates

   !> The wall moves at all (a fixed wall keeps its nodes and its arithmetic).
   pure logical function motion_moving(self)
      class(wall_motion_t), intent(in) :: self
      motion_moving = self%kind /= motion_kind_none
   end function motion_moving

   !> Length of the whole motion along `direction` [m] (solitary: S; waves: the largest |X| either way).
   pure real(rp) function motion_stroke(self) result(stroke)
      class(wall_motion_t), intent(in) :: self
      stroke = 0.0_rp
      if (self%kind == motion_kind_solitary) stroke = paddle_position(self, solitary_theta0)
      if (self%kind == motion_kind_waves) stroke = self%signal%extent(self%record)
      if (self%kind == motion_kind_table) stroke = maxval(norm2(self%table%values, dim=1))
   end function motion_stroke

   !> The time the motion ends [s] (the wall is at rest after it).
   pure real(rp) function motion_end_time(self) result(t)
      class(wall_motion_t), intent(in) :: self
      t = self%start
      if (self%kind == motion_kind_solitary) &
         t = self%start + time_of_theta(self, solitary_theta0)
      if (self%kind == motion_kind_table) t = self%table%time(size(self%table%time))
      if (self%kind == motion_kind_waves) t = huge(1.0_rp)
   end function motion_end_time

   !> Displacement from the scene position at time t, world frame [m].
   pure function motion_displacement(self, t) result(d)
      class(wall_motion_t), intent(in) :: self
      real(rp), intent(in) :: t
      real(rp) :: d(3)
      d = 0.0_rp
      if (self%kind == motion_kind_solitary) d = paddle_position(self, theta_at(self, t)) * self%direction
      if (self%kind == motion_kind_table) d(1:size(self%table%values, 1)) = self%table%value_at(t)
      if (self%kind == motion_kind_waves) d = self%signal%displacement(t) * self%direction
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
      integer :: i
      speed = 0.0_rp
      if (self%kind == motion_kind_table) then
         ! the steepest row interval that overlaps [t0, t1]
         associate (time => self%table%time, values => self%table%values)
            do i = 1, size(time) - 1
               if (time(i + 1) <= t0 .or. time(i) > t1) cycle
               speed = max(speed, norm2(values(:, i + 1) - values(:, i)) / (time(i + 1) - time(i)))
            end do
         end associate
         return
      end if
      if (self%kind == motion_kind_waves .and. t1 > self%start) speed = self%signal%speed_bound()
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

   !> Rank 0, after validate_scene: read the table of every `&wall` and `&structure` with motion = 'table'
   !> into scene%wall_tables / scene%structure_tables (columns x, y[, z]: the displacement from the place
   !> in the scene), check that no row drives the wall's point or the structure's shape out of the scene
   !> box, set motion_file to the absolute path read and motion_checksum (a given one must match). A
   !> relative motion_file is relative to the scene file.
   subroutine load_motion_tables(scene, label, status)
      type(scene_t), intent(inout) :: scene
      character(len=*), intent(in) :: label
      type(status_t), intent(inout) :: status
      real(rp) :: lower(3), upper(3)
      integer :: w, s
      if (allocated(scene%walls)) then
         if (allocated(scene%wall_tables)) deallocate (scene%wall_tables)
         allocate (scene%wall_tables(size(scene%walls)))
         do w = 1, size(scene%walls)
            associate (wall => scene%walls(w))
               if (wall%motion%kind /= motion_table) cycle
               call load_motion_table(scene%source_file, scene%grid, group_context(label, 'wall', w, named(wall%name)), &
                                      'wall', wall%point, wall%point, wall%motion, scene%wall_tables(w), status)
            end associate
            if (.not. status%ok) return
         end do
      end if
      if (.not. allocated(scene%structures)) return
      if (allocated(scene%structure_tables)) deallocate (scene%structure_tables)
      allocate (scene%structure_tables(size(scene%structures)))
      do s = 1, size(scene%structures)
         associate (structure => scene%structures(s))
            if (structure%motion%kind /= motion_table) cycle
            call shape_bounds(structure_shape(structure, scene%grid%dim), scene%grid%dim, lower, upper)
            call load_motion_table(scene%source_file, scene%grid, group_context(label, 'structure', s, &
                                   named(structure%name)), 'structure', lower, upper, structure%motion, &
                                   scene%structure_tables(s), status)
         end associate
         if (.not. status%ok) return
      end do
   end subroutine load_motion_tables

   !> The table of one motion (load_motion_tables) of a scene read from `source_file` with the scene box
   !> of `grid`: `context` the group's, `what` 'wall' (its point lower = upper) or 'structure' (its world
   !> bounding box lower..upper at rest).
   subroutine load_motion_table(source_file, grid, context, what, lower, upper, spec, table, status)
      character(len=*), intent(in) :: source_file
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: context, what
      real(rp), intent(in) :: lower(3), upper(3)
      type(motion_spec_t), intent(inout) :: spec
      type(time_table_t), intent(out) :: table
      type(status_t), intent(inout) :: status
      character(len=*), parameter :: axes(3) = ['x', 'y', 'z']
      character(len=:), allocatable :: where, excursion
      character(len=1024) :: message
      integer :: dim, r

      dim = grid%dim
      where = context//": variable motion_file = '"//trim(spec%file)//"'"
      call read_time_table(beside(source_file, trim(spec%file)), axes(1:dim), table, message)
      if (len_trim(message) > 0) then
         call status%fail(where//': '//trim(message))
         return
      end if
      if (len_trim(spec%checksum) > 0 .and. trim(spec%checksum) /= table%checksum) then
         call status%fail(where//': '//trim(table%path)//": the table does not match motion_checksum = '"// &
                          trim(spec%checksum)//"' (the file gives '"//table%checksum// &
                          "'): the file changed since the scene was written")
         return
      end if
      ! the motion is rigid: the point (the shape's box) stays in the scene box at every row, linear in between
      do r = 1, size(table%time)
         excursion = box_excursion(grid, what, lower, upper, table%values(1:dim, r))
         if (len(excursion) > 0) then
            call status%fail(where//': the motion drives the '//what//' out of the scene box of &grid: at t = '// &
                             real_text(table%time(r))//' s '//excursion)
            return
         end if
      end do
      if (len_trim(table%path) > path_len) then
         call status%fail(where//': the path is longer than '//int_text(path_len)//' characters')
         return
      end if
      spec%file = table%path
      spec%checksum = table%checksum
   end subroutine load_motion_table

   !> Where a wall's point (`what` = 'wall', lower = upper) or a structure's world box lower..upper (at
   !> rest), moved by the displacement d(1:dim), leaves the scene box of `grid`: "its point(k) reaches v, the
   !> box is a .. b" or "it spans x = v .. w, the box is a .. b" for the first axis out; '' when inside.
   function box_excursion(grid, what, lower, upper, d) result(text)
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: what
      real(rp), intent(in) :: lower(3), upper(3), d(:)
      character(len=:), allocatable :: text
      character(len=*), parameter :: axes(3) = ['x', 'y', 'z']
      real(rp) :: tolerance, low, high, box_lower, box_upper
      integer :: k
      text = ''
      tolerance = 1.0e-9_rp * grid%cell_size
      do k = 1, grid%dim
         low = lower(k) + d(k)
         high = upper(k) + d(k)
         box_lower = grid%origin(k)
         box_upper = grid%origin(k) + grid%extent(k)
         if (low >= box_lower - tolerance .and. high <= box_upper + tolerance) cycle
         if (what == 'wall') then
            text = 'its point('//int_text(k)//') reaches '//real_text(low)
         else
            text = 'it spans '//axes(k)//' = '//real_text(low)//' .. '//real_text(high)
         end if
         text = text//', the box is '//real_text(box_lower)//' .. '//real_text(box_upper)
         return
      end do
   end function box_excursion

   !> "name 'paddle'" (every wall and structure has a name once the scene is resolved; '' before).
   pure function named(name) result(detail)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: detail
      detail = ''
      if (len_trim(name) > 0) detail = "name '"//trim(name)//"'"
   end function named

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
