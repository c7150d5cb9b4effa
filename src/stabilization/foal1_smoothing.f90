!> FOAL1, the limited constant-flux smoothing of [Y17] section 3 (algorithms.md section 3):
!>   (a) C0 anti-locking of the rate of deformation (inherited from c0_anti_locking_t),
!>   (b) constitutive update with d~ (done by the solver),
!>   (c) cell-wise averaging q_c = sum m_p q_p / m_c of the smoothed variables ([Y17] section 3.2),
!>   (d) limited face fluxes q^_c = q_c + dq_c (limited_flux_smoothing, eqs. 5-13),
!>   (e) particle update q_p := q^_c (or q_p := q_p + dq_c with cell averaging off).
!> q is every component of the mass-specific stress s = sigma / rho (default [R]) or the mass-specific
!> pressure p / rho = -tr(s) / 3 only (frame-invariant option). With gamma_max = 0 no face is active
!> and FOAL1 is C0, bit for bit. Cell data next to a subdomain boundary comes from a two-layer face
!> halo exchange (cell_halo), so both ranks compute the same flux for a shared face.
module foal1_smoothing
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use stabilizer, only: stage_context_t, smoothing_passes
   use c0_anti_locking, only: c0_anti_locking_t
   use cell_binning, only: cell_list_t, bin_cell_mass_and_centre, cell_average, bin_cell_mass_and_local_moments
   use cell_halo, only: padded_cells_t, exchange_cell_halo, halo_width
   use background_grid, only: grid_t
   use limited_flux_smoothing, only: flux_options_t, flux_workspace_t, field_flux_increments
   implicit none
   private

   public :: sum_and_pack    ! for the tests

   type, extends(c0_anti_locking_t), public :: foal1_smoothing_t
      type(flux_options_t) :: options
      logical :: pressure_only = .false.       !< smooth p / rho only, not every stress component
      logical :: cell_averaging = .true.       !< step (c); off: purely incremental update
      type(padded_cells_t) :: box
      real(rp), allocatable :: centre(:, :)    !< mass centre x_o^c of the owned cells at x^n (occupied ones)
      ! work arrays kept between steps
      real(rp), allocatable :: q_sums(:, :), field(:, :), dq(:, :)   !< q_sums: m_c q_c of the owned cells
      real(rp), allocatable :: pass_dq(:, :)   !< one pass's increments, in a step of more than one
      logical, allocatable :: exists(:)
      integer, allocatable :: packed(:)        !< packed(1:n_packed): owned cells written into `field` by the last step
      integer :: n_packed = 0
      type(flux_workspace_t) :: workspace
   contains
      procedure :: prepare => foal1_prepare
      procedure :: filter_strain_rate => foal1_filter_strain_rate
      procedure :: filter_stress => foal1_filter_stress
   end type foal1_smoothing_t

