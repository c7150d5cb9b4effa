!> Unit tests of the nodal contact of src/solver/body_contact.f90 (resolve_node_contact): momentum
!> conserved to round-off, approaching against separating fields, the Coulomb limit of the tangential
!> correction, fields without a &contact pair sticking, three clusters.
module test_body_contact
   use kinds, only: rp
   use body_contact, only: resolve_node_contact
   use assertions, only: assertEqual, assertTrue, assertLessThanOrEqual
   implicit none
   private

   public :: test_approaching_fields_conserve_momentum, test_separating_fields_keep_velocities, &
             test_coulomb_limit_of_the_slip, test_slip_never_reverses, test_fields_without_contact_stick, &
             test_three_clusters_conserve_momentum

   !> Round-off bound of momentum sums of O(1) values.
   real(rp), parameter :: round_off = 1.0e-14_rp

contains

   !> a and b meet with a tilted normal (a's surface is the flatter: |g_a| > |g_b|) and a slip:
   !> afterwards sum m v is unchanged, they share the normal velocity, and each lost mu times its normal
   !> correction of tangential velocity.
   subroutine test_approaching_fields_conserve_momentum()
      real(rp) :: mass(2), v(2, 2), g(2, 2), mu(2, 2), before(2), n(2), t(2), dv_n, dv_t
      integer :: clusters
      mass = [0.7_rp, 0.3_rp]
      v(:, 1) = [1.0_rp, 0.4_rp]
      v(:, 2) = [-0.5_rp, 0.1_rp]
      g(:, 1) = [3.0_rp, 1.0_rp]             ! a's outward normal: the larger gradient
      g(:, 2) = [-1.0_rp, -0.2_rp]
      mu = 0.1_rp
      before = mass(1) * v(:, 1) + mass(2) * v(:, 2)
      ! the common normal of body_contact: that of the flatter face (the larger |g|), a's
      n = g(:, 1) / norm2(g(:, 1))
      t = [-n(2), n(1)]
      call resolve_node_contact(mass, v, g, mu, clusters)
      call assertEqual(2, clusters, 'two clusters')
      call assertEqual(before, mass(1) * v(:, 1) + mass(2) * v(:, 2), round_off, 'momentum')
      call assertEqual(0.0_rp, dot_product(v(:, 1) - v(:, 2), n), round_off, 'no normal approach left')
      ! a: v_cm = (0.55, 0.31); v_a - v_cm = (0.45, 0.09)
      dv_n = dot_product([1.0_rp, 0.4_rp] - v(:, 1), n)
      dv_t = dot_product([1.0_rp, 0.4_rp] - v(:, 1), t)
      call assertEqual(dot_product([0.45_rp, 0.09_rp], n), dv_n, round_off, 'normal correction of a')
      call assertEqual(0.1_rp * dv_n * sign(1.0_rp, dot_product([0.45_rp, 0.09_rp], t)), dv_t, round_off, &
                       'tangential correction of a = mu times the normal one, against the slip')
   end subroutine test_approaching_fields_conserve_momentum

   !> The same fields moving apart keep their velocities (to the round-off of sum m v / m).
   subroutine test_separating_fields_keep_velocities()
      real(rp) :: mass(2), v(2, 2), g(2, 2), mu(2, 2), vn(2, 2)
      integer :: clusters
      mass = [0.7_rp, 0.3_rp]
      v(:, 1) = [-1.0_rp, 0.4_rp]
      v(:, 2) = [0.5_rp, 0.1_rp]
      g(:, 1) = [3.0_rp, 1.0_rp]
      g(:, 2) = [-1.0_rp, -0.2_rp]
      mu = 0.5_rp
      vn = v
      call resolve_node_contact(mass, v, g, mu, clusters, vn)
      call assertEqual(2, clusters, 'two clusters')
      call assertEqual(reshape([-1.0_rp, 0.4_rp, 0.5_rp, 0.1_rp], [2, 2]), v, round_off, 'velocities unchanged')
      call assertEqual(reshape([-1.0_rp, 0.4_rp, 0.5_rp, 0.1_rp], [2, 2]), vn, round_off, 'v^n unchanged')
   end subroutine test_separating_fields_keep_velocities

   !> A small normal approach and a large slip: the slip is reduced by exactly mu times the normal
   !> correction (Coulomb, sliding), in 3-D with the normal along z.
   subroutine test_coulomb_limit_of_the_slip()
      real(rp) :: mass(2), v(3, 2), g(3, 2), mu(2, 2), slip_before, slip_after
      integer :: clusters
      mass = [1.0_rp, 1.0_rp]
      v(:, 1) = [2.0_rp, 0.0_rp, -0.01_rp]     ! a on top, sliding along x, sinking into b
      v(:, 2) = [0.0_rp, 0.0_rp, 0.0_rp]
      g(:, 1) = [0.0_rp, 0.0_rp, -4.0_rp]      ! a's surface faces down
      g(:, 2) = [0.0_rp, 0.0_rp, 2.0_rp]
      mu = 0.3_rp
      slip_before = v(1, 1) - v(1, 2)
      call resolve_node_contact(mass, v, g, mu, clusters)
      slip_after = v(1, 1) - v(1, 2)
      call assertEqual(0.0_rp, v(3, 1) - v(3, 2), round_off, 'normal approach removed')
      ! each field's normal correction is 0.005, so each loses 0.3 * 0.005 of its slip relative to v_cm
      call assertEqual(slip_before - 2.0_rp * 0.3_rp * 0.005_rp, slip_after, round_off, 'slip reduced by 2 mu dv_n')
      call assertEqual([2.0_rp, 0.0_rp, -0.01_rp], v(:, 1) + v(:, 2), round_off, 'momentum')
   end subroutine test_coulomb_limit_of_the_slip

   !> A large normal approach and a small slip with a large mu: the fields stick tangentially (the same
   !> velocity), the slip is not reversed.
   subroutine test_slip_never_reverses()
      real(rp) :: mass(2), v(2, 2), g(2, 2), mu(2, 2)
      integer :: clusters
      mass = [2.0_rp, 1.0_rp]
      v(:, 1) = [0.01_rp, -1.0_rp]
      v(:, 2) = [0.0_rp, 1.0_rp]
      g(:, 1) = [0.0_rp, -3.0_rp]
      g(:, 2) = [0.0_rp, 1.0_rp]
      mu = 5.0_rp
      call resolve_node_contact(mass, v, g, mu, clusters)
      call assertEqual(v(:, 2), v(:, 1), round_off, 'stuck: one velocity')
      call assertEqual([0.02_rp / 3.0_rp, -1.0_rp / 3.0_rp], v(:, 1), round_off, 'the centre of mass velocity')
   end subroutine test_slip_never_reverses

   !> Three fields, the first two without a &contact pair (friction < 0): they are one cluster and share
   !> a velocity; with the third they make two clusters. Without any pair: one cluster, nothing changes.
   subroutine test_fields_without_contact_stick()
      real(rp) :: mass(3), v(2, 3), g(2, 3), mu(3, 3), before(2, 3)
      integer :: clusters
      mass = [1.0_rp, 3.0_rp, 2.0_rp]
      v = reshape([1.0_rp, 0.0_rp, 0.0_rp, 0.0_rp, -1.0_rp, 0.0_rp], [2, 3])
      g = reshape([1.0_rp, 0.0_rp, 1.0_rp, 0.0_rp, -3.0_rp, 0.0_rp], [2, 3])
      mu = 0.0_rp
      mu(1, 2) = -1.0_rp
      mu(2, 1) = -1.0_rp
      call resolve_node_contact(mass, v, g, mu, clusters)
      call assertEqual(2, clusters, 'fields 1 and 2 one cluster, 3 the other')
      call assertEqual(v(:, 1), v(:, 2), round_off, 'fields 1 and 2 share a velocity')
      call assertEqual([-1.0_rp, 0.0_rp], mass(1) * v(:, 1) + mass(2) * v(:, 2) + mass(3) * v(:, 3), round_off, &
                       'momentum (1 - 2 along x)')
      v = reshape([1.0_rp, 0.0_rp, 0.0_rp, 0.0_rp, -1.0_rp, 0.0_rp], [2, 3])
      before = v
      mu = -1.0_rp
      call resolve_node_contact(mass, v, g, mu, clusters)
      call assertEqual(1, clusters, 'no pair in contact: one cluster')
      call assertEqual(before, v, 0.0_rp, 'one cluster: velocities left to the caller')
   end subroutine test_fields_without_contact_stick

   !> Three bodies meeting at a node, each with its own normal: momentum is conserved to round-off and
   !> no cluster approaches the centre of mass faster than before.
   subroutine test_three_clusters_conserve_momentum()
      real(rp) :: mass(3), v(2, 3), g(2, 3), mu(3, 3), before(2), v_cm(2), approach_before(3), n(2, 3)
      integer :: clusters, c
      mass = [1.0_rp, 2.0_rp, 1.5_rp]
      v = reshape([1.0_rp, 0.2_rp, -0.5_rp, 0.5_rp, 0.0_rp, -1.0_rp], [2, 3])
      g = reshape([1.0_rp, 0.0_rp, -1.0_rp, 1.0_rp, 0.0_rp, -1.0_rp], [2, 3])
      mu = 0.2_rp
      before = matmul(v, mass)
      v_cm = before / sum(mass)
      do c = 1, 3
         n(:, c) = g(:, c) / norm2(g(:, c))
         approach_before(c) = dot_product(v(:, c) - v_cm, n(:, c))
      end do
      call resolve_node_contact(mass, v, g, mu, clusters)
      call assertEqual(3, clusters, 'three clusters')
      call assertEqual(before, matmul(v, mass), round_off, 'momentum')
      do c = 1, 3
         call assertLessThanOrEqual(dot_product(v(:, c) - v_cm, n(:, c)), max(approach_before(c), 0.0_rp) + round_off, &
                                    'no faster approach')
      end do
      call assertTrue(any(approach_before > 0.0_rp), 'some cluster was approaching')
   end subroutine test_three_clusters_conserve_momentum
end module test_body_contact
