!> Wall-pressure sensors: the mean pressure a wall or structure takes over a patch of its surface, read
!> from the impulse its constraint gives the material (docs/loads.md, "Wall pressure"; docs/theory.md
!> section 3.2).
!>
!> The constraint changes the momentum of each wall node i by dp_i in a step; for a pressure p on the
!> surface that is the consistent nodal load dp_i . n = dt * integral of p N_i over the wetted surface.
!> A sensor is a patch of the surface about its point x_s (a segment of half-length r in 2-D, a square of
!> half-width r in 3-D, in the tangent plane of the unit normal n_s into the fluid). Each node whose foot
!> point (the node moved onto the surface along its normal) lies in the sensor's plane with a normal close
!> to n_s is a tap with the weight
!>
!>   w_i = prod_k  integral over (patch cut to the wetted interval) of N_i  /  integral over the wetted
!>                 interval of N_i
!>
!> along each tangent axis k, N_i the hat function of width h about the foot point. The sensor reads
!> p = sum_i w_i dp_i . n_s / (|patch| dt): for a uniform pressure exact, whatever the patch's size and
!> place, because the nodal loads are the hat integrals over the wetted surface and the weights the part
!> of each in the patch; sensors tiling a face add up to its load. The wetted interval is where the
!> surface can carry fluid along a tangent that is a grid axis: the scene box, cut by the planar walls
!> normal to that axis (a floor below a sensor in a corner); on a surface whose tangents are not grid
!> axes (a turned grid, a curved structure) it is unbounded and the weights are approximate near an edge.
module wall_pressure_taps
   use kinds, only: rp
   implicit none
   private

   !> Normals within this cosine count as the sensor's face (a box's other faces are at 90 degrees).
   real(rp), parameter :: same_face_cosine = 0.7_rp

   !> One sensor on a wall: what it sees (grid frame).
   type, public :: wall_sensor_t
      integer :: slot = 0                    !< its index among the scene's wall-pressure sensors
      real(rp) :: point(3) = 0.0_rp          !< centre of the patch, on the surface
      real(rp) :: normal(3) = 0.0_rp         !< unit normal into the fluid at the point
      real(rp) :: radius = 0.0_rp            !< half-size of the patch along each tangent [m]
      !> along grid axis k (a tangent), the interval of the surface that can be wetted
      real(rp) :: wet_lo(3) = -huge(1.0_rp), wet_hi(3) = huge(1.0_rp)
   end type wall_sensor_t

   !> The sensors of one wall and their taps on the wall's current node list.
   type, public :: pressure_taps_t
      type(wall_sensor_t), allocatable :: sensors(:)
      integer, allocatable :: first(:)          !< taps of the wall's node i: first(i) .. first(i + 1) - 1
      integer, allocatable :: slot(:)           !< the sensor slot of tap t
      real(rp), allocatable :: vector(:, :)     !< (dim, t): w_i n_s / |patch|, so that dp_i . vector = p dt
   contains
      procedure :: place => taps_place
      procedure :: any => taps_any
   end type pressure_taps_t

   public :: tangent_axes, patch_weight

