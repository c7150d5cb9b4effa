!> A free elastic body spinning without gravity or walls (docs/theory.md "APIC"): with APIC the angular
!> momentum L = sum_p m_p (x_p x v_p + eps : (C_p D_p)^T) ([J15] sec. 5.3) stays within a bound set by
!> the change of D_p as the particles move on the multilinear grid (each transfer keeps it exactly:
!> tests/unit/transfer/test_affine_transfer.f90), and does not drift; PIC (flip_fraction 0) loses all of
!> L = sum_p m_p x_p x v_p. The kinetic energy of the spinning disk decays far less with APIC than with
!> PIC. On 1, 2 and 4 ranks.
module test_apic_rotation
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use assertions, only: assertTrue, assertLessThanOrEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, body_spec_t, wall_none, model_linear_elastic
   use shape_geometry, only: shape_circle, shape_box
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use test_scenes, only: water_scene
   use apic_measures, only: particle_angular_momentum
   implicit none
   private

   public :: test_spinning_disk_keeps_angular_momentum, test_spinning_box_3d_keeps_angular_momentum, &
             test_spinning_disk_kinetic_energy, test_spinning_bspline2_conserves_angular_momentum

   !> Angular velocity [rad/s]: rim speed 0.6 m/s on the disk, well below the wave speed (37 m/s).
   real(rp), parameter :: omega = 2.0_rp

   !> What one run measured: relative change of |L| and the kinetic energy after the steps / before.
   type :: spin_result_t
      real(rp) :: l_change = 0.0_rp, energy_ratio = 0.0_rp
   end type spin_result_t

