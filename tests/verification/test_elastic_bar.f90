!> Axial vibration of a fixed-free elastic bar (verification.md section 1; Bardenhagen 2002):
!> L = 25, E = 100, rho = 1, nu = 0, v(x, 0) = v0 sin(beta x), beta = pi / (2 L).
!> Exact: v_cm(t) = v0 / (beta L) cos(omega t), omega = beta sqrt(E / rho), period 10 s.
!> The period error and its order of convergence over three cell sizes for each shape function (the table
!> of docs/speed-accuracy.md, "Shape functions").
module test_elastic_bar
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use assertions, only: assertTrue, assertRelativelyEqual, assertLessThanOrEqual
   use error_status, only: status_t
   use scene_description, only: scene_t, body_spec_t, wall_no_slip, model_linear_elastic
   use mpm_solver, only: solver_t
   use input_text, only: real_text
   implicit none
   private

   public :: test_fixed_free_bar_period, test_bar_period_convergence

   real(rp), parameter :: bar_length = 25.0_rp, youngs_modulus = 100.0_rp, v0 = 0.1_rp
   real(rp), parameter :: pi = acos(-1.0_rp), beta = pi / (2.0_rp * bar_length)

contains

   !> The bar on a grid of cell size h (1 / h cells across it) with `shape_function` ('linear' default).
   function bar_scene(h, shape_function) result(scene)
      real(rp), intent(in), optional :: h
      character(len=*), intent(in), optional :: shape_function
      type(scene_t) :: scene
      type(body_spec_t) :: bar
      real(rp) :: cell
      cell = 1.0_rp
      if (present(h)) cell = h
      if (present(shape_function)) scene%grid%shape_function = shape_function
      ! the convergence study in pure FLIP: no PIC damping that grows with the number of steps
      if (present(h)) scene%run%flip_fraction = 1.0_rp
      scene%grid%dim = 2
      scene%grid%cell_size = cell
      scene%grid%extent = [30.0_rp, 1.0_rp, 0.0_rp]
      scene%grid%ncells = [nint(30.0_rp / cell), nint(1.0_rp / cell), 1]
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
      real(rp) :: period
      period = measured_period(comm, bar_scene())
      call assertTrue(period > 0.0_rp, 'a period was measured')
   end subroutine test_fixed_free_bar_period

   !> Period error |T - T_exact| / T_exact at h = 1, 1/2, 1/4 for 'linear' and 'bspline2', and the observed
   !> order log2(e_h / e_h/2) of each refinement. Asserted: bspline2 converges (order >= 0.9 at each
   !> refinement; measured 1.05, 1.04); both stay within 2 % of the exact period (as the test above). The multilinear error
   !> does not converge (5.7e-4, 7.7e-5, 3.4e-3): at h = 1/4 the amplitude (0.16 m) exceeds half a particle
   !> spacing and particles cross cells, whose error the C1 B-spline removes [SKB08].
   subroutine test_bar_period_convergence(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=8), parameter :: shapes(2) = [character(len=8) :: 'linear', 'bspline2']
      real(rp), parameter :: sizes(3) = [1.0_rp, 0.5_rp, 0.25_rp]
      real(rp) :: error(3, 2), exact, order
      integer :: s, r, rank
      call MPI_Comm_rank(comm, rank)
      exact = 2.0_rp * pi / (beta * sqrt(youngs_modulus / 1.0_rp))
      do s = 1, 2
         do r = 1, 3
            error(r, s) = abs(measured_period(comm, bar_scene(sizes(r), trim(shapes(s)))) - exact) / exact
         end do
      end do
      if (rank == 0) then
         print '(a)', '  shape      h      period error   order'
         do s = 1, 2
            print '(2x,a8,f7.3,es14.3)', shapes(s), sizes(1), error(1, s)
            do r = 2, 3
               print '(2x,a8,f7.3,es14.3,f8.2)', shapes(s), sizes(r), error(r, s), &
                  log(error(r - 1, s) / error(r, s)) / log(2.0_rp)
            end do
         end do
      end if
      do r = 2, 3
         order = log(error(r - 1, 2) / error(r, 2)) / log(2.0_rp)
         call assertTrue(order >= 0.9_rp, 'bspline2: order >= 0.9 from h = '//trim(adjustl(real_text(sizes(r - 1)))))
      end do
      do s = 1, 2
         call assertLessThanOrEqual(maxval(error(:, s)), 0.02_rp, trim(shapes(s))//': period within 2 %')
      end do
   end subroutine test_bar_period_convergence

   !> The period of v_cm(t) from its first and third zero crossings, with the bar's initial mode set.
   real(rp) function measured_period(comm, scene) result(period)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp) :: sums(2), v_cm, v_cm_old, t_old, crossings(3), omega
      integer :: p, n_crossings, rank

      period = 0.0_rp
      call MPI_Comm_rank(comm, rank)
      call solver%init(scene, comm, status)
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
         period = crossings(3) - crossings(1)
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
   end function measured_period
end module test_elastic_bar
