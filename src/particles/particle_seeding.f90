!> Fills the declared bodies with particles on a regular lattice, each rank creating only the
!> particles inside its own cells.
!>
!> A body spans lower..upper; along axis k it holds n_k = nint((upper_k - lower_k) / (h / ppc))
!> particles at spacing (upper_k - lower_k) / n_k, centred in their lattice cells, so the body's mass
!> is exactly rho0 times its volume. Bodies are given in the world frame: the lattice is the body's
!> (on a rotated grid cells hold unequal particle counts, as in [Y17]'s 45 degree test), positions and
!> velocities are mapped into the grid frame. Particle ids are body offset + lattice index: they do not
!> depend on the number of ranks.
module particle_seeding
   use kinds, only: rp, i8
   use input_text, only: int_text
   use scene_description, only: scene_t, body_spec_t, relaxes_to_eos
   use tensor_layout, only: n_components
   use background_grid, only: grid_t
   use domain_decomposition, only: domain_t
   use particle_set, only: particle_set_t
   use newtonian_fluid, only: eos_density
   implicit none
   private

   public :: lattice_counts, seed_bodies, body_particle_count

contains

   !> Particles of a body along each axis (1 on unused axes).
   pure function lattice_counts(body, dim, cell_size) result(n)
      type(body_spec_t), intent(in) :: body
      integer, intent(in) :: dim
      real(rp), intent(in) :: cell_size
      integer :: n(3)
      n = 1
      n(1:dim) = nint((body%upper(1:dim) - body%lower(1:dim)) / (cell_size / body%particles_per_cell))
   end function lattice_counts

   !> Number of particles of all bodies of the scene (over all ranks): the first id free for others.
   pure integer(i8) function body_particle_count(scene) result(total)
      type(scene_t), intent(in) :: scene
      integer :: b
      total = 0
      do b = 1, size(scene%bodies)
         total = total + product(int(lattice_counts(scene%bodies(b), scene%grid%dim, scene%grid%cell_size), i8))
      end do
   end function body_particle_count

   !> Create this rank's particles of every body of the scene. A first pass counts them, so the arrays
   !> are allocated once at their size (a failure shows in particles%allocation).
   subroutine seed_bodies(scene, grid, domain, particles)
      type(scene_t), intent(in) :: scene
      type(grid_t), intent(in) :: grid
      type(domain_t), intent(in) :: domain
      type(particle_set_t), intent(inout) :: particles
      integer :: b, dim, n(3), i, j, l, c(3), pass
      integer(i8) :: id_offset, owned
      real(rp) :: spacing(3), x(3), particle_volume, up(3), g_norm, pressure, density, x_grid(3), v_grid(3), rho
      logical :: eos_state
      real(rp), allocatable :: sbar(:)

      dim = grid%dim
      allocate (sbar(n_components(dim)))
      g_norm = norm2(scene%gravity(1:dim))
      up = 0.0_rp
      if (g_norm > 0.0_rp) up(1:dim) = -scene%gravity(1:dim) / g_norm
      owned = 0
      do pass = 1, 2
         if (pass == 2) then
            if (particles%count + owned > huge(1)) then
               call particles%allocation%fail('more than '//int_text(huge(1))//' particles on one rank; use more ranks')
               return
            end if
            call particles%reserve(int(particles%count + owned))
            if (.not. particles%allocation%ok) return
         end if
         id_offset = 0
         do b = 1, size(scene%bodies)
            associate (body => scene%bodies(b))
               n = lattice_counts(body, dim, grid%h)
               spacing = 1.0_rp
               spacing(1:dim) = (body%upper(1:dim) - body%lower(1:dim)) / n(1:dim)
               particle_volume = product(spacing(1:dim))
               density = scene%materials(body%material_index)%density
               ! a fluid whose pressure relaxes toward its EOS starts in an EOS state (docs/volume-conservation.md)
               eos_state = relaxes_to_eos(scene%materials(body%material_index))
               v_grid = 0.0_rp
               v_grid(1:dim) = grid%frame%grid_vector(body%velocity(1:dim))
               x_grid = 0.0_rp
               do l = 0, n(3) - 1
                  do j = 0, n(2) - 1
                     do i = 0, n(1) - 1
                        x = body%lower + ([i, j, l] + 0.5_rp) * spacing
                        x_grid(1:dim) = grid%frame%grid_point(x(1:dim))
                        c = grid%cell_of_position(x_grid(1:dim))
                        if (.not. domain%owns_cell(c(1:dim))) cycle
                        if (pass == 1) then
                           owned = owned + 1
                           cycle
                        end if
                        sbar = 0.0_rp
                        rho = density
                        if (body%hydrostatic) then
                           ! p = rho0 |g| (depth below the free surface); sbar = -p / rho on the normal components
                           pressure = density * g_norm * max(0.0_rp, body%free_surface_level - dot_product(up(1:dim), x(1:dim)))
                           if (eos_state) rho = eos_density(density, scene%materials(body%material_index)%bulk_modulus, pressure)
                           sbar(1:3) = -pressure / rho
                        end if
                        call particles%add(x_grid(1:dim), v_grid(1:dim), density * particle_volume, rho, sbar, &
                                        body%material_index, id_offset + i + int(n(1), i8) * (j + int(n(2), i8) * l))
                     end do
                  end do
               end do
               id_offset = id_offset + product(int(n, i8))
            end associate
         end do
      end do
   end subroutine seed_bodies
end module particle_seeding
