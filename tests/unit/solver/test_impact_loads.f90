!> Loads, gauges and bodies (issue 13) against loads known exactly, on 1, 2 and 4 ranks:
!>  - a tank of water at rest: each side wall carries rho g H^2 / 2 (and rho g H^2 / 2 times the width
!>    in 3-D), the floor the weight, the moment about the floor rho g H^3 / 6;
!>  - momentum balance of a collapsing column: the walls' impulses plus gravity's are the change of
!>    the particles' momentum, to round-off (every constraint is accounted for);
!>  - gauges read a linear pressure and velocity field exactly, also on a wall (half the disc empty),
!>    and a level gauge the top of a column; an empty gauge reads 0 with 0 samples;
!>  - a solid body turned and moved rigidly: centroid, angle (2-D) and rotation vector (3-D) exactly,
!>    and the force (P - P_prev) / dt - M g.
module test_impact_loads
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use assertions, only: assertTrue, assertEqual, assertRelativelyEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, gauge_spec_t, wall_none, gauge_pressure, gauge_level, gauge_velocity, &
                                gauge_connected_level, &
                                model_linear_elastic
   use mpm_solver, only: solver_t
   use body_motion, only: body_state_t
   use test_scenes, only: water_scene, add_body
   use input_text, only: real_text
   implicit none
   private

   public :: test_hydrostatic_wall_loads_2d, test_hydrostatic_wall_loads_3d, test_wall_impulses_balance_momentum, &
             test_gauges_read_linear_fields, test_connected_level_ignores_spray, &
             test_rigid_body_motion_2d, test_rigid_body_motion_3d

   real(rp), parameter :: rho = 1000.0_rp, g = 9.81_rp

