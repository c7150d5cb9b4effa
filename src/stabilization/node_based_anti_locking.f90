!> Node-based anti-locking NB of Mast et al. (2012) as reconstructed in algorithms.md section 2.3 [?]/[R]:
!> lumped, mass-weighted projection onto the nodal shape functions and interpolation back,
!>   d~_i = sum_p N_ip m_p d_p / m_i ,   d_p := sum_i N_ip d~_i        (before the constitutive update)
!>   s~_i = sum_p N_ip m_p s_p / m_i ,   s_p := sum_i N_ip s~_i        (after it)
!> per material, with m_i = sum_p N_ip m_p of that material, at the positions x^n (the shape values
!> are stored by `prepare`, before the particles move). Nodal sums use the solver's ghost-node sum. N_ip are
!> the grid's shape functions, multilinear or quadratic B-spline (the projection onto the nodes is the same
!> lumped L2 projection whatever the stencil; docs/theory.md section 1.1).
module node_based_anti_locking
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use stabilizer, only: stabilizer_t, stage_context_t
   use shape_functions, only: stencil_base, stencil_values
   use background_grid, only: grid_t
   use node_halo, only: sum_shared_nodes
   implicit none
   private

   type, extends(stabilizer_t), public :: node_based_anti_locking_t
      integer, allocatable :: base(:)            !< base node of each particle's stencil (slice order)
      real(rp), allocatable :: weight(:, :)      !< N_a(x_p^n) of the stencil's nodes (slice order)
      real(rp), allocatable :: nodal_mass(:)     !< m_i of this material, summed over ranks
   contains
      procedure :: prepare => nb_prepare
      procedure :: filter_strain_rate => nb_filter_strain_rate
      procedure :: filter_stress => nb_filter_stress
   end type node_based_anti_locking_t

contains

   !> Shape values at x^n and the material's nodal masses.
   subroutine nb_prepare(self, context, particles)
      class(node_based_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      real(rp) :: xi(3)
      integer :: p, q, a, c(3), first, last, dim, k
      real(rp), allocatable :: mass(:, :), gradients(:, :)

      associate (grid => context%grid)
         dim = grid%dim
         first = context%first
         last = context%last
         if (allocated(self%base)) deallocate (self%base, self%weight)
         allocate (self%base(max(0, last - first + 1)), self%weight(grid%stencil_size, max(0, last - first + 1)))
         allocate (mass(1, grid%node_count), gradients(dim, grid%stencil_size))
         mass = 0.0_rp
         do p = first, last
            q = p - first + 1
            xi(1:dim) = (particles%x(:, p) - grid%origin(1:dim)) * grid%inv_h
            c = 0
            do k = 1, dim
               c(k) = stencil_base(grid%shape, xi(k), grid%global_cells(k))
            end do
            self%base(q) = grid%local_node(c)
            xi(1:dim) = xi(1:dim) - c(1:dim)
            call stencil_values(grid%shape, dim, xi(1:dim), grid%inv_h, self%weight(:, q), gradients)
            do a = 1, grid%stencil_size
               associate (node => self%base(q) + grid%stencil_stride(a))
                  mass(1, node) = mass(1, node) + self%weight(a, q) * particles%mass(p)
               end associate
            end do
         end do
         call sum_shared_nodes(context%domain, grid, mass)
         self%nodal_mass = mass(1, :)
      end associate
   end subroutine nb_prepare

   subroutine nb_filter_strain_rate(self, context, particles)
      class(node_based_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call project_and_interpolate(self, context, particles, particles%strain_rate(:, context%first:context%last))
   end subroutine nb_filter_strain_rate

   subroutine nb_filter_stress(self, context, particles)
      class(node_based_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(inout) :: particles
      call project_and_interpolate(self, context, particles, particles%sbar(:, context%first:context%last))
   end subroutine nb_filter_stress

   !> values(:, q) := sum_i N_iq (sum_r N_ir m_r values_r / m_i) for the material's slice (values(:, q)
   !> belongs to particle context%first + q - 1). Collective.
   subroutine project_and_interpolate(self, context, particles, values)
      type(node_based_anti_locking_t), intent(in) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(inout) :: values(:, :)
      real(rp), allocatable :: nodal(:, :)
      integer :: q, a, node, i
      type(grid_t), pointer :: grid

      grid => context%grid
      allocate (nodal(size(values, 1), grid%node_count))
      nodal = 0.0_rp
      do q = 1, size(values, 2)
         do a = 1, grid%stencil_size
            node = self%base(q) + grid%stencil_stride(a)
            nodal(:, node) = nodal(:, node) + self%weight(a, q) * particles%mass(context%first + q - 1) * values(:, q)
         end do
      end do
      call sum_shared_nodes(context%domain, grid, nodal)
      do i = 1, grid%node_count
         if (self%nodal_mass(i) > 0.0_rp) nodal(:, i) = nodal(:, i) / self%nodal_mass(i)
      end do
      do q = 1, size(values, 2)
         values(:, q) = 0.0_rp
         do a = 1, grid%stencil_size
            node = self%base(q) + grid%stencil_stride(a)
            values(:, q) = values(:, q) + self%weight(a, q) * nodal(:, node)
         end do
      end do
   end subroutine project_and_interpolate
end module node_based_anti_locking
