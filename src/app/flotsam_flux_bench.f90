!> FOAL1's flux stage alone (issue 17): `flotsam_flux_bench dense|sparse [rounds]` times
!> limited_flux_smoothing's field_flux_increments on a synthetic 2-D stress field and prints one line:
!>   flux_bench <field> cells <existing cells> increments <non-zero increments> best_us <best time per call>
!>   checksum <sum |dq|>
!> The padded box holds 172 x 172 cells with a triangle of water (a column after some collapse: the flux
!> stage runs over the bounding box of the existing cells) with hydrostatic stresses; `dense` puts a
!> checkerboard on every cell (most faces active, as in the collapsing column's first steps), `sparse` on
!> 15 % of them (as later, and in the tank). The field is the same from run to run (a fixed seed), so the
!> checksum compares two builds' increments; the time is the best of `rounds` (default 30) rounds of 20
!> calls. A whole run's step time moves by 5-10 % on a shared machine; the kernel alone, alternating two
!> binaries over a dozen processes, moves by a few per cent (docs/performance-history.md, "FOAL1's flags and
!> slopes in vector lanes").
program flotsam_flux_bench
   use, intrinsic :: iso_fortran_env, only: error_unit, int64
   use kinds, only: rp
   use cell_halo, only: padded_cells_t
   use limited_flux_smoothing, only: flux_options_t, flux_workspace_t, field_flux_increments
   implicit none
   integer, parameter :: nx = 172, ny = 172, nq = 4, calls_per_round = 20
   real(rp), parameter :: h = 0.01_rp, gravity = 9.81_rp
   type(padded_cells_t) :: box
   type(flux_options_t) :: options
   type(flux_workspace_t) :: workspace
   real(rp), allocatable :: field(:, :), dq(:, :)
   logical, allocatable :: exists(:)
   integer, allocatable :: seed(:)
   integer :: i, j, c, round, call_index, rounds, seed_size, status
   integer(int64) :: t0, t1, rate
   real(rp) :: best, noise, u, depth, checkerboard_share
   character(len=16) :: which, text

   call get_command_argument(1, which)
   rounds = 30
   if (command_argument_count() >= 2) then
      call get_command_argument(2, text)
      read (text, *, iostat=status) rounds
      if (status /= 0 .or. rounds < 1) then
         write (error_unit, '(a)') 'flotsam_flux_bench: rounds must be a positive integer'
         error stop 2
      end if
   end if
   select case (which)
   case ('dense')
      checkerboard_share = 1.0_rp
   case ('sparse')
      checkerboard_share = 0.15_rp
   case default
      write (error_unit, '(a)') 'usage: flotsam_flux_bench dense|sparse [rounds]'
      error stop 2
   end select
   call random_seed(size=seed_size)
   allocate (seed(seed_size))
   seed = 12345
   call random_seed(put=seed)

   box%dim = 2
   box%n = [nx, ny, 1]
   box%count = nx * ny
   box%stride = [1, nx, nx * ny]
   allocate (box%owned(box%count), field(2 + 2 + nq, box%count), dq(nq, box%count), exists(box%count))
   box%owned = .false.
   field = 0.0_rp
   exists = .false.
   do j = 3, ny - 2          ! two ghost layers around the owned cells
      do i = 3, nx - 2
         c = i + (j - 1) * nx
         box%owned(c) = .true.
         if (real(i, rp) > 10.0_rp + 1.4_rp * real(j - 3, rp)) cycle     ! the triangle of water
         exists(c) = .true.
         call random_number(u)
         noise = 0.0_rp
         if (u < checkerboard_share) noise = 200.0_rp * (u - 0.5_rp) * merge(1, -1, mod(i + j, 2) == 0)
         depth = real(ny - j, rp) * h
         field(1, c) = 1.0_rp                                              ! the flag
         field(2, c) = 0.01_rp * (1.0_rp + 0.1_rp * u)                     ! m_c
         field(3, c) = (real(i, rp) - 0.5_rp + 0.2_rp * (u - 0.5_rp)) * h  ! x_o^c
         field(4, c) = (real(j, rp) - 0.5_rp) * h
         field(5, c) = -gravity * depth + noise                            ! sigma / rho (xx, yy, zz, xy)
         field(6, c) = -gravity * depth + 0.5_rp * noise
         field(7, c) = 0.3_rp * noise
         field(8, c) = -gravity * depth - noise
      end do
   end do

   call system_clock(count_rate=rate)
   best = huge(1.0_rp)
   do round = 1, rounds
      call system_clock(t0)
      do call_index = 1, calls_per_round
         call field_flux_increments(box, h, exists, field, options, dq, workspace)
      end do
      call system_clock(t1)
      best = min(best, real(t1 - t0, rp) / real(rate, rp) / calls_per_round)
   end do
   print '(a, a, a, i0, a, i0, a, f10.1, a, es24.16)', 'flux_bench ', trim(which), ' cells ', count(exists), &
      ' increments ', count(abs(dq) > 0.0_rp), ' best_us ', best * 1.0e6_rp, ' checksum ', sum(abs(dq))
end program flotsam_flux_bench
