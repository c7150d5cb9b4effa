!> Contact between solid bodies by multiple velocity fields (docs/contact.md, docs/theory.md section 3.3;
!> Bardenhagen, Brackbill & Sulsky 2000 [B00]; Bardenhagen et al. 2001 [B01]).
!>
!> Every `&body` of a solid material named by some `&contact` group is a velocity field of its own
!> (fields 1..n, in &body order); everything else (fluids, other solids, inlet particles) is the common
!> field 0. A particle's field follows from its id (particle_seeding: body offset + lattice index; the id
!> ranges are body_motion's), recomputed every step, so restarts and rank counts give the same fields.
!> P2G adds each body field's mass, momentum, force and mass gradient in rows of grid%accumulated after
!> the totals (one ghost-node exchange for all). At a node:
!>   * common field present, or fewer than two body fields: every field moves with the centre of mass,
!>     v = P / M and v + dt F / M of the totals: the single-field result [Y17];
!>   * otherwise resolve_node_contact: fields that no &contact pair joins stick together (clusters);
!>     two clusters meet along one common normal, the outward normal g / |g| of the one with the larger
!>     |g|, g = sum_p m_p grad N_i(x_p) (minus the gradient of the nodal mass: it points out of the body);
!>     approaching ones lose
!>     the normal part of v - v_cm and up to mu times it of the tangential part [B00] eq. 19-22, [B01].
!> Each particle then reads its own field (grid_transfer's multi-field kernels). Without &contact nothing
!> here runs and the step is the single-field one, bit for bit.
!> A `&contact` of a material and a `&structure` makes the structure act on that material's body fields
!> as a friction surface with the pair's mu (its own condition still holds for the other fields), and
!> the loads keep each body field's share of every wall's impulse (`field_impulse`, loads.csv's
!> `<structure>_by_<body>` columns).
module body_contact
   use kinds, only: rp, i8, name_len
   use scene_description, only: scene_t
   use background_grid, only: grid_t, row_mass
   use particle_set, only: particle_set_t
   use constraint_list, only: constraint_list_t
   use body_motion, only: body_motion_t
   implicit none
   private

   public :: contact_field_rows, resolve_node_contact, contact_body_names


   type, public :: contact_t
      logical :: active = .false.                    !< the scene has body fields (some &contact applies)
      integer :: dim = 2
      integer :: fields = 0                          !< body fields n (field 0, the common one, not counted)
      integer :: stride = 0                          !< rows per body field in grid%accumulated: 1 + 3 dim
      integer :: field_row = 0                       !< row of field 1's mass in grid%accumulated
      integer(i8), allocatable :: first_id(:), end_id(:)  !< field f holds the ids first_id(f) <= id < end_id(f)
      logical, allocatable :: contact_material(:)    !< (material) its bodies are body fields
      !> (field, field): the Coulomb coefficient of the pair's &contact, -1 where none: they stick
      real(rp), allocatable :: friction(:, :)
      integer :: structures = 0                      !< the scene's &structure groups
      !> (structure, field): the Coulomb coefficient of the &contact of the field's material and the
      !> structure, -1 where none: the structure's own condition
      real(rp), allocatable :: structure_friction(:, :)
      integer, allocatable :: particle_field(:)      !< field of each particle this step (0: common)
      !> (dim (n + 1), node), field f in rows f dim + 1..: v^{n+1} (walls applied) and dv = v^{n+1} - v^n
      real(rp), allocatable :: velocity(:, :), increment(:, :)
      real(rp), allocatable :: remapped(:, :)        !< MUSL: re-mapped momentum, then velocity, same rows
      logical, allocatable :: separate(:)            !< (node) the fields keep velocities of their own this step
      real(rp), allocatable :: common_mass(:)        !< (node) mass of field 0: total - body fields [kg]
   contains
      procedure :: init => contact_init
      procedure :: assign_fields => contact_assign_fields
      procedure :: size_nodes => contact_size_nodes
      procedure :: nodal_velocities => contact_nodal_velocities
      procedure :: apply_walls => contact_apply_walls
      procedure :: remapped_velocities => contact_remapped_velocities
      procedure :: wall_friction => contact_wall_friction
   end type contact_t

contains

   !> True if material m is named by some &contact group.
   pure logical function in_contact(scene, m)
      type(scene_t), intent(in) :: scene
      integer, intent(in) :: m
      integer :: c
      in_contact = .false.
      if (.not. allocated(scene%contacts)) return
      do c = 1, size(scene%contacts)
         if (any(scene%contacts(c)%material_index == m)) in_contact = .true.
      end do
   end function in_contact

   !> Rows the body fields of `scene` add to grid%accumulated (0 without &contact): 1 + 3 dim per body of
   !> a material some &contact names (such materials are solids, scene_validation).
   pure integer function contact_field_rows(scene) result(rows)
      type(scene_t), intent(in) :: scene
      integer :: b
      rows = 0
      if (.not. allocated(scene%bodies)) return
      do b = 1, size(scene%bodies)
         if (in_contact(scene, scene%bodies(b)%material_index)) rows = rows + 1 + 3 * scene%grid%dim
      end do
   end function contact_field_rows

   !> The names of the bodies that are body fields (in field order): the bodies of a material some
   !> &contact names (all solid, so all tracked by body_motion in the same order).
   function contact_body_names(scene) result(names)
      type(scene_t), intent(in) :: scene
      character(len=name_len), allocatable :: names(:)
      integer :: b
      allocate (names(0))
      if (.not. allocated(scene%bodies)) return
      do b = 1, size(scene%bodies)
         if (in_contact(scene, scene%bodies(b)%material_index)) names = [names, scene%bodies(b)%name]
      end do
   end function contact_body_names

   !> The body fields of the scene: the tracked (solid) bodies of a material in some &contact, their id
   !> ranges, the friction of every pair of fields and of every structure and field.
   subroutine contact_init(self, scene, bodies, n_materials)
      class(contact_t), intent(inout) :: self
      type(scene_t), intent(in) :: scene
      type(body_motion_t), intent(in) :: bodies
      integer, intent(in) :: n_materials
      integer :: b, f, g, c, m(2), n
      integer, allocatable :: material(:)

      self%dim = scene%grid%dim
      self%stride = 1 + 3 * self%dim
      self%field_row = 2 + 2 * self%dim
      allocate (self%contact_material(n_materials))
      do b = 1, n_materials
         self%contact_material(b) = in_contact(scene, b)
      end do
      n = 0
      do b = 1, bodies%count()
         if (self%contact_material(bodies%bodies(b)%material)) n = n + 1
      end do
      self%fields = n
      self%active = n > 0
      allocate (self%first_id(n), self%end_id(n), material(n), self%friction(n, n), self%particle_field(0))
      n = 0
      do b = 1, bodies%count()
         associate (body => bodies%bodies(b))
            if (.not. self%contact_material(body%material)) cycle
            n = n + 1
            self%first_id(n) = body%first_id
            self%end_id(n) = body%first_id + body%id_count
            material(n) = body%material
         end associate
      end do
      self%friction = -1.0_rp
      do f = 1, n
         do g = 1, n
            do c = 1, size(scene%contacts)
               m = scene%contacts(c)%material_index
               if ((m(1) == material(f) .and. m(2) == material(g)) .or. (m(2) == material(f) .and. m(1) == material(g))) &
                  self%friction(f, g) = scene%contacts(c)%friction
            end do
         end do
      end do
      self%structures = 0
      if (allocated(scene%structures)) self%structures = size(scene%structures)
      allocate (self%structure_friction(self%structures, n))
      self%structure_friction = -1.0_rp
      do f = 1, n
         do c = 1, size(scene%contacts)
            associate (contact => scene%contacts(c))
               do g = 1, 2
                  if (contact%material_index(g) == material(f) .and. contact%structure_index(3 - g) > 0) &
                     self%structure_friction(contact%structure_index(3 - g), f) = contact%friction
               end do
            end associate
         end do
      end do
   end subroutine contact_init

   !> (constraint, field) the mu constraint w applies to body field f instead of its condition, -1 where
   !> none; structure(w) is constraint w's &structure number, 0 if it is not one (constraint_list).
   pure function contact_wall_friction(self, structure) result(friction)
      class(contact_t), intent(in) :: self
      integer, intent(in) :: structure(:)
      real(rp) :: friction(size(structure), self%fields)
      integer :: w
      friction = -1.0_rp
      do w = 1, size(structure)
         if (structure(w) > 0) friction(w, :) = self%structure_friction(structure(w), :)
      end do
   end function contact_wall_friction

   !> particle_field(p) for this step's particles: the body field whose id range holds the id (a binary
   !> search over the ascending ranges), 0 for every particle of a material in no &contact.
   subroutine contact_assign_fields(self, particles)
      class(contact_t), intent(inout) :: self
      type(particle_set_t), intent(in) :: particles
      integer :: p, lo, hi, mid
      integer(i8) :: id
      if (size(self%particle_field) < particles%count) then
         deallocate (self%particle_field)
         allocate (self%particle_field(size(particles%mass)))
      end if
      do p = 1, particles%count
         self%particle_field(p) = 0
         if (.not. self%contact_material(particles%material(p))) cycle
         id = particles%id(p)
         lo = 1
         hi = self%fields
         do while (lo < hi)
            mid = (lo + hi + 1) / 2
            if (self%first_id(mid) <= id) then
               lo = mid
            else
               hi = mid - 1
            end if
         end do
         if (id >= self%first_id(lo) .and. id < self%end_id(lo)) self%particle_field(p) = lo
      end do
   end subroutine contact_assign_fields

   !> Node arrays of the fields for the grid's nodes (after every new layout).
   subroutine contact_size_nodes(self, grid, musl)
      class(contact_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      logical, intent(in) :: musl
      integer :: rows
      if (allocated(self%velocity)) deallocate (self%velocity, self%increment, self%common_mass, self%separate)
      if (allocated(self%remapped)) deallocate (self%remapped)
      rows = self%dim * (self%fields + 1)
      allocate (self%velocity(rows, grid%node_count), self%increment(rows, grid%node_count), &
                self%common_mass(grid%node_count), self%separate(grid%node_count))
      if (musl) allocate (self%remapped(rows, grid%node_count))
   end subroutine contact_size_nodes

   !> Step 2 with fields: v^{n+1} of every field into `velocity` and v^n into `increment` (the walls and
   !> dv = v^{n+1} - v^n follow in apply_walls), and the common field's mass. Nodes lighter than
   !> `tolerance` carry no velocity; a body field lighter than it at a node moves with the centre of mass.
   subroutine contact_nodal_velocities(self, grid, dt, tolerance)
      class(contact_t), intent(inout) :: self
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: dt, tolerance
      integer :: i, f, j, k, o, row, dim, mom, frc, clusters
      integer :: found(self%fields)
      real(rp) :: m, rest, vn(grid%dim), v(grid%dim)
      real(rp) :: fm(self%fields), fv(grid%dim, self%fields), fvn(grid%dim, self%fields), fg(grid%dim, self%fields)
      logical :: stuck

      dim = grid%dim
      mom = grid%row_momentum
      frc = grid%row_force
      associate (acc => grid%accumulated)
         do i = 1, grid%node_count
            m = acc(row_mass, i)
            if (.not. m > tolerance) then
               self%velocity(:, i) = 0.0_rp
               self%increment(:, i) = 0.0_rp
               self%common_mass(i) = 0.0_rp
               self%separate(i) = .false.
               cycle
            end if
            ! the single-field arithmetic of mpm_solver's update_nodes, for the centre of mass
            vn = acc(mom:mom + dim - 1, i) / m
            v = vn + dt * acc(frc:frc + dim - 1, i) / m
            k = 0
            rest = m
            do f = 1, self%fields
               row = self%field_row + (f - 1) * self%stride
               rest = rest - acc(row, i)
               if (acc(row, i) > tolerance) then
                  k = k + 1
                  found(k) = f
               end if
            end do
            self%common_mass(i) = rest
            stuck = k < 2 .or. rest > tolerance
            if (.not. stuck) then
               do j = 1, k
                  row = self%field_row + (found(j) - 1) * self%stride
                  fm(j) = acc(row, i)
                  fvn(:, j) = acc(row + 1:row + dim, i) / fm(j)
                  fv(:, j) = fvn(:, j) + dt * acc(row + dim + 1:row + 2 * dim, i) / fm(j)
                  fg(:, j) = acc(row + 2 * dim + 1:row + 3 * dim, i)
               end do
               call resolve_node_contact(fm(1:k), fv(:, 1:k), fg(:, 1:k), self%friction(found(1:k), found(1:k)), &
                                         clusters, fvn(:, 1:k))
               stuck = clusters < 2
            end if
            do f = 0, self%fields
               self%velocity(f * dim + 1:f * dim + dim, i) = v
               self%increment(f * dim + 1:f * dim + dim, i) = vn
            end do
            self%separate(i) = .not. stuck
            if (stuck) cycle
            do j = 1, k
               o = found(j) * dim
               self%velocity(o + 1:o + dim, i) = fv(:, j)
               self%increment(o + 1:o + dim, i) = fvn(:, j)
            end do
         end do
      end associate
   end subroutine contact_nodal_velocities

   !> The walls on every field's v^{n+1}, each with its own mass (the impulses add up to the wall's load,
   !> algorithms.md section 9.1), a structure with a &contact to a body field's material as a friction
   !> surface with that mu, then dv = v^{n+1} - v^n. field_impulse(:, w, f) gains body field f's share of
   !> impulse(:, w).
   subroutine contact_apply_walls(self, constraints, grid, impulse, field_impulse)
      class(contact_t), intent(inout) :: self
      type(constraint_list_t), intent(in) :: constraints
      type(grid_t), intent(in) :: grid
      real(rp), intent(inout) :: impulse(:, :)
      real(rp), intent(inout) :: field_impulse(:, :, :)
      real(rp) :: friction(constraints%count(), self%fields), share(size(impulse, 1), size(impulse, 2))
      integer :: f, o, dim, n
      dim = self%dim
      friction = self%wall_friction(constraints%structure)
      call constraints%constrain(dim, self%velocity(1:dim, :), self%common_mass, impulse)
      do f = 1, self%fields
         o = f * dim
         share = 0.0_rp
         call constraints%constrain(dim, self%velocity(o + 1:o + dim, :), &
                                    grid%accumulated(self%field_row + (f - 1) * self%stride, :), share, friction(:, f))
         ! the sensors' columns after the constraints' take the body fields' part too (a panel under debris)
         impulse = impulse + share
         n = constraints%count()
         field_impulse(:, :, f) = field_impulse(:, :, f) + share(:, 1:n)
      end do
      self%increment = self%velocity - self%increment
   end subroutine contact_apply_walls

   !> MUSL with fields: `remapped` holds the re-mapped momentum (rows 1:dim the total, rows f dim + 1.. body
   !> field f's, ghost nodes summed); it becomes each field's velocity, p_f / m_f where the fields kept
   !> velocities of their own in this step's contact (`separate`), the centre of mass elsewhere, then the
   !> walls. Contact is not resolved again here: these velocities only give the rate of deformation, and
   !> taking the approach out of them (but not out of the particles' momentum) lets the stress see a
   !> compression the bodies' motion never made. A stiff or slow impact then gained kinetic energy
   !> (E = 1e8 Pa: +65 %; docs/contact.md, "Energy in stiff impacts") [R].
   subroutine contact_remapped_velocities(self, constraints, grid, tolerance)
      class(contact_t), intent(inout) :: self
      type(constraint_list_t), intent(in) :: constraints
      type(grid_t), intent(in) :: grid
      real(rp), intent(in) :: tolerance
      integer :: i, f, o, row, dim
      real(rp) :: m, v(grid%dim)
      real(rp) :: friction(constraints%count(), self%fields)

      dim = grid%dim
      associate (acc => grid%accumulated, r => self%remapped)
         do i = 1, grid%node_count
            m = acc(row_mass, i)
            if (.not. m > tolerance) then
               r(:, i) = 0.0_rp
               cycle
            end if
            v = r(1:dim, i) / m
            do f = 1, self%fields
               o = f * dim
               row = self%field_row + (f - 1) * self%stride
               if (self%separate(i) .and. acc(row, i) > tolerance) then
                  r(o + 1:o + dim, i) = r(o + 1:o + dim, i) / acc(row, i)
               else
                  r(o + 1:o + dim, i) = v
               end if
            end do
            r(1:dim, i) = v
         end do
      end associate
      call constraints%constrain(dim, self%remapped(1:dim, :))
      friction = self%wall_friction(constraints%structure)
      do f = 1, self%fields
         o = f * dim
         call constraints%constrain(dim, self%remapped(o + 1:o + dim, :), friction=friction(:, f))
      end do
   end subroutine contact_remapped_velocities

   !> Contact at one node among k >= 2 body fields with mass there ([B00] section 4, [B01]; docs/contact.md):
   !>   1. fields whose pair has no &contact (friction < 0) stick: they form one cluster (transitively);
   !>      one cluster: clusters = 1 and nothing changes (the caller gives every field the centre of mass);
   !>   2. per cluster c: mass m_c, velocity v_c = sum m v / m_c, g_c = sum_p m_p grad N_i(x_p) (= -grad m_c: it
   !>      points out of the cluster's bodies); v_cm = sum m_c v_c / sum m_c;
   !>   3. outward normals: two clusters a, b one common normal n_a = -n_b (momentum is then conserved to
   !>      round-off): n_a = g_a / |g_a| if |g_a| >= |g_b|, else -g_b / |g_b|, the normal of the flatter face
   !>      (Nairn's "larger gradient" choice) [R]. The difference g_a - g_b tilts at a corner sitting on a
   !>      face, and a blend of the two unit normals by |g|**p (continuous in g) takes in the noise of the
   !>      moving body's normal: a block sliding on another then brakes by 6 % (difference) or 3.5 % (blend,
   !>      p = 8 or 32) of mu g too much, against 0.8 % (docs/contact.md). Three or more clusters: each its
   !>      own n_c = g_c / |g_c| [B00] eq. 19;
   !>   4. a cluster approaching the others, delta = (v_c - v_cm) . n_c > 0, loses delta n_c and the
   !>      tangential part t of v_c - v_cm by min(mu delta, |t|) (Coulomb, never reversing the slip) [B01];
   !>      separating clusters keep their velocities; mu is the largest of the pairs between c and the others;
   !>   5. three or more clusters: the own normals do not balance, so the net change of momentum is taken
   !>      back from all clusters alike (a common velocity shift) [R].
   !> `velocity` (dim, k): v^{n+1} of each field on entry, after contact on return (cluster members share
   !> it). `old_velocity` (v^n), if present, becomes the cluster's v^n for members of a cluster of several.
   !> An undefined normal (both g zero) makes them stick (clusters = 1).
   pure subroutine resolve_node_contact(mass, velocity, gradient, friction, clusters, old_velocity)
      real(rp), intent(in) :: mass(:)              !< (k) field masses at the node, > 0 [kg]
      real(rp), intent(inout) :: velocity(:, :)    !< (dim, k) [m/s]
      real(rp), intent(in) :: gradient(:, :)       !< (dim, k) sum_p m_p grad N_i(x_p) of each field (outward) [kg/m]
      real(rp), intent(in) :: friction(:, :)       !< (k, k) mu of each pair; < 0: no contact, they stick
      integer, intent(out) :: clusters
      real(rp), intent(inout), optional :: old_velocity(:, :)
      integer :: k, dim, i, j, c, old, new
      integer :: label(size(mass)), cluster_of(size(mass))
      real(rp) :: cm(size(mass)), cp(size(velocity, 1), size(mass)), cg(size(velocity, 1), size(mass))
      real(rp) :: cpn(size(velocity, 1), size(mass)), normal(size(velocity, 1), size(mass)), mu(size(mass))
      real(rp) :: dv(size(velocity, 1), size(mass)), v_cm(size(velocity, 1)), rel(size(velocity, 1))
      real(rp) :: tangential(size(velocity, 1)), shift(size(velocity, 1)), total, length, approach, slip

      k = size(mass)
      dim = size(velocity, 1)
      ! 1. clusters: label(i) is a representative r with label(r) = r
      label = [(i, i=1, k)]
      do i = 1, k
         do j = i + 1, k
            if (friction(i, j) >= 0.0_rp .or. label(i) == label(j)) cycle
            old = label(j)
            new = label(i)
            where (label == old) label = new
         end do
      end do
      clusters = 0
      do i = 1, k
         if (label(i) == i) then
            clusters = clusters + 1
            where (label == i) cluster_of = clusters
         end if
      end do
      if (clusters < 2) return

      ! 2. cluster sums
      cm = 0.0_rp
      cp = 0.0_rp
      cg = 0.0_rp
      cpn = 0.0_rp
      do i = 1, k
         c = cluster_of(i)
         cm(c) = cm(c) + mass(i)
         cp(:, c) = cp(:, c) + mass(i) * velocity(:, i)
         cg(:, c) = cg(:, c) + gradient(:, i)
         if (present(old_velocity)) cpn(:, c) = cpn(:, c) + mass(i) * old_velocity(:, i)
      end do
      total = sum(cm(1:clusters))
      v_cm = sum(cp(:, 1:clusters), dim=2) / total
      mu = 0.0_rp
      do i = 1, k
         do j = 1, k
            if (cluster_of(i) == cluster_of(j)) cycle
            mu(cluster_of(i)) = max(mu(cluster_of(i)), friction(i, j))
         end do
      end do

      ! 3. normals
      normal = 0.0_rp
      if (clusters == 2) then
         if (norm2(cg(:, 1)) >= norm2(cg(:, 2))) then
            normal(:, 1) = cg(:, 1)
         else
            normal(:, 1) = -cg(:, 2)
         end if
         length = norm2(normal(:, 1))
         if (.not. length > 0.0_rp) then
            clusters = 1
            return
         end if
         normal(:, 1) = normal(:, 1) / length
         normal(:, 2) = -normal(:, 1)
      else
         do c = 1, clusters
            length = norm2(cg(:, c))
            if (length > 0.0_rp) normal(:, c) = cg(:, c) / length
         end do
      end if

      ! 4. approaching clusters: normal part removed, tangential part reduced by Coulomb friction
      dv = 0.0_rp
      do c = 1, clusters
         rel = cp(:, c) / cm(c) - v_cm
         approach = dot_product(rel, normal(:, c))
         if (.not. approach > 0.0_rp) cycle
         tangential = rel - approach * normal(:, c)
         slip = norm2(tangential)
         dv(:, c) = -approach * normal(:, c)
         if (slip > 0.0_rp) dv(:, c) = dv(:, c) - min(mu(c) * approach, slip) / slip * tangential
      end do
      ! 5. three or more: the net change of momentum back from all alike
      if (clusters > 2) then
         shift = 0.0_rp
         do c = 1, clusters
            shift = shift + cm(c) * dv(:, c)
         end do
         shift = shift / total
         do c = 1, clusters
            dv(:, c) = dv(:, c) - shift
         end do
      end if

      do i = 1, k
         c = cluster_of(i)
         velocity(:, i) = cp(:, c) / cm(c) + dv(:, c)
         if (present(old_velocity)) old_velocity(:, i) = cpn(:, c) / cm(c)
      end do
   end subroutine resolve_node_contact
end module body_contact
