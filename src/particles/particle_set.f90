!> The material points a rank owns, as a structure of arrays (style.md, lesson 5).
!>
!> Persistent state: position, velocity, mass, density, mass-specific stress sbar = sigma / rho
!> (algorithms.md section 1), material, global id, and with APIC (`&run transfer = 'apic'`) the affine
!> matrix C_p (docs/theory.md, "APIC"; not allocated otherwise: n_affine = 0). Scratch per step: the (filtered) rate of deformation
!> and the spin. After `sort_by_material_and_cell` the particles of material m occupy the contiguous
!> range material_first(m):material_last(m), ordered by cell, so material updates and cell sums run
!> over contiguous slices. The sort permutes the arrays in place (no second copy of the set); the
!> arrays grow by an eighth when full (docs/performance.md, "Memory per particle").
!>
!> Growing the arrays can fail for want of memory: `allocation` then fails (the first failure wins),
!> the set keeps the particles it had (an `add` that finds no room drops its particle), and the caller
!> stops the run with that message (solver_t%check_particle_memory) instead of a runtime error.
module particle_set
   use kinds, only: rp, i8
   use error_status, only: status_t
   use memory_budget, only: byte_text
   use input_text, only: int_text
   use tensor_layout, only: n_components, n_spin
   implicit none
   private

   type, public :: particle_set_t
      integer :: dim = 2, n_sigma = 4, n_materials = 1
      integer :: n_spin = 1                         !< spin components, 0 when no model reads the spin
      integer :: n_rate = 4                         !< rows of strain_rate: n_sigma, or 0 when not stored
      integer :: n_affine = 0                       !< dim**2 with APIC, else 0
      integer :: count = 0                          !< particles held
      real(rp), allocatable :: x(:, :)              !< position (dim, p), grid frame [m]
      real(rp), allocatable :: v(:, :)              !< velocity (dim, p) [m/s]
      real(rp), allocatable :: mass(:)              !< mass [kg] (per unit thickness in 2-D)
      real(rp), allocatable :: density(:)           !< current density [kg/m^3]
      real(rp), allocatable :: sbar(:, :)           !< mass-specific stress (n_sigma, p) [Pa m^3/kg]
      !> APIC's C_p = sum_i v_i (x) grad N_ip = B_p D_p^-1, column-major (n_affine, p) [1/s]
      real(rp), allocatable :: affine(:, :)
      integer, allocatable :: material(:)           !< material index
      integer(i8), allocatable :: id(:)             !< globally unique id
      integer, allocatable :: cell(:)               !< local cell index at x^n (set by the sort)
      !> d_p, replaced by d~_p when filtered (n_rate, p): kept only when a scheme filters it
      real(rp), allocatable :: strain_rate(:, :)
      real(rp), allocatable :: spin(:, :)           !< w_p components (n_spin, p)
      integer, allocatable :: material_first(:), material_last(:)
      type(status_t) :: allocation                  !< failed if the arrays could not grow
   contains
      procedure :: init => particles_init
      procedure :: reserve => particles_reserve
      procedure :: fit => particles_fit
      procedure :: permute => particles_permute
      procedure :: record_size => particles_record_size
      procedure :: pack_record => particles_pack_record
      procedure :: append_record => particles_append_record
      procedure :: add => particles_add
      procedure :: copy_particle => particles_copy_particle
      procedure :: volume => particles_volume
   end type particle_set_t

