!> The same scene on 1 rank and on all ranks of the communicator gives the same diagnostics after 200
!> steps (relative difference <= 1e-10): decomposition, ghost-node sums and migration change nothing
!> but the order of floating-point sums. A quantity that is zero up to round-off (the kinetic energy of
!> a tank in exact hydrostatic equilibrium, ~1e-30 J) is compared against a physical scale instead of
!> itself: 1e-10 of m g H for the energy and of sqrt(g H) for the speed.
module test_rank_count_invariance
   use kinds, only: rp
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_split, MPI_Comm_free, MPI_Bcast, MPI_DOUBLE_PRECISION, &
                      MPI_UNDEFINED, MPI_COMM_NULL, operator(/=)
   use assertions, only: assertTrue, assertRelativelyEqual, assertEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use test_scenes, only: water_scene, add_body
   implicit none
   private

   public :: test_hydrostatic_tank_rank_invariance, test_settling_tank_rank_invariance, test_schemes_rank_invariance, &
             test_collapsing_column_rank_invariance, test_collapsing_column_3d_rank_invariance, &
             test_collapsing_column_cfl_rank_invariance, test_bspline2_rank_invariance, &
             test_apic_column_rank_invariance

   integer, parameter :: n_steps = 200

contains

   !> The paper's tank (3.2 m x 6.4 m, water 3.2 m deep at rest, 8 cells per 3.2 m, 3 x 3 ppc).
   subroutine test_hydrostatic_tank_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = water_scene(2, 0.4_rp, [3.2_rp, 6.4_rp, 0.0_rp], 2.2e9_rp, 10.0_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [3.2_rp, 3.2_rp, 0.0_rp], 3, .true., 3.2_rp)
      ! scales: the block's m g H and sqrt(g H)
      call compare_rank_counts(comm, scene, 1000.0_rp * 3.2_rp**2 * 10.0_rp * 3.2_rp, sqrt(10.0_rp * 3.2_rp))
   end subroutine test_hydrostatic_tank_rank_invariance

   !> The same tank with the water released without its hydrostatic stress: it compresses under gravity
   !> and oscillates, so every diagnostic is a physical, non-zero quantity.
   subroutine test_settling_tank_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = water_scene(2, 0.4_rp, [3.2_rp, 6.4_rp, 0.0_rp], 2.0e7_rp, 10.0_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [3.2_rp, 3.2_rp, 0.0_rp], 3, .false., 0.0_rp)
      call compare_rank_counts(comm, scene)
   end subroutine test_settling_tank_rank_invariance

   !> The settling tank and the collapsing column with each stabilization scheme (C0, NB, FOAL1).
   subroutine test_schemes_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=5), parameter :: schemes(3) = [character(len=5) :: 'C0', 'NB', 'FOAL1']
      type(scene_t) :: scene
      integer :: i
      do i = 1, size(schemes)
         scene = water_scene(2, 0.4_rp, [3.2_rp, 6.4_rp, 0.0_rp], 2.0e7_rp, 10.0_rp)
         call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [3.2_rp, 3.2_rp, 0.0_rp], 3, .false., 0.0_rp)
         scene%materials(1)%stabilization = schemes(i)
         call compare_rank_counts(comm, scene, label='settling tank, '//trim(schemes(i)))
         scene = collapsing_column()
         scene%run%fixed_dt = 5.0e-4_rp
         scene%materials(1)%stabilization = schemes(i)
         call compare_rank_counts(comm, scene, label='collapsing column, '//trim(schemes(i)))
      end do
   end subroutine test_schemes_rank_invariance

   !> A water column collapsing in a 4 m x 2 m box (dam break), particles crossing rank boundaries.
   subroutine test_collapsing_column_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = collapsing_column()
      scene%run%fixed_dt = 5.0e-4_rp
      call compare_rank_counts(comm, scene)
   end subroutine test_collapsing_column_rank_invariance

   !> The same dam break with the CFL step: its signal speed c(rho_min) + max |v| must be the material's
   !> on every rank count, although the fastest particle (the front) and the lightest one lie on different
   !> ranks (the largest per-rank sum c + |v| is not: it changed the step by 4e-5 in a dam break).
   subroutine test_collapsing_column_cfl_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = collapsing_column()
      call compare_rank_counts(comm, scene)
   end subroutine test_collapsing_column_cfl_rank_invariance

   !> A 1 m x 1 m water column in the corner of a 4 m x 2 m box, h = 0.05 m, 2 x 2 particles per cell.
   type(scene_t) function collapsing_column() result(scene)
      scene = water_scene(2, 0.05_rp, [4.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 9.81_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [1.0_rp, 1.0_rp, 0.0_rp], 2, .false., 0.0_rp)
   end function collapsing_column

   !> A 0.6 m cube of water in the corner of a 2 m x 0.6 m x 1.2 m box, h = 0.1 m, 2 x 2 x 2 per cell.
   type(scene_t) function collapsing_column_3d() result(scene)
      scene = water_scene(3, 0.1_rp, [2.0_rp, 0.6_rp, 1.2_rp], 2.0e6_rp, 9.81_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [0.6_rp, 0.6_rp, 0.6_rp], 2, .false., 0.0_rp)
   end function collapsing_column_3d

   subroutine test_collapsing_column_3d_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = collapsing_column_3d()
      scene%run%fixed_dt = 1.0e-3_rp
      call compare_rank_counts(comm, scene)
   end subroutine test_collapsing_column_3d_rank_invariance

   !> Quadratic B-splines (3-plane node halo, ghost layers, slabs of 3 cells): the collapsing column in 2-D
   !> plain and with each scheme that combines with them (C0, NB, FOAL1), and in 3-D.
   subroutine test_bspline2_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=5), parameter :: schemes(4) = [character(len=5) :: 'none', 'C0', 'NB', 'FOAL1']
      type(scene_t) :: scene
      integer :: i
      do i = 1, size(schemes)
         scene = collapsing_column()
         scene%grid%shape_function = 'bspline2'
         scene%run%fixed_dt = 5.0e-4_rp
         scene%materials(1)%stabilization = schemes(i)
         call compare_rank_counts(comm, scene, label='bspline2 collapsing column, '//trim(schemes(i)))
      end do
      scene = collapsing_column_3d()
      scene%grid%shape_function = 'bspline2'
      scene%run%fixed_dt = 1.0e-3_rp
      call compare_rank_counts(comm, scene, label='bspline2 3-D collapsing column')
   end subroutine test_bspline2_rank_invariance

   !> The collapsing columns (2-D, 3-D) with APIC: the affine matrices migrate with their particles. A step
   !> of a fifth of the FLIP/PIC columns': with multilinear shape functions APIC is not stable at the CFL
   !> step on a free surface (docs/theory.md, "APIC").
   subroutine test_apic_column_rank_invariance(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = collapsing_column()
      scene%run%fixed_dt = 1.0e-4_rp
      scene%run%transfer = 'apic'
      call compare_rank_counts(comm, scene, label='2-D, APIC')
      scene = collapsing_column_3d()
      scene%run%fixed_dt = 2.0e-4_rp
      scene%run%transfer = 'apic'
      call compare_rank_counts(comm, scene, label='3-D, APIC')
   end subroutine test_apic_column_rank_invariance

   !> Run on a one-rank communicator (rank 0 alone) and on `comm`; compare. Optional scales replace
   !> the serial value as the reference of the relative tolerance when they are larger.
   subroutine compare_rank_counts(comm, scene, energy_scale, speed_scale, label)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      real(rp), intent(in), optional :: energy_scale, speed_scale
      character(len=*), intent(in), optional :: label
      character(len=:), allocatable :: what
      type(MPI_Comm) :: serial
      type(diagnostics_t) :: one, all
      real(rp) :: serial_values(6)
      integer :: rank, colour

      call MPI_Comm_rank(comm, rank)
      colour = merge(0, MPI_UNDEFINED, rank == 0)
      call MPI_Comm_split(comm, colour, 0, serial)
      serial_values = 0.0_rp
      if (serial /= MPI_COMM_NULL) then
         one = run_steps(serial, scene)
         serial_values = values(one)
         call MPI_Comm_free(serial)
      end if
      call MPI_Bcast(serial_values, 6, MPI_DOUBLE_PRECISION, 0, comm)
      all = run_steps(comm, scene)
      what = ''
      if (present(label)) what = ' ('//label//')'
      call assertRelativelyEqual(serial_values(1), all%time, 1.0e-12_rp, 'time'//what)
      call assertRelativelyEqual(serial_values(2), all%total_mass, 1.0e-12_rp, 'total mass'//what)
      if (present(energy_scale)) then
         call assertEqual(serial_values(3), all%kinetic_energy, 1.0e-10_rp * max(energy_scale, abs(serial_values(3))), &
                          'kinetic energy (against m g H)'//what)
         call assertEqual(serial_values(6), all%max_speed, 1.0e-10_rp * max(speed_scale, abs(serial_values(6))), &
                          'max speed (against sqrt(g H))'//what)
      else
         call assertRelativelyEqual(serial_values(3), all%kinetic_energy, 1.0e-10_rp, 'kinetic energy'//what)
         call assertRelativelyEqual(serial_values(6), all%max_speed, 1.0e-10_rp, 'max speed'//what)
         call assertTrue(all%kinetic_energy > 0.0_rp, 'the scene moved')
      end if
      call assertRelativelyEqual(serial_values(4), all%fluid_volume, 1.0e-10_rp, 'fluid volume'//what)
      call assertRelativelyEqual(serial_values(5), all%h_eq, 1.0e-10_rp, 'h_eq'//what)
   end subroutine compare_rank_counts

   function run_steps(comm, scene) result(diag)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      type(diagnostics_t) :: diag
      type(solver_t) :: solver
      type(status_t) :: status
      integer :: step
      call solver%init(scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do step = 1, n_steps
         call solver%advance()
      end do
      diag = solver%diagnostics()
      call solver%free()
   end function run_steps

   pure function values(diag) result(v)
      type(diagnostics_t), intent(in) :: diag
      real(rp) :: v(6)
      v = [diag%time, diag%total_mass, diag%kinetic_energy, diag%fluid_volume, diag%h_eq, diag%max_speed]
   end function values
end module test_rank_count_invariance
