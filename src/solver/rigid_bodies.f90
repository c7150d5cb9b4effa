!> Rigid bodies: the bodies of a `&material model = 'rigid'` (docs/theory.md section 3.7, issue 18).
!>
!> Each such `&body` moves as one rigid body: centre of mass c, velocity V, angular momentum L about c and
!> rotation R from its reference placement (where seed_bodies put its particles: body_motion's reference
!> positions X, centre of mass X_c). Its particles share the grid with the fluid and the other solids (the
!> paper's single-field coupling): they give the nodes their mass and momentum and no stress
!> (rigid_material). The rigid limit of that coupling [R]: a stiff body's stress makes every node its
!> particles touch move rigidly, with the fluid mass on those nodes. So after the nodal update (fluid
!> stress, gravity, the walls' nodal constraints) the increments dv_i of the body's nodes S (body and fluid
!> mass m_i together) are projected on a rigid motion, which keeps their momentum and angular momentum:
!>    dV = sum_S m_i dv_i / M_S,   dw = I_S^-1 sum_S m_i (x_i - c_S) x dv_i,
!> those nodes take dv_i = dV + dw x (x_i - c_S), and the body V += dV + dw x (c - c_S), L += I dw. Only
!> increments are projected (FLIP): in a vacuum dv_i = g dt at every node, so the body keeps its spin (L to
!> round-off); projecting the nodal velocities would lose it as PIC does. The body moves rigidly:
!>    c^{n+1} = c^n + dt V^{n+1},   R^{n+1} = exp(dt [w]) R^n,   w = I^-1 L^{n+1},  I = R^n I_0 R^n^T,
!>    x_p = c^{n+1} + R^{n+1} (X_p - X_c),   v_p = V^{n+1} + w^{n+1} x (x_p - c^{n+1})   (APIC: C_p = [w^{n+1}])
!> so it never deforms and its particles never drift. With MUSL its particles' share of the re-mapped
!> momentum is that of these rigid velocities (at x^n): remap_correction.
!>
!> Walls and structures [R]: a nodal constraint stops only the nodes it holds, and a rigid body averages
!> over all its nodes, so a body resting on the floor would sink at g dt (1/phi - 1), phi its mass share on
!> the floor's nodes, and one coming down would creep over its last cell. The walls therefore act on the
!> body itself, and their nodal constraints (applied after the projection) leave its nodes alone: each of
!> its particles within a cell of a wall is a contact point with gap g = phi_w(x_p) - r_p (r_p half its spacing: the particle's
!> surface), whose normal velocity may close the gap within the step but not pass it, u_n >= -g / dt
!> ("speculative contact"; a gap already closed, g < 0, opens at 0.2 |g| / dt), with Coulomb friction mu
!> (slip 0, no_slip unbounded, friction the wall's mu). Its impulses act on the cluster S and follow from
!> projected Gauss-Seidel over the points with accumulated impulses ("sequential impulses"); the contact is
!> inelastic. They are part of the wall's load in loads.csv, with what its nodal constraint took. The
!> particle safeguard of the constraints leaves rigid particles alone. Every rank holds every body's state
!> and solves the same contact problem (the points gathered from all ranks and sorted by particle id), so
!> the state is the same on every rank.
module rigid_bodies
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_size, MPI_Allreduce, MPI_Allgather, MPI_Allgatherv, MPI_IN_PLACE, &
                      MPI_DOUBLE_PRECISION, MPI_INTEGER, MPI_SUM
   use communication_counters, only: count_collective, comm_other, comm_rigid, real_bytes, int_bytes
   use scene_description, only: scene_t, model_rigid
   use particle_set, only: particle_set_t
   use background_grid, only: grid_t, row_mass
   use body_motion, only: body_motion_t
   use constraint_list, only: constraint_list_t
   use grid_transfer, only: spread_to_grid, mass_to_grid
   use domain_decomposition, only: domain_t
   use node_halo, only: sum_shared_nodes
   use body_contact, only: contact_t
   use small_matrices, only: cross, identity, rotation_of, inverse_3x3
   implicit none
   private

   !> Particles per block of the transfers (the buffers stay in L1).
   integer, parameter :: block_size = 256
   !> Iterations of the contact solver at most, and its relative tolerance on an impulse change.
   integer, parameter :: max_iterations = 200
   real(rp), parameter :: impulse_tolerance = 1.0e-12_rp
   !> Fraction of a closed gap (overlap) opened per step: a full one would throw the body off.
   real(rp), parameter :: overlap_recovery = 0.2_rp
   !> Columns of a contact point record: id, wall, body, r (3), n (3), gap, mu, the wall's velocity (3).
   integer, parameter :: record_width = 14

   type :: rigid_body_t
      integer :: tracked = 0                     !< its index among body_motion's solid bodies
      integer :: material = 0
      integer(i8) :: first_id = 0, id_count = 0
      real(rp) :: mass = 0.0_rp                  !< M [kg, kg/m in 2-D]
      real(rp) :: reference_centre(3) = 0.0_rp   !< X_c, centre of mass of the reference placement (grid frame)
      real(rp) :: inertia(3, 3) = 0.0_rp         !< I_0 about X_c in the reference placement
      real(rp) :: centre(3) = 0.0_rp             !< c^n (grid frame)
      real(rp) :: velocity(3) = 0.0_rp           !< V^n, then V^{n+1} after solve
      real(rp) :: angular_momentum(3) = 0.0_rp   !< L about c (2-D: component 3 only)
      real(rp) :: rotation(3, 3) = 0.0_rp        !< R^n
      real(rp) :: spin(3) = 0.0_rp               !< solve: w of L^{n+1} with I at R^n (the step's rotation)
      real(rp) :: next_centre(3) = 0.0_rp        !< solve: c^{n+1}
      real(rp) :: next_rotation(3, 3) = 0.0_rp   !< solve: R^{n+1}
      real(rp) :: next_spin(3) = 0.0_rp          !< solve: w^{n+1} = I(R^{n+1})^-1 L^{n+1}
   end type rigid_body_t

   type, public :: rigid_set_t
      logical :: active = .false.                !< the scene has rigid bodies
      integer :: dim = 2
      type(rigid_body_t), allocatable :: bodies(:)
      logical, allocatable :: rigid_material(:)  !< (material) its bodies are rigid
      !> (node) the node belongs to a body's cluster this step: the walls' nodal constraints leave it alone
      logical, allocatable :: held(:)
   contains
      procedure :: init => rigid_init
      procedure :: solve => rigid_solve
      procedure :: remap_correction => rigid_remap_correction
      procedure :: move => rigid_move
      procedure :: finish => rigid_finish
      procedure :: moves_material => rigid_moves_material
      procedure :: state => rigid_state
      procedure :: set_state => rigid_set_state
   end type rigid_set_t

   !> Reals per body in a checkpoint: mass, X_c, I_0, c, V, L, R.
   integer, parameter, public :: rigid_state_width = 1 + 3 + 9 + 3 + 3 + 3 + 9

contains

   !> The rigid bodies of the scene (the solid bodies body_motion tracks whose material is rigid). With
   !> `measure`, their mass, inertia and motion from the particles (collective: one reduction); without (a
   !> restart), set_state gives them.
   subroutine rigid_init(self, scene, tracked, grid, particles, comm, measure)
      class(rigid_set_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      type(body_motion_t), intent(in) :: tracked
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      type(MPI_Comm), intent(in) :: comm
      logical, intent(in) :: measure
      integer :: b, m, n
      self%dim = scene%grid%dim
      self%rigid_material = [(scene%materials(m)%model == model_rigid, m = 1, size(scene%materials))]
      n = 0
      do b = 1, tracked%count()
         if (self%rigid_material(tracked%bodies(b)%material)) n = n + 1
      end do
      allocate (self%bodies(n))
      self%active = n > 0
      if (.not. self%active) return
      n = 0
      do b = 1, tracked%count()
         if (.not. self%rigid_material(tracked%bodies(b)%material)) cycle
         n = n + 1
         self%bodies(n)%tracked = b
         self%bodies(n)%material = tracked%bodies(b)%material
         self%bodies(n)%first_id = tracked%bodies(b)%first_id
         self%bodies(n)%id_count = tracked%bodies(b)%id_count
         self%bodies(n)%rotation = identity()
      end do
      if (measure) call measure_bodies(self, tracked, grid, particles, comm)
   end subroutine rigid_init

   !> Mass, centres, inertia, momentum and angular momentum of every body from its particles, summed about
   !> body_motion's centre of each body (conditioning), then one reduction.
   subroutine measure_bodies(self, tracked, grid, particles, comm)
      type(rigid_set_t), intent(inout) :: self
      type(body_motion_t), intent(in) :: tracked
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(in) :: particles
      type(MPI_Comm), intent(in) :: comm
      integer, parameter :: width = 1 + 3 + 3 + 3 + 9 + 3
      real(rp) :: sums(width, size(self%bodies)), x(3), xr(3), v(3), anchor(3), mean_x(3), rr(3, 3), spread(3, 3)
      real(rp), allocatable :: mine(:, :), all(:, :)
      integer, allocatable :: order(:)
      integer :: b, p, d, i, j, n, c
      integer(i8) :: k
      d = self%dim
      ! every rank's rigid particles (id, body, m, x, v), summed in the order of their ids on every rank: the
      ! same sums, bit for bit, on any number of ranks
      allocate (mine(12, particles%count))
      n = 0
      do p = 1, particles%count
         if (.not. self%rigid_material(particles%material(p))) cycle
         b = body_of(self, particles%material(p), particles%id(p))
         if (b == 0) cycle
         n = n + 1
         mine(:, n) = 0.0_rp
         mine(1:3, n) = [real(particles%id(p), rp), real(b, rp), particles%mass(p)]
         mine(4:3 + d, n) = particles%x(:, p)
         mine(7:6 + d, n) = particles%v(:, p)
      end do
      call gather_columns(mine(:, 1:n), comm, comm_other, all)
      order = key_order(int(all(1, :), i8))
      sums = 0.0_rp
      do c = 1, size(order)
         b = nint(all(2, order(c)))
         associate (body => self%bodies(b), s => sums(:, b), m => all(3, order(c)))
            anchor = tracked%bodies(body%tracked)%centre
            k = int(all(1, order(c)), i8) - body%first_id
            x = 0.0_rp
            xr = 0.0_rp
            x(1:d) = all(4:3 + d, order(c)) - anchor(1:d)
            xr(1:d) = tracked%reference(body%tracked, k, grid%frame) - anchor(1:d)
            v = all(7:9, order(c))
            s(1) = s(1) + m
            s(2:4) = s(2:4) + m * xr
            s(5:7) = s(5:7) + m * x
            s(8:10) = s(8:10) + m * v
            do j = 1, 3
               do i = 1, 3
                  s(10 + i + 3 * (j - 1)) = s(10 + i + 3 * (j - 1)) + m * xr(i) * xr(j)
               end do
            end do
            s(20:22) = s(20:22) + m * cross(x, v)
         end associate
      end do
      do b = 1, size(self%bodies)
         associate (body => self%bodies(b), s => sums(:, b))
            anchor = tracked%bodies(body%tracked)%centre
            body%mass = s(1)
            if (body%mass <= 0.0_rp) cycle
            mean_x = s(2:4) / s(1)
            body%reference_centre = anchor + mean_x
            body%centre = anchor + s(5:7) / s(1)
            body%velocity = s(8:10) / s(1)
            ! I_0 = sum m ((r.r) 1 - r r^T), r = X - X_c: sum m r r^T = sum m X X^T - M X_c X_c^T (about anchor)
            spread = reshape(s(11:19), [3, 3])
            do j = 1, 3
               spread(:, j) = spread(:, j) - s(1) * mean_x * mean_x(j)
            end do
            rr = -spread
            do i = 1, 3
               rr(i, i) = rr(i, i) + (spread(1, 1) + spread(2, 2) + spread(3, 3))
            end do
            body%inertia = rr
            ! L about c = sum m x v - (c - anchor) x P
            body%angular_momentum = s(20:22) - cross(body%centre - anchor, s(8:10))
            body%rotation = identity()
         end associate
      end do
   end subroutine measure_bodies

   !> Step 2 of the rigid bodies, after the nodal update (grid%velocity v^{n+1}, grid%velocity_increment dv)
   !> and before the walls' nodal constraints, which then leave the clusters' nodes alone (`held`); with
   !> &contact after the fields' walls (a body there still feels the walls' nodal constraints). Before G2P.
   !> Each body's nodes (those its particles touch; a node two bodies touch goes with the one of the larger
   !> mass there) form its cluster S, body and fluid mass
   !> together: the rigid limit of the single-field coupling, in which a stiff body's stress makes all the
   !> nodes of its particles move rigidly. The increments of S are projected on a rigid motion, which keeps
   !> their momentum and angular momentum [R]:
   !>    dV = sum m_i dv_i / M_S,   dw = I_S^-1 sum m_i (x_i - c_S) x dv_i   (sums over S, I_S about c_S),
   !> the walls' contact on the body's particles adds its impulses to S's motion, the nodes of S take the
   !> rigid increments dv_i = dV + dw x (x_i - c_S) (so the fluid there moves with the body), and the body
   !> its share: V += dV + dw x (c - c_S), L += I dw. On the rank with `records_loads`, impulse(:, w) gains
   !> the impulses wall w gave the bodies. With `contact` (its fields active) the nodal velocities are the
   !> fields' (body_contact): a body of a material in some &contact is its field f; at a node where the
   !> fields separated this step its cluster has that field's mass and only that field takes the rigid
   !> increment, elsewhere all fields move together (the total mass, every field's rows); a structure of
   !> its &contact acts on it with the pair's mu, and field_impulse(:, w, f) gains its share of the load.
   !> Collective.
   subroutine rigid_solve(self, domain, grid, particles, constraints, dt, records_loads, impulse, contact, field_impulse)
      class(rigid_set_t), intent(inout) :: self
      type(domain_t), intent(in) :: domain
      type(grid_t), intent(inout) :: grid
      type(particle_set_t), intent(in) :: particles
      type(constraint_list_t), intent(in) :: constraints
      real(rp), intent(in) :: dt
      logical, intent(in) :: records_loads
      real(rp), intent(inout) :: impulse(:, :)
      type(contact_t), intent(inout), optional :: contact
      real(rp), intent(inout), optional :: field_impulse(:, :, :)
      integer, parameter :: width = 1 + 3 + 3 + 3 + 9
      real(rp) :: sums(width, size(self%bodies)), x(3), dv(3), r(3)
      real(rp), allocatable :: share(:, :), records(:, :), all_records(:, :), applied(:, :), motion(:, :), nodes(:, :)
      real(rp), allocatable :: all_nodes(:, :)
      integer, allocatable :: owner(:), order(:)
      integer :: rows(block_size), m, first, last, b0, e, n, q, p, b, d, found, total, i, j, k, g(3), f
      integer :: field(size(self%bodies))
      real(rp) :: mass
      real(rp), allocatable :: field_friction(:, :)
      logical :: fields

      d = self%dim
      ! the velocity field of each body: 0 (the common one), or its own with &contact
      fields = .false.
      if (present(contact)) fields = contact%active
      field = 0
      if (fields) then
         do b = 1, size(self%bodies)
            do f = 1, contact%fields
               if (contact%first_id(f) == self%bodies(b)%first_id) field(b) = f
            end do
         end do
         field_friction = contact%wall_friction(constraints%structure)
      end if
      ! the bodies' masses on the nodes, and the contact points of their particles
      allocate (share(size(self%bodies), grid%node_count), records(record_width, 64))
      share = 0.0_rp
      found = 0
      do m = 1, size(self%rigid_material)
         if (.not. self%rigid_material(m)) cycle
         first = particles%material_first(m)
         last = particles%material_last(m)
         do b0 = first, last, block_size
            e = min(last, b0 + block_size - 1)
            n = e - b0 + 1
            do q = 1, n
               p = b0 + q - 1
               rows(q) = body_of(self, m, particles%id(p))
               if (rows(q) == 0) cycle
               r = 0.0_rp
               r(1:d) = particles%x(:, p) - self%bodies(rows(q))%centre(1:d)
               call find_contacts(p, rows(q), r)
            end do
            call mass_to_grid(grid, particles, b0, e, rows(1:n), share)
         end do
      end do
      call sum_shared_nodes(domain, grid, share)
      allocate (owner(grid%node_count))
      owner = 0
      do i = 1, grid%node_count
         if (any(share(:, i) > 0.0_rp)) owner(i) = maxloc(share(:, i), 1)
      end do
      self%held = owner > 0

      ! each cluster's owned nodes (global index, body, mass, dv), gathered and summed in the order of the
      ! global index on every rank: the same sums, bit for bit, on any number of ranks
      allocate (nodes(6, count(owner > 0)))
      n = 0
      g = 0
      do i = 1, grid%node_count
         b = owner(i)
         if (b == 0) cycle
         g(1:d) = grid%node_indices(i)
         if (.not. grid%owns_node(g(1:d))) cycle
         mass = grid%accumulated(row_mass, i)
         dv = 0.0_rp
         if (fields) then
            f = field(b)
            if (f > 0 .and. contact%separate(i)) mass = grid%accumulated(contact%field_row + (f - 1) * contact%stride, i)
            dv(1:d) = contact%increment(f * d + 1:f * d + d, i)
         else
            dv(1:d) = grid%velocity_increment(:, i)
         end if
         n = n + 1
         nodes(:, n) = [real(node_key(g), rp), real(b, rp), mass, dv]
      end do
      call gather_columns(nodes(:, 1:n), domain%comm, comm_rigid, all_nodes)
      order = key_order(int(all_nodes(1, :), i8))
      sums = 0.0_rp
      do k = 1, size(order)
         associate (node => all_nodes(:, order(k)))
            b = nint(node(2))
            mass = node(3)
            dv = node(4:6)
            g = key_node(int(node(1), i8))
            x = 0.0_rp
            x(1:d) = grid%origin(1:d) + g(1:d) * grid%h - self%bodies(b)%centre(1:d)
         end associate
         associate (s => sums(:, b))
            s(1) = s(1) + mass
            s(2:4) = s(2:4) + mass * x
            s(5:7) = s(5:7) + mass * dv
            s(8:10) = s(8:10) + mass * cross(x, dv)
            do j = 1, 3
               do p = 1, 3
                  s(10 + p + 3 * (j - 1)) = s(10 + p + 3 * (j - 1)) + mass * x(p) * x(j)
               end do
            end do
         end associate
      end do
      call gather_columns(records(:, 1:found), domain%comm, comm_rigid, all_records)
      total = size(all_records, 2)
      order = record_order(all_records)
      allocate (applied(3, total), motion(9, size(self%bodies)))
      applied = 0.0_rp

      do b = 1, size(self%bodies)
         call project_cluster(self%dim, self%bodies(b), b, sums(:, b), all_records, order, dt, grid%h, applied, &
                              motion(:, b))
      end do
      ! the clusters' nodes take their rigid increments
      do i = 1, grid%node_count
         b = owner(i)
         if (b == 0) cycle
         ! a body on no node (all its particles gone) has no cluster to move
         if (sums(1, b) <= 0.0_rp .or. self%bodies(b)%mass <= 0.0_rp) cycle
         x = 0.0_rp
         x(1:d) = grid%origin(1:d) + grid%node_indices(i) * grid%h
         x = x - motion(7:9, b)
         dv = motion(1:3, b) + cross(motion(4:6, b), x)
         if (.not. fields) then
            grid%velocity(:, i) = grid%velocity(:, i) + (dv(1:d) - grid%velocity_increment(:, i))
            grid%velocity_increment(:, i) = dv(1:d)
         else if (field(b) > 0 .and. contact%separate(i)) then
            call take_increment(field(b))
         else
            do f = 0, contact%fields
               call take_increment(f)
            end do
         end if
      end do
      if (records_loads) call record_loads()

   contains

      !> The contact points of particle p of body b (r: its offset from the centre) with the walls.
      subroutine find_contacts(p, b, r)
         integer, intent(in) :: p, b
         real(rp), intent(in) :: r(3)
         real(rp) :: radius, x(d), normal(3), mu, phi
         integer :: w
         real(rp), allocatable :: grown(:, :)
         radius = 0.5_rp * (particles%mass(p) / particles%density(p))**(1.0_rp / d)
         x = particles%x(:, p)
         do w = 1, constraints%count()
            associate (wall => constraints%items(w)%item)
               if (.not. wall%active) cycle
               if (.not. wall%behind(grid, x, radius + grid%h)) cycle
               normal = 0.0_rp
               phi = wall%distance(grid, x, normal(1:d))
               mu = wall%traits%body_friction
               if (fields .and. field(b) > 0) then
                  if (field_friction(w, field(b)) >= 0.0_rp) mu = field_friction(w, field(b))
               end if
               if (found == size(records, 2)) then
                  allocate (grown(record_width, 2 * found))
                  grown(:, 1:found) = records(:, 1:found)
                  call move_alloc(grown, records)
               end if
               found = found + 1
               records(:, found) = [real(particles%id(p), rp), real(w, rp), real(b, rp), r, normal, &
                                    phi - radius, mu, wall%wall_velocity]
            end associate
         end do
      end subroutine find_contacts

      !> impulse(:, w) += the impulses of wall w's contact points and their moments about its moment point.
      subroutine record_loads()
         integer :: c, w
         real(rp) :: arm(3), j(3)
         do c = 1, total
            j = applied(:, c)
            if (all(j == 0.0_rp)) cycle
            w = nint(all_records(2, c))
            b = nint(all_records(3, c))
            arm = self%bodies(b)%centre + all_records(4:6, c)
            arm(1:d) = arm(1:d) - constraints%items(w)%item%moment_point(1:d)
            impulse(1:d, w) = impulse(1:d, w) + j(1:d)
            impulse(4:6, w) = impulse(4:6, w) + cross(arm, j)
            if (present(field_impulse) .and. field(b) > 0) then
               field_impulse(1:d, w, field(b)) = field_impulse(1:d, w, field(b)) + j(1:d)
               field_impulse(4:6, w, field(b)) = field_impulse(4:6, w, field(b)) + cross(arm, j)
            end if
         end do
      end subroutine record_loads

      !> The global node g as one integer (x fastest) and back.
      integer(i8) function node_key(g)
         integer, intent(in) :: g(3)
         node_key = int(g(1), i8) + int(grid%global_cells(1) + 1, i8) * (int(g(2), i8) + &
                    int(grid%global_cells(2) + 1, i8) * int(g(3), i8))
      end function node_key

      function key_node(key) result(g)
         integer(i8), intent(in) :: key
         integer :: g(3)
         integer(i8) :: nx, ny
         nx = grid%global_cells(1) + 1
         ny = grid%global_cells(2) + 1
         g = int([mod(key, nx), mod(key / nx, ny), key / (nx * ny)])
      end function key_node

      !> Field f's rows of the contact velocities at node i take the increment dv.
      subroutine take_increment(f)
         integer, intent(in) :: f
         associate (v => contact%velocity(f * d + 1:f * d + d, i), inc => contact%increment(f * d + 1:f * d + d, i))
            v = v + (dv(1:d) - inc)
            inc = dv(1:d)
         end associate
      end subroutine take_increment
   end subroutine rigid_solve

   !> One body's cluster (its sums over S, about its centre c): the rigid projection of the increments, the
   !> walls' contact, and the body's new velocity, angular momentum and step rotation. motion = (dV, dw,
   !> c_S), the cluster's rigid increment (all 0 for a body on no node).
   subroutine project_cluster(dim, body, b, s, records, order, dt, h, applied, motion)
      integer, intent(in) :: dim
      type(rigid_body_t), intent(inout) :: body
      integer, intent(in) :: b, order(:)
      real(rp), intent(in) :: s(:), records(:, :), dt, h
      real(rp), intent(inout) :: applied(:, :)
      real(rp), intent(out) :: motion(9)
      real(rp) :: mass, offset(3), dv(3), dw(3), spread(3, 3), inertia(3, 3), inverse(3, 3), momentum(3)
      integer :: j
      motion = 0.0_rp
      body%spin = matmul(inverse_inertia(body, body%rotation, dim), body%angular_momentum)
      mass = s(1)
      if (mass > 0.0_rp .and. body%mass > 0.0_rp) then
         offset = s(2:4) / mass                              ! c_S - c
         dv = s(5:7) / mass
         momentum = s(8:10) - cross(offset, s(5:7))          ! sum m (x_i - c_S) x dv_i
         spread = reshape(s(11:19), [3, 3])
         do j = 1, 3
            spread(:, j) = spread(:, j) - mass * offset * offset(j)
         end do
         inertia = -spread
         do j = 1, 3
            inertia(j, j) = inertia(j, j) + (spread(1, 1) + spread(2, 2) + spread(3, 3))
         end do
         if (dim == 2) then
            inverse = 0.0_rp
            if (inertia(3, 3) > 0.0_rp) inverse(3, 3) = 1.0_rp / inertia(3, 3)
         else
            inverse = inverse_3x3(inertia)
         end if
         dw = matmul(inverse, momentum)
         call resolve_contacts(body, b, records, order, dt, h, mass, offset, inverse, dv, dw, applied)
         motion(1:3) = dv
         motion(4:6) = dw
         motion(7:9) = body%centre + offset
         body%velocity = body%velocity + dv - cross(dw, offset)
         body%angular_momentum = body%angular_momentum + matmul(inertia_of(body, body%rotation, dim), dw)
         if (dim == 2) body%angular_momentum(1:2) = 0.0_rp
         body%spin = matmul(inverse_inertia(body, body%rotation, dim), body%angular_momentum)
      end if
      body%next_centre = body%centre + dt * body%velocity
      body%next_rotation = matmul(rotation_of(dt * body%spin), body%rotation)
      body%next_spin = matmul(inverse_inertia(body, body%next_rotation, dim), body%angular_momentum)
   end subroutine project_cluster

   !> Every rank's columns `mine` (rows, n) on every rank, in rank order, counted under `category`. Collective.
   subroutine gather_columns(mine, comm, category, all)
      real(rp), intent(in) :: mine(:, :)
      type(MPI_Comm), intent(in) :: comm
      integer, intent(in) :: category
      real(rp), allocatable, intent(out) :: all(:, :)
      integer, allocatable :: counts(:), displacements(:)
      integer :: nranks, r, n
      call MPI_Comm_size(comm, nranks)
      allocate (counts(nranks), displacements(nranks))
      n = size(mine)
      call MPI_Allgather(n, 1, MPI_INTEGER, counts, 1, MPI_INTEGER, comm)
      call count_collective(category, 1, int_bytes)
      displacements(1) = 0
      do r = 2, nranks
         displacements(r) = displacements(r - 1) + counts(r - 1)
      end do
      allocate (all(size(mine, 1), sum(counts) / size(mine, 1)))
      if (sum(counts) == 0) return
      call MPI_Allgatherv(mine, n, MPI_DOUBLE_PRECISION, all, counts, displacements, MPI_DOUBLE_PRECISION, comm)
      call count_collective(category, sum(counts), real_bytes)
   end subroutine gather_columns

   !> The contact records in the order of (particle id, wall): the same on any number of ranks.
   function record_order(records) result(order)
      real(rp), intent(in) :: records(:, :)
      integer, allocatable :: order(:)
      integer :: key_walls
      key_walls = 1
      if (size(records, 2) > 0) key_walls = nint(maxval(records(2, :))) + 1
      order = key_order(int(records(1, :), i8) * key_walls + nint(records(2, :), i8))
   end function record_order

   !> The permutation that sorts `keys` ascending (stable bottom-up merge sort: the gathered columns are
   !> runs in order per rank, interleaved across ranks).
   function key_order(keys) result(order)
      integer(i8), intent(in) :: keys(:)
      integer, allocatable :: order(:), merged(:)
      integer :: n, width, lo, mid, hi, i, j, k
      n = size(keys)
      order = [(i, i = 1, n)]
      allocate (merged(n))
      width = 1
      do while (width < n)
         do lo = 1, n, 2 * width
            mid = min(lo + width - 1, n)
            hi = min(lo + 2 * width - 1, n)
            i = lo
            j = mid + 1
            do k = lo, hi
               if (j > hi) then
                  merged(k) = order(i)
                  i = i + 1
               else if (i > mid) then
                  merged(k) = order(j)
                  j = j + 1
               else if (keys(order(j)) < keys(order(i))) then
                  merged(k) = order(j)
                  j = j + 1
               else
                  merged(k) = order(i)
                  i = i + 1
               end if
            end do
         end do
         order = merged
         width = 2 * width
      end do
   end function key_order

   !> Projected Gauss-Seidel over the contact points of body b (in `order`): accumulated normal impulses
   !> lambda_n >= 0 that keep u_n >= -g / dt, and tangential impulses within mu lambda_n (mu < 0: no bound),
   !> u the velocity relative to the wall's (a moving wall's mean velocity over the step).
   !> The body's particle at r (from c) moves at u = V + w x r + dv + dw x (r - offset) after the step; an
   !> impulse j there changes the cluster's (mass, inverse inertia about c_S = c + offset) dv and dw.
   !> applied(:, c) gets the impulse of point c.
   subroutine resolve_contacts(body, b, records, order, dt, h, mass, offset, inverse, dv, dw, applied)
      type(rigid_body_t), intent(in) :: body
      integer, intent(in) :: b, order(:)
      real(rp), intent(in) :: records(:, :), dt, h, mass, offset(3), inverse(3, 3)
      real(rp), intent(inout) :: dv(3), dw(3), applied(:, :)
      real(rp) :: r(3), rs(3), n(3), u(3), un, target, change, largest, normal_impulse, tangential(3), t(3)
      real(rp) :: speed, limit, tolerance, new_tangential(3), dj(3), wall_velocity(3)
      integer :: k, c, iteration
      if (size(records, 2) == 0) return
      if (.not. any(nint(records(3, :)) == b)) return
      tolerance = impulse_tolerance * mass * (h / dt + norm2(body%velocity))
      do iteration = 1, max_iterations
         largest = 0.0_rp
         do k = 1, size(order)
            c = order(k)
            if (nint(records(3, c)) /= b) cycle
            r = records(4:6, c)
            rs = r - offset
            n = records(7:9, c)
            wall_velocity = records(12:14, c)
            un = dot_product(velocity_at() - wall_velocity, n)
            if (records(10, c) >= 0.0_rp) then
               target = -records(10, c) / dt
            else
               target = -overlap_recovery * records(10, c) / dt
            end if
            normal_impulse = dot_product(applied(:, c), n)
            change = max(0.0_rp, normal_impulse + (target - un) / effective_inverse_mass(n)) - normal_impulse
            if (change /= 0.0_rp) call apply(change * n, c)
            largest = max(largest, abs(change))
            if (records(11, c) == 0.0_rp) cycle
            ! friction: stop the sliding at the point, within mu times the normal impulse
            normal_impulse = normal_impulse + change
            tangential = applied(:, c) - normal_impulse * n
            u = velocity_at() - wall_velocity
            u = u - dot_product(u, n) * n
            speed = norm2(u)
            if (speed == 0.0_rp) cycle
            t = u / speed
            new_tangential = tangential - t * (speed / effective_inverse_mass(t))
            if (records(11, c) > 0.0_rp) then
               limit = records(11, c) * normal_impulse
               if (norm2(new_tangential) > limit) new_tangential = new_tangential * (limit / norm2(new_tangential))
            end if
            dj = new_tangential - tangential
            call apply(dj, c)
            largest = max(largest, norm2(dj))
         end do
         if (largest <= tolerance) exit
      end do

   contains

      !> The velocity of the body's particle at r after the step.
      function velocity_at() result(v)
         real(rp) :: v(3)
         v = body%velocity + cross(body%spin, r) + dv + cross(dw, rs)
      end function velocity_at

      !> 1 / (effective mass) of the cluster at rs along the unit vector t: 1/M + t . ((I^-1 (rs x t)) x rs).
      real(rp) function effective_inverse_mass(t)
         real(rp), intent(in) :: t(3)
         effective_inverse_mass = 1.0_rp / mass + dot_product(t, cross(matmul(inverse, cross(rs, t)), rs))
      end function effective_inverse_mass

      !> The impulse j at the point (c): dv += j / M, dw += I^-1 (rs x j).
      subroutine apply(j, c)
         real(rp), intent(in) :: j(3)
         integer, intent(in) :: c
         applied(:, c) = applied(:, c) + j
         dv = dv + j / mass
         dw = dw + matmul(inverse, cross(rs, j))
      end subroutine apply
   end subroutine resolve_contacts

   !> MUSL, after update_velocity_and_remap: the rigid particles take their body's velocity at x^n,
   !> V^{n+1} + w x (x_p - c^n) (APIC: C_p = [w]), and `momentum` (the re-map, rows 1:dim; with `field`,
   !> the particles' contact fields, also rows field(p) dim + 1..) the change of their momentum. Before
   !> finish.
   subroutine rigid_remap_correction(self, grid, particles, momentum, field)
      class(rigid_set_t), intent(in) :: self
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      real(rp), intent(inout) :: momentum(:, :)
      integer, intent(in), optional :: field(:)
      real(rp), allocatable :: change(:, :)
      real(rp) :: r(3), v(3), c(self%dim * self%dim)
      integer :: offsets(block_size), m, first, last, b0, e, n, q, p, b, d, rows
      d = self%dim
      rows = d
      if (particles%n_affine > 0) rows = d + d * d
      allocate (change(rows, block_size))
      do m = 1, size(self%rigid_material)
         if (.not. self%rigid_material(m)) cycle
         first = particles%material_first(m)
         last = particles%material_last(m)
         do b0 = first, last, block_size
            e = min(last, b0 + block_size - 1)
            n = e - b0 + 1
            offsets(1:n) = 0
            if (present(field)) offsets(1:n) = field(b0:e) * d
            do q = 1, n
               p = b0 + q - 1
               change(:, q) = 0.0_rp
               b = body_of(self, m, particles%id(p))
               if (b == 0) cycle
               r = 0.0_rp
               r(1:d) = particles%x(:, p) - self%bodies(b)%centre(1:d)
               v = self%bodies(b)%velocity + cross(self%bodies(b)%spin, r)
               change(1:d, q) = v(1:d) - particles%v(:, p)
               particles%v(:, p) = v(1:d)
               if (rows > d) then
                  c = spin_matrix(self%bodies(b)%spin, d)
                  change(d + 1:, q) = c - particles%affine(:, p)
                  particles%affine(:, p) = c
               end if
            end do
            call spread_to_grid(grid, particles, b0, e, change(:, 1:n), offsets(1:n), momentum)
         end do
      end do
   end subroutine rigid_remap_correction

   !> G2P of the rigid particles first:last (one material's): x_p = c^{n+1} + R^{n+1} (X_p - X_c),
   !> v_p = V^{n+1} + w^{n+1} x (x_p - c^{n+1}), APIC's C_p = [w^{n+1}]; lo, hi: their extent.
   subroutine rigid_move(self, tracked, grid, particles, first, last, lo, hi)
      class(rigid_set_t), intent(in) :: self
      type(body_motion_t), intent(in) :: tracked
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer, intent(in) :: first, last
      real(rp), intent(inout) :: lo(:), hi(:)
      real(rp) :: x(3), r(3), v(3)
      integer :: p, b, d
      d = self%dim
      do p = first, last
         b = body_of(self, particles%material(p), particles%id(p))
         if (b == 0) cycle
         associate (body => self%bodies(b))
            x = 0.0_rp
            x(1:d) = tracked%reference(body%tracked, particles%id(p) - body%first_id, grid%frame)
            r = matmul(body%next_rotation, x - body%reference_centre)
            if (d == 2) r(3) = 0.0_rp
            v = body%velocity + cross(body%next_spin, r)
            particles%x(:, p) = body%next_centre(1:d) + r(1:d)
            particles%v(:, p) = v(1:d)
            if (particles%n_affine > 0) particles%affine(:, p) = spin_matrix(body%next_spin, d)
            lo(1:d) = min(lo(1:d), particles%x(:, p))
            hi(1:d) = max(hi(1:d), particles%x(:, p))
         end associate
      end do
   end subroutine rigid_move

   !> True if material m's particles move as rigid bodies (move), not by G2P.
   pure logical function rigid_moves_material(self, m) result(moves)
      class(rigid_set_t), intent(in) :: self
      integer, intent(in) :: m
      moves = .false.
      if (self%active) moves = self%rigid_material(m)
   end function rigid_moves_material

   !> The end of the step: c := c^{n+1}, R := R^{n+1} (nothing without bodies).
   subroutine rigid_finish(self)
      class(rigid_set_t), intent(inout) :: self
      integer :: b
      do b = 1, size(self%bodies)
         self%bodies(b)%centre = self%bodies(b)%next_centre
         self%bodies(b)%rotation = self%bodies(b)%next_rotation
         self%bodies(b)%spin = self%bodies(b)%next_spin
      end do
   end subroutine rigid_finish

   !> The bodies' state for a checkpoint, rigid_state_width reals per body (mass, X_c, I_0, c, V, L, R).
   function rigid_state(self) result(values)
      class(rigid_set_t), intent(in) :: self
      real(rp), allocatable :: values(:)
      integer :: b
      allocate (values(0))
      do b = 1, size(self%bodies)
         associate (body => self%bodies(b))
            values = [values, body%mass, body%reference_centre, reshape(body%inertia, [9]), body%centre, body%velocity, &
                      body%angular_momentum, reshape(body%rotation, [9])]
         end associate
      end do
   end function rigid_state

   !> The state `state` wrote (a restart); the spin follows from L and R.
   subroutine rigid_set_state(self, values)
      class(rigid_set_t), intent(inout) :: self
      real(rp), intent(in) :: values(:)
      integer :: b, at
      at = 0
      do b = 1, size(self%bodies)
         associate (body => self%bodies(b))
            body%mass = values(at + 1)
            body%reference_centre = values(at + 2:at + 4)
            body%inertia = reshape(values(at + 5:at + 13), [3, 3])
            body%centre = values(at + 14:at + 16)
            body%velocity = values(at + 17:at + 19)
            body%angular_momentum = values(at + 20:at + 22)
            body%rotation = reshape(values(at + 23:at + 31), [3, 3])
            body%spin = matmul(inverse_inertia(body, body%rotation, self%dim), body%angular_momentum)
            at = at + rigid_state_width
         end associate
      end do
   end subroutine rigid_set_state

   !> The rigid body of material m holding the particle id, 0 if none.
   pure integer function body_of(self, m, id) result(b)
      type(rigid_set_t), intent(in) :: self
      integer, intent(in) :: m
      integer(i8), intent(in) :: id
      do b = 1, size(self%bodies)
         if (self%bodies(b)%material /= m) cycle
         if (id >= self%bodies(b)%first_id .and. id < self%bodies(b)%first_id + self%bodies(b)%id_count) return
      end do
      b = 0
   end function body_of

   !> I^-1 = R I_0^-1 R^T in the placement R (2-D: only the zz entry, 1 / I_zz, which R leaves alone).
   pure function inverse_inertia(body, rotation, dim) result(inverse)
      type(rigid_body_t), intent(in) :: body
      real(rp), intent(in) :: rotation(3, 3)
      integer, intent(in) :: dim
      real(rp) :: inverse(3, 3)
      inverse = 0.0_rp
      if (dim == 2) then
         if (body%inertia(3, 3) > 0.0_rp) inverse(3, 3) = 1.0_rp / body%inertia(3, 3)
      else
         inverse = matmul(rotation, matmul(inverse_3x3(body%inertia), transpose(rotation)))
      end if
   end function inverse_inertia

   !> I = R I_0 R^T in the placement R (2-D: only the zz entry matters).
   pure function inertia_of(body, rotation, dim) result(inertia)
      type(rigid_body_t), intent(in) :: body
      real(rp), intent(in) :: rotation(3, 3)
      integer, intent(in) :: dim
      real(rp) :: inertia(3, 3)
      inertia = 0.0_rp
      if (dim == 2) then
         inertia(3, 3) = body%inertia(3, 3)
      else
         inertia = matmul(rotation, matmul(body%inertia, transpose(rotation)))
      end if
   end function inertia_of

   !> [w] of dim x dim, column by column (APIC's C_p of a rigid rotation: v = w x r has gradient [w]).
   pure function spin_matrix(w, dim) result(c)
      real(rp), intent(in) :: w(3)
      integer, intent(in) :: dim
      real(rp) :: c(dim * dim)
      if (dim == 2) then
         c = [0.0_rp, w(3), -w(3), 0.0_rp]
      else
         c = [0.0_rp, w(3), -w(2), -w(3), 0.0_rp, w(1), w(2), -w(1), 0.0_rp]
      end if
   end function spin_matrix
end module rigid_bodies
