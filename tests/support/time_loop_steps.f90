!> Steps of a solver as the time loop takes them (src/driver/simulation.f90), without output: balanced
!> at the start and every rebalance_interval steps. For the tests that compare whole runs.
module time_loop_steps
   use kinds, only: i8
   use mpi_f08, only: MPI_Comm
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   implicit none
   private

   public :: start_run, step_run

contains

   !> Set the solver up for `scene` and balance it, as a new run starts. Collective.
   subroutine start_run(solver, scene, comm, status)
      type(solver_t), intent(inout) :: solver
      type(scene_t), intent(in) :: scene
      type(MPI_Comm), intent(in) :: comm
      type(status_t), intent(inout) :: status
      call solver%init(scene, comm, status)
      if (status%ok) call solver%balance_load(status)
   end subroutine start_run

   !> One step and, every rebalance_interval steps, the balance check. Collective.
   subroutine step_run(solver, status)
      type(solver_t), intent(inout) :: solver
      type(status_t), intent(inout) :: status
      call solver%advance()
      if (mod(solver%step, int(solver%run%rebalance_interval, i8)) == 0) call solver%balance_load(status)
   end subroutine step_run
end module time_loop_steps
