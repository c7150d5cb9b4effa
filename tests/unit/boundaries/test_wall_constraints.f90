!> Unit tests of the node constraint of src/boundaries/constraint.f90 and wall_conditions.f90 (issue 15): Coulomb friction
!> on a node approaching a surface at an angle, no reversal under large friction, separating nodes left
!> alone, and a structure whose nodes each carry their own normal.
module test_wall_constraints
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue
   use surface_condition, only: unilateral_velocity
   use wall_conditions, only: friction_condition_t, slip_condition_t, condition_of
   use free_condition, only: free_condition_t
   use planar_wall, only: planar_wall_t
   use structure_surface, only: structure_surface_t
   use constraint_list, only: constraint_list_t
   implicit none
   private

   public :: test_friction_on_an_approaching_node, test_large_friction_does_not_reverse, &
             test_separating_node_is_untouched, test_structure_nodes_carry_their_normals, &
             test_free_wall_constrains_nothing

   real(rp), parameter :: tolerance = 1.0e-14_rp

contains

   !> One node of mass 2 constrained by a planar friction wall of normal n; its impulse recorded.
   function friction_wall(n, mu) result(walls)
      real(rp), intent(in) :: n(2), mu
      type(constraint_list_t) :: walls
      type(planar_wall_t) :: wall
      wall%normal(1:2) = n
      wall%normals = reshape(n, [2, 1])
      call wall%set_condition(friction_condition_t(mu=mu))
      wall%nodes = [1]
      wall%counted = [.true.]
      allocate (wall%arm(3, 1))
      wall%arm = 0.0_rp
      call walls%append(wall, 0)
   end function friction_wall

   !> v = (3, -4) on a floor (n = (0, 1)), mu = 0.5: v_n = -4 removed, v_t = 3 shortened by 0.5 x 4 = 2 to 1;
   !> the same on a surface turned by 30 degrees; the recorded impulse is m (v^c - v).
   subroutine test_friction_on_an_approaching_node()
      type(constraint_list_t) :: walls
      real(rp) :: v(2, 1), impulse(6, 1), n(2), t(2), c, s
      call assertEqual([1.0_rp, 0.0_rp], unilateral_velocity([3.0_rp, -4.0_rp], [0.0_rp, 1.0_rp], 0.5_rp), &
                       tolerance, 'floor: normal part removed, tangential 3 - 0.5 x 4')
      c = cos(acos(-1.0_rp) / 6.0_rp)
      s = sin(acos(-1.0_rp) / 6.0_rp)
      n = [-s, c]
      t = [c, s]
      walls = friction_wall(n, 0.5_rp)
      v(:, 1) = 3.0_rp * t - 4.0_rp * n
      impulse = 0.0_rp
      call walls%constrain(2, v, [2.0_rp], impulse)
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
      type(constraint_list_t) :: walls
      real(rp) :: v(2, 1), impulse(6, 1)
      walls = friction_wall([0.0_rp, 1.0_rp], 0.5_rp)
      v(:, 1) = [3.0_rp, 4.0_rp]
      impulse = 0.0_rp
      call walls%constrain(2, v, [2.0_rp], impulse)
      call assertEqual([3.0_rp, 4.0_rp], v(:, 1), 0.0_rp, 'leaving: untouched')
      call assertEqual(0.0_rp, maxval(abs(impulse)), 0.0_rp, 'leaving: no impulse')
      v(:, 1) = [3.0_rp, 0.0_rp]
      call walls%constrain(2, v, [2.0_rp], impulse)
      call assertEqual([3.0_rp, 0.0_rp], v(:, 1), 0.0_rp, 'sliding along it (v.n = 0): untouched, no friction')
   end subroutine test_separating_node_is_untouched

   !> A structure (shaped) constrains each node along that node's own normal: two nodes on opposite sides,
   !> both approaching, each loses its own inward part; the moment of the impulses about the centre.
   subroutine test_structure_nodes_carry_their_normals()
      type(constraint_list_t) :: walls
      type(structure_surface_t) :: structure
      real(rp) :: v(2, 2), impulse(6, 1)
      call structure%set_condition(slip_condition_t())
      structure%nodes = [1, 2]
      structure%counted = [.true., .false.]
      structure%normals = reshape([1.0_rp, 0.0_rp, -1.0_rp, 0.0_rp], [2, 2])
      allocate (structure%arm(3, 2))
      structure%arm = reshape([1.0_rp, 0.0_rp, 0.0_rp, -1.0_rp, 0.0_rp, 0.0_rp], [3, 2])
      call walls%append(structure, 1)
      v = reshape([-1.0_rp, 2.0_rp, 1.0_rp, 2.0_rp], [2, 2])
      impulse = 0.0_rp
      call walls%constrain(2, v, [1.0_rp, 1.0_rp], impulse)
      call assertEqual([0.0_rp, 2.0_rp], v(:, 1), 0.0_rp, 'node on the +x side: -x part removed')
      call assertEqual([0.0_rp, 2.0_rp], v(:, 2), 0.0_rp, 'node on the -x side: +x part removed')
      call assertEqual([1.0_rp, 0.0_rp], impulse(1:2, 1), 0.0_rp, 'only the counted node adds its impulse')
      call assertTrue(abs(impulse(6, 1)) <= 0.0_rp, 'a radial impulse has no moment about the centre')
   end subroutine test_structure_nodes_carry_their_normals

   !> condition = 'free' (the worked example of docs/conventions.md): the wall is never active, leaves an
   !> approaching node alone, records no impulse, lets fluid through; its neighbour in the list still acts.
   subroutine test_free_wall_constrains_nothing()
      type(constraint_list_t) :: walls
      type(planar_wall_t) :: wall
      real(rp) :: v(2, 1), impulse(6, 2)
      wall%normal(1:2) = [0.0_rp, 1.0_rp]
      wall%normals = reshape([0.0_rp, 1.0_rp], [2, 1])
      call wall%set_condition(condition_of('free', 0.0_rp))
      wall%nodes = [1]
      wall%counted = [.true.]
      allocate (wall%arm(3, 1))
      wall%arm = 0.0_rp
      call walls%append(wall, 0)
      call assertTrue(same_type_as(walls%items(1)%item%condition, free_condition_t()), "'free' makes a free condition")
      call walls%set_activity(0.0_rp)
      call assertTrue(.not. any(walls%activity()), 'a free wall is never active')
      call assertTrue(.not. walls%blocks_flow(1), 'a free wall lets fluid through')
      v(:, 1) = [1.0_rp, -3.0_rp]
      impulse = 0.0_rp
      call walls%constrain(2, v, [2.0_rp], impulse)
      call assertEqual([1.0_rp, -3.0_rp], v(:, 1), 0.0_rp, 'an approaching node passes a free wall')
      call assertEqual(0.0_rp, maxval(abs(impulse)), 0.0_rp, 'a free wall takes no load')
      ! the same wall with slip, after it in the list: it acts
      call wall%set_condition(condition_of('slip', 0.0_rp))
      call walls%append(wall, 0)
      call walls%set_activity(0.0_rp)
      call walls%constrain(2, v, [2.0_rp], impulse)
      call assertEqual([1.0_rp, 0.0_rp], v(:, 1), 0.0_rp, 'the slip wall after it holds the node')
      call assertEqual([0.0_rp, 6.0_rp], impulse(1:2, 2), 0.0_rp, 'and takes the load m |v_n| = 6')
      call assertEqual(0.0_rp, maxval(abs(impulse(:, 1))), 0.0_rp, 'the free wall still none')
   end subroutine test_free_wall_constrains_nothing
end module test_wall_constraints
