!> A progress line on standard error every few wall-clock seconds: simulated time and percentage,
!> steps/s, particle-steps/s and the estimated time left.
module progress_reporter
   use, intrinsic :: iso_fortran_env, only: error_unit
   use kinds, only: rp, i8
   implicit none
   private

   type, public :: progress_reporter_t
      real(rp) :: interval = 5.0_rp         !< wall seconds between lines; <= 0 disables
      real(rp) :: end_time = 1.0_rp
      integer(i8) :: start_count = 0, last_count = 0, rate = 1
      integer(i8) :: last_step = 0
      real(rp) :: last_particle_steps = 0.0_rp, particle_steps = 0.0_rp
      real(rp) :: start_time = 0.0_rp
   contains
      procedure :: start => progress_start
      procedure :: update => progress_update
      procedure :: elapsed => progress_elapsed
   end type progress_reporter_t

contains

   subroutine progress_start(self, interval, start_time, end_time)
      class(progress_reporter_t), intent(inout) :: self
      real(rp), intent(in) :: interval, start_time, end_time
      self%interval = interval
      self%start_time = start_time
      self%end_time = end_time
      call system_clock(self%start_count, self%rate)
      self%last_count = self%start_count
   end subroutine progress_start

   !> Wall seconds since start.
   real(rp) function progress_elapsed(self)
      class(progress_reporter_t), intent(in) :: self
      integer(i8) :: now
      call system_clock(now)
      progress_elapsed = real(now - self%start_count, rp) / real(self%rate, rp)
   end function progress_elapsed

   !> Account one step over `particles` global particles and print if the interval has passed.
   subroutine progress_update(self, time, step, particles, print_line)
      class(progress_reporter_t), intent(inout) :: self
      real(rp), intent(in) :: time
      integer(i8), intent(in) :: step, particles
      logical, intent(in) :: print_line
      integer(i8) :: now
      real(rp) :: since_last, steps_per_s, psteps_per_s, fraction, left
      self%particle_steps = self%particle_steps + real(particles, rp)
      if (self%interval <= 0.0_rp .or. .not. print_line) return
      call system_clock(now)
      since_last = real(now - self%last_count, rp) / real(self%rate, rp)
      if (since_last < self%interval) return
      steps_per_s = real(step - self%last_step, rp) / since_last
      psteps_per_s = (self%particle_steps - self%last_particle_steps) / since_last
      fraction = (time - self%start_time) / max(self%end_time - self%start_time, tiny(1.0_rp))
      left = self%elapsed() * (1.0_rp - fraction) / max(fraction, 1.0e-12_rp)
      write (error_unit, '(a,es11.4,a,f6.2,a,i0,a,es9.2,a,es9.2,a,a)') 't = ', time, ' s (', 100 * fraction, &
         ' %)  step ', step, '  ', steps_per_s, ' steps/s  ', psteps_per_s, ' particle-steps/s  ETA ', &
         trim(clock_text(left))
      flush (error_unit)
      self%last_count = now
      self%last_step = step
      self%last_particle_steps = self%particle_steps
   end subroutine progress_update

   pure function clock_text(seconds) result(text)
      real(rp), intent(in) :: seconds
      character(len=16) :: text
      integer :: s
      s = nint(min(seconds, 3.6e7_rp))
      write (text, '(i0,":",i2.2,":",i2.2)') s / 3600, mod(s / 60, 60), mod(s, 60)
   end function clock_text
end module progress_reporter