contains

   !> C0's cell masses plus the mass centres, at x^n (one pass); with the rate from the grid in 3-D also the
   !> local moments (in 2-D the rate needs the mass centres only).
   subroutine foal1_prepare(self, context, particles)
      class(foal1_smoothing_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call self%size_cell_arrays(context%grid%cell_count, particles%n_sigma)
      if (.not. same_cells(self%box, context%grid)) then
         call self%box%init(context%grid)
         if (allocated(self%q_sums)) deallocate (self%q_sums, self%field, self%dq, self%exists, self%packed)   ! a new layout
      end if
      if (allocated(self%centre)) then
         if (size(self%centre, 2) /= context%grid%cell_count) deallocate (self%centre)
      end if
      if (.not. allocated(self%centre)) allocate (self%centre(context%grid%dim, context%grid%cell_count))
      if (context%rate_from_grid .and. context%grid%dim == 3) then
         call self%size_means(context%grid)
         call bin_cell_mass_and_local_moments(context%grid, particles, context%first, context%last, self%occupied, &
                                              self%cell_mass, self%means, self%centre)
      else
         call bin_cell_mass_and_centre(particles, context%first, context%last, self%occupied, self%cell_mass, &
                                       self%centre)
      end if
   end subroutine foal1_prepare

   !> C0's filter of the rate (step (a)); with the rate from the grid in 2-D from the mass centres FOAL1 keeps.
   subroutine foal1_filter_strain_rate(self, context, particles)
      class(foal1_smoothing_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      if (context%rate_from_grid .and. context%grid%dim == 2) then
         call self%rates_from_grid(context, self%centre)
      else
         call self%c0_anti_locking_t%filter_strain_rate(context, particles)
      end if
   end subroutine foal1_filter_strain_rate

   !> Steps (c) to (e) for the material's particles.
   subroutine foal1_filter_stress(self, context, particles)
      class(foal1_smoothing_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      real(rp), allocatable :: q(:, :)
      real(rp) :: share
      integer :: first, last, nq, dim, p, c, i, passes

      first = context%first
      last = context%last
      dim = context%grid%dim
      nq = merge(1, particles%n_sigma, self%pressure_only)

      call ensure_work_arrays(self, nq, dim, context%grid%cell_count)

      associate (q_sums => self%q_sums, field => self%field, dq => self%dq, exists => self%exists, &
                 of_owned => self%box%of_owned)
         ! padded cell field: exists, m_c, x_o^c, q_c; ghost layers from the neighbours (collective). Rows
         ! other than "exists" are read only where it is set. Only the occupied cells are written: first
         ! clear the cells the last step wrote that hold none of the material now (m_c = 0: unlisted);
         ! the rest of `field` and `exists` stays 0 from allocation, or is rewritten by every exchange.
         do i = 1, self%n_packed
            c = self%packed(i)
            if (self%cell_mass(c) > 0.0_rp) cycle
            field(1, of_owned(c)) = 0.0_rp
            exists(of_owned(c)) = .false.
         end do
         ! (c) the sums m_c q_c and the occupied cells' entries, in one pass over the particles
         if (self%pressure_only) then
            allocate (q(nq, max(0, last - first + 1)))
            do p = first, last
               q(1, p - first + 1) = -(particles%sbar(1, p) + particles%sbar(2, p) + particles%sbar(3, p)) / 3.0_rp
            end do
            call sum_and_pack(dim, nq, self%occupied, particles%cell(first:last), particles%mass(first:last), q, &
                              of_owned, self%cell_mass, self%centre, q_sums, field, exists)
         else if (dim == 2 .and. nq == 4) then
            call sum_and_pack(2, 4, self%occupied, particles%cell(first:last), particles%mass(first:last), &
                              particles%sbar(:, first:last), of_owned, self%cell_mass, self%centre, q_sums, field, exists)
         else if (dim == 3 .and. nq == 6) then
            call sum_and_pack(3, 6, self%occupied, particles%cell(first:last), particles%mass(first:last), &
                              particles%sbar(:, first:last), of_owned, self%cell_mass, self%centre, q_sums, field, exists)
         else
            call sum_and_pack(dim, nq, self%occupied, particles%cell(first:last), particles%mass(first:last), &
                              particles%sbar(:, first:last), of_owned, self%cell_mass, self%centre, q_sums, field, exists)
         end if
         self%n_packed = self%occupied%count
         self%packed(1:self%n_packed) = self%occupied%cells(1:self%n_packed)
         call exchange_cell_halo(context%domain, context%grid, self%box, field, flags=exists)

         ! (d) limited face fluxes, in as many passes as the step is reference steps long (smoothing_passes):
         ! each pass from the cell values the last left, their ghost layers exchanged anew; dq ends as the
         ! sum of the passes' increments and the packed q_c as they were
         call smoothing_passes(context%reference_steps, passes, share)
         call field_flux_increments(self%box, context%grid%h, exists, field, self%options, dq, self%workspace)
         if (share < 1.0_rp) dq = share * dq
         if (passes > 1) call further_passes(self, context, passes, share)

         ! (e) particle update
         if (self%pressure_only) then
            ! q = p / rho = -tr(s) / 3: its increment enters the normal components with opposite sign
            if (self%cell_averaging) &
               call cell_average(particles, first, last, self%occupied, self%cell_mass, particles%sbar(:, first:last), &
                                 self%average)
            do p = first, last
               c = particles%cell(p)
               if (self%cell_averaging) particles%sbar(:, p) = self%average(:, c)
               particles%sbar(1:3, p) = particles%sbar(1:3, p) - dq(1, of_owned(c))
            end do
         else if (self%cell_averaging) then
            ! q_p := q^_c = q_c + dq_c (eq. 13), q_c as packed
            if (dim == 2 .and. nq == 4) then
               call gather_smoothed(2, 4, particles%cell(first:last), of_owned, field, dq, particles%sbar(:, first:last))
            else if (dim == 3 .and. nq == 6) then
               call gather_smoothed(3, 6, particles%cell(first:last), of_owned, field, dq, particles%sbar(:, first:last))
            else
               call gather_smoothed(dim, nq, particles%cell(first:last), of_owned, field, dq, &
                                    particles%sbar(:, first:last))
            end if
         else
            do p = first, last
               particles%sbar(:, p) = particles%sbar(:, p) + dq(:, of_owned(particles%cell(p)))
            end do
         end if
      end associate
   end subroutine foal1_filter_stress

   !> Passes 2 to `passes` of step (d), dq holding the first's increments (scaled by share): the owned cells'
   !> q_c advanced by the increments so far, their ghost layers exchanged (collective), the fluxes formed anew
   !> and added to dq; afterwards the packed q_c are restored, so that q_c + dq is the smoothed value.
   subroutine further_passes(self, context, passes, share)
      type(foal1_smoothing_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      integer, intent(in) :: passes
      real(rp), intent(in) :: share
      integer :: pass, i, k, first_q
      first_q = 3 + context%grid%dim
      if (allocated(self%pass_dq)) then
         if (any(shape(self%pass_dq) /= shape(self%dq))) deallocate (self%pass_dq)
      end if
      ! the workspace clears the box of cells its last call wrote, in whichever array it is given: within a
      ! step every call has the same cells, so dq and pass_dq are both clear where a call writes
      if (.not. allocated(self%pass_dq)) allocate (self%pass_dq(size(self%dq, 1), size(self%dq, 2)), source=0.0_rp)
      associate (field => self%field, dq => self%dq, pass_dq => self%pass_dq)
         do pass = 2, passes
            do i = 1, self%n_packed
               k = self%box%of_owned(self%packed(i))
               if (pass == 2) then
                  field(first_q:, k) = field(first_q:, k) + dq(:, k)
               else
                  field(first_q:, k) = field(first_q:, k) + pass_dq(:, k)
               end if
            end do
            call exchange_cell_halo(context%domain, context%grid, self%box, field, flags=self%exists)
            call field_flux_increments(self%box, context%grid%h, self%exists, field, self%options, pass_dq, &
                                       self%workspace)
            do i = 1, self%n_packed
               k = self%box%of_owned(self%packed(i))
               pass_dq(:, k) = share * pass_dq(:, k)
               dq(:, k) = dq(:, k) + pass_dq(:, k)
            end do
         end do
         ! back to the packed q_c: the passes advanced them by dq less the last pass's increments
         do i = 1, self%n_packed
            k = self%box%of_owned(self%packed(i))
            field(first_q:, k) = field(first_q:, k) - (dq(:, k) - pass_dq(:, k))
         end do
      end associate
   end subroutine further_passes

   !> Step (c) and the packing of the cell field in one pass over the slice's particles (sorted by cell, nearly):
   !> the sums m_c q_c of cell_binning's cell_sums, in the same order (kept in `sums`, which a run that comes
   !> back to a cell continues), and where a run of one cell ends, its entry field(:, of_owned(c)) :=
   !> [1, m_c, x_o^c, q_c] with q_c = sum / m_c (the division unconditional, by 1 where m_c = 0; exists
   !> likewise), written while the run's sums are in registers instead of in a pass of its own over the cells.
   !> A cell whose particles come in more than one run (they changed cell since the last full sort) is
   !> written at the end of each: the last, with the complete sum, stays. dim and nq are literals at the
   !> calls that matter.
   subroutine sum_and_pack(dim, nq, occupied, cell, mass, values, of_owned, cell_mass, centre, sums, field, exists)
      integer, intent(in) :: dim, nq, cell(:), of_owned(:)
      type(cell_list_t), intent(in) :: occupied
      real(rp), intent(in) :: mass(:), values(nq, *), cell_mass(:), centre(dim, *)
      real(rp), intent(inout) :: sums(nq, *), field(2 + dim + nq, *)
      logical, intent(inout) :: exists(:)
      integer :: i, c, k, next
      logical :: first_visit
      real(rp) :: running(nq), m
      if (occupied%count == 0) return
      c = cell(1)
      running = 0.0_rp
      next = 2
      do i = 1, size(cell)
         if (cell(i) /= c) then
            ! the run of cell c ends
            sums(:, c) = running
            k = of_owned(c)
            m = cell_mass(c)
            exists(k) = m > 0.0_rp
            field(1, k) = merge(1.0_rp, 0.0_rp, m > 0.0_rp)
            field(2, k) = m
            field(3:2 + dim, k) = centre(:, c)
            field(3 + dim:, k) = running / merge(m, 1.0_rp, m > 0.0_rp)
            c = cell(i)
            ! the next cell of the list: its first visit (the runs come in the order the list was made)
            first_visit = .false.
            if (next <= occupied%count) first_visit = c == occupied%cells(next)
            if (first_visit) then
               next = next + 1
               running = 0.0_rp
            else
               running = sums(:, c)
            end if
         end if
         running = running + mass(i) * values(:, i)
      end do
      ! the last run ends (the entry as in the loop: a subroutine for it made the tank's FOAL1 slower)
      sums(:, c) = running
      k = of_owned(c)
      m = cell_mass(c)
      exists(k) = m > 0.0_rp
      field(1, k) = merge(1.0_rp, 0.0_rp, m > 0.0_rp)
      field(2, k) = m
      field(3:2 + dim, k) = centre(:, c)
      field(3 + dim:, k) = running / merge(m, 1.0_rp, m > 0.0_rp)
   end subroutine sum_and_pack

   !> values(:, i) := q_c + dq_c (eq. 13) of particle i's cell c = cell(i), q_c from the packed cell field.
   !> The particles come sorted by cell: the sum is formed once per run of one cell (the same addition as per
   !> cell), and a cell's values are stored as one vector per particle.
   subroutine gather_smoothed(dim, nq, cell, of_owned, field, dq, values)
      integer, intent(in) :: dim, nq, cell(:), of_owned(:)
      real(rp), intent(in) :: field(2 + dim + nq, *), dq(nq, *)
      real(rp), intent(inout) :: values(nq, *)
      real(rp) :: smoothed(nq)
      integer :: p, c, i
      c = 0
      smoothed = 0.0_rp
      !GCC$ novector
      do p = 1, size(cell)
         if (cell(p) /= c) then
            c = cell(p)
            i = of_owned(c)
            smoothed = field(3 + dim:2 + dim + nq, i) + dq(:, i)
         end if
         values(:, p) = smoothed
      end do
   end subroutine gather_smoothed

   !> Size the work arrays for nq smoothed values on the current cells (kept while the sizes hold). A new
   !> `field` starts at 0 and `exists` false: ghost cells no exchange writes (beyond the grid) stay so.
   subroutine ensure_work_arrays(self, nq, dim, cell_count)
      type(foal1_smoothing_t), intent(inout) :: self
      integer, intent(in) :: nq, dim, cell_count
      if (allocated(self%q_sums)) then
         if (size(self%q_sums, 2) == cell_count .and. size(self%field, 2) == self%box%count) return
         deallocate (self%q_sums, self%field, self%dq, self%exists, self%packed)
         if (allocated(self%pass_dq)) deallocate (self%pass_dq)
      end if
      allocate (self%q_sums(nq, cell_count), self%field(2 + dim + nq, self%box%count), self%dq(nq, self%box%count), &
                self%exists(self%box%count), self%packed(cell_count))
      self%field = 0.0_rp
      self%exists = .false.
      self%n_packed = 0
      self%workspace = flux_workspace_t()     ! it belongs to the old dq
   end subroutine ensure_work_arrays

   !> True if the padded box was built for the cells the grid owns now (they move when ranks rebalance).
   pure logical function same_cells(box, grid)
      type(padded_cells_t), intent(in) :: box
      type(grid_t), intent(in) :: grid
      same_cells = box%count > 0 .and. all(box%lo(1:grid%dim) == grid%cell_lo(1:grid%dim) - halo_width) .and. &
                   all(box%hi(1:grid%dim) == grid%cell_hi(1:grid%dim) + halo_width)
   end function same_cells
end module foal1_smoothing