contains

   !> An elastic body (rho 1000, E 1 MPa, nu 0.3) in an open box without gravity: a disk of radius 0.3 m
   !> (2-D, h = 0.05 m) or a cube of 0.3 m (3-D, h = 0.1 m) at the box's centre, 2 particles per cell
   !> and direction, a fixed step below the CFL limit.
   function spinning_scene(dim, transfer, flip_fraction, shape_function) result(scene)
      integer, intent(in) :: dim
      character(len=*), intent(in) :: transfer
      real(rp), intent(in) :: flip_fraction
      character(len=*), intent(in), optional :: shape_function
      type(scene_t) :: scene
      type(body_spec_t) :: body
      if (dim == 2) then
         scene = water_scene(2, 0.05_rp, [1.0_rp, 1.0_rp, 0.0_rp], 2.0e6_rp, 0.0_rp)
         body%shape%kind = shape_circle
         body%shape%centre = [0.5_rp, 0.5_rp, 0.0_rp]
         body%shape%radius = 0.3_rp
         scene%run%fixed_dt = 4.0e-4_rp
      else
         scene = water_scene(3, 0.1_rp, [1.0_rp, 1.0_rp, 1.0_rp], 2.0e6_rp, 0.0_rp)
         body%shape%kind = shape_box
         body%lower = [0.35_rp, 0.35_rp, 0.35_rp]
         body%upper = [0.65_rp, 0.65_rp, 0.65_rp]
         scene%run%fixed_dt = 7.0e-4_rp
      end if
      scene%grid%wall = wall_none
      scene%materials(1)%name = 'rubber'
      scene%materials(1)%model = model_linear_elastic
      scene%materials(1)%youngs_modulus = 1.0e6_rp
      scene%materials(1)%poisson_ratio = 0.3_rp
      body%material = 'rubber'
      body%material_index = 1
      body%particles_per_cell = 2
      scene%bodies = [body]
      scene%run%transfer = transfer
      scene%run%flip_fraction = flip_fraction
      if (present(shape_function)) scene%grid%shape_function = shape_function
   end function spinning_scene

   !> Set the body spinning at omega about `axis` through its mass centre (no net momentum), run `steps`.
   function spin(comm, scene, axis, steps) result(result)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      real(rp), intent(in) :: axis(3)
      integer, intent(in) :: steps
      type(spin_result_t) :: result
      type(solver_t) :: solver
      type(status_t) :: status
      type(diagnostics_t) :: before, after
      real(rp) :: sums(4), centre(3), r(3), w(3), l0(3), l1(3)
      integer :: p, step, dim
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      dim = solver%grid%dim
      sums = 0.0_rp
      do p = 1, solver%particles%count
         sums(1:dim) = sums(1:dim) + solver%particles%mass(p) * solver%particles%x(:, p)
         sums(4) = sums(4) + solver%particles%mass(p)
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, 4, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      centre = sums(1:3) / sums(4)
      w = omega * axis / norm2(axis)
      do p = 1, solver%particles%count
         r = 0.0_rp
         r(1:dim) = solver%particles%x(:, p) - centre(1:dim)
         r = [w(2) * r(3) - w(3) * r(2), w(3) * r(1) - w(1) * r(3), w(1) * r(2) - w(2) * r(1)]
         solver%particles%v(:, p) = r(1:dim)
      end do
      before = solver%diagnostics()
      l0 = particle_angular_momentum(solver%particles, solver%grid, comm)
      do step = 1, steps
         call solver%advance()
      end do
      after = solver%diagnostics()
      l1 = particle_angular_momentum(solver%particles, solver%grid, comm)
      call assertTrue(after%particles == before%particles .and. after%lost_particles == 0, 'every particle kept')
      result%l_change = norm2(l1 - l0) / norm2(l0)
      result%energy_ratio = after%kinetic_energy / before%kinetic_energy
      call solver%free()
   end function spin

   !> 2-D disk, 500 steps (0.2 s, 0.4 rad): APIC keeps L within 5e-3 (measured 2.3e-3), PIC loses over half.
   subroutine test_spinning_disk_keeps_angular_momentum(comm)
      type(MPI_Comm), intent(in) :: comm
      type(spin_result_t) :: apic, pic
      apic = spin(comm, spinning_scene(2, 'apic', 0.95_rp), [0.0_rp, 0.0_rp, 1.0_rp], 500)
      pic = spin(comm, spinning_scene(2, 'flip_pic', 0.0_rp), [0.0_rp, 0.0_rp, 1.0_rp], 500)
      call report(comm, 'disk, 500 steps', apic, pic)
      call assertLessThanOrEqual(apic%l_change, 5.0e-3_rp, 'APIC: |L - L0| / |L0| after 500 steps')
      call assertLessThanOrEqual(0.5_rp, pic%l_change, 'PIC loses angular momentum')
   end subroutine test_spinning_disk_keeps_angular_momentum

   !> 3-D cube (3 cells wide) spinning about a tilted axis, 300 steps: L within 5e-2 (measured 2.5e-2).
   subroutine test_spinning_box_3d_keeps_angular_momentum(comm)
      type(MPI_Comm), intent(in) :: comm
      type(spin_result_t) :: apic, pic
      apic = spin(comm, spinning_scene(3, 'apic', 0.95_rp), [0.3_rp, 0.5_rp, 0.8_rp], 300)
      pic = spin(comm, spinning_scene(3, 'flip_pic', 0.0_rp), [0.3_rp, 0.5_rp, 0.8_rp], 300)
      call report(comm, 'cube 3-D, 300 steps', apic, pic)
      call assertLessThanOrEqual(apic%l_change, 5.0e-2_rp, 'APIC 3-D: |L - L0| / |L0| after 300 steps')
      call assertLessThanOrEqual(0.5_rp, pic%l_change, 'PIC 3-D loses angular momentum')
   end subroutine test_spinning_box_3d_keeps_angular_momentum

   !> The disk's kinetic energy after 1500 steps (0.6 s): APIC loses less than a tenth of what PIC loses.
   !> FLIP 0.95 (the default blend) is reported alongside.
   subroutine test_spinning_disk_kinetic_energy(comm)
      type(MPI_Comm), intent(in) :: comm
      type(spin_result_t) :: apic, pic, flip
      apic = spin(comm, spinning_scene(2, 'apic', 0.95_rp), [0.0_rp, 0.0_rp, 1.0_rp], 1500)
      pic = spin(comm, spinning_scene(2, 'flip_pic', 0.0_rp), [0.0_rp, 0.0_rp, 1.0_rp], 1500)
      flip = spin(comm, spinning_scene(2, 'flip_pic', 0.95_rp), [0.0_rp, 0.0_rp, 1.0_rp], 1500)
      call report(comm, 'disk, 1500 steps', apic, pic, flip)
      call assertLessThanOrEqual(1.0_rp - apic%energy_ratio, 0.1_rp * (1.0_rp - pic%energy_ratio), &
                                 'APIC loses < 1/10 of the kinetic energy PIC loses')
      ! no drift: after three times the steps the change of L is still within the 500-step bound
      call assertLessThanOrEqual(apic%l_change, 5.0e-3_rp, 'APIC: |L - L0| / |L0| after 1500 steps')
   end subroutine test_spinning_disk_kinetic_energy

   !> With quadratic B-splines D_p = h^2/4 I does not change as the particles move, so APIC keeps L to
   !> round-off over the whole run ([J15] sec. 5.3), 2-D disk and 3-D cube; PIC on the same grid loses it.
   subroutine test_spinning_bspline2_conserves_angular_momentum(comm)
      type(MPI_Comm), intent(in) :: comm
      type(spin_result_t) :: apic, pic
      apic = spin(comm, spinning_scene(2, 'apic', 0.95_rp, 'bspline2'), [0.0_rp, 0.0_rp, 1.0_rp], 500)
      pic = spin(comm, spinning_scene(2, 'flip_pic', 0.0_rp, 'bspline2'), [0.0_rp, 0.0_rp, 1.0_rp], 500)
      call report(comm, 'disk, bspline2, 500 steps', apic, pic)
      call assertLessThanOrEqual(apic%l_change, 1.0e-12_rp, 'APIC, bspline2: |L - L0| / |L0| after 500 steps')
      call assertLessThanOrEqual(0.5_rp, pic%l_change, 'PIC, bspline2 loses angular momentum')
      apic = spin(comm, spinning_scene(3, 'apic', 0.95_rp, 'bspline2'), [0.3_rp, 0.5_rp, 0.8_rp], 100)
      call report(comm, 'cube 3-D, bspline2, 100 steps', apic, pic)
      call assertLessThanOrEqual(apic%l_change, 1.0e-12_rp, 'APIC 3-D, bspline2: |L - L0| / |L0| after 100 steps')
   end subroutine test_spinning_bspline2_conserves_angular_momentum

   !> One line per transfer on rank 0: the numbers docs/speed-accuracy.md quotes.
   subroutine report(comm, label, apic, pic, flip)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), intent(in) :: label
      type(spin_result_t), intent(in) :: apic, pic
      type(spin_result_t), intent(in), optional :: flip
      integer :: rank
      call MPI_Comm_rank(comm, rank)
      if (rank /= 0) return
      write (*, '(a, ": APIC dL/L = ", es10.3, ", KE/KE0 = ", f10.6)') label, apic%l_change, apic%energy_ratio
      write (*, '(a, ": PIC  dL/L = ", es10.3, ", KE/KE0 = ", f10.6)') label, pic%l_change, pic%energy_ratio
      if (present(flip)) write (*, '(a, ": FLIP 0.95 dL/L = ", es10.3, ", KE/KE0 = ", f10.6)') label, flip%l_change, &
         flip%energy_ratio
   end subroutine report
end module test_apic_rotation
