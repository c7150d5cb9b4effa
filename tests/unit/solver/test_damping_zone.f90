!> The damping zones of `&damping_zone` (src/solver/damping_zone.f90, docs/theory.md section 3.9):
!>  - the ramp: s = 0 at the zone's inner face, 1 at its outer one, quadratic rate between; -1 outside;
!>    'x-' mirrors 'x+'; 'none' is 1 everywhere inside; the factor is exp(-rate s^2 dt);
!>  - a block of water moving uniformly through free space (no walls, no gravity, so nothing else changes
!>    its velocity) inside a zone with ramp 'none': its velocity relaxes as v_t + (v0 - v_t) exp(-rate t),
!>    the exact solution of dv/dt = -rate (v - v_t), to round-off at every step and on 1 and 2 ranks,
!>    whatever the step (the factor is exact per step); a block beside the zone keeps its velocity.
module test_damping_zone
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm
   use assertions, only: assertTrue, assertEqual, assertRelativelyEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, wall_none
   use damping_zone_group, only: damping_zone_spec_t
   use damping_zone, only: ramp_place, damping_factor
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use test_scenes, only: water_scene, add_body
   use input_text, only: real_text
   implicit none
   private

   public :: test_ramp_and_factor, test_uniform_flow_relaxes_exactly

contains

   subroutine test_ramp_and_factor(comm)
      type(MPI_Comm), intent(in) :: comm
      type(damping_zone_spec_t) :: zone
      zone%lower = [6.0_rp, -1.0_rp, 0.0_rp]
      zone%upper = [8.0_rp, 1.0_rp, 0.0_rp]
      zone%rate = 5.0_rp
      zone%ramp = 'x+'
      call assertEqual(ramp_place(zone, [6.0_rp, 0.0_rp], 2), 0.0_rp, 'inner face: s = 0')
      call assertEqual(ramp_place(zone, [7.5_rp, 0.5_rp], 2), 0.75_rp, 'x+: s = (x - lower) / length')
      call assertEqual(ramp_place(zone, [8.0_rp, 1.0_rp], 2), 1.0_rp, 'outer face: s = 1')
      call assertEqual(ramp_place(zone, [5.9_rp, 0.0_rp], 2), -1.0_rp, 'before the zone: outside')
      call assertEqual(ramp_place(zone, [7.0_rp, 1.5_rp], 2), -1.0_rp, 'above the zone: outside')
      zone%ramp = 'x-'
      call assertEqual(ramp_place(zone, [7.5_rp, 0.5_rp], 2), 0.25_rp, 'x- mirrors x+')
      zone%ramp = 'y+'
      call assertEqual(ramp_place(zone, [7.5_rp, 0.5_rp], 2), 0.75_rp, 'y+ along y')
      zone%ramp = 'none'
      call assertEqual(ramp_place(zone, [6.5_rp, -0.5_rp], 2), 1.0_rp, 'none: the full rate everywhere inside')
      call assertRelativelyEqual(damping_factor(5.0_rp, 0.5_rp, 0.01_rp), exp(-5.0_rp * 0.25_rp * 0.01_rp), 1.0e-15_rp, &
                                 'factor exp(-rate s^2 dt)')
      call assertEqual(damping_factor(5.0_rp, 0.0_rp, 0.01_rp), 1.0_rp, 'no damping at the inner face')
   end subroutine test_ramp_and_factor

   !> Two blocks of water moving at v0 = (0.5, -0.2) m/s in a 4 x 2 m box without walls or gravity; a zone
   !> (ramp 'none', rate 2 /s, target (0.1, 0)) holds the left one for the whole run, the right one lies
   !> beside it.
   subroutine test_uniform_flow_relaxes_exactly(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp), parameter :: v0(2) = [0.5_rp, -0.2_rp], target(2) = [0.1_rp, 0.0_rp], rate = 2.0_rp
      real(rp) :: v(2), expected, inside, beside
      integer :: step, p

      scene = water_scene(2, 0.1_rp, [4.0_rp, 2.0_rp, 1.0_rp], 2.0e5_rp, 0.0_rp)
      scene%grid%wall(:, 1:2) = wall_none
      call add_body(scene, 1, [0.4_rp, 0.6_rp, 0.0_rp], [1.2_rp, 1.4_rp, 0.0_rp], 2, .false., 0.0_rp)
      call add_body(scene, 1, [2.6_rp, 0.6_rp, 0.0_rp], [3.4_rp, 1.4_rp, 0.0_rp], 2, .false., 0.0_rp)
      scene%bodies(1)%velocity(1:2) = v0
      scene%bodies(2)%velocity(1:2) = v0
      allocate (scene%damping_zones(1))
      scene%damping_zones(1)%name = 'zone'
      scene%damping_zones(1)%lower = [0.0_rp, 0.0_rp, 0.0_rp]
      scene%damping_zones(1)%upper = [2.0_rp, 2.0_rp, 0.0_rp]
      scene%damping_zones(1)%rate = rate
      scene%damping_zones(1)%ramp = 'none'
      scene%damping_zones(1)%target_velocity(1:2) = target
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'init: '//trim(status%message))
      do step = 1, 400
         call solver%advance()
         inside = 0.0_rp
         beside = 0.0_rp
         do p = 1, solver%particles%count
            v = solver%particles%v(1:2, p)
            if (solver%particles%x(1, p) < 2.0_rp) then
               ! the exact relaxation at t_{n+1}: each step multiplies v - v_t by exp(-rate dt)
               expected = maxval(abs(v - (target + (v0 - target) * exp(-rate * solver%time))))
               inside = max(inside, expected)
            else
               beside = max(beside, maxval(abs(v - v0)))
            end if
         end do
         call assertTrue(inside < 1.0e-12_rp, 'inside: v = v_t + (v0 - v_t) exp(-rate t), off by '//real_text(inside))
         call assertTrue(beside < 1.0e-12_rp, 'beside the zone: v = v0, off by '//real_text(beside))
         if (solver%time > 0.5_rp) exit
      end do
      call assertTrue(solver%time > 0.5_rp, 'ran to 0.5 s')
      call solver%free()
   end subroutine test_uniform_flow_relaxes_exactly
end module test_damping_zone
