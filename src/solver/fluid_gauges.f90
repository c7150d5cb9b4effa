!> Gauges: what a pressure sensor, a wave gauge or a current meter at a point of the scene would read
!> (gauges.csv; docs/loads.md, docs/theory.md section 3.2). Only fluid particles are seen.
!>
!>   pressure  p at the point from the fluid particles within `radius`: the mass-weighted least-squares
!>             plane p(x) = a + b . (x - x_g) through their pressures p = -rho tr(sigma)/3, read at the
!>             point (p = a). A gauge on a wall has only half its disc in the fluid; the plane
!>             extrapolates to the wall, which a mean over the particles would not (it would read the
!>             pressure half a radius inside). Where the particles do not span the dimensions (fewer
!>             than dim + 2 of them, or their spread along some direction below radius / 10) the plane
!>             is not determined: the mass-weighted mean is read instead.
!>   velocity  the same fit for each velocity component.
!>   level     the free-surface elevation above the point, as a wave gauge reads it: in the vertical
!>             column of half-width `radius` through the point, the highest top of a fluid particle
!>             (centre + half its size (m / rho)^(1/dim) along the vertical) minus the point's
!>             elevation, at least 0. Vertical is -g, or +y (2-D) / +z (3-D) without gravity.
!>   connected_level  the top of the water standing on the point, as a resistance wave gauge reads it:
!>             the same column, cut into bins of half a cell along the vertical from the point; a bin is
!>             wet where a particle's vertical extent (centre +- half its size) reaches into it, and the
!>             reading is the highest top among the particles of the wet bins reached from the point
!>             upward across gaps of up to one cell. Spray, droplets and a jet falling over the gauge above
!>             a larger gap are not read (`level` reads them); 0 where no water is within a cell above the
!>             point.
!>   wall_pressure  the mean pressure the wall `wall` takes over a patch of its surface about the point
!>             (half-size `radius`), from its constraint's impulse over the row's interval (wall_pressure_taps,
!>             wall_loads): the load the wall feels, not the particles' pressure next to it, which the
!>             constraint bypasses in part (docs/loads.md, "Wall pressure").
!> Each particle gauge also writes the number of particles it saw (`<name>_samples`): 0 means no fluid
!> there, and the values are then 0. Collective: two reductions (sums, maxima) for all gauges together.
module fluid_gauges
   use kinds, only: rp, name_len
   use communication_counters, only: count_collective, comm_records, real_bytes
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM, MPI_MAX
   use scene_description, only: scene_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, &
                                gauge_wall_pressure
   use material_model, only: material_slot_t
   use particle_set, only: particle_set_t
   use tensor_layout, only: mean_stress
   use world_frame, only: frame_t
   implicit none
   private

   !> Below this spread (standard deviation along a principal direction, in radii) the plane is not fitted.
   real(rp), parameter :: min_spread = 0.1_rp
   !> connected_level: bins per cell along the vertical, and the empty bins bridged (one cell).
   integer, parameter :: bins_per_cell = 2, bridged_bins = bins_per_cell

   type :: gauge_t
      character(len=name_len) :: name = ''
      character(len=name_len) :: kind = ''
      real(rp) :: point(3) = 0.0_rp            !< grid frame
      real(rp) :: radius = 0.0_rp
      integer :: first_sum = 0, first_max = 0  !< where its partial sums / maxima start in the packed arrays
      integer :: slot = 0                      !< wall_pressure: its index among the wall-pressure gauges
      integer :: bins = 0                      !< connected_level: bins of the column (its maxima)
      real(rp) :: bin = 0.0_rp                 !< connected_level: their height [m]
   end type gauge_t

   type, public :: fluid_gauges_t
      integer :: dim = 2
      type(gauge_t), allocatable :: gauges(:)
      real(rp) :: up(3) = 0.0_rp               !< vertical unit vector, grid frame
      integer :: n_sums = 0, n_max = 0
   contains
      procedure :: init => gauges_init
      procedure :: count => gauges_count
      procedure :: sample => gauges_sample
      procedure :: column_names => gauges_column_names
   end type fluid_gauges_t