contains

   !> An empty set; `affine` (default .false.): carry APIC's affine matrix per particle; `spin` and
   !> `strain_rate` (default .true.): hold the spin and the rate of deformation between the steps'
   !> stages (only a scheme that filters the rate, and a model with uses_spin behind one, need them: the
   !> solver's fused stage keeps both in a block buffer otherwise).
   subroutine particles_init(self, dim, n_materials, capacity, affine, spin, strain_rate)
      class(particle_set_t), intent(inout) :: self
      integer, intent(in) :: dim, n_materials, capacity
      logical, intent(in), optional :: affine, spin, strain_rate
      self%dim = dim
      self%n_sigma = n_components(dim)
      self%n_spin = n_spin(dim)
      if (present(spin)) then
         if (.not. spin) self%n_spin = 0
      end if
      self%n_rate = self%n_sigma
      if (present(strain_rate)) then
         if (.not. strain_rate) self%n_rate = 0
      end if
      self%n_affine = 0
      if (present(affine)) then
         if (affine) self%n_affine = dim * dim
      end if
      self%n_materials = n_materials
      self%count = 0
      call self%allocation%reset()
      if (allocated(self%x)) call free_arrays(self)
      if (allocated(self%material_first)) deallocate (self%material_first, self%material_last)
      call allocate_arrays(self, max(capacity, 16))
      allocate (self%material_first(n_materials), self%material_last(n_materials))
      self%material_first = 1
      self%material_last = 0
   end subroutine particles_init

   subroutine allocate_arrays(self, capacity)
      type(particle_set_t), intent(inout) :: self
      integer, intent(in) :: capacity
      integer :: stat
      allocate (self%x(self%dim, capacity), self%v(self%dim, capacity), self%mass(capacity), &
                self%density(capacity), self%sbar(self%n_sigma, capacity), self%material(capacity), &
                self%id(capacity), self%cell(capacity), self%strain_rate(self%n_rate, capacity), &
                self%spin(self%n_spin, capacity), self%affine(self%n_affine, capacity), stat=stat)
      if (stat == 0) return
      call no_memory(self, capacity)
      ! an empty set, so that the caller can still report and stop
      call free_arrays(self)
      allocate (self%x(self%dim, 0), self%v(self%dim, 0), self%mass(0), self%density(0), self%sbar(self%n_sigma, 0), &
                self%material(0), self%id(0), self%cell(0), self%strain_rate(self%n_rate, 0), self%spin(self%n_spin, 0), &
                self%affine(self%n_affine, 0))
   end subroutine allocate_arrays

   !> Record that room for `capacity` particles could not be allocated.
   subroutine no_memory(self, capacity)
      type(particle_set_t), intent(inout) :: self
      integer, intent(in) :: capacity
      call self%allocation%fail('no memory for '//int_text(capacity)//' particles ('//byte_text(int(capacity, i8) * &
                                particle_bytes(self))//' for the particle arrays); use more ranks or nodes, or fewer '// &
                                'particles per cell')
   end subroutine no_memory

   !> Bytes of the particle arrays per particle.
   pure integer(i8) function particle_bytes(self)
      type(particle_set_t), intent(in) :: self
      particle_bytes = 8_i8 * (2 * self%dim + 2 + self%n_sigma + self%n_rate + self%n_spin + self%n_affine + 1) + 4_i8 * 2
   end function particle_bytes

   subroutine free_arrays(self)
      type(particle_set_t), intent(inout) :: self
      ! each on its own: a failed allocate may have left some of them unallocated
      if (allocated(self%x)) deallocate (self%x)
      if (allocated(self%v)) deallocate (self%v)
      if (allocated(self%mass)) deallocate (self%mass)
      if (allocated(self%density)) deallocate (self%density)
      if (allocated(self%sbar)) deallocate (self%sbar)
      if (allocated(self%material)) deallocate (self%material)
      if (allocated(self%id)) deallocate (self%id)
      if (allocated(self%cell)) deallocate (self%cell)
      if (allocated(self%strain_rate)) deallocate (self%strain_rate)
      if (allocated(self%spin)) deallocate (self%spin)
      if (allocated(self%affine)) deallocate (self%affine)
   end subroutine free_arrays

   !> Make room for at least `capacity` particles, keeping the first `count`. Growing takes an eighth
   !> more than asked: repeated small growths (arrivals every step, an inlet's particles) then copy
   !> the set only now and then, and the slack stays small (pages never written are not resident).
   subroutine particles_reserve(self, capacity)
      class(particle_set_t), intent(inout) :: self
      integer, intent(in) :: capacity
      if (capacity <= size(self%mass)) return
      call resize(self, max(capacity, size(self%mass) + size(self%mass) / 8))
   end subroutine particles_reserve

   !> Let the arrays hold just the particles held (after removals: the structures' displaced fluid).
   subroutine particles_fit(self)
      class(particle_set_t), intent(inout) :: self
      if (size(self%mass) > max(self%count, 16)) call resize(self, max(self%count, 16))
   end subroutine particles_fit

   !> Arrays of `capacity` slots holding the first `count` particles. The scratch arrays (rate of
   !> deformation, spin) are not carried: they are rebuilt every step. Without memory for a new array
   !> the set is left as it was before that array (arrays already moved stay moved: the contents are
   !> then inconsistent, and the run stops at the end of the step).
   subroutine resize(self, capacity)
      type(particle_set_t), intent(inout) :: self
      integer, intent(in) :: capacity
      logical :: ok
      integer :: stat, n
      n = min(self%count, capacity)
      ok = resize_real2(self%x, n, capacity)
      if (ok) ok = resize_real2(self%v, n, capacity)
      if (ok) ok = resize_real1(self%mass, n, capacity)
      if (ok) ok = resize_real1(self%density, n, capacity)
      if (ok) ok = resize_real2(self%sbar, n, capacity)
      if (ok) ok = resize_real2(self%affine, n, capacity)
      if (ok) ok = resize_int1(self%material, n, capacity)
      if (ok) ok = resize_int1(self%cell, n, capacity)
      if (ok) ok = resize_i8(self%id, n, capacity)
      if (ok .and. capacity /= size(self%strain_rate, 2)) then
         deallocate (self%strain_rate, self%spin)
         allocate (self%strain_rate(self%n_rate, capacity), self%spin(self%n_spin, capacity), stat=stat)
         if (stat /= 0) then
            if (allocated(self%strain_rate)) deallocate (self%strain_rate)
            if (allocated(self%spin)) deallocate (self%spin)
            allocate (self%strain_rate(self%n_rate, 0), self%spin(self%n_spin, 0))
            ok = .false.
         end if
      end if
      if (.not. ok) call no_memory(self, capacity)
   end subroutine resize

   !> Move particle p to slot dest(p) (a permutation of 1..count), in place: each cycle of the
   !> permutation is followed carrying one particle, so the sort needs no second copy of the set (which
   !> would double the particle memory at every sort). dest is marked while the cycles are followed
   !> (negative: done) and restored on return. The scratch arrays are not carried.
   subroutine particles_permute(self, dest)
      class(particle_set_t), intent(inout) :: self
      integer, intent(inout) :: dest(:)
      real(rp) :: x(3), v(3), sbar(6), affine(9), mass, density
      integer :: start, p, q, d, s, a, material, cell
      integer(i8) :: id
      d = self%dim
      s = self%n_sigma
      a = self%n_affine
      do start = 1, size(dest)
         if (dest(start) <= 0 .or. dest(start) == start) cycle
         ! carry particle `start` to its slot, pick up the one there, and so on round the cycle
         x(1:d) = self%x(:, start)
         v(1:d) = self%v(:, start)
         mass = self%mass(start)
         density = self%density(start)
         sbar(1:s) = self%sbar(:, start)
         affine(1:a) = self%affine(:, start)
         material = self%material(start)
         cell = self%cell(start)
         id = self%id(start)
         p = start
         do
            q = dest(p)
            dest(p) = -q
            call swap_real(self%x(:, q), x(1:d))
            call swap_real(self%v(:, q), v(1:d))
            call swap_real(self%mass(q), mass)
            call swap_real(self%density(q), density)
            call swap_real(self%sbar(:, q), sbar(1:s))
            call swap_real(self%affine(:, q), affine(1:a))
            call swap_int(self%material(q), material)
            call swap_int(self%cell(q), cell)
            call swap_i8(self%id(q), id)
            if (q == start) exit
            p = q
         end do
      end do
      dest = abs(dest)
   end subroutine particles_permute

   !> Elemental: one particle's scalar field or, element by element, its columns.
   elemental subroutine swap_real(slot, held)
      real(rp), intent(inout) :: slot, held
      real(rp) :: t
      t = slot
      slot = held
      held = t
   end subroutine swap_real

   pure subroutine swap_int(slot, held)
      integer, intent(inout) :: slot, held
      integer :: t
      t = slot
      slot = held
      held = t
   end subroutine swap_int

   pure subroutine swap_i8(slot, held)
      integer(i8), intent(inout) :: slot, held
      integer(i8) :: t
      t = slot
      slot = held
      held = t
   end subroutine swap_i8

   ! One routine per array type (Fortran has no generics over types): b(:n) = a(:n) in a new array of
   ! `capacity` slots; false (a unchanged) without memory for b.
   logical function resize_real2(a, n, capacity) result(ok)
      real(rp), allocatable, intent(inout) :: a(:, :)
      integer, intent(in) :: n, capacity
      real(rp), allocatable :: b(:, :)
      integer :: stat
      allocate (b(size(a, 1), capacity), stat=stat)
      ok = stat == 0
      if (.not. ok) return
      b(:, 1:n) = a(:, 1:n)
      call move_alloc(b, a)
   end function resize_real2

   logical function resize_real1(a, n, capacity) result(ok)
      real(rp), allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n, capacity
      real(rp), allocatable :: b(:)
      integer :: stat
      allocate (b(capacity), stat=stat)
      ok = stat == 0
      if (.not. ok) return
      b(1:n) = a(1:n)
      call move_alloc(b, a)
   end function resize_real1

   logical function resize_int1(a, n, capacity) result(ok)
      integer, allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n, capacity
      integer, allocatable :: b(:)
      integer :: stat
      allocate (b(capacity), stat=stat)
      ok = stat == 0
      if (.not. ok) return
      b(1:n) = a(1:n)
      call move_alloc(b, a)
   end function resize_int1

   logical function resize_i8(a, n, capacity) result(ok)
      integer(i8), allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n, capacity
      integer(i8), allocatable :: b(:)
      integer :: stat
      allocate (b(capacity), stat=stat)
      ok = stat == 0
      if (.not. ok) return
      b(1:n) = a(1:n)
      call move_alloc(b, a)
   end function resize_i8

   !> Reals needed to carry one particle's persistent state between ranks.
   pure integer function particles_record_size(self)
      class(particle_set_t), intent(in) :: self
      particles_record_size = 2 * self%dim + 2 + self%n_sigma + 2 + self%n_affine
   end function particles_record_size

   !> Persistent state of particle p as reals (ids travel bit-for-bit through transfer()).
   pure subroutine particles_pack_record(self, p, record)
      class(particle_set_t), intent(in) :: self
      integer, intent(in) :: p
      real(rp), intent(out) :: record(:)
      integer :: d, s
      d = self%dim
      s = self%n_sigma
      record(1:d) = self%x(:, p)
      record(d + 1:2 * d) = self%v(:, p)
      record(2 * d + 1) = self%mass(p)
      record(2 * d + 2) = self%density(p)
      record(2 * d + 3:2 * d + 2 + s) = self%sbar(:, p)
      record(2 * d + 3 + s) = real(self%material(p), rp)
      record(2 * d + 4 + s) = transfer(self%id(p), 1.0_rp)
      record(2 * d + 5 + s:2 * d + 4 + s + self%n_affine) = self%affine(:, p)
   end subroutine particles_pack_record

   !> Append one particle from a record made by pack_record.
   subroutine particles_append_record(self, record)
      class(particle_set_t), intent(inout) :: self
      real(rp), intent(in) :: record(:)
      integer :: d, s
      d = self%dim
      s = self%n_sigma
      call self%add(record(1:d), record(d + 1:2 * d), record(2 * d + 1), record(2 * d + 2), &
                    record(2 * d + 3:2 * d + 2 + s), nint(record(2 * d + 3 + s)), transfer(record(2 * d + 4 + s), 1_i8), &
                    record(2 * d + 5 + s:2 * d + 4 + s + self%n_affine))
   end subroutine particles_append_record

   !> Append one particle given its persistent state (dropped if the arrays cannot grow: see allocation).
   !> `affine`: its C_p with APIC (default zero: a uniform velocity, as seeding and inflow create).
   subroutine particles_add(self, x, v, mass, density, sbar, material, id, affine)
      class(particle_set_t), intent(inout) :: self
      real(rp), intent(in) :: x(:), v(:), mass, density, sbar(:)
      integer, intent(in) :: material
      integer(i8), intent(in) :: id
      real(rp), intent(in), optional :: affine(:)
      integer :: p
      if (.not. self%allocation%ok) return      ! no memory: the run stops at the end of the step
      if (self%count == size(self%mass)) then
         call self%reserve(max(16, self%count + 1))
         if (.not. self%allocation%ok) return
      end if
      p = self%count + 1
      self%count = p
      self%x(:, p) = x
      self%v(:, p) = v
      self%mass(p) = mass
      self%density(p) = density
      self%sbar(:, p) = sbar
      self%material(p) = material
      self%id(p) = id
      self%cell(p) = 0
      if (self%n_affine == 0) return
      self%affine(:, p) = 0.0_rp
      if (present(affine)) self%affine(:, p) = affine
   end subroutine particles_add

   !> Copy the persistent state of particle `from` into slot `to` (compaction after removal).
   pure subroutine particles_copy_particle(self, from, to)
      class(particle_set_t), intent(inout) :: self
      integer, intent(in) :: from, to
      self%x(:, to) = self%x(:, from)
      self%v(:, to) = self%v(:, from)
      self%mass(to) = self%mass(from)
      self%density(to) = self%density(from)
      self%sbar(:, to) = self%sbar(:, from)
      self%material(to) = self%material(from)
      self%id(to) = self%id(from)
      self%cell(to) = self%cell(from)
      self%affine(:, to) = self%affine(:, from)
   end subroutine particles_copy_particle

   !> Current volume m / rho of particle p (area per unit thickness in 2-D).
   pure real(rp) function particles_volume(self, p)
      class(particle_set_t), intent(in) :: self
      integer, intent(in) :: p
      particles_volume = self%mass(p) / self%density(p)
   end function particles_volume
end module particle_set
