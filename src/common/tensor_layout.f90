!> Storage of symmetric tensors in component vectors, shared by 2-D plane strain and 3-D.
!>
!> Normal components come first so the trace is always sum(s(1:3)):
!>   2-D plane strain: (xx, yy, zz, xy)             -> 4 components (zz needed for the mean stress)
!>   3-D:              (xx, yy, zz, yz, xz, xy)     -> 6 components (Voigt order)
!> Rates of deformation use the same layout (d_zz = 0 in plane strain).
module tensor_layout
   use kinds, only: rp
   implicit none
   private

   public :: n_components, n_spin, trace3, mean_stress, to_components, to_matrix

contains

   !> Number of stored components of a symmetric tensor in `dim` dimensions.
   pure integer function n_components(dim)
      integer, intent(in) :: dim
      n_components = merge(4, 6, dim == 2)
   end function n_components

   !> Number of independent spin components (w_xy in 2-D; w_yz, w_xz, w_xy in 3-D).
   pure integer function n_spin(dim)
      integer, intent(in) :: dim
      n_spin = merge(1, 3, dim == 2)
   end function n_spin

   !> Trace over the three normal components.
   pure real(rp) function trace3(s)
      real(rp), intent(in) :: s(:)
      trace3 = s(1) + s(2) + s(3)
   end function trace3

   !> Mean stress (sigma_xx + sigma_yy + sigma_zz)/3 = -p (algorithms.md section 6.3).
   pure real(rp) function mean_stress(s)
      real(rp), intent(in) :: s(:)
      mean_stress = (s(1) + s(2) + s(3)) / 3.0_rp
   end function mean_stress

   !> Symmetric 3x3 matrix -> components in the layout of this module.
   pure function to_components(a, dim) result(s)
      real(rp), intent(in) :: a(3, 3)
      integer, intent(in) :: dim
      real(rp) :: s(n_components(dim))
      s(1) = a(1, 1); s(2) = a(2, 2); s(3) = a(3, 3)
      if (dim == 2) then
         s(4) = a(1, 2)
      else
         s(4) = a(2, 3); s(5) = a(1, 3); s(6) = a(1, 2)
      end if
   end function to_components

   !> Components -> symmetric 3x3 matrix.
   pure function to_matrix(s, dim) result(a)
      real(rp), intent(in) :: s(:)
      integer, intent(in) :: dim
      real(rp) :: a(3, 3)
      a = 0.0_rp
      a(1, 1) = s(1); a(2, 2) = s(2); a(3, 3) = s(3)
      if (dim == 2) then
         a(1, 2) = s(4); a(2, 1) = s(4)
      else
         a(2, 3) = s(4); a(3, 2) = s(4)
         a(1, 3) = s(5); a(3, 1) = s(5)
         a(1, 2) = s(6); a(2, 1) = s(6)
      end if
   end function to_matrix
end module tensor_layout
