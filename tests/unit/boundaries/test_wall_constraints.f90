!> Unit tests of the node constraint of src/boundaries/boundary_walls.f90 (issue 15): Coulomb friction
!> on a node approaching a surface at an angle, no reversal under large friction, separating nodes left
!> alone, and a structure whose nodes each carry their own normal.
module test_wall_constraints
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use boundary_walls, only: wall_t, unilateral_velocity, apply_wall_constraints, wall_kind_friction, wall_kind_slip
   implicit none
   private

   public :: test_friction_on_an_approaching_node, test_large_friction_does_not_reverse, &
             test_separating_node_is_untouched, test_structure_nodes_carry_their_normals

   real(rp), parameter :: tolerance = 1.0e-14_rp

contains

   !> One node of mass 2 constrained by a planar friction wall of normal n; its impulse recorded.
   function friction_wall(n, mu) result(wall)
      real(rp), intent(in) :: n(2), mu
      type(wall_t) :: wall
      wall%normal(1:2) = n
      wall%kind = wall_kind_friction
      wall%friction = mu
      wall%nodes = [1]
      wall%counted = [.true.]
      allocate (wall%arm(3, 1))
      wall%arm = 0.0_rp
   end function friction_wall

   !> v = (3, -4) on a floor (n = (0, 1)), mu = 0.5: v_n = -4 removed, v_t = 3 shortened by 0.5 x 4 = 2 to 1;
   !> the same on a surface turned by 30 degrees; the recorded impulse is m (v^c - v).
   subroutine test_friction_on_an_approaching_node()
      type(wall_t) :: walls(1)
      real(rp) :: v(2, 1), impulse(6, 1), n(2), t(2), c, s
      call assertEqual([1.0_rp, 0.0_rp], unilateral_velocity([3.0_rp, -4.0_rp], [0.0_rp, 1.0_rp], 0.5_rp), &
                       tolerance, 'floor: normal part removed, tangential 3 - 0.5 x 4')
      c = cos(acos(-1.0_rp) / 6.0_rp)
      s = sin(acos(-1.0_rp) / 6.0_rp)
      n = [-s, c]
      t = [c, s]
      walls(1) = friction_wall(n, 0.5_rp)
      v(:, 1) = 3.0_rp * t - 4.0_rp * n
      impulse = 0.0_rp
      call apply_wall_constraints(walls, 2, v, [2.0_rp], impulse)
      call assertEqual(1.0_rp * t, v(:, 1), tolerance, 'turned surface: v = (3 - 0.5 x 4) t')
      call assertEqual(2.0_rp * (1.0_rp * t - (3.0_rp * t - 4.0_rp * n)), impulse(1:2, 1), 1.0e-13_rp, &
                       'impulse m (v^c - v)')
   end subroutine test_friction_on_an_approaching_node

   !> mu |v_n| >= |v_t|: the node sticks (v = 0), it is not pushed backwards; mu = 0 is the slip of eq. 14.
   subroutine test_large_friction_does_not_reverse()
      call assertEqual([0.0_rp, 0.0_rp], unilateral_velocity([3.0_rp, -4.0_rp], [0.0_rp, 1.0_rp], 2.0_rp), &
                       tolerance, 'mu = 2: sticks')
      call assertEqual([0.0_rp, 0.0_rp], unilateral_velocity([3.0_rp, -4.0_rp], [0.0_rp, 1.0_rp], 0.75_rp), &
                       tolerance, 'mu |v_n| = |v_t|: sticks exactly')
      call assertEqual([3.0_rp, 0.0_rp], unilateral_velocity([3.0_rp, -4.0_rp], [0.0_rp, 1.0_rp], 0.0_rp), &
                       tolerance, 'mu = 0: slip')
      call assertEqual([0.0_rp, 0.0_rp, 0.0_rp], unilateral_velocity([0.0_rp, 0.0_rp, -1.0_rp], &
                                                                     [0.0_rp, 0.0_rp, 1.0_rp], 0.3_rp), &
                       tolerance, '3-D, head-on: stops, no tangential direction needed')
   end subroutine test_large_friction_does_not_reverse

   !> v.n >= 0: the material leaves the surface or slides along it; no change, no impulse.
   subroutine test_separating_node_is_untouched()
      type(wall_t) :: walls(1)
      real(rp) :: v(2, 1), impulse(6, 1)
      walls(1) = friction_wall([0.0_rp, 1.0_rp], 0.5_rp)
      v(:, 1) = [3.0_rp, 4.0_rp]
      impulse = 0.0_rp
      call apply_wall_constraints(walls, 2, v, [2.0_rp], impulse)
      call assertEqual([3.0_rp, 4.0_rp], v(:, 1), 0.0_rp, 'leaving: untouched')
      call assertEqual(0.0_rp, maxval(abs(impulse)), 0.0_rp, 'leaving: no impulse')
      v(:, 1) = [3.0_rp, 0.0_rp]
      call apply_wall_constraints(walls, 2, v, [2.0_rp], impulse)
      call assertEqual([3.0_rp, 0.0_rp], v(:, 1), 0.0_rp, 'sliding along it (v.n = 0): untouched, no friction')
   end subroutine test_separating_node_is_untouched

   !> A structure (shaped) constrains each node along that node's own normal: two nodes on opposite sides,
   !> both approaching, each loses its own inward part; the moment of the impulses about the centre.
   subroutine test_structure_nodes_carry_their_normals()
      type(wall_t) :: walls(1)
      real(rp) :: v(2, 2), impulse(6, 1)
      walls(1)%shaped = .true.
      walls(1)%kind = wall_kind_slip
      walls(1)%nodes = [1, 2]
      walls(1)%counted = [.true., .false.]
      walls(1)%node_normal = reshape([1.0_rp, 0.0_rp, -1.0_rp, 0.0_rp], [2, 2])
      allocate (walls(1)%arm(3, 2))
      walls(1)%arm = reshape([1.0_rp, 0.0_rp, 0.0_rp, -1.0_rp, 0.0_rp, 0.0_rp], [3, 2])
      v = reshape([-1.0_rp, 2.0_rp, 1.0_rp, 2.0_rp], [2, 2])
      impulse = 0.0_rp
      call apply_wall_constraints(walls, 2, v, [1.0_rp, 1.0_rp], impulse)
      call assertEqual([0.0_rp, 2.0_rp], v(:, 1), 0.0_rp, 'node on the +x side: -x part removed')
      call assertEqual([0.0_rp, 2.0_rp], v(:, 2), 0.0_rp, 'node on the -x side: +x part removed')
      call assertEqual([1.0_rp, 0.0_rp], impulse(1:2, 1), 0.0_rp, 'only the counted node adds its impulse')
      call assertTrue(abs(impulse(6, 1)) <= 0.0_rp, 'a radial impulse has no moment about the centre')
   end subroutine test_structure_nodes_carry_their_normals
end module test_wall_constraints
