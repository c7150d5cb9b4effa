!> Hydrostatic column (verification.md section 2, the cb-geo validation case): 0.2 m wide, 0.1 m of
!> fluid (rho = 1800, K = 1e6 Pa, mu = 0), sides and base restrained, 5 x 5 particles per cell, g = 9.81,
!> t = 0.2 s. The base stress -rho g H = -1765.8 Pa is compared with the vertical stress of the lowest
!> particle row; published first-order errors: 4.85 % (h = 0.01), 2.33 % (0.005), 1.08 % (0.0025).
!> Our column starts from the hydrostatic state (&body hydrostatic), so the error measures how well the
!> scheme keeps it, plus the half particle spacing between the lowest particles and the base.
module test_hydrostatic_column
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_Comm_rank
   use assertions, only: assertTrue, assertLessThanOrEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use test_scenes, only: water_scene, add_body
   implicit none
   private

   public :: test_base_stress_convergence

   real(rp), parameter :: column_height = 0.1_rp, rho = 1800.0_rp, g = 9.81_rp
   integer, parameter :: ppc = 5

contains

   subroutine test_base_stress_convergence(comm)
      type(MPI_Comm), intent(in) :: comm
      real(rp), parameter :: cell_sizes(3) = [0.01_rp, 0.005_rp, 0.0025_rp]
      real(rp), parameter :: published_error(3) = [0.0485_rp, 0.0233_rp, 0.0108_rp]
      real(rp) :: error(3), order
      integer :: i, rank
      call MPI_Comm_rank(comm, rank)
      do i = 1, 3
         error(i) = base_stress_error(comm, cell_sizes(i))
         if (rank == 0) print '(a,f7.4,a,f7.3,a,f6.2,a)', '  h = ', cell_sizes(i), ' m: base stress error ', &
            100 * error(i), ' % (published USF: ', 100 * published_error(i), ' %)'
         call assertLessThanOrEqual(error(i), published_error(i), 'base stress error within the published figure')
      end do
      order = log(error(1) / error(3)) / log(cell_sizes(1) / cell_sizes(3))
      if (rank == 0) print '(a,f5.2)', '  measured convergence order: ', order
      call assertTrue(order > 0.8_rp, 'at least first-order convergence of the base stress')
   end subroutine test_base_stress_convergence

   !> |sigma_yy(lowest particle row) - (-rho g H)| / (rho g H) at t = 0.2 s.
   real(rp) function base_stress_error(comm, h) result(error)
      type(MPI_Comm), intent(in) :: comm
      real(rp), intent(in) :: h
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      real(rp) :: sums(2), exact
      integer :: p
      scene = water_scene(2, h, [0.2_rp, 0.15_rp, 0.0_rp], 1.0e6_rp, g)
      scene%materials(1)%density = rho
      scene%materials(1)%viscosity = 0.0_rp
      scene%run%end_time = 0.2_rp
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [0.2_rp, column_height, 0.0_rp], ppc, .true., column_height)
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do while (solver%time < scene%run%end_time)
         solver%dt = min(solver%dt, scene%run%end_time - solver%time)
         call solver%advance()
      end do
      sums = 0.0_rp
      do p = 1, solver%particles%count
         if (solver%particles%x(2, p) < h / ppc) then     ! the lowest particle row
            sums = sums + [solver%particles%density(p) * solver%particles%sbar(2, p), 1.0_rp]
         end if
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, 2, MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      exact = -rho * g * column_height
      error = abs(sums(1) / sums(2) - exact) / abs(exact)
      call solver%free()
   end function base_stress_error
end module test_hydrostatic_column
