!> Point updates of the constitutive models against closed-form results.
module test_constitutive_updates
   use kinds, only: rp, i8
   use assertions, only: assertEqual, assertRelativelyEqual, assertTrue
   use tensor_layout, only: mean_stress
   use newtonian_fluid, only: fluid_point_update, newtonian_fluid_t
   use linear_elastic, only: elastic_point_update
   implicit none
   private

   public :: test_fluid_pressure_increment, test_fluid_viscous_stress, test_inviscid_update_bitwise, test_viscous_update_bitwise, &
             test_elastic_uniaxial_strain, &
             test_elastic_uniaxial_stress_nu0, test_jaumann_hydrostatic_invariance, test_jaumann_rotation_rate

contains

   !> Rate form: p^{n+1} - p^n = -K tr(d) dt, density / det(I + dt d) (algorithms.md section 5.1).
   subroutine test_fluid_pressure_increment()
      real(rp), parameter :: k = 2.2e9_rp, rho0 = 1000.0_rp, dt = 1.0e-5_rp, p0 = 3.2e4_rp
      real(rp) :: d(4), sbar(4), density, p1, d3(6), sbar3(6)
      ! 2-D plane strain compression
      d = [-0.3_rp, 0.1_rp, 0.0_rp, 0.05_rp]
      sbar = [-p0, -p0, -p0, 0.0_rp] / rho0
      density = rho0
      call fluid_point_update(k, 0.0_rp, 2, dt, d, density, sbar)
      p1 = -density * mean_stress(sbar)
      call assertRelativelyEqual(p0 - k * (d(1) + d(2)) * dt, p1, 1.0e-13_rp, '2-D pressure increment -K dtheta')
      call assertRelativelyEqual(rho0 / ((1 + dt * d(1)) * (1 + dt * d(2)) - (dt * d(4))**2), density, 1.0e-14_rp, &
                                 '2-D density')
      ! 3-D
      d3 = [0.2_rp, -0.1_rp, 0.4_rp, 0.01_rp, -0.02_rp, 0.03_rp]
      sbar3 = [-p0, -p0, -p0, 0.0_rp, 0.0_rp, 0.0_rp] / rho0
      density = rho0
      call fluid_point_update(k, 0.0_rp, 3, dt, d3, density, sbar3)
      p1 = -density * mean_stress(sbar3)
      call assertRelativelyEqual(p0 - k * sum(d3(1:3)) * dt, p1, 1.0e-13_rp, '3-D pressure increment -K dtheta')
   end subroutine test_fluid_pressure_increment

   !> sigma = -p I + 2 mu dev(d): the shear stress is 2 mu d_xy and the deviator is traceless.
   subroutine test_fluid_viscous_stress()
      real(rp), parameter :: mu = 2.0_rp, dt = 1.0e-6_rp
      real(rp) :: d(4), sbar(4), density, sigma(4)
      d = [1.0_rp, -0.5_rp, 0.0_rp, 0.25_rp]
      sbar = 0.0_rp
      density = 1000.0_rp
      call fluid_point_update(1.0e6_rp, mu, 2, dt, d, density, sbar)
      sigma = density * sbar
      call assertRelativelyEqual(2 * mu * d(4), sigma(4), 1.0e-14_rp, 'shear stress 2 mu d_xy')
      call assertRelativelyEqual(2 * mu * (d(1) - d(2)), sigma(1) - sigma(2), 1.0e-12_rp, 'normal stress difference')
   end subroutine test_fluid_viscous_stress

   !> With viscosity 0 the slice update takes a path without the viscous terms: it must give the bits of
   !> the general point update with mu = 0, signs of zero included (zero pressure, shear rates of both
   !> signs and -0), in 2-D and 3-D.
   subroutine test_inviscid_update_bitwise()
      real(rp) :: d(4, 3), sbar(4, 3), d3(6, 2), sbar3(6, 2)
      d(:, 1) = [-0.3_rp, 0.1_rp, 0.0_rp, -0.05_rp]
      d(:, 2) = [0.0_rp, 0.0_rp, 0.0_rp, -0.0_rp]          ! at rest with zero stress: p = 0
      d(:, 3) = [0.2_rp, -0.2_rp, 0.0_rp, 0.7_rp]           ! tr d = 0
      sbar = 0.0_rp
      sbar(1:3, 1) = -30.0_rp
      call check_slice(2, 0.0_rp, d, sbar, '2-D')
      d3(:, 1) = [0.2_rp, -0.1_rp, 0.4_rp, -0.01_rp, 0.0_rp, 0.03_rp]
      d3(:, 2) = [0.1_rp, -0.1_rp, 0.0_rp, -0.0_rp, 0.0_rp, -0.03_rp]
      sbar3 = 0.0_rp
      call check_slice(3, 0.0_rp, d3, sbar3, '3-D')
   end subroutine test_inviscid_update_bitwise

   !> A viscous fluid's slice update, its components written out so that the compiler vectorises it,
   !> must give the bits of the point update, in 2-D and 3-D, over 13 particles (a vector loop and its
   !> remainder), compressed and stretched, with shear of both signs.
   subroutine test_viscous_update_bitwise()
      integer, parameter :: n = 13
      real(rp) :: d(4, n), sbar(4, n), d3(6, n), sbar3(6, n)
      integer :: p, k
      do p = 1, n
         do k = 1, 6
            d3(k, p) = 0.3_rp * sin(1.7_rp * p + 0.9_rp * k)
            sbar3(k, p) = merge(-30.0_rp + p, 0.4_rp * cos(1.1_rp * p * k), k <= 3)
         end do
      end do
      d = d3([1, 2, 3, 6], :)
      d(3, :) = 0.0_rp                                       ! plane strain
      sbar = sbar3([1, 2, 3, 6], :)
      call check_slice(2, 1.0e-3_rp, d, sbar, '2-D viscous')
      call check_slice(3, 1.0e-3_rp, d3, sbar3, '3-D viscous')
   end subroutine test_viscous_update_bitwise

   !> The slice update of a fluid against fluid_point_update, bit for bit (viscosity 0: the inviscid path).
   subroutine check_slice(dim, viscosity, d, sbar, label)
      integer, intent(in) :: dim
      real(rp), intent(in) :: viscosity
      real(rp), intent(in), contiguous :: d(:, :), sbar(:, :)
      character(len=*), intent(in) :: label
      real(rp), parameter :: dt = 1.0e-4_rp, k = 2.0e7_rp
      type(newtonian_fluid_t) :: fluid
      real(rp) :: spin(3, size(d, 2)), slice_sbar(size(sbar, 1), size(sbar, 2)), point_sbar(size(sbar, 1), size(sbar, 2))
      real(rp) :: slice_density(size(d, 2)), point_density(size(d, 2))
      integer :: p, n
      fluid%bulk_modulus = k
      fluid%viscosity = viscosity
      spin = 0.0_rp
      n = size(d, 2)
      slice_density = 1000.0_rp - [(2.0_rp * p, p = 1, n)]
      point_density = slice_density
      slice_sbar = sbar
      point_sbar = sbar
      do p = 1, n
         call fluid_point_update(k, viscosity, dim, dt, d(:, p), point_density(p), point_sbar(:, p))
      end do
      call fluid%update_stress(dim, dt, d, spin, slice_density, slice_sbar)
      call assertTrue(all(transfer(slice_sbar, 0_i8, size(sbar)) == transfer(point_sbar, 0_i8, size(sbar))), &
                      label//' sbar bit for bit')
      call assertTrue(all(transfer(slice_density, 0_i8, n) == transfer(point_density, 0_i8, n)), &
                      label//' density bit for bit')
   end subroutine check_slice

   !> Uniaxial strain in 3-D: sigma_xx = (lambda + 2 G) eps, sigma_yy = sigma_zz = lambda eps.
   subroutine test_elastic_uniaxial_strain()
      real(rp), parameter :: e = 1.0e6_rp, nu = 0.25_rp, dt = 1.0e-4_rp, rate = 0.01_rp
      real(rp) :: lambda, g, d(6), w(3), sbar(6), density, sigma(6)
      integer :: step
      lambda = e * nu / ((1 + nu) * (1 - 2 * nu))
      g = e / (2 * (1 + nu))
      d = [rate, 0.0_rp, 0.0_rp, 0.0_rp, 0.0_rp, 0.0_rp]
      w = 0.0_rp
      sbar = 0.0_rp
      density = 300.0_rp
      do step = 1, 10
         call elastic_point_update(lambda, g, 3, dt, d, w, density, sbar)
      end do
      sigma = density * sbar
      call assertRelativelyEqual((lambda + 2 * g) * rate * 10 * dt, sigma(1), 1.0e-12_rp, 'sigma_xx')
      call assertRelativelyEqual(lambda * rate * 10 * dt, sigma(2), 1.0e-12_rp, 'sigma_yy')
      call assertRelativelyEqual(lambda * rate * 10 * dt, sigma(3), 1.0e-12_rp, 'sigma_zz')
   end subroutine test_elastic_uniaxial_strain

   !> With nu = 0 (lambda = 0) a plane-strain bar in uniaxial strain carries sigma_xx = E eps only:
   !> the 1-D bar of the verification problem.
   subroutine test_elastic_uniaxial_stress_nu0()
      real(rp), parameter :: e = 100.0_rp, dt = 1.0e-3_rp, rate = -0.2_rp
      real(rp) :: d(4), w(1), sbar(4), density, sigma(4)
      d = [rate, 0.0_rp, 0.0_rp, 0.0_rp]
      w = 0.0_rp
      sbar = 0.0_rp
      density = 1.0_rp
      call elastic_point_update(0.0_rp, e / 2, 2, dt, d, w, density, sbar)
      sigma = density * sbar
      call assertRelativelyEqual(e * rate * dt, sigma(1), 1.0e-14_rp, 'sigma_xx = E eps')
      call assertEqual([0.0_rp, 0.0_rp, 0.0_rp], sigma(2:4), 0.0_rp, 'no lateral stress with nu = 0')
   end subroutine test_elastic_uniaxial_stress_nu0

   !> W sigma - sigma W = 0 for sigma = -p I: a spinning hydrostatic state keeps its stress.
   subroutine test_jaumann_hydrostatic_invariance()
      real(rp) :: d(6), w(3), sbar(6), sbar0(6), density, d2(4), w2(1), s2(4), s20(4)
      integer :: step
      d = 0.0_rp
      w = [0.3_rp, -1.2_rp, 2.0_rp]
      sbar0 = [-5.0_rp, -5.0_rp, -5.0_rp, 0.0_rp, 0.0_rp, 0.0_rp]
      sbar = sbar0
      density = 1000.0_rp
      do step = 1, 100
         call elastic_point_update(4.0e5_rp, 4.0e5_rp, 3, 1.0e-3_rp, d, w, density, sbar)
      end do
      call assertEqual(sbar0, sbar, 1.0e-14_rp, '3-D hydrostatic stress under spin')
      d2 = 0.0_rp
      w2 = [0.7_rp]
      s20 = [-2.0_rp, -2.0_rp, -2.0_rp, 0.0_rp]
      s2 = s20
      do step = 1, 100
         call elastic_point_update(4.0e5_rp, 4.0e5_rp, 2, 1.0e-3_rp, d2, w2, density, s2)
      end do
      call assertEqual(s20, s2, 1.0e-14_rp, '2-D hydrostatic stress under spin')
   end subroutine test_jaumann_hydrostatic_invariance

   !> A uniaxial stress under pure spin rotates with the material: after a quarter turn
   !> (small steps) sigma_xx and sigma_yy have swapped, to first order in the step.
   subroutine test_jaumann_rotation_rate()
      real(rp), parameter :: omega = 1.0_rp, dt = 1.0e-4_rp
      real(rp) :: d(4), w(1), sbar(4), density
      integer :: step, n
      real(rp), parameter :: pi = acos(-1.0_rp)
      d = 0.0_rp
      w = [omega]
      sbar = [1.0_rp, 0.0_rp, 0.0_rp, 0.0_rp]
      density = 1.0_rp
      n = nint(0.5_rp * pi / omega / dt)
      do step = 1, n
         call elastic_point_update(0.0_rp, 1.0_rp, 2, dt, d, w, density, sbar)
      end do
      call assertEqual(0.0_rp, sbar(1), 1.0e-3_rp, 'sigma_xx after a quarter turn')
      call assertEqual(1.0_rp, sbar(2), 1.0e-3_rp, 'sigma_yy after a quarter turn')
      call assertEqual(1.0_rp, sbar(1) + sbar(2), 1.0e-3_rp, 'trace kept')
   end subroutine test_jaumann_rotation_rate
end module test_constitutive_updates
