!> Motion of the solid bodies of a scene and the resultant force on each (bodies.csv; docs/loads.md,
!> docs/theory.md section 3.2).
!>
!> A body is the set of particles seeded for one `&body` of a solid material: its particles carry ids
!> offset_b + lattice index, or + row of its points file (particle_seeding, body_lattice), so every
!> particle knows its body and its reference position X (its lattice point, or its point in the file),
!> wherever it is and on whichever rank. Over a body's particles
!>   centroid    x_c = sum m x / M,   velocity v_c = P / M,   P = sum m v
!>   rotation    the rotation R closest to the deformation of the lattice: the polar factor of
!>               A = sum m (x - x_c)(X - X_c)^T  (2-D: theta = atan2(A21 - A12, A11 + A22), continued
!>               across +-pi from row to row; 3-D: the rotation vector theta n of R, |theta n| <= pi)
!>   force       F = (P(t) - P(t_prev)) / (t - t_prev) - M g, the resultant of the fluid, walls and other
!>               bodies on it averaged over the interval since the previous row (the same averaging as
!>               loads.csv, so the impulse is conserved whatever the interval).
!> Sums are local, then one reduction over the ranks. Everything is computed in the grid frame and
!> written in the world frame.
module body_motion
   use kinds, only: rp, i8, name_len
   use communication_counters, only: count_collective, comm_records, real_bytes
   use mpi_f08, only: MPI_Comm, MPI_Allreduce, MPI_IN_PLACE, MPI_DOUBLE_PRECISION, MPI_SUM
   use scene_description, only: scene_t
   use material_model, only: material_slot_t
   use particle_set, only: particle_set_t
   use body_lattice, only: body_lattice_t, body_lattice_of, lattice_point, has_points_file, body_id_count, body_bounds
   use world_frame, only: frame_t
   use small_matrices, only: identity
   implicit none
   private

   real(rp), parameter :: pi = acos(-1.0_rp)

   !> One solid body: where its ids lie and how an id maps to a reference position.
   type :: tracked_body_t
      character(len=name_len) :: name = ''
      integer :: material = 0
      integer(i8) :: first_id = 0, id_count = 0
      type(body_lattice_t) :: lattice           !< a body of a shape: id - first_id is its lattice index
      !> a body of a points file: the grid-frame reference position of each id (dim, id_count)
      real(rp), allocatable :: reference(:, :)
      real(rp) :: centre(3) = 0.0_rp            !< grid-frame point sums are taken about (conditioning)
   end type tracked_body_t

   !> The state of all bodies at one time (grid frame).
   type, public :: body_state_t
      real(rp), allocatable :: mass(:)          !< (body) [kg, kg/m in 2-D]
      real(rp), allocatable :: centroid(:, :)   !< (dim, body) [m]
      real(rp), allocatable :: momentum(:, :)   !< (dim, body) [kg m/s, per metre in 2-D]
      real(rp), allocatable :: rotation(:, :)   !< (1 in 2-D / 3 in 3-D, body) [rad]
   end type body_state_t

   type, public :: body_motion_t
      integer :: dim = 2
      type(tracked_body_t), allocatable :: bodies(:)
      real(rp) :: gravity(3) = 0.0_rp           !< grid frame
      !> at the previous row: momentum (dim, body) and 2-D angle (body); saved in checkpoints
      real(rp), allocatable :: previous_momentum(:, :)
      real(rp), allocatable :: previous_angle(:)
   contains
      procedure :: init => bodies_init
      procedure :: measure => bodies_measure
      procedure :: start => bodies_start
      procedure :: row_values => bodies_row_values
      procedure :: column_names => bodies_column_names
      procedure :: count => bodies_count
      procedure :: reference => bodies_reference
   end type body_motion_t

