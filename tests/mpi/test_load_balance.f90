!> Load balancing (docs/theory.md section 6): scenes whose particles start in one part of the domain,
!> run for 200 steps with and without rebalancing (as the time loop does it: at the start and every
!> rebalance_interval steps). The diagnostics agree to round-off (relative 1e-10, as between rank
!> counts: only the order of the particle-grid sums changes), the layout did change, and afterwards the
!> largest rank holds at most 60 % of the particles on 2 ranks (a lower share than without on more).
!> Without rebalancing the slabs of the active region keep their inner cuts (section 6.2). A layout search
!> that finds no better layout is not repeated at every check while the counts stay.
module test_load_balance
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_size
   use assertions, only: assertTrue, assertRelativelyEqual, assertEqual, assertLessThanOrEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use input_text, only: real_text
   use test_scenes, only: tank_with_inlet, corner_column, water_scene, add_body
   use time_loop_steps, only: start_run, step_run
   implicit none
   private

   public :: test_collapsing_column_rebalanced, test_apic_column_rebalanced, test_filling_tank_rebalanced
   public :: test_fruitless_search_not_repeated

   integer, parameter :: n_steps = 200

contains

   !> A 1 m x 1 m water column in the corner of a 4 m x 2 m box. The active region starts at the column,
   !> split evenly; as the column collapses to the right the region grows with the last slab, which
   !> gathers the water (without rebalancing the largest rank holds 68 % on 2 ranks, 49 % on 4 after
   !> 200 steps). Standard MPM and each stabilization scheme (their cell arrays follow the new box).
   subroutine test_collapsing_column_rebalanced(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=5), parameter :: schemes(4) = [character(len=5) :: 'none', 'C0', 'NB', 'FOAL1']
      type(scene_t) :: scene
      integer :: i
      do i = 1, size(schemes)
         scene = corner_column([4.0_rp, 2.0_rp], 1.0_rp, schemes(i))
         scene%run%fixed_dt = 5.0e-4_rp
         call compare_with_and_without(comm, scene, 'collapsing column, '//trim(schemes(i)))
      end do
   end subroutine test_collapsing_column_rebalanced

   !> The collapsing column with APIC: the affine matrices go with their particles to the new owners (a
   !> small step: APIC on multilinear shape functions is not stable at the CFL step here, docs/theory.md).
   subroutine test_apic_column_rebalanced(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = corner_column([4.0_rp, 2.0_rp], 1.0_rp, 'none')
      scene%run%fixed_dt = 1.0e-4_rp
      scene%run%transfer = 'apic'
      call compare_with_and_without(comm, scene, 'collapsing column, APIC')
   end subroutine test_apic_column_rebalanced

   !> A 3 m x 2 m tank filled through an opening 0.6 m high at the foot of the left wall: the walls'
   !> node lists and the inlet's feeder are rebuilt for the new boxes, the new layers are created by
   !> their new owners. On 2 ranks the uniform split is along x and the stream stays within the first
   !> two columns for these 200 steps: only a split along y can share it. The CFL step: its signal speed
   !> is reduced per material over the ranks (solver local_speeds), so it does not depend on which rank
   !> holds the fastest and which the lightest particle (before, it jumped by 1e-7 in time at step 200).
   subroutine test_filling_tank_rebalanced(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = tank_with_inlet(0.6_rp, 1.0_rp, 1.0_rp)
      scene%inlets(1)%hydrostatic = .true.
      call compare_with_and_without(comm, scene, 'filling tank')
   end subroutine test_filling_tank_rebalanced

   !> A block of water at rest (no gravity) 3 x 3 cells in the middle of the box: the cell layers cannot be
   !> shared evenly (on 2 ranks the best split holds 2 of the 3 layers, a share of 2/3), so every balance
   !> check finds the ranks unbalanced. The first search takes the best layout, the next finds none better;
   !> after that, with the counts unchanged, the checks must not search again (before, each of the 10
   !> checks of 200 steps made a search: a pass over the particles per rank grid).
   subroutine test_fruitless_search_not_repeated(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(status_t) :: status
      integer :: nranks, step, searches_after_start
      call MPI_Comm_size(comm, nranks)
      scene = water_scene(2, 0.05_rp, [2.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 0.0_rp)
      call add_body(scene, 1, [0.9_rp, 0.9_rp, 0.0_rp], [1.05_rp, 1.05_rp, 0.0_rp], 2, .false., 0.0_rp)
      scene%run%fixed_dt = 1.0e-4_rp
      call start_run(solver, scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      searches_after_start = solver%layout_searches
      do step = 1, n_steps
         call step_run(solver, status)
      end do
      call assertTrue(status%ok, 'balance: '//trim(status%message))
      associate (diag => solver%diagnostics())
         call assertEqual(diag%particles, 36_i8, 'the block: 3 x 3 cells of 4 particles')
         if (nranks == 1) then
            call assertEqual(solver%layout_searches, 0, 'one rank: no search')
         else
            call assertTrue(diag%max_rank_share > 1.02_rp / nranks, 'the block cannot be balanced, share '// &
                            real_text(diag%max_rank_share))
            if (nranks == 2) call assertRelativelyEqual(diag%max_rank_share, 2.0_rp / 3.0_rp, 1.0e-12_rp, &
                                                        'the best split: 2 of 3 layers')
            call assertTrue(solver%unimproved_largest > 0_i8, 'the last search found no better layout')
            call assertTrue(solver%layout_searches <= searches_after_start + 1, 'at most one search after the start '// &
                            'in 10 checks with unchanged counts: '//real_text(real(solver%layout_searches, rp)))
         end if
      end associate
      call solver%free()
   end subroutine test_fruitless_search_not_repeated

   subroutine compare_with_and_without(comm, scene, label)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: label
      type(scene_t) :: fixed
      type(diagnostics_t) :: off, on
      integer, allocatable :: cuts_off(:, :), cuts_on(:, :)
      integer :: nranks
      character(len=:), allocatable :: what

      call MPI_Comm_size(comm, nranks)
      what = ' ('//label//')'
      fixed = scene
      fixed%run%rebalance_threshold = 0.0_rp
      off = run_steps(comm, fixed, cuts_off)
      on = run_steps(comm, scene, cuts_on)
      call assertRelativelyEqual(off%time, on%time, 1.0e-12_rp, 'time'//what)
      call assertEqual(off%particles, on%particles, 'particles'//what)
      call assertTrue(on%particles > 0_i8, 'the scene has particles'//what)
      call assertRelativelyEqual(off%total_mass, on%total_mass, 1.0e-12_rp, 'total mass'//what)
      call assertRelativelyEqual(off%kinetic_energy, on%kinetic_energy, 1.0e-10_rp, 'kinetic energy'//what)
      call assertTrue(on%kinetic_energy > 0.0_rp, 'the scene moved'//what)
      call assertRelativelyEqual(off%fluid_volume, on%fluid_volume, 1.0e-10_rp, 'fluid volume'//what)
      call assertRelativelyEqual(off%h_eq, on%h_eq, 1.0e-10_rp, 'h_eq'//what)
      call assertRelativelyEqual(off%max_speed, on%max_speed, 1.0e-10_rp, 'max speed'//what)
      call assertEqual(off%lost_particles, on%lost_particles, 'lost particles'//what)
      if (nranks == 1) then
         call assertTrue(all(cuts_on == cuts_off), 'one rank: nothing to balance'//what)
         return
      end if
      call assertTrue(off%max_rank_share > 1.3_rp / nranks, 'without rebalancing one rank holds more than 1.3 times '// &
                      'its share, share '//real_text(off%max_rank_share)//what)
      call assertTrue(any(cuts_on /= cuts_off), 'rebalancing moved the cuts'//what)
      call assertTrue(on%max_rank_share < off%max_rank_share, 'rebalanced share '//real_text(on%max_rank_share)// &
                      ' below '//real_text(off%max_rank_share)//what)
      if (nranks == 2) call assertLessThanOrEqual(on%max_rank_share, 0.6_rp, &
                                                  'largest share on 2 ranks <= 60 % after rebalancing'//what)
   end subroutine compare_with_and_without

   !> n_steps steps, balance checks as in the time loop (simulation.f90); the diagnostics and the cuts.
   function run_steps(comm, scene, cuts) result(diag)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      integer, allocatable, intent(out) :: cuts(:, :)
      type(diagnostics_t) :: diag
      type(solver_t) :: solver
      type(status_t) :: status
      integer :: step
      call start_run(solver, scene, comm, status)
      call assertTrue(status%ok, 'solver init: '//trim(status%message))
      do step = 1, n_steps
         call step_run(solver, status)
      end do
      call assertTrue(status%ok, 'balance: '//trim(status%message))
      diag = solver%diagnostics()
      cuts = solver%domain%cuts
      call solver%free()
   end function run_steps
end module test_load_balance