contains

   subroutine gauges_init(self, scene, frame, gravity)
      class(fluid_gauges_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      type(frame_t), intent(in) :: frame
      real(rp), intent(in) :: gravity(3)          !< grid frame
      integer :: g, d, slots
      d = scene%grid%dim
      slots = 0
      self%dim = d
      self%up = 0.0_rp
      if (norm2(gravity(1:d)) > 0.0_rp) then
         self%up(1:d) = -gravity(1:d) / norm2(gravity(1:d))
      else
         self%up(d) = 1.0_rp
         self%up(1:d) = frame%grid_vector(self%up(1:d))
      end if
      if (allocated(scene%gauges)) then
         allocate (self%gauges(size(scene%gauges)))
      else
         allocate (self%gauges(0))
      end if
      self%n_sums = 0
      self%n_max = 0
      do g = 1, size(self%gauges)
         associate (gauge => self%gauges(g), spec => scene%gauges(g))
            gauge%name = spec%name
            gauge%kind = spec%kind
            gauge%point = 0.0_rp
            gauge%point(1:d) = frame%grid_point(spec%point(1:d))
            gauge%radius = spec%radius
            gauge%first_sum = self%n_sums + 1
            gauge%first_max = self%n_max + 1
            select case (gauge%kind)
            case (gauge_level)
               self%n_sums = self%n_sums + 1          ! particles in the column
               self%n_max = self%n_max + 1            ! highest top
            case (gauge_connected_level)
               ! bins from the point up to the far corner of the grid box, each holding its highest top
               gauge%bin = scene%grid%cell_size / bins_per_cell
               gauge%bins = ceiling(norm2(scene%grid%extent(1:d)) / gauge%bin) + 1
               self%n_sums = self%n_sums + 1
               self%n_max = self%n_max + gauge%bins
            case (gauge_wall_pressure)
               slots = slots + 1                      ! read from the wall's impulse, no particle sums
               gauge%slot = slots
            case default
               self%n_sums = self%n_sums + fit_width(d, quantity_count(gauge%kind, d))
            end select
         end associate
      end do
   end subroutine gauges_init

   pure integer function gauges_count(self)
      class(fluid_gauges_t), intent(in) :: self
      gauges_count = 0
      if (allocated(self%gauges)) gauges_count = size(self%gauges)
   end function gauges_count

   !> Quantities a fitting gauge fits: the pressure, or the dim velocity components.
   pure integer function quantity_count(kind, dim)
      character(len=*), intent(in) :: kind
      integer, intent(in) :: dim
      quantity_count = merge(1, dim, kind == gauge_pressure)
   end function quantity_count

   !> Partial sums of a fit: count, M, sum m dx (dim), sum m dx dx^T (dim^2), then per quantity
   !> sum m q and sum m q dx (1 + dim).
   pure integer function fit_width(dim, quantities)
      integer, intent(in) :: dim, quantities
      fit_width = 2 + dim + dim * dim + quantities * (1 + dim)
   end function fit_width

   !> The row of gauges.csv now: per gauge its value(s) (pressure [Pa]; level [m]; vx, vy[, vz] [m/s],
   !> world frame) and the number of particles it saw; a wall-pressure gauge its entry of `wall_pressures`
   !> (wall_loads' sensor_pressure of the same row) alone. Collective.
   function gauges_sample(self, particles, materials, frame, comm, wall_pressures) result(values)
      class(fluid_gauges_t), intent(in) :: self
      type(particle_set_t), intent(in) :: particles
      type(material_slot_t), intent(in) :: materials(:)
      type(frame_t), intent(in) :: frame
      type(MPI_Comm), intent(in) :: comm
      real(rp), intent(in) :: wall_pressures(:)
      real(rp), allocatable :: values(:)
      real(rp) :: sums(self%n_sums), maxima(max(1, self%n_max)), dx(self%dim), q(self%dim), m, rise, size_p, &
                  across(self%dim), n_seen
      integer :: g, p, mat, d, at, nq, i, j
      d = self%dim
      allocate (values(0))
      if (self%count() == 0) return
      sums = 0.0_rp
      maxima = -huge(1.0_rp)
      do mat = 1, size(materials)
         if (.not. materials(mat)%model%is_fluid) cycle
         do p = particles%material_first(mat), particles%material_last(mat)
            do g = 1, size(self%gauges)
               associate (gauge => self%gauges(g))
                  if (gauge%kind == gauge_wall_pressure) cycle
                  dx = particles%x(:, p) - gauge%point(1:d)
                  m = particles%mass(p)
                  if (gauge%kind == gauge_level .or. gauge%kind == gauge_connected_level) then
                     rise = dot_product(dx, self%up(1:d))
                     across = dx - rise * self%up(1:d)
                     if (dot_product(across, across) > gauge%radius**2) cycle
                     size_p = (m / particles%density(p))**(1.0_rp / d)
                     sums(gauge%first_sum) = sums(gauge%first_sum) + 1.0_rp
                     if (gauge%kind == gauge_level) then
                        maxima(gauge%first_max) = max(maxima(gauge%first_max), rise + 0.5_rp * size_p)
                     else
                        call mark_bins(maxima(gauge%first_max:gauge%first_max + gauge%bins - 1), gauge%bin, &
                                       rise - 0.5_rp * size_p, rise + 0.5_rp * size_p)
                     end if
                     cycle
                  end if
                  if (dot_product(dx, dx) > gauge%radius**2) cycle
                  if (gauge%kind == gauge_pressure) then
                     q(1) = -particles%density(p) * mean_stress(particles%sbar(:, p))
                  else
                     q = particles%v(:, p)
                  end if
                  nq = quantity_count(gauge%kind, d)
                  associate (s => sums(gauge%first_sum:gauge%first_sum + fit_width(d, nq) - 1))
                     s(1) = s(1) + 1.0_rp
                     s(2) = s(2) + m
                     s(3:2 + d) = s(3:2 + d) + m * dx
                     at = 2 + d
                     do j = 1, d
                        do i = 1, d
                           at = at + 1
                           s(at) = s(at) + m * dx(i) * dx(j)
                        end do
                     end do
                     do i = 1, nq
                        s(at + 1) = s(at + 1) + m * q(i)
                        s(at + 2:at + 1 + d) = s(at + 2:at + 1 + d) + m * q(i) * dx
                        at = at + 1 + d
                     end do
                  end associate
               end associate
            end do
         end do
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, size(sums), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call count_collective(comm_records, size(sums), real_bytes)
      if (self%n_max > 0) call MPI_Allreduce(MPI_IN_PLACE, maxima, size(maxima), MPI_DOUBLE_PRECISION, MPI_MAX, comm)
      if (self%n_max > 0) call count_collective(comm_records, size(maxima), real_bytes)

      do g = 1, size(self%gauges)
         associate (gauge => self%gauges(g))
            select case (gauge%kind)
            case (gauge_level)
               n_seen = sums(gauge%first_sum)
               rise = 0.0_rp
               if (n_seen > 0.0_rp) rise = max(0.0_rp, maxima(gauge%first_max))
               values = [values, rise, n_seen]
            case (gauge_connected_level)
               values = [values, connected_top(maxima(gauge%first_max:gauge%first_max + gauge%bins - 1)), &
                         sums(gauge%first_sum)]
            case (gauge_pressure)
               values = [values, fitted_values(sums(gauge%first_sum:gauge%first_sum + fit_width(d, 1) - 1), d, 1, &
                                               gauge%radius), sums(gauge%first_sum)]
            case (gauge_velocity)
               q = fitted_values(sums(gauge%first_sum:gauge%first_sum + fit_width(d, d) - 1), d, d, gauge%radius)
               values = [values, frame%world_vector(q), sums(gauge%first_sum)]
            case (gauge_wall_pressure)
               values = [values, wall_pressures(gauge%slot)]
            end select
         end associate
      end do
   end function gauges_sample

   !> The values at the gauge point (dx = 0) of the fitted planes of nq quantities from their partial
   !> sums (see fit_width); the weighted means where the plane is not determined; 0 without particles.
   pure function fitted_values(s, d, nq, radius) result(values)
      real(rp), intent(in) :: s(:), radius
      integer, intent(in) :: d, nq
      real(rp) :: values(nq)
      real(rp) :: mass, mean(d), cov(d, d), chol(d, d), rhs(d), b(d), qmean
      integer :: i, j, at
      logical :: determined
      values = 0.0_rp
      mass = s(2)
      if (s(1) < 1.0_rp .or. mass <= 0.0_rp) return
      mean = s(3:2 + d) / mass
      cov = reshape(s(3 + d:2 + d + d * d), [d, d]) / mass
      do j = 1, d
         cov(:, j) = cov(:, j) - mean * mean(j)
      end do
      ! Cholesky of the covariance; a pivot below (min_spread radius)^2 means a direction the particles do
      ! not span
      determined = s(1) >= real(d + 2, rp)
      chol = 0.0_rp
      if (determined) then
         do j = 1, d
            chol(j, j) = cov(j, j) - sum(chol(j, 1:j - 1)**2)
            if (chol(j, j) < (min_spread * radius)**2) then
               determined = .false.
               exit
            end if
            chol(j, j) = sqrt(chol(j, j))
            do i = j + 1, d
               chol(i, j) = (cov(i, j) - sum(chol(i, 1:j - 1) * chol(j, 1:j - 1))) / chol(j, j)
            end do
         end do
      end if
      at = 2 + d + d * d
      do i = 1, nq
         qmean = s(at + 1) / mass
         values(i) = qmean
         if (determined) then
            ! cov b = sum m q dx / M - qmean mean; then q(0) = qmean - b . mean
            rhs = s(at + 2:at + 1 + d) / mass - qmean * mean
            b = cholesky_solve(chol, rhs, d)
            values(i) = qmean - dot_product(b, mean)
         end if
         at = at + 1 + d
      end do
   end function fitted_values

   pure function cholesky_solve(chol, rhs, d) result(x)
      integer, intent(in) :: d
      real(rp), intent(in) :: chol(d, d), rhs(d)
      real(rp) :: x(d), y(d)
      integer :: i
      do i = 1, d
         y(i) = (rhs(i) - sum(chol(i, 1:i - 1) * y(1:i - 1))) / chol(i, i)
      end do
      do i = d, 1, -1
         x(i) = (y(i) - sum(chol(i + 1:d, i) * x(i + 1:d))) / chol(i, i)
      end do
   end function cholesky_solve

   !> Column names of gauges.csv after `time`, in the order of sample.
   function gauges_column_names(self) result(columns)
      class(fluid_gauges_t), intent(in) :: self
      character(len=name_len + 9), allocatable :: columns(:)
      character(len=*), parameter :: axes(3) = ['x', 'y', 'z']
      integer :: g, k, n
      n = 0
      do g = 1, self%count()
         n = n + column_count(self%gauges(g)%kind, self%dim)
      end do
      allocate (columns(n))
      n = 0
      do g = 1, self%count()
         associate (name => self%gauges(g)%name)
            select case (self%gauges(g)%kind)
            case (gauge_wall_pressure)
               columns(n + 1) = trim(name)//'_pressure'
               n = n + 1
               cycle
            case (gauge_pressure)
               columns(n + 1) = trim(name)//'_pressure'
            case (gauge_level, gauge_connected_level)
               columns(n + 1) = trim(name)//'_level'
            case default
               do k = 1, self%dim
                  columns(n + k) = trim(name)//'_v'//axes(k)
               end do
            end select
            n = n + column_count(self%gauges(g)%kind, self%dim)
            columns(n) = trim(name)//'_samples'
         end associate
      end do
   end function gauges_column_names

   !> connected_level: a particle reaching from `bottom` to `top` above the point wets the bins it
   !> overlaps; each keeps the highest top of the particles that wet it (-huge: dry).
   pure subroutine mark_bins(tops, bin, bottom, top)
      real(rp), intent(inout) :: tops(0:)
      real(rp), intent(in) :: bin, bottom, top
      integer :: first, last
      if (top < 0.0_rp) return
      first = max(0, floor(bottom / bin))
      last = min(ubound(tops, 1), floor(top / bin))
      if (first > last) return
      tops(first:last) = max(tops(first:last), top)
   end subroutine mark_bins

   !> connected_level: the highest top among the wet bins reached from the point (bin 0) upward across
   !> gaps of at most `bridged_bins` dry bins (also the first: a floor particle may sit a little above
   !> the floor); 0 when none is reached.
   pure real(rp) function connected_top(tops) result(top)
      real(rp), intent(in) :: tops(0:)
      integer :: b, dry
      top = 0.0_rp
      dry = 0
      do b = 0, ubound(tops, 1)
         if (tops(b) > -0.5_rp * huge(1.0_rp)) then
            top = max(top, tops(b))
            dry = 0
         else
            dry = dry + 1
            if (dry > bridged_bins) exit
         end if
      end do
   end function connected_top

   !> Columns of gauges.csv of a gauge of `kind`: its value(s) and the particles it saw; a wall pressure alone.
   pure integer function column_count(kind, dim)
      character(len=*), intent(in) :: kind
      integer, intent(in) :: dim
      select case (kind)
      case (gauge_wall_pressure)
         column_count = 1
      case (gauge_velocity)
         column_count = dim + 1
      case default
         column_count = 2
      end select
   end function column_count
end module fluid_gauges
