!> Node-based anti-locking NB of Mast et al. (2012) as reconstructed in algorithms.md section 2.3 [?]/[R]:
!> lumped, mass-weighted projection onto the nodal shape functions and interpolation back,
!>   d~_i = sum_p N_ip m_p d_p / m_i ,   d_p := sum_i N_ip d~_i        (before the constitutive update)
!>   s~_i = sum_p N_ip m_p s_p / m_i ,   s_p := sum_i N_ip s~_i        (after it)
!> per material, with m_i = sum_p N_ip m_p of that material, at the positions x^n (the shape values
!> are stored by `prepare`, before the particles move). Nodal sums use the solver's ghost-node sum. N_ip are
!> the grid's shape functions, multilinear or quadratic B-spline (the projection onto the nodes is the same
!> lumped L2 projection whatever the stencil; docs/theory.md section 1.1).
!>
!> Cost (docs/performance-history.md, "NB"): the particle loops are node_based_kernels' compile-time instances;
!> the work arrays are kept from step to step (they only grow); and when the material's particles are
!> all the particles (context%sole_material) m_i is the grid's mass row of the step's P2G, the same sum
!> in the same order, so `prepare` neither sums nor exchanges the masses again.
module node_based_anti_locking
   use kinds, only: rp
   use particle_set, only: particle_set_t
   use stabilizer, only: stabilizer_t, stage_context_t, smoothing_passes
   use background_grid, only: grid_t, row_mass
   use node_halo, only: sum_shared_nodes
   use node_based_kernels, only: store_shape_values, scatter_to_nodes, gather_from_nodes, divide_by_mass, clear
   implicit none
   private

   type, extends(stabilizer_t), public :: node_based_anti_locking_t
      integer, allocatable :: base(:)            !< base node of each particle's stencil (slice order)
      real(rp), allocatable :: weight(:, :)      !< N_a(x_p^n) of the stencil's nodes (slice order)
      real(rp), allocatable :: nodal_mass(:, :)  !< m_i of this material, summed over ranks (1, node; if own_mass)
      real(rp), allocatable :: nodal(:, :)       !< the projected values (components, node)
      logical :: own_mass = .true.               !< m_i is nodal_mass, else the grid's mass row
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
      integer :: n

      associate (grid => context%grid)
         n = max(0, context%last - context%first + 1)
         if (allocated(self%base)) then
            if (size(self%base) < n .or. size(self%weight, 1) /= grid%stencil_size) deallocate (self%base, self%weight)
         end if
         if (.not. allocated(self%base)) allocate (self%base(n), self%weight(grid%stencil_size, n))
         self%own_mass = .not. context%sole_material
         if (self%own_mass) then
            if (allocated(self%nodal_mass)) then
               if (size(self%nodal_mass, 2) < grid%node_count) deallocate (self%nodal_mass)
            end if
            if (.not. allocated(self%nodal_mass)) allocate (self%nodal_mass(1, grid%node_count))
            associate (mass => self%nodal_mass(:, 1:grid%node_count))
               mass = 0.0_rp
               call store_shape_values(grid, particles, context%first, context%last, self%base, self%weight, &
                                       mass(1, :), context%stencils)
               call sum_shared_nodes(context%domain, grid, mass)
            end associate
         else
            call store_shape_values(grid, particles, context%first, context%last, self%base, self%weight, &
                                    stencils=context%stencils)
         end if
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
      real(rp), allocatable :: before(:, :)
      real(rp) :: share
      integer :: passes, pass
      ! the projection smooths again at every step: a step shorter than the reference takes that part of its
      ! change (applied whole at every step of CFL 0.05 it put 44 J into the paper's tank at rest within
      ! 1.2 s, 0.05 J with the share; docs/theory.md, "The FLIP/PIC blend as a rate"), a longer one takes
      ! it in smoothing_passes' passes, each from the values the last left
      call smoothing_passes(context%reference_steps, passes, share)
      associate (sbar => particles%sbar(:, context%first:context%last))
         do pass = 1, passes
            if (share < 1.0_rp) before = sbar
            call project_and_interpolate(self, context, particles, sbar)
            if (share < 1.0_rp) sbar = before + share * (sbar - before)
         end do
      end associate
   end subroutine nb_filter_stress

   !> values(:, q) := sum_i N_iq (sum_r N_ir m_r values_r / m_i) for the material's slice (values(:, q)
   !> belongs to particle context%first + q - 1). Collective.
   subroutine project_and_interpolate(self, context, particles, values)
      type(node_based_anti_locking_t), intent(inout) :: self
      type(stage_context_t), intent(in) :: context
      type(particle_set_t), intent(in) :: particles
      real(rp), intent(inout), contiguous :: values(:, :)
      integer :: nodes
      type(grid_t), pointer :: grid

      grid => context%grid
      nodes = grid%node_count
      if (allocated(self%nodal)) then
         if (size(self%nodal, 1) /= size(values, 1) .or. size(self%nodal, 2) < nodes) deallocate (self%nodal)
      end if
      if (.not. allocated(self%nodal)) allocate (self%nodal(size(values, 1), nodes))
      call clear(size(values, 1) * nodes, self%nodal)
      associate (nodal => self%nodal(:, 1:nodes))
         call scatter_to_nodes(grid, self%base, self%weight, particles%mass(context%first:context%last), values, nodal)
         call sum_shared_nodes(context%domain, grid, nodal)
         if (self%own_mass) then
            call divide_by_mass(grid, self%nodal_mass(1, 1:nodes), nodal)
         else
            call divide_by_mass(grid, grid%accumulated(row_mass, 1:nodes), nodal)
         end if
         call gather_from_nodes(grid, self%base, self%weight, nodal, values)
      end associate
   end subroutine project_and_interpolate
end module node_based_anti_locking