contains

   pure logical function taps_any(self)
      class(pressure_taps_t), intent(in) :: self
      taps_any = .false.
      if (allocated(self%sensors)) taps_any = size(self%sensors) > 0
   end function taps_any

   !> The taps of the wall's nodes, whose foot points `feet` (dim, node) and unit normals `normals` are given
   !> (grid frame), h the cell size.
   pure subroutine taps_place(self, dim, h, feet, normals)
      class(pressure_taps_t), intent(inout) :: self
      integer, intent(in) :: dim
      real(rp), intent(in) :: h, feet(:, :), normals(:, :)
      integer :: i, s, n, count
      real(rp) :: weight, area
      integer, allocatable :: slot(:)
      real(rp), allocatable :: vector(:, :)
      if (.not. self%any()) return
      n = size(feet, 2)
      allocate (slot(n * size(self%sensors)), vector(dim, n * size(self%sensors)))
      if (allocated(self%first)) deallocate (self%first)
      allocate (self%first(n + 1))
      count = 0
      do i = 1, n
         self%first(i) = count + 1
         do s = 1, size(self%sensors)
            associate (sensor => self%sensors(s))
               if (dot_product(normals(1:dim, i), sensor%normal(1:dim)) < same_face_cosine) cycle
               if (abs(dot_product(feet(1:dim, i) - sensor%point(1:dim), sensor%normal(1:dim))) > 0.5_rp * h) cycle
               call patch_weight(sensor, dim, h, feet(1:dim, i), weight, area)
               if (weight <= 0.0_rp .or. area <= 0.0_rp) cycle
               count = count + 1
               slot(count) = sensor%slot
               vector(:, count) = weight / area * sensor%normal(1:dim)
            end associate
         end do
      end do
      self%first(n + 1) = count + 1
      self%slot = slot(1:count)
      self%vector = vector(:, 1:count)
   end subroutine taps_place

   !> The weight of a node whose foot point is `foot` in the sensor's patch, and the patch's area (its
   !> length in 2-D), both cut to the wetted intervals.
   pure subroutine patch_weight(sensor, dim, h, foot, weight, area)
      type(wall_sensor_t), intent(in) :: sensor
      integer, intent(in) :: dim
      real(rp), intent(in) :: h, foot(dim)
      real(rp), intent(out) :: weight, area
      real(rp) :: tangents(dim, dim - 1), s, c, lo, hi, a, b, whole
      logical :: axes
      integer :: k, along
      call tangent_axes(sensor%normal(1:dim), dim, tangents, axes)
      weight = 1.0_rp
      area = 1.0_rp
      do k = 1, dim - 1
         if (axes) then
            along = maxloc(abs(tangents(:, k)), 1)
            s = foot(along)
            c = sensor%point(along)
            lo = sensor%wet_lo(along)
            hi = sensor%wet_hi(along)
         else
            s = dot_product(foot - sensor%point(1:dim), tangents(:, k))
            c = 0.0_rp
            lo = -huge(1.0_rp)
            hi = huge(1.0_rp)
         end if
         ! the patch cut to the wetted interval, and the part of it the node's hat covers
         area = area * max(0.0_rp, min(c + sensor%radius, hi) - max(c - sensor%radius, lo))
         lo = max(lo, s - h)
         hi = min(hi, s + h)
         a = max(c - sensor%radius, lo)
         b = min(c + sensor%radius, hi)
         whole = hat_integral(lo, hi, s, h)
         if (b <= a .or. whole <= 0.0_rp) then
            weight = 0.0_rp
         else
            weight = weight * hat_integral(a, b, s, h) / whole
         end if
      end do
   end subroutine patch_weight

   !> dim - 1 unit tangents of the plane normal to n: the other grid axes when n is a grid axis (`axes`),
   !> else the grid axes least aligned with n, made orthonormal against n (Gram-Schmidt).
   pure subroutine tangent_axes(n, dim, tangents, axes)
      real(rp), intent(in) :: n(:)
      integer, intent(in) :: dim
      real(rp), intent(out) :: tangents(dim, dim - 1)
      logical, intent(out) :: axes
      integer :: normal_axis, k, t, j
      real(rp) :: e(dim)
      normal_axis = maxloc(abs(n(1:dim)), 1)
      axes = abs(abs(n(normal_axis)) - 1.0_rp) <= 1.0e-9_rp
      t = 0
      do k = 1, dim
         if (k == normal_axis) cycle
         t = t + 1
         e = 0.0_rp
         e(k) = 1.0_rp
         if (.not. axes) then
            e = e - dot_product(e, n(1:dim)) * n(1:dim)
            do j = 1, t - 1
               e = e - dot_product(e, tangents(:, j)) * tangents(:, j)
            end do
            e = e / norm2(e)
         end if
         tangents(:, t) = e
      end do
   end subroutine tangent_axes

   !> The integral over a .. b of the hat function of half-width h about s, max(0, 1 - |u - s| / h) [m].
   pure real(rp) function hat_integral(a, b, s, h)
      real(rp), intent(in) :: a, b, s, h
      hat_integral = h * (primitive((b - s) / h) - primitive((a - s) / h))
   end function hat_integral

   !> Antiderivative of the unit hat, 0 below -1 and 1 above 1.
   pure real(rp) function primitive(z)
      real(rp), intent(in) :: z
      if (z <= -1.0_rp) then
         primitive = 0.0_rp
      else if (z <= 0.0_rp) then
         primitive = 0.5_rp * (z + 1.0_rp)**2
      else if (z < 1.0_rp) then
         primitive = 1.0_rp - 0.5_rp * (1.0_rp - z)**2
      else
         primitive = 1.0_rp
      end if
   end function primitive
end module wall_pressure_taps
