!> Particle-grid transfers of the explicit MPM step (algorithms.md section 1.2, steps 1, 3 and 7).
!>
!> The kernels are written once, in grid_transfer_kernels.inc, and instantiated for 2-D and 3-D, for
!> each shape function (multilinear, quadratic B-spline) and for each velocity transfer (FLIP/PIC, APIC)
!> with the dimension and the stencil as compile-time constants, so that the loops over axes and stencil
!> nodes unroll. The public routines pick the instance from grid%dim, grid%shape (the scene's &grid
!> shape_function) and whether the particles carry APIC's affine matrix C_p (particles%n_affine > 0,
!> `&run transfer = 'apic'`; docs/theory.md, "APIC").
module grid_transfer
   use kinds, only: rp
   use background_grid, only: grid_t, row_mass
   use shape_functions, only: shape_bspline2
   use particle_set, only: particle_set_t
   use stencil_cache, only: stencil_cache_t, size_stencil_cache, holds_stencils, forget_stencils
   implicit none
   private

   public :: particles_to_grid, update_velocity_and_remap, grid_to_particles, volume_to_grid, gradient_at_particles, &
             node_offsets, spread_to_grid, mass_to_grid

   !> Particles per block of the kernels' loops (PARTICLE_BLOCK of grid_transfer_stencil.inc is this constant):
   !> volume_to_grid's extremes come one column per such block. The rows of a column: the least and the largest
   !> coordinate of each axis (1:3, 4:6), the largest mass, the least density.
   integer, parameter, public :: transfer_block = 64, extremes_rows = 8

   !> The kernel instances: shape function and dimension; APIC's are these + apic.
   integer, parameter :: kernels_linear_2d = 1, kernels_linear_3d = 2, kernels_bspline2_2d = 3, kernels_bspline2_3d = 4
   integer, parameter :: apic = 4