contains

   !> Water of depth `depth` at rest (hydrostatic start) filling the box's width; steps advanced.
   subroutine settled_tank(comm, dim, extent, depth, steps, solver, mean_row)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim, steps
      real(rp), intent(in) :: extent(3), depth
      type(solver_t), intent(inout) :: solver
      real(rp), allocatable, intent(out) :: mean_row(:)
      type(scene_t) :: scene
      type(status_t) :: status
      real(rp) :: upper(3), start
      integer :: step
      scene = water_scene(dim, 0.05_rp, extent, 2.0e7_rp, g)
      scene%grid%wall(2, dim) = wall_none
      upper = extent
      upper(dim) = depth
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], upper, 2, .true., depth)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'tank: '//trim(status%message))
      start = solver%time
      do step = 1, steps
         call solver%advance()
      end do
      mean_row = solver%loads%row_values(solver%grid%frame, solver%time - start, solver%domain%comm, solver%domain%nranks)
   end subroutine settled_tank

   subroutine test_hydrostatic_wall_loads_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: solver
      real(rp), allocatable :: row(:)
      real(rp) :: depth
      depth = 0.5_rp
      call settled_tank(comm, 2, [1.0_rp, 1.0_rp, 0.0_rp], depth, 40, solver, row)
      ! entries: x_min, x_max, y_min (fx, fy, mz each); the material pushes x_min towards -x
      call assertEqual(9, size(row), 'columns of x_min, x_max, y_min')
      call assertRelativelyEqual(-rho * g * depth**2 / 2, row(1), 1.0e-3_rp, 'x_min fx = -rho g H^2 / 2')
      call assertRelativelyEqual(rho * g * depth**2 / 2, row(4), 1.0e-3_rp, 'x_max fx = rho g H^2 / 2')
      call assertRelativelyEqual(-rho * g * depth * 1.0_rp, row(8), 1.0e-6_rp, 'floor fy = -weight')
      ! about the x_min side's lower corner (the origin): z . (y e_y x (-p e_x)) = y p
      call assertRelativelyEqual(rho * g * depth**3 / 6, row(3), 2.0e-3_rp, 'x_min mz = rho g H^3 / 6')
      call assertTrue(abs(row(2)) <= 1.0e-9_rp * abs(row(1)), 'a slip wall takes no tangential force')
      call solver%free()
   end subroutine test_hydrostatic_wall_loads_2d

   subroutine test_hydrostatic_wall_loads_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: solver
      real(rp), allocatable :: row(:)
      real(rp) :: depth, width(3)
      depth = 0.3_rp
      width = [0.4_rp, 0.3_rp, 0.6_rp]
      call settled_tank(comm, 3, width, depth, 10, solver, row)
      ! entries: x_min, x_max, y_min, y_max, z_min (6 columns each)
      call assertEqual(30, size(row), 'columns of five sides')
      call assertRelativelyEqual(-rho * g * depth**2 / 2 * width(2), row(1), 1.0e-3_rp, 'x_min fx')
      call assertRelativelyEqual(rho * g * depth**2 / 2 * width(1), row(20), 1.0e-3_rp, 'y_max fy')
      call assertRelativelyEqual(-rho * g * depth * width(1) * width(2), row(27), 1.0e-6_rp, 'floor fz = -weight')
      call solver%free()
   end subroutine test_hydrostatic_wall_loads_3d

   !> Particles' momentum now (grid frame), summed over the ranks.
   function total_momentum(solver) result(p)
      type(solver_t), intent(in) :: solver
      real(rp) :: p(solver%grid%dim)
      integer :: k
      do k = 1, solver%grid%dim
         p(k) = sum(solver%particles%mass(1:solver%particles%count) * solver%particles%v(k, 1:solver%particles%count))
      end do
      call MPI_Allreduce(MPI_IN_PLACE, p, size(p), MPI_DOUBLE_PRECISION, MPI_SUM, solver%domain%comm)
   end function total_momentum

   subroutine test_wall_impulses_balance_momentum(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp) :: before(2), after(2), mass, walls(2), gravity_impulse(2), t0
      real(rp), allocatable :: row(:)
      integer :: step, e
      scene = water_scene(2, 0.05_rp, [1.0_rp, 0.6_rp, 0.0_rp], 2.0e6_rp, g)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [0.4_rp, 0.4_rp, 0.0_rp], 2, .false., 0.0_rp)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'column: '//trim(status%message))
      ! let it reach the far wall and the ceiling-free corners, then balance over a stretch of steps
      do step = 1, 400
         call solver%advance()
      end do
      mass = rho * 0.4_rp * 0.4_rp
      before = total_momentum(solver)
      solver%loads%impulse = 0.0_rp
      t0 = solver%time
      do step = 1, 200
         call solver%advance()
      end do
      after = total_momentum(solver)
      ! row values are the material's force on each wall: the walls gave -row * interval
      row = solver%loads%row_values(solver%grid%frame, 1.0_rp, solver%domain%comm, solver%domain%nranks)
      walls = 0.0_rp
      do e = 1, size(row) / 3
         walls = walls - row(3 * e - 2:3 * e - 1)
      end do
      gravity_impulse = mass * [0.0_rp, -g] * (solver%time - t0)
      call assertTrue(abs(walls(1)) > 1.0_rp, 'the walls push: '//real_text(walls(1)))
      call assertTrue(all(abs(after - before - walls - gravity_impulse) <= 1.0e-9_rp * mass * g * (solver%time - t0)), &
                      'dP = wall impulses + gravity impulse: residual '//real_text(maxval(abs(after - before - walls - &
                                                                                                  gravity_impulse))))
      call solver%free()
   end subroutine test_wall_impulses_balance_momentum

   subroutine test_gauges_read_linear_fields(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp), allocatable :: values(:)
      real(rp) :: p0, grad(2), v0(2), dv(2, 2), x(2), p
      integer :: i
      scene = water_scene(2, 0.1_rp, [2.0_rp, 1.0_rp, 0.0_rp], 2.0e6_rp, g)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [2.0_rp, 0.6_rp, 0.0_rp], 2, .false., 0.0_rp)
      allocate (scene%gauges(5))
      scene%gauges(1) = gauge_spec_t(name='inside', kind=gauge_pressure, point=[0.73_rp, 0.31_rp, 0.0_rp], radius=0.1_rp)
      scene%gauges(2) = gauge_spec_t(name='wall', kind=gauge_pressure, point=[2.0_rp, 0.25_rp, 0.0_rp], radius=0.1_rp)
      scene%gauges(3) = gauge_spec_t(name='flow', kind=gauge_velocity, point=[0.0_rp, 0.4_rp, 0.0_rp], radius=0.1_rp)
      scene%gauges(4) = gauge_spec_t(name='eta', kind=gauge_level, point=[1.0_rp, 0.0_rp, 0.0_rp], radius=0.05_rp)
      scene%gauges(5) = gauge_spec_t(name='dry', kind=gauge_pressure, point=[1.0_rp, 0.9_rp, 0.0_rp], radius=0.1_rp)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'gauge scene: '//trim(status%message))
      ! a linear pressure and velocity field on the particles (sbar = -p / rho on the normal components)
      p0 = 5000.0_rp
      grad = [300.0_rp, -9810.0_rp]
      v0 = [0.5_rp, -0.2_rp]
      dv = reshape([0.1_rp, 0.3_rp, -0.7_rp, 0.2_rp], [2, 2])
      do i = 1, solver%particles%count
         x = solver%particles%x(:, i)
         p = p0 + dot_product(grad, x)
         solver%particles%sbar(:, i) = 0.0_rp
         solver%particles%sbar(1:3, i) = -p / solver%particles%density(i)
         solver%particles%v(:, i) = v0 + matmul(dv, x)
      end do
      values = solver%gauges%sample(solver%particles, solver%materials, solver%grid%frame, solver%domain%comm, &
                                    solver%loads%sensor_pressure)
      ! inside: p, samples; wall: p, samples; flow: vx, vy, samples; eta: level, samples; dry: p, samples
      call assertEqual(11, size(values), 'gauge columns')
      call assertRelativelyEqual(p0 + dot_product(grad, [0.73_rp, 0.31_rp]), values(1), 1.0e-10_rp, 'pressure inside')
      call assertTrue(values(2) >= 8.0_rp, 'particles in the disc')
      call assertRelativelyEqual(p0 + dot_product(grad, [2.0_rp, 0.25_rp]), values(3), 1.0e-10_rp, 'pressure on the wall')
      call assertRelativelyEqual(v0(1) + dot_product(dv(1, :), [0.0_rp, 0.4_rp]), values(5), 1.0e-10_rp, 'vx on the wall')
      call assertRelativelyEqual(v0(2) + dot_product(dv(2, :), [0.0_rp, 0.4_rp]), values(6), 1.0e-10_rp, 'vy on the wall')
      ! the column's particle tops: the body's upper side
      call assertRelativelyEqual(0.6_rp, values(8), 1.0e-12_rp, 'level = depth')
      call assertTrue(values(9) > 0.0_rp, 'particles in the column')
      call assertTrue(values(10) == 0.0_rp .and. values(11) == 0.0_rp, 'a dry gauge reads 0 with 0 samples')
      call solver%free()
   end subroutine test_gauges_read_linear_fields

   !> A level gauge reads the highest fluid in its column, a connected_level gauge the water standing on
   !> its point: a blob a few centimetres above the surface (a gap under one cell) counts, spray 0.3 m
   !> above it does not. Tank of 0.6 m at h = 0.1 m (particles 0.05 m), the gauges' column x = 0.95-1.05.
   subroutine test_connected_level_ignores_spray(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp), allocatable :: values(:)
      integer :: i
      scene = water_scene(2, 0.1_rp, [2.0_rp, 1.0_rp, 0.0_rp], 2.0e6_rp, g)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [2.0_rp, 0.6_rp, 0.0_rp], 2, .false., 0.0_rp)
      allocate (scene%gauges(3))
      scene%gauges(1) = gauge_spec_t(name='top', kind=gauge_level, point=[1.0_rp, 0.0_rp, 0.0_rp], radius=0.05_rp)
      scene%gauges(2) = gauge_spec_t(name='wire', kind=gauge_connected_level, point=[1.0_rp, 0.0_rp, 0.0_rp], &
                                     radius=0.05_rp)
      scene%gauges(3) = gauge_spec_t(name='dry', kind=gauge_connected_level, point=[1.0_rp, 0.75_rp, 0.0_rp], &
                                     radius=0.05_rp)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'spray scene: '//trim(status%message))
      ! of the column's two particles per row, move one of the top row up as spray (0.925-0.975 m) and
      ! one of the row below to a blob just above the surface (0.635-0.685 m); the other keeps each row wet
      do i = 1, solver%particles%count
         associate (x => solver%particles%x(:, i))
            if (abs(x(1) - 0.975_rp) < 1.0e-6_rp .and. abs(x(2) - 0.575_rp) < 1.0e-6_rp) x(2) = 0.95_rp
            if (abs(x(1) - 1.025_rp) < 1.0e-6_rp .and. abs(x(2) - 0.525_rp) < 1.0e-6_rp) x(2) = 0.66_rp
         end associate
      end do
      values = solver%gauges%sample(solver%particles, solver%materials, solver%grid%frame, solver%domain%comm, &
                                    solver%loads%sensor_pressure)
      call assertEqual(6, size(values), 'level and samples of each gauge')
      call assertRelativelyEqual(0.975_rp, values(1), 1.0e-12_rp, 'level: the spray particle''s top')
      call assertRelativelyEqual(0.685_rp, values(3), 1.0e-12_rp, 'connected_level: the blob''s top, not the spray')
      call assertEqual(values(2), values(4), 'both saw the same particles')
      call assertTrue(values(5) == 0.0_rp, 'connected_level: 0 with no water within a cell above its point')
      call solver%free()
   end subroutine test_connected_level_ignores_spray

   !> A scene with one solid block (and no fluid body) for the body measurements.
   function block_scene(dim) result(scene)
      integer, intent(in) :: dim
      type(scene_t) :: scene
      scene = water_scene(dim, 0.1_rp, [2.0_rp, 2.0_rp, 2.0_rp], 2.0e6_rp, g)
      scene%materials = [scene%materials, scene%materials(1)]
      scene%materials(2)%name = 'wood'
      scene%materials(2)%model = model_linear_elastic
      scene%materials(2)%density = 500.0_rp
      scene%materials(2)%youngs_modulus = 1.0e7_rp
      scene%materials(2)%poisson_ratio = 0.25_rp
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [2.0_rp, 0.2_rp, 0.2_rp], 2, .false., 0.0_rp)
      call add_body(scene, 2, [0.6_rp, 0.6_rp, 0.6_rp], [1.0_rp, 0.8_rp, 1.2_rp], 2, .false., 0.0_rp)
   end function block_scene

   subroutine test_rigid_body_motion_2d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_rigid_motion(comm, 2)
   end subroutine test_rigid_body_motion_2d

   subroutine test_rigid_body_motion_3d(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_rigid_motion(comm, 3)
   end subroutine test_rigid_body_motion_3d

   !> Turn the block by a known rotation about its centre, move it, give it a velocity: the measured
   !> state must be that motion, and the row's force (P - P_prev) / dt - M g.
   subroutine check_rigid_motion(comm, dim)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: dim
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      type(body_state_t) :: state
      real(rp) :: r(3, 3), axis(3), angle, centre(3), shift(3), velocity(3), x(3), mass, dt
      real(rp), allocatable :: row(:)
      integer :: i, d
      scene = block_scene(dim)
      d = dim
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'block scene: '//trim(status%message))
      call assertEqual(1, solver%bodies%count(), 'the fluid body is not tracked')
      centre = [0.8_rp, 0.7_rp, 0.9_rp]
      shift = [0.15_rp, -0.05_rp, 0.1_rp]
      velocity = [1.5_rp, -0.5_rp, 0.25_rp]
      angle = 2.5_rp                          ! beyond pi / 2: the polar factor, not a small-angle guess
      axis = [0.0_rp, 0.0_rp, 1.0_rp]
      if (d == 3) axis = [1.0_rp, 2.0_rp, 2.0_rp] / 3.0_rp
      r = rotation_matrix(axis, angle)
      mass = 0.0_rp
      do i = 1, solver%particles%count
         if (solver%particles%material(i) /= 2) cycle
         x = 0.0_rp
         x(1:d) = solver%particles%x(:, i) - centre(1:d)
         x = matmul(r, x)
         solver%particles%x(:, i) = centre(1:d) + shift(1:d) + x(1:d)
         solver%particles%v(:, i) = velocity(1:d)
         mass = mass + solver%particles%mass(i)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, mass, 1, MPI_DOUBLE_PRECISION, MPI_SUM, solver%domain%comm)
      state = solver%bodies%measure(solver%particles, solver%grid%frame, solver%domain%comm)
      call assertRelativelyEqual(mass, state%mass(1), 1.0e-12_rp, 'body mass')
      do i = 1, d
         call assertTrue(abs(state%centroid(i, 1) - centre(i) - shift(i)) < 1.0e-12_rp, 'centroid')
         call assertTrue(abs(state%momentum(i, 1) - mass * velocity(i)) < 1.0e-10_rp * mass, 'momentum')
      end do
      dt = 0.01_rp
      row = solver%bodies%row_values(state, solver%grid%frame, dt)
      if (d == 2) then
         ! x, y, vx, vy, angle, fx, fy; the block started at rest: F = M v / dt - M g
         call assertTrue(abs(row(5) - angle) < 1.0e-12_rp, 'angle 2.5 rad: '//real_text(row(5)))
         call assertRelativelyEqual(mass * velocity(2) / dt + mass * g, row(7), 1.0e-12_rp, 'force fy')
      else
         ! x, y, z, vx, vy, vz, rx, ry, rz, fx, fy, fz
         call assertTrue(all(abs(row(7:9) - angle * axis) < 1.0e-10_rp), 'rotation vector 2.5 (1, 2, 2) / 3')
         call assertRelativelyEqual(mass * velocity(3) / dt + mass * g, row(12), 1.0e-12_rp, 'force fz')
      end if
      call solver%free()
   end subroutine check_rigid_motion

   !> Rodrigues: the rotation by `angle` about the unit vector `axis`.
   pure function rotation_matrix(axis, angle) result(r)
      real(rp), intent(in) :: axis(3), angle
      real(rp) :: r(3, 3), k(3, 3)
      integer :: i
      k = reshape([0.0_rp, axis(3), -axis(2), -axis(3), 0.0_rp, axis(1), axis(2), -axis(1), 0.0_rp], [3, 3])
      r = 0.0_rp
      do i = 1, 3
         r(i, i) = 1.0_rp
      end do
      r = r + sin(angle) * k + (1.0_rp - cos(angle)) * matmul(k, k)
   end function rotation_matrix
end module test_impact_loads
