!> Axial vibration of a fixed-free elastic bar (verification.md section 1; Bardenhagen 2002):
!> L = 25, E = 100, rho = 1, nu = 0, v(x, 0) = v0 sin(beta x), beta = pi / (2 L).
!> Exact: v_cm(t) = v0 / (beta L) cos(omega t), omega = beta sqrt(E / rho), period 10 s.
module test_elastic_bar
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use assertions, only: assertTrue, assertRelativelyEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, body_spec_t, wall_no_slip, model_linear_elastic
   use mpm_solver, only: solver_t
   implicit none
   private

   public :: test_fixed_free_bar_period

   real(rp), parameter :: bar_length = 25.0_rp, youngs_modulus = 100.0_rp, v0 = 0.1_rp
   real(rp), parameter :: pi = acos(-1.0_rp), beta = pi / (2.0_rp * bar_length)

contains

   function bar_scene() result(scene)
      type(scene_t) :: scene
      type(body_spec_t) :: bar
      scene%grid%dim = 2
      scene%grid%cell_size = 1.0_rp
      scene%grid%extent = [30.0_rp, 1.0_rp, 0.0_rp]
      scene%grid%ncells = [30, 1, 1]
      scene%grid%wall(1, 1) = wall_no_slip      ! the fixed end at x = 0
      scene%run%end_time = 16.0_rp
      scene%run%floor_size = 30.0_rp
      allocate (scene%materials(1))
      scene%materials(1)%name = 'bar'
      scene%materials(1)%model = model_linear_elastic
      scene%materials(1)%density = 1.0_rp
      scene%materials(1)%youngs_modulus = youngs_modulus
      scene%materials(1)%poisson_ratio = 0.0_rp
      bar%material = 'bar'
      bar%material_index = 1
      bar%lower = 0.0_rp
      bar%upper = [bar_length, 1.0_rp, 0.0_rp]
      bar%particles_per_cell = 2
      scene%bodies = [bar]
   end function bar_scene

   !> The period from the first and third zero crossings of v_cm(t) (exact: 2.5 s and 12.5 s).
   subroutine test_fixed_free_bar_period(comm)
      type(MPI_Comm), intent(in) :: comm
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp) :: sums(2), v_cm, v_cm_old, t_old, crossings(3), omega
      integer :: p, n_crossings, rank

      call MPI_Comm_rank(comm, rank)
      call solver%init(bar_scene(), comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do p = 1, solver%particles%count
         solver%particles%v(:, p) = [v0 * sin(beta * solver%particles%x(1, p)), 0.0_rp]
      end do
      v_cm_old = centre_of_mass_velocity()
      omega = beta * sqrt(youngs_modulus / 1.0_rp)
      call assertRelativelyEqual(v0 / (beta * bar_length), v_cm_old, 0.01_rp, 'initial v_cm')
      n_crossings = 0
      t_old = 0.0_rp
      do while (solver%time < solver%run%end_time .and. n_crossings < 3)
         call solver%advance()
         v_cm = centre_of_mass_velocity()
         if (sign(1.0_rp, v_cm) /= sign(1.0_rp, v_cm_old)) then
            n_crossings = n_crossings + 1
            crossings(n_crossings) = t_old + (solver%time - t_old) * v_cm_old / (v_cm_old - v_cm)
         end if
         v_cm_old = v_cm
         t_old = solver%time
      end do
      call assertTrue(n_crossings == 3, 'three zero crossings of v_cm within 16 s')
      if (n_crossings == 3) then
         if (rank == 0) print '(a,f8.4,a,f8.4,a)', '  measured period ', crossings(3) - crossings(1), ' s (exact ', &
            2.0_rp * pi / omega, ' s)'
         call assertRelativelyEqual(2.0_rp * pi / omega, crossings(3) - crossings(1), 0.02_rp, 'period within 2 %')
      end if
      call solver%free()

   contains

      real(rp) function centre_of_mass_velocity()
         integer :: q
         sums = 0.0_rp
         do q = 1, solver%particles%count
            sums = sums + [solver%particles%mass(q) * solver%particles%v(1, q), solver%particles%mass(q)]
         end do
         call MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
         centre_of_mass_velocity = sums(1) / sums(2)
      end function centre_of_mass_velocity
   end subroutine test_fixed_free_bar_period
end module test_elastic_bar
