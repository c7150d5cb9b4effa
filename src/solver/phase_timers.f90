!> Wall-clock time of each phase of the time loop, accumulated over a run (written to timing.csv by
!> run_summary; docs/output.md). The clock is read once per phase change (MPI_Wtime, about 20 ns), never
!> per particle: a step makes about 15 changes. The phases tile the time from the first switch_to on,
!> so their sum is the loop's wall time; a phase a scene does not use costs two clock reads per step.
module phase_timers
   use kinds, only: rp
   use mpi_f08, only: MPI_Wtime
   implicit none
   private

   integer, parameter, public :: phase_particles_to_grid = 1, phase_grid_update = 2, phase_walls = 3, &
                                 phase_stabilization = 4, phase_grid_to_particles = 5, phase_constitutive = 6, &
                                 phase_inflow = 7, phase_halo = 8, phase_migration = 9, phase_sort = 10, &
                                 phase_time_step = 11, phase_health = 12, phase_diagnostics = 13, phase_output = 14, &
                                 phase_checkpoint = 15, phase_rebalance = 16, phase_volume_correction = 17, &
                                 phase_loads = 18, phase_other = 19
   integer, parameter, public :: phase_count = 19

   !> Column names of timing.csv, in the order of the phase numbers.
   character(len=*), parameter, public :: phase_names(phase_count) = [character(len=18) :: &
                                          'particles_to_grid', 'grid_update', 'walls', 'stabilization', &
                                          'grid_to_particles', 'constitutive', 'inflow', 'node_halo', &
                                          'migration', 'sort', 'time_step', 'health_check', 'diagnostics', &
                                          'output', 'checkpoint', 'rebalance', 'volume_correction', 'loads', 'other']

   type, public :: phase_timers_t
      real(rp) :: seconds(phase_count) = 0.0_rp   !< accumulated wall time per phase [s]
      integer :: current = 0                      !< phase being timed (0: not started)
      real(rp) :: since = 0.0_rp                  !< MPI_Wtime when `current` began
   contains
      procedure :: switch_to => timers_switch_to
      procedure :: reset => timers_reset
   end type phase_timers_t

contains

   !> Charge the time since the last switch to the current phase and start timing `phase`.
   subroutine timers_switch_to(self, phase)
      class(phase_timers_t), intent(inout) :: self
      integer, intent(in) :: phase
      real(rp) :: now
      now = MPI_Wtime()
      if (self%current > 0) self%seconds(self%current) = self%seconds(self%current) + (now - self%since)
      self%current = phase
      self%since = now
   end subroutine timers_switch_to

   !> Zero the sums and stop timing (the next switch_to starts again).
   subroutine timers_reset(self)
      class(phase_timers_t), intent(inout) :: self
      self%seconds = 0.0_rp
      self%current = 0
   end subroutine timers_reset
end module phase_timers