contains

   !> The kernel instance of a grid (1 .. 4).
   pure integer function instance(grid)
      type(grid_t), intent(in) :: grid
      instance = merge(kernels_linear_2d, kernels_linear_3d, grid%dim == 2)
      if (grid%shape == shape_bspline2) instance = instance + 2
   end function instance

   !> The transfer kernels' instance of a grid and its particles: APIC's when they carry C_p (1 .. 8).
   pure integer function transfer_instance(grid, particles)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      transfer_instance = instance(grid)
      if (particles%n_affine > 0) transfer_instance = transfer_instance + apic
   end function transfer_instance

   !> Step 1: m_i = sum N m_p, P_i = sum N m_p v_p (APIC: + sum N m_p C_p (x_i - x_p)),
   !> f_i = -sum m_p sbar_p . grad N_i + sum N m_p g   ([Y17] eq. 3; sbar is the filtered stress).
   !> With `field` (contact, src/solver/body_contact.f90): also each body field's mass, momentum, force and
   !> mass gradient sum m_p grad N_i in its rows of grid%accumulated from `field_row` on (field(p) = 0: the
   !> common field, only in the totals).
   !> With `stencils` (3-D): each particle's stencil is kept there for the later passes of the same step
   !> (src/transfer/stencil_cache.f90).
   subroutine particles_to_grid(grid, particles, gravity, field, field_row, stencils)
      type(grid_t), intent(inout) :: grid
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(in) :: gravity(:)
      integer, intent(in), optional :: field(:), field_row
      type(stencil_cache_t), intent(inout), optional :: stencils
      grid%accumulated = 0.0_rp
      if (present(stencils)) then
         call forget_stencils(stencils)
         ! only the 3-D kernels keep stencils: the 2-D ones locate a block of particles at a time, vectorised
         if (grid%dim == 3) call size_stencil_cache(stencils, size(particles%mass))
      end if
      if (present(field)) then
         select case (transfer_instance(grid, particles))
         case (kernels_linear_2d); call particles_to_grid_fields_2d(grid, particles, gravity, field, field_row)
         case (kernels_linear_3d); call particles_to_grid_fields_3d(grid, particles, gravity, field, field_row, stencils)
         case (kernels_bspline2_2d); call particles_to_grid_fields_b2_2d(grid, particles, gravity, field, field_row)
         case (kernels_bspline2_3d)
            call particles_to_grid_fields_b2_3d(grid, particles, gravity, field, field_row, stencils)
         case (apic + kernels_linear_2d); call particles_to_grid_fields_apic_2d(grid, particles, gravity, field, field_row)
         case (apic + kernels_linear_3d)
            call particles_to_grid_fields_apic_3d(grid, particles, gravity, field, field_row, stencils)
         case (apic + kernels_bspline2_2d)
            call particles_to_grid_fields_apic_b2_2d(grid, particles, gravity, field, field_row)
         case default; call particles_to_grid_fields_apic_b2_3d(grid, particles, gravity, field, field_row, stencils)
         end select
      else
         select case (transfer_instance(grid, particles))
         case (kernels_linear_2d); call particles_to_grid_2d(grid, particles, gravity)
         case (kernels_linear_3d); call particles_to_grid_3d(grid, particles, gravity, stencils)
         case (kernels_bspline2_2d); call particles_to_grid_b2_2d(grid, particles, gravity)
         case (kernels_bspline2_3d); call particles_to_grid_b2_3d(grid, particles, gravity, stencils)
         case (apic + kernels_linear_2d); call particles_to_grid_apic_2d(grid, particles, gravity)
         case (apic + kernels_linear_3d); call particles_to_grid_apic_3d(grid, particles, gravity, stencils)
         case (apic + kernels_bspline2_2d); call particles_to_grid_apic_b2_2d(grid, particles, gravity)
         case default; call particles_to_grid_apic_b2_3d(grid, particles, gravity, stencils)
         end select
      end if
      if (present(stencils)) then
         if (grid%dim == 3) stencils%count = particles%count
      end if
   end subroutine particles_to_grid

   !> MUSL, first half of step 7 fused with the re-map: v_p := alpha (v_p + sum N dv_i) + (1 - alpha) sum N
   !> v_i^{n+1}, then momentum(:, i) = sum N m_p v_p with the updated velocities (both at x^n).
   !> APIC: v_p := sum N v_i^{n+1}, C_p := B_p D_p^-1 from v_i^{n+1}, and the momentum as in step 1.
   !> With `field`: each particle's nodal velocities come from its field's rows of `velocity` and
   !> `increment` (dim (fields + 1), node); momentum rows 1:dim get the total, rows f dim + 1.. field f's.
   !> `stencils`: P2G's of this step (used when it holds this set's particles).
   subroutine update_velocity_and_remap(grid, particles, flip_fraction, momentum, field, velocity, increment, stencils)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      real(rp), intent(in) :: flip_fraction
      real(rp), intent(out), contiguous :: momentum(:, :)
      integer, intent(in), optional :: field(:)
      real(rp), intent(in), optional, contiguous :: velocity(:, :), increment(:, :)
      type(stencil_cache_t), intent(in), optional :: stencils
      momentum = 0.0_rp
      if (present(field)) then
         select case (transfer_instance(grid, particles))
         case (kernels_linear_2d)
            call momentum_to_grid_fields_2d(grid, particles, flip_fraction, momentum, field, velocity, increment)
         case (kernels_linear_3d)
            call momentum_to_grid_fields_3d(grid, particles, flip_fraction, momentum, field, velocity, increment, stencils)
         case (kernels_bspline2_2d)
            call momentum_to_grid_fields_b2_2d(grid, particles, flip_fraction, momentum, field, velocity, increment)
         case (kernels_bspline2_3d)
            call momentum_to_grid_fields_b2_3d(grid, particles, flip_fraction, momentum, field, velocity, increment, stencils)
         case (apic + kernels_linear_2d)
            call momentum_to_grid_fields_apic_2d(grid, particles, momentum, field, velocity, increment)
         case (apic + kernels_linear_3d)
            call momentum_to_grid_fields_apic_3d(grid, particles, momentum, field, velocity, increment, stencils)
         case (apic + kernels_bspline2_2d)
            call momentum_to_grid_fields_apic_b2_2d(grid, particles, momentum, field, velocity, increment)
         case default
            call momentum_to_grid_fields_apic_b2_3d(grid, particles, momentum, field, velocity, increment, stencils)
         end select
      else
         select case (transfer_instance(grid, particles))
         case (kernels_linear_2d); call momentum_to_grid_2d(grid, particles, flip_fraction, momentum)
         case (kernels_linear_3d); call momentum_to_grid_3d(grid, particles, flip_fraction, momentum, stencils)
         case (kernels_bspline2_2d); call momentum_to_grid_b2_2d(grid, particles, flip_fraction, momentum)
         case (kernels_bspline2_3d); call momentum_to_grid_b2_3d(grid, particles, flip_fraction, momentum, stencils)
         case (apic + kernels_linear_2d); call momentum_to_grid_apic_2d(grid, particles, momentum)
         case (apic + kernels_linear_3d); call momentum_to_grid_apic_3d(grid, particles, momentum, stencils)
         case (apic + kernels_bspline2_2d); call momentum_to_grid_apic_b2_2d(grid, particles, momentum)
         case default; call momentum_to_grid_apic_b2_3d(grid, particles, momentum, stencils)
         end select
      end if
   end subroutine update_velocity_and_remap

   !> Steps 3 and 7 at x^n. With v_i^{n+theta} = v_i^{n+1} - (1 - theta) dv_i:
   !>   L_p = sum v_i^{n+theta} (x) grad N_i  -> strain_rate = sym(L), spin = skew(L)   (if compute_strain)
   !>   v_p := alpha (v_p + sum N dv_i) + (1 - alpha) sum N v_i^{n+1}                  (if update_velocity)
   !>          APIC: v_p := sum N v_i^{n+1}, C_p := B_p D_p^-1 from v_i^{n+1}
   !>   x_p := x_p + dt sum N v_i^{n+theta}                                             (if update_position)
   !> `strain_velocity`, when present, replaces v^{n+theta} in L (MUSL: the re-mapped velocities).
   !> `compute_spin` (default: as compute_strain) = .false. leaves the spin alone: only solids use it.
   !> `extent` returns the lowest (:, 1) and highest (:, 2) new position along each axis (with
   !> update_position; 0 beyond dim): the active region's check needs it, and here it costs no pass.
   !> With `field` (contact): particle p reads v, dv (and the strain velocity) of its field, rows
   !> field(p) dim + 1.. of `velocity` and `increment` (dim (fields + 1), node), not the grid's.
   !> `first`, `last` (default: all particles) restrict it to a slice. d_p and w_p of particle p go to
   !> column p - first + 1 of `strain_rate` (n_sigma rows when compute_strain) and `spin` (no rows: no
   !> spin): the particles' own arrays, or the block buffer of the solver's fused stage, on which the
   !> stress update follows while it is in cache (docs/performance.md, "Memory per particle").
   !> `stencils`: P2G's of this step (used when it holds this set's particles).
   subroutine grid_to_particles(grid, particles, dt, flip_fraction, theta, update_velocity, compute_strain, &
                                update_position, strain_rate, spin, strain_velocity, compute_spin, extent, field, &
                                velocity, increment, first, last, stencils)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      real(rp), intent(in) :: dt, flip_fraction, theta
      logical, intent(in) :: update_velocity, compute_strain, update_position
      real(rp), intent(inout), contiguous :: strain_rate(:, :), spin(:, :)
      real(rp), intent(in), optional, contiguous :: strain_velocity(:, :)
      logical, intent(in), optional :: compute_spin
      real(rp), intent(out), optional :: extent(3, 2)
      integer, intent(in), optional :: field(:)
      real(rp), intent(in), optional, contiguous :: velocity(:, :), increment(:, :)
      integer, intent(in), optional :: first, last
      type(stencil_cache_t), intent(in), optional :: stencils
      real(rp) :: lo(3), hi(3)
      integer :: p1, p2
      logical :: with_spin
      p1 = 1
      p2 = particles%count
      if (present(first)) p1 = first
      if (present(last)) p2 = last
      with_spin = compute_strain
      if (present(compute_spin)) with_spin = compute_strain .and. compute_spin
      with_spin = with_spin .and. size(spin, 1) > 0       ! no rows: a set without spin (no model reads it)
      lo = 0.0_rp
      hi = 0.0_rp
      if (present(field)) then
         select case (transfer_instance(grid, particles))
         case (kernels_linear_2d)
            call grid_to_particles_fields_2d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                             compute_strain, with_spin, update_position, strain_rate, spin, &
                                             lo(1:2), hi(1:2), field, velocity, increment, strain_velocity)
         case (kernels_linear_3d)
            call grid_to_particles_fields_3d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                             compute_strain, with_spin, update_position, strain_rate, spin, lo, hi, &
                                             field, velocity, increment, strain_velocity, stencils)
         case (kernels_bspline2_2d)
            call grid_to_particles_fields_b2_2d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                                compute_strain, with_spin, update_position, strain_rate, spin, &
                                                lo(1:2), hi(1:2), field, velocity, increment, strain_velocity)
         case (kernels_bspline2_3d)
            call grid_to_particles_fields_b2_3d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                                compute_strain, with_spin, update_position, strain_rate, spin, lo, &
                                                hi, field, velocity, increment, strain_velocity, stencils)
         case (apic + kernels_linear_2d)
            call grid_to_particles_fields_apic_2d(grid, particles, p1, p2, dt, theta, update_velocity, &
                                                  compute_strain, with_spin, update_position, strain_rate, spin, &
                                                  lo(1:2), hi(1:2), field, velocity, increment, strain_velocity)
         case (apic + kernels_linear_3d)
            call grid_to_particles_fields_apic_3d(grid, particles, p1, p2, dt, theta, update_velocity, &
                                                  compute_strain, with_spin, update_position, strain_rate, spin, &
                                                  lo, hi, field, velocity, increment, strain_velocity, stencils)
         case (apic + kernels_bspline2_2d)
            call grid_to_particles_fields_apic_b2_2d(grid, particles, p1, p2, dt, theta, update_velocity, &
                                                     compute_strain, with_spin, update_position, strain_rate, spin, &
                                                     lo(1:2), hi(1:2), field, velocity, increment, strain_velocity)
         case default
            call grid_to_particles_fields_apic_b2_3d(grid, particles, p1, p2, dt, theta, update_velocity, &
                                                     compute_strain, with_spin, update_position, strain_rate, spin, &
                                                     lo, hi, field, velocity, increment, strain_velocity, stencils)
         end select
      else
         select case (transfer_instance(grid, particles))
         case (kernels_linear_2d)
            call grid_to_particles_2d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                      compute_strain, with_spin, update_position, strain_rate, spin, lo(1:2), &
                                      hi(1:2), strain_velocity)
         case (kernels_linear_3d)
            call grid_to_particles_3d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                      compute_strain, with_spin, update_position, strain_rate, spin, lo, hi, &
                                      strain_velocity, stencils)
         case (kernels_bspline2_2d)
            call grid_to_particles_b2_2d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                         compute_strain, with_spin, update_position, strain_rate, spin, lo(1:2), &
                                         hi(1:2), strain_velocity)
         case (kernels_bspline2_3d)
            call grid_to_particles_b2_3d(grid, particles, p1, p2, dt, flip_fraction, theta, update_velocity, &
                                         compute_strain, with_spin, update_position, strain_rate, spin, lo, hi, &
                                         strain_velocity, stencils)
         case (apic + kernels_linear_2d)
            call grid_to_particles_apic_2d(grid, particles, p1, p2, dt, theta, update_velocity, compute_strain, &
                                           with_spin, update_position, strain_rate, spin, lo(1:2), hi(1:2), &
                                           strain_velocity)
         case (apic + kernels_linear_3d)
            call grid_to_particles_apic_3d(grid, particles, p1, p2, dt, theta, update_velocity, compute_strain, &
                                           with_spin, update_position, strain_rate, spin, lo, hi, strain_velocity, stencils)
         case (apic + kernels_bspline2_2d)
            call grid_to_particles_apic_b2_2d(grid, particles, p1, p2, dt, theta, update_velocity, compute_strain, &
                                              with_spin, update_position, strain_rate, spin, lo(1:2), hi(1:2), &
                                              strain_velocity)
         case default
            call grid_to_particles_apic_b2_3d(grid, particles, p1, p2, dt, theta, update_velocity, compute_strain, &
                                              with_spin, update_position, strain_rate, spin, lo, hi, &
                                              strain_velocity, stencils)
         end select
      end if
      if (present(extent)) then
         extent(:, 1) = lo
         extent(:, 2) = hi
      end if
   end subroutine grid_to_particles

   !> d(:, a) = x_a - x_p for the stencil nodes a of a particle at fractional position xi in a cell of
   !> edge h, multilinear functions (APIC's offsets; exposed for the tests of D_p): node a's offset along
   !> axis k from the cell's lower node, times h, from the kernels' per-axis table.
   pure subroutine node_offsets(dim, xi, h, d)
      integer, intent(in) :: dim
      real(rp), intent(in) :: xi(:), h
      real(rp), intent(out) :: d(:, :)
      real(rp) :: per_axis(0:1, 3)
      integer :: a, k
      if (dim == 2) then
         call node_offsets_2d(xi, h, per_axis(:, 1:2))
      else
         call node_offsets_3d(xi, h, per_axis)
      end if
      do a = 1, 2**dim
         do k = 1, dim
            d(k, a) = per_axis(mod((a - 1) / 2**(k - 1), 2), k)
         end do
      end do
   end subroutine node_offsets

   !> o_i += sum_p N_ip m_p / rho_p over all particles (src/stabilization/volume_correction.f90).
   !> `stencils`: P2G's of this step (used when it holds this set's particles). `extremes(:, j)`, if given: the
   !> extremes of the particles of block j (transfer_block particles from particle 1, extremes_rows rows; the
   !> axes the grid lacks hold 0), taken while they are at hand.
   subroutine volume_to_grid(grid, particles, occupancy, stencils, extremes)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(inout) :: occupancy(:)
      type(stencil_cache_t), intent(in), optional :: stencils
      real(rp), intent(inout), optional :: extremes(:, :)
      select case (instance(grid))
      case (kernels_linear_2d); call volume_to_grid_2d(grid, particles, occupancy, extremes)
      case (kernels_linear_3d); call volume_to_grid_3d(grid, particles, occupancy, extremes, stencils)
      case (kernels_bspline2_2d); call volume_to_grid_b2_2d(grid, particles, occupancy, extremes)
      case default; call volume_to_grid_b2_3d(grid, particles, occupancy, extremes, stencils)
      end select
   end subroutine volume_to_grid

   !> The extremes of particles first:last into e (extremes_rows values, see transfer_block): loops with the
   !> dimension written out, which vectorise.
   subroutine particle_extremes(particles, first, last, e)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(out) :: e(extremes_rows)
      real(rp) :: lo(3), hi(3), mass_max, density_min
      integer :: p
      lo = 0.0_rp
      hi = 0.0_rp
      mass_max = -huge(1.0_rp)
      density_min = huge(1.0_rp)
      if (particles%dim == 2) then
         lo(1:2) = huge(1.0_rp)
         hi(1:2) = -huge(1.0_rp)
         do p = first, last
            lo(1) = min(lo(1), particles%x(1, p))
            lo(2) = min(lo(2), particles%x(2, p))
            hi(1) = max(hi(1), particles%x(1, p))
            hi(2) = max(hi(2), particles%x(2, p))
            mass_max = max(mass_max, particles%mass(p))
            density_min = min(density_min, particles%density(p))
         end do
      else
         lo = huge(1.0_rp)
         hi = -huge(1.0_rp)
         do p = first, last
            lo(1) = min(lo(1), particles%x(1, p))
            lo(2) = min(lo(2), particles%x(2, p))
            lo(3) = min(lo(3), particles%x(3, p))
            hi(1) = max(hi(1), particles%x(1, p))
            hi(2) = max(hi(2), particles%x(2, p))
            hi(3) = max(hi(3), particles%x(3, p))
            mass_max = max(mass_max, particles%mass(p))
            density_min = min(density_min, particles%density(p))
         end do
      end if
      e = [lo, hi, mass_max, density_min]
   end subroutine particle_extremes

   !> gradient(:, p) = factor sum_a grad N_a(x_p) field_a for p = first..last at x^n (factor default 1); a node
   !> that is not `known` takes the N-weighted mean of the particle's known stencil nodes. `stencils`: P2G's of
   !> this step (used when it holds this set's particles).
   subroutine gradient_at_particles(grid, particles, first, last, field, known, gradient, stencils, factor)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(in) :: field(:)
      logical, intent(in) :: known(:)
      real(rp), intent(inout) :: gradient(:, :)
      type(stencil_cache_t), intent(in), optional :: stencils
      real(rp), intent(in), optional :: factor
      real(rp) :: f
      f = 1.0_rp
      if (present(factor)) f = factor
      select case (instance(grid))
      case (kernels_linear_2d); call gradient_at_particles_2d(grid, particles, first, last, field, known, f, gradient)
      case (kernels_linear_3d)
         call gradient_at_particles_3d(grid, particles, first, last, field, known, f, gradient, stencils)
      case (kernels_bspline2_2d)
         call gradient_at_particles_b2_2d(grid, particles, first, last, field, known, f, gradient)
      case default; call gradient_at_particles_b2_3d(grid, particles, first, last, field, known, f, gradient, stencils)
      end select
   end subroutine gradient_at_particles

   !> nodal(1:dim, i) += sum_p N_i(x_p) m_p (u_p + B_p (x_i - x_p)) over p = first..last, u_p = values(1:dim, q),
   !> B_p = values(dim + 1:, q) column by column if given (q = p - first + 1); a particle with row_offset(q) =
   !> o > 0 also adds to rows o + 1:o + dim (its contact field).
   subroutine spread_to_grid(grid, particles, first, last, values, row_offset, nodal)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, row_offset(:)
      real(rp), intent(in) :: values(:, :)
      real(rp), intent(inout) :: nodal(:, :)
      select case (instance(grid))
      case (kernels_linear_2d); call spread_to_grid_2d(grid, particles, first, last, values, row_offset, nodal)
      case (kernels_linear_3d); call spread_to_grid_3d(grid, particles, first, last, values, row_offset, nodal)
      case (kernels_bspline2_2d); call spread_to_grid_b2_2d(grid, particles, first, last, values, row_offset, nodal)
      case default; call spread_to_grid_b2_3d(grid, particles, first, last, values, row_offset, nodal)
      end select
   end subroutine spread_to_grid

   !> nodal(row(q), i) += sum_p N_i(x_p) m_p over p = first..last (q = p - first + 1; row 0: skipped).
   subroutine mass_to_grid(grid, particles, first, last, row, nodal)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: first, last, row(:)
      real(rp), intent(inout) :: nodal(:, :)
      select case (instance(grid))
      case (kernels_linear_2d); call mass_to_grid_2d(grid, particles, first, last, row, nodal)
      case (kernels_linear_3d); call mass_to_grid_3d(grid, particles, first, last, row, nodal)
      case (kernels_bspline2_2d); call mass_to_grid_b2_2d(grid, particles, first, last, row, nodal)
      case default; call mass_to_grid_b2_3d(grid, particles, first, last, row, nodal)
      end select
   end subroutine mass_to_grid

! APIC's C_p = B_p D_p^-1 = sum_a v_a (x) D_p^-1 (x_a - x_p) N_a (Jiang et al. 2015), per instance the term
! AFFINE_GRADIENT(j, a) = [D_p^-1 (x_a - x_p) N_a]_j: for multilinear functions it is grad N_a exactly, also
! on the grid lines where D_p is singular; for quadratic B-splines D_p = h^2/4 I at every position, so it
! is (4 / h^2) (x_a - x_p) N_a, with x_a - x_p from OFFSETS (docs/theory.md, "APIC").

! FLIP/PIC, single field: nodal velocities from the grid (and the volume and gradient kernels)
#define BLEND flip_fraction,
#define NODE_MOMENTUM(i) mv(i)
#define VEL(i, node) grid%velocity(i, node)
#define INC(i, node) grid%velocity_increment(i, node)

#define STENCIL 1
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_2d
#define M2G momentum_to_grid_2d
#define G2P grid_to_particles_2d
#define V2G volume_to_grid_2d
#define GRAD2P gradient_at_particles_2d
#define GRADIENT_COEFFICIENTS gradient_coefficients_2d
#define SPREAD2G spread_to_grid_2d
#define MASS2G mass_to_grid_2d
#include "../grid/multilinear_shape.inc"
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 2
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_3d
#define M2G momentum_to_grid_3d
#define G2P grid_to_particles_3d
#define V2G volume_to_grid_3d
#define GRAD2P gradient_at_particles_3d
#define GRADIENT_COEFFICIENTS gradient_coefficients_3d
#define SPREAD2G spread_to_grid_3d
#define MASS2G mass_to_grid_3d
#include "../grid/multilinear_shape.inc"
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 3
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_b2_2d
#define M2G momentum_to_grid_b2_2d
#define G2P grid_to_particles_b2_2d
#define V2G volume_to_grid_b2_2d
#define GRAD2P gradient_at_particles_b2_2d
#define SPREAD2G spread_to_grid_b2_2d
#define MASS2G mass_to_grid_b2_2d
#include "../grid/bspline2_shape.inc"
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 4
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_b2_3d
#define M2G momentum_to_grid_b2_3d
#define G2P grid_to_particles_b2_3d
#define V2G volume_to_grid_b2_3d
#define GRAD2P gradient_at_particles_b2_3d
#define SPREAD2G spread_to_grid_b2_3d
#define MASS2G mass_to_grid_b2_3d
#include "../grid/bspline2_shape.inc"
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

! FLIP/PIC, the multi-field kernels of contact: each particle's own field, rows o + 1.. (o = field(p) dim)
#define FIELDS
#undef VEL
#undef INC
#define VEL(i, node) velocity(o + (i), node)
#define INC(i, node) increment(o + (i), node)

#define STENCIL 1
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_2d
#define M2G momentum_to_grid_fields_2d
#define G2P grid_to_particles_fields_2d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 2
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_3d
#define M2G momentum_to_grid_fields_3d
#define G2P grid_to_particles_fields_3d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 3
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_b2_2d
#define M2G momentum_to_grid_fields_b2_2d
#define G2P grid_to_particles_fields_b2_2d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 4
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_b2_3d
#define M2G momentum_to_grid_fields_b2_3d
#define G2P grid_to_particles_fields_b2_3d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

! APIC (AFFINE), single field: the same kernels with the affine terms; the FLIP/PIC ones above are untouched
#define AFFINE
#undef BLEND
#define BLEND
#undef NODE_MOMENTUM
#define NODE_MOMENTUM(i) pv(i)
#undef FIELDS
#undef VEL
#undef INC
#define VEL(i, node) grid%velocity(i, node)
#define INC(i, node) grid%velocity_increment(i, node)

#define STENCIL 1
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_apic_2d
#define M2G momentum_to_grid_apic_2d
#define G2P grid_to_particles_apic_2d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 2
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_apic_3d
#define M2G momentum_to_grid_apic_3d
#define G2P grid_to_particles_apic_3d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 3
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_apic_b2_2d
#define M2G momentum_to_grid_apic_b2_2d
#define G2P grid_to_particles_apic_b2_2d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 4
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_apic_b2_3d
#define M2G momentum_to_grid_apic_b2_3d
#define G2P grid_to_particles_apic_b2_3d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

! APIC, the multi-field kernels of contact
#define FIELDS
#undef VEL
#undef INC
#define VEL(i, node) velocity(o + (i), node)
#define INC(i, node) increment(o + (i), node)

#define STENCIL 1
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_apic_2d
#define M2G momentum_to_grid_fields_apic_2d
#define G2P grid_to_particles_fields_apic_2d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 2
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_apic_3d
#define M2G momentum_to_grid_fields_apic_3d
#define G2P grid_to_particles_fields_apic_3d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 3
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_apic_b2_2d
#define M2G momentum_to_grid_fields_apic_b2_2d
#define G2P grid_to_particles_fields_apic_b2_2d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"

#define STENCIL 4
#include "grid_transfer_stencil.inc"
#define P2G particles_to_grid_fields_apic_b2_3d
#define M2G momentum_to_grid_fields_apic_b2_3d
#define G2P grid_to_particles_fields_apic_b2_3d
#include "grid_transfer_kernels.inc"
#include "grid_transfer_undef.inc"
end module grid_transfer
