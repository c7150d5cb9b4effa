!> Unit tests of src/common/tensor_layout.f90: symmetric tensors stored as component vectors,
!> (xx, yy, zz, xy) in 2-D plane strain and Voigt order (xx, yy, zz, yz, xz, xy) in 3-D.
module test_tensor_layout
   use kinds, only: rp
   use tensor_layout, only: n_components, n_spin, trace3, mean_stress, to_components, to_matrix
   use assertions, only: assertEqual
   implicit none
   private

   public :: test_n_components, test_component_order, test_round_trip_2d, test_round_trip_3d
   public :: test_trace_and_mean_stress

contains

   !> A symmetric matrix whose entries name their component: xx=1, yy=2, zz=3, yz=4, xz=5, xy=6.
   pure function numbered_matrix() result(a)
      real(rp) :: a(3, 3)
      a = reshape([1.0_rp, 6.0_rp, 5.0_rp, &
                   6.0_rp, 2.0_rp, 4.0_rp, &
                   5.0_rp, 4.0_rp, 3.0_rp], [3, 3])
   end function numbered_matrix

   subroutine test_n_components()
      call assertEqual(4, n_components(2), 'components in 2-D (xx, yy, zz, xy)')
      call assertEqual(6, n_components(3), 'components in 3-D')
      call assertEqual(1, n_spin(2), 'spin components in 2-D')
      call assertEqual(3, n_spin(3), 'spin components in 3-D')
   end subroutine test_n_components

   subroutine test_component_order()
      call assertEqual([1.0_rp, 2.0_rp, 3.0_rp, 6.0_rp], to_components(numbered_matrix(), 2), 0.0_rp, &
                       '2-D order (xx, yy, zz, xy)')
      call assertEqual([1.0_rp, 2.0_rp, 3.0_rp, 4.0_rp, 5.0_rp, 6.0_rp], to_components(numbered_matrix(), 3), &
                       0.0_rp, '3-D Voigt order (xx, yy, zz, yz, xz, xy)')
   end subroutine test_component_order

   !> Plane strain: no xz, yz coupling, so matrix -> components -> matrix is exact; so is the reverse.
   subroutine test_round_trip_2d()
      real(rp) :: a(3, 3)
      real(rp), parameter :: s(4) = [-1.5_rp, 2.25_rp, 0.125_rp, 7.0_rp]
      a = numbered_matrix()
      a(1:2, 3) = 0.0_rp
      a(3, 1:2) = 0.0_rp
      call assertEqual(a, to_matrix(to_components(a, 2), 2), 0.0_rp, '2-D matrix round trip')
      call assertEqual(s, to_components(to_matrix(s, 2), 2), 0.0_rp, '2-D components round trip')
      call assertEqual(transpose(to_matrix(s, 2)), to_matrix(s, 2), 0.0_rp, '2-D matrix is symmetric')
   end subroutine test_round_trip_2d

   subroutine test_round_trip_3d()
      real(rp), parameter :: s(6) = [-1.5_rp, 2.25_rp, 0.125_rp, 7.0_rp, -3.0_rp, 1.0e-3_rp]
      call assertEqual(numbered_matrix(), to_matrix(to_components(numbered_matrix(), 3), 3), 0.0_rp, &
                       '3-D matrix round trip')
      call assertEqual(s, to_components(to_matrix(s, 3), 3), 0.0_rp, '3-D components round trip')
      call assertEqual(transpose(to_matrix(s, 3)), to_matrix(s, 3), 0.0_rp, '3-D matrix is symmetric')
   end subroutine test_round_trip_3d

   !> The trace runs over the three normal components in both layouts; mean stress is a third of it.
   subroutine test_trace_and_mean_stress()
      call assertEqual(6.0_rp, trace3(to_components(numbered_matrix(), 2)), 1.0e-15_rp, '2-D trace')
      call assertEqual(6.0_rp, trace3(to_components(numbered_matrix(), 3)), 1.0e-15_rp, '3-D trace')
      call assertEqual(2.0_rp, mean_stress(to_components(numbered_matrix(), 3)), 1.0e-15_rp, 'mean stress')
   end subroutine test_trace_and_mean_stress
end module test_tensor_layout