contains

   !> The solid bodies of the scene, in &body order (fluid bodies are not tracked).
   subroutine bodies_init(self, scene, materials, frame, gravity)
      class(body_motion_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      type(material_slot_t), intent(in) :: materials(:)
      type(frame_t), intent(in) :: frame
      real(rp), intent(in) :: gravity(3)
      integer :: b, dim, p
      integer(i8) :: offset
      real(rp) :: lo(3), hi(3)
      type(tracked_body_t) :: body

      dim = scene%grid%dim
      self%dim = dim
      self%gravity = gravity
      allocate (self%bodies(0))
      offset = 0
      do b = 1, size(scene%bodies)
         associate (spec => scene%bodies(b))
            body%first_id = offset
            body%id_count = body_id_count(scene, b)
            offset = offset + body%id_count
            if (materials(spec%material_index)%model%is_fluid) cycle
            body%name = spec%name
            body%material = spec%material_index
            if (allocated(body%reference)) deallocate (body%reference)
            if (has_points_file(spec)) then
               allocate (body%reference(dim, body%id_count))
               do p = 1, int(body%id_count)
                  body%reference(:, p) = frame%grid_point(scene%body_points(b)%position(:, p))
               end do
            else
               body%lattice = body_lattice_of(spec, scene%grid)
            end if
            call body_bounds(scene, b, lo, hi)
            body%centre = 0.0_rp
            body%centre(1:dim) = frame%grid_point(0.5_rp * (lo(1:dim) + hi(1:dim)))
            self%bodies = [self%bodies, body]
         end associate
      end do
      allocate (self%previous_momentum(dim, size(self%bodies)), self%previous_angle(size(self%bodies)))
      self%previous_momentum = 0.0_rp
      self%previous_angle = 0.0_rp
   end subroutine bodies_init

   pure integer function bodies_count(self)
      class(body_motion_t), intent(in) :: self
      bodies_count = 0
      if (allocated(self%bodies)) bodies_count = size(self%bodies)
   end function bodies_count

   !> Grid-frame reference position of the particle with index k (0-based) in tracked body b.
   pure function bodies_reference(self, b, k, frame) result(x)
      class(body_motion_t), intent(in) :: self
      integer, intent(in) :: b
      integer(i8), intent(in) :: k
      type(frame_t), intent(in) :: frame
      real(rp) :: x(self%dim)
      x = reference_position(self%bodies(b), k, frame, self%dim)
   end function bodies_reference

   !> Grid-frame reference position of the particle with index k (0-based) in the body: where
   !> seed_bodies put it.
   pure function reference_position(body, k, frame, dim) result(x)
      type(tracked_body_t), intent(in) :: body
      integer(i8), intent(in) :: k
      type(frame_t), intent(in) :: frame
      integer, intent(in) :: dim
      real(rp) :: x(dim), world(3)
      if (allocated(body%reference)) then
         x = body%reference(:, k + 1)
      else
         world = lattice_point(body%lattice, k)
         x = frame%grid_point(world(1:dim))
      end if
   end function reference_position

   !> The bodies' state now, from all ranks' particles. Collective (one reduction), also with no bodies
   !> on this rank; returns at once in a scene without solid bodies.
   function bodies_measure(self, particles, frame, comm) result(state)
      class(body_motion_t), intent(in) :: self
      type(particle_set_t), intent(in) :: particles
      type(frame_t), intent(in) :: frame
      type(MPI_Comm), intent(in) :: comm
      type(body_state_t) :: state
      integer :: d, nb, b, p, width, i, j, at
      integer(i8) :: k
      real(rp), allocatable :: sums(:, :)
      real(rp) :: x(self%dim), xr(self%dim), dx(self%dim), a(self%dim, self%dim)

      d = self%dim
      nb = self%count()
      allocate (state%mass(nb), state%centroid(d, nb), state%momentum(d, nb), state%rotation(merge(1, 3, d == 2), nb))
      if (nb == 0) return
      ! per body: M, sum m dx, sum m v, sum m dX, sum m dx dX^T (dx, dX about the body's centre)
      width = 1 + 3 * d + d * d
      allocate (sums(width, nb))
      sums = 0.0_rp
      do b = 1, nb
         associate (body => self%bodies(b))
            do p = particles%material_first(body%material), particles%material_last(body%material)
               k = particles%id(p) - body%first_id
               if (k < 0 .or. k >= body%id_count) cycle
               xr = reference_position(body, k, frame, d) - body%centre(1:d)
               dx = particles%x(:, p) - body%centre(1:d)
               associate (m => particles%mass(p), s => sums(:, b))
                  s(1) = s(1) + m
                  s(2:1 + d) = s(2:1 + d) + m * dx
                  s(2 + d:1 + 2 * d) = s(2 + d:1 + 2 * d) + m * particles%v(:, p)
                  s(2 + 2 * d:1 + 3 * d) = s(2 + 2 * d:1 + 3 * d) + m * xr
                  at = 1 + 3 * d
                  do j = 1, d
                     do i = 1, d
                        at = at + 1
                        s(at) = s(at) + m * dx(i) * xr(j)
                     end do
                  end do
               end associate
            end do
         end associate
      end do
      call MPI_Allreduce(MPI_IN_PLACE, sums, size(sums), MPI_DOUBLE_PRECISION, MPI_SUM, comm)
      call count_collective(comm_records, size(sums), real_bytes)

      do b = 1, nb
         associate (s => sums(:, b))
            state%mass(b) = s(1)
            state%rotation(:, b) = 0.0_rp
            if (s(1) <= 0.0_rp) then
               ! every particle of the body left the grid
               state%centroid(:, b) = 0.0_rp
               state%momentum(:, b) = 0.0_rp
               cycle
            end if
            x = s(2:1 + d) / s(1)
            state%centroid(:, b) = self%bodies(b)%centre(1:d) + x
            state%momentum(:, b) = s(2 + d:1 + 2 * d)
            xr = s(2 + 2 * d:1 + 3 * d) / s(1)
            ! A = sum m dx dX^T - M x_c X_c^T (about the centroids)
            a = reshape(s(2 + 3 * d:1 + 3 * d + d * d), [d, d])
            do j = 1, d
               a(:, j) = a(:, j) - s(1) * x * xr(j)
            end do
            if (d == 2) then
               state%rotation(1, b) = atan2(a(2, 1) - a(1, 2), a(1, 1) + a(2, 2))
            else
               state%rotation(:, b) = rotation_vector(polar_rotation(a))
            end if
         end associate
      end do
   end function bodies_measure

   !> Take the state at the start of the series (t = 0 of a new run) as the previous row.
   subroutine bodies_start(self, state)
      class(body_motion_t), intent(inout) :: self
      type(body_state_t), intent(in) :: state
      if (self%count() == 0) return
      self%previous_momentum = state%momentum
      if (self%dim == 2) self%previous_angle = state%rotation(1, :)
   end subroutine bodies_start

   !> The row of bodies.csv for `state`, `interval` seconds after the previous row (world frame), and the
   !> state kept as the previous row: per body x, y[, z], vx, vy[, vz], angle (2-D) or rx, ry, rz (3-D),
   !> fx, fy[, fz].
   function bodies_row_values(self, state, frame, interval) result(values)
      class(body_motion_t), intent(inout) :: self
      type(body_state_t), intent(in) :: state
      type(frame_t), intent(in) :: frame
      real(rp), intent(in) :: interval
      real(rp), allocatable :: values(:)
      integer :: b, d, at
      real(rp) :: angle, force(self%dim), velocity(self%dim)
      d = self%dim
      allocate (values(self%count() * merge(7, 12, d == 2)))
      at = 0
      do b = 1, self%count()
         velocity = 0.0_rp
         force = 0.0_rp
         if (state%mass(b) > 0.0_rp) then
            velocity = state%momentum(:, b) / state%mass(b)
            force = (state%momentum(:, b) - self%previous_momentum(:, b)) / interval - state%mass(b) * self%gravity(1:d)
            values(at + 1:at + d) = frame%world_point(state%centroid(:, b))
         else
            values(at + 1:at + d) = 0.0_rp
         end if
         at = at + d
         values(at + 1:at + d) = frame%world_vector(velocity)
         at = at + d
         if (d == 2) then
            ! the branch of atan2 nearest the previous row: the angle runs on past +-pi
            angle = state%rotation(1, b)
            angle = angle + 2.0_rp * pi * anint((self%previous_angle(b) - angle) / (2.0_rp * pi))
            self%previous_angle(b) = angle
            ! a rotation of the grid frame about z leaves an angle about z unchanged
            values(at + 1) = angle
            at = at + 1
         else
            values(at + 1:at + 3) = frame%world_vector(state%rotation(:, b))
            at = at + 3
         end if
         values(at + 1:at + d) = frame%world_vector(force)
         at = at + d
         self%previous_momentum(:, b) = state%momentum(:, b)
      end do
   end function bodies_row_values

   !> Column names of bodies.csv after `time`, in the order of row_values.
   function bodies_column_names(self) result(columns)
      class(body_motion_t), intent(in) :: self
      character(len=name_len + 6), allocatable :: columns(:)
      character(len=*), parameter :: suffixes_2d(7) = [character(len=6) :: '_x', '_y', '_vx', '_vy', '_angle', '_fx', '_fy']
      character(len=*), parameter :: suffixes_3d(12) = [character(len=6) :: '_x', '_y', '_z', '_vx', '_vy', '_vz', '_rx', &
                                                        '_ry', '_rz', '_fx', '_fy', '_fz']
      integer :: b, s, n
      n = merge(7, 12, self%dim == 2)
      allocate (columns(n * self%count()))
      do b = 1, self%count()
         do s = 1, n
            if (self%dim == 2) then
               columns((b - 1) * n + s) = trim(self%bodies(b)%name)//trim(suffixes_2d(s))
            else
               columns((b - 1) * n + s) = trim(self%bodies(b)%name)//trim(suffixes_3d(s))
            end if
         end do
      end do
   end function bodies_column_names

   !> The rotation factor of the polar decomposition A = R U (Higham's scaled Newton iteration
   !> R <- (zeta R + R^{-T} / zeta) / 2). A degenerate A (a body collapsed to a plane) gives the identity.
   pure function polar_rotation(a) result(r)
      real(rp), intent(in) :: a(3, 3)
      real(rp) :: r(3, 3), inverse_t(3, 3), det, zeta, change
      integer :: iteration
      r = a
      do iteration = 1, 100
         det = determinant(r)
         if (abs(det) <= epsilon(1.0_rp) * sum(r**2)**1.5_rp) then
            r = identity()
            return
         end if
         inverse_t = cofactor_inverse_t(r, det)
         zeta = (sum(inverse_t**2) / sum(r**2))**0.25_rp
         change = sum((0.5_rp * (zeta * r + inverse_t / zeta) - r)**2)
         r = 0.5_rp * (zeta * r + inverse_t / zeta)
         if (change <= (64.0_rp * epsilon(1.0_rp))**2) exit
      end do
   end function polar_rotation

   !> (M^{-1})^T = cofactor matrix / det.
   pure function cofactor_inverse_t(m, det) result(c)
      real(rp), intent(in) :: m(3, 3), det
      real(rp) :: c(3, 3)
      c(1, 1) = m(2, 2) * m(3, 3) - m(2, 3) * m(3, 2)
      c(1, 2) = m(2, 3) * m(3, 1) - m(2, 1) * m(3, 3)
      c(1, 3) = m(2, 1) * m(3, 2) - m(2, 2) * m(3, 1)
      c(2, 1) = m(1, 3) * m(3, 2) - m(1, 2) * m(3, 3)
      c(2, 2) = m(1, 1) * m(3, 3) - m(1, 3) * m(3, 1)
      c(2, 3) = m(1, 2) * m(3, 1) - m(1, 1) * m(3, 2)
      c(3, 1) = m(1, 2) * m(2, 3) - m(1, 3) * m(2, 2)
      c(3, 2) = m(1, 3) * m(2, 1) - m(1, 1) * m(2, 3)
      c(3, 3) = m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1)
      c = c / det
   end function cofactor_inverse_t

   pure real(rp) function determinant(m)
      real(rp), intent(in) :: m(3, 3)
      determinant = m(1, 1) * (m(2, 2) * m(3, 3) - m(2, 3) * m(3, 2)) - m(1, 2) * (m(2, 1) * m(3, 3) - m(2, 3) * m(3, 1)) + &
                    m(1, 3) * (m(2, 1) * m(3, 2) - m(2, 2) * m(3, 1))
   end function determinant


   !> The rotation vector theta n of a rotation matrix (0 <= theta <= pi).
   pure function rotation_vector(r) result(w)
      real(rp), intent(in) :: r(3, 3)
      real(rp) :: w(3), skew(3), theta, s, c, diag(3)
      integer :: k
      skew = 0.5_rp * [r(3, 2) - r(2, 3), r(1, 3) - r(3, 1), r(2, 1) - r(1, 2)]    ! sin(theta) n
      c = max(-1.0_rp, min(1.0_rp, 0.5_rp * (r(1, 1) + r(2, 2) + r(3, 3) - 1.0_rp)))
      s = norm2(skew)
      theta = atan2(s, c)
      if (theta < 1.0e-6_rp) then
         w = skew                      ! theta / sin(theta) = 1 to round-off
      else if (pi - theta > 1.0e-4_rp) then
         w = theta / s * skew
      else
         ! near pi: R = -I + 2 n n^T, so n_k^2 = (R_kk + 1) / 2 and n_i n_k = (R_ik + R_ki) / 4: the column of
         ! the largest n_k gives n_k n; the sign from the skew part
         diag = [(max(0.0_rp, 0.5_rp * (r(k, k) + 1.0_rp)), k = 1, 3)]
         k = maxloc(diag, 1)
         w = 0.25_rp * [r(1, k) + r(k, 1), r(2, k) + r(k, 2), r(3, k) + r(k, 3)]
         w(k) = diag(k)
         w = w / norm2(w)
         if (dot_product(w, skew) < 0.0_rp) w = -w
         w = theta * w
      end if
   end function rotation_vector
end module body_motion
