!> Fills the declared bodies with particles, each rank creating only the particles inside its own
!> cells (docs/input.md "&body", docs/theory.md section 3.5).
!>
!> Where the particles sit is body_lattice's: an unrotated box on its own lattice (n_k =
!> nint((upper_k - lower_k) / (h / ppc)) particles at spacing (upper_k - lower_k) / n_k, so its mass is
!> exactly rho0 times its volume), any other shape on the lattice of the scene box of spacing h / ppc,
!> keeping the points inside the shape, each with the lattice cell's volume; a body of a points file
!> one particle per point with the file's volume. Bodies are given in the world frame (on a rotated
!> grid cells hold unequal particle counts, as in [Y17]'s 45 degree test); positions and velocities
!> are mapped into the grid frame. Particle ids are body offset + lattice index (or row of the file):
!> they do not depend on the number of ranks.
module particle_seeding
   use kinds, only: rp, i8
   use input_text, only: int_text
   use scene_description, only: scene_t, relaxes_to_eos
   use body_lattice, only: body_lattice_t, body_lattice_of, lattice_point, lattice_keeps, has_points_file, body_id_count, &
                           body_bounds
   use tensor_layout, only: n_components
   use background_grid, only: grid_t
   use domain_decomposition, only: domain_t
   use particle_set, only: particle_set_t
   use newtonian_fluid, only: eos_density
   implicit none
   private

   public :: seed_bodies

contains

   !> Create this rank's particles of every body of the scene. A first pass counts them, so the arrays
   !> are allocated once at their size (a failure shows in particles%allocation).
   subroutine seed_bodies(scene, grid, domain, particles)
      type(scene_t), intent(in) :: scene
      type(grid_t), intent(in) :: grid
      type(domain_t), intent(in) :: domain
      type(particle_set_t), intent(inout) :: particles
      integer :: b, dim, c(3), pass
      integer(i8) :: id_offset, owned, k, points
      real(rp) :: x(3), up(3), g_norm, density, x_grid(3), v_grid(3), volume, centre(3), lo(3), hi(3)
      logical :: eos_state, from_file
      type(body_lattice_t) :: lattice
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
               from_file = has_points_file(body)
               points = body_id_count(scene, b)
               if (.not. from_file) then
                  lattice = body_lattice_of(body, scene%grid)
                  volume = product(lattice%spacing(1:dim))
               end if
               density = scene%materials(body%material_index)%density
               ! a fluid whose pressure relaxes toward its EOS starts in an EOS state (docs/volume-conservation.md)
               eos_state = relaxes_to_eos(scene%materials(body%material_index))
               v_grid = 0.0_rp
               v_grid(1:dim) = grid%frame%grid_vector(body%velocity(1:dim))
               ! a spinning body: v = v0 + omega x (x - centre) about the centre of its bounding box
               call body_bounds(scene, b, lo, hi)
               centre = 0.5_rp * (lo + hi)
               x_grid = 0.0_rp
               x = 0.0_rp
               do k = 0, points - 1
                  if (from_file) then
                     x(1:dim) = scene%body_points(b)%position(:, k + 1)
                     volume = scene%body_points(b)%volume(k + 1)
                  else
                     x = lattice_point(lattice, k)
                  end if
                  x_grid(1:dim) = grid%frame%grid_point(x(1:dim))
                  c = grid%cell_of_position(x_grid(1:dim))
                  if (.not. domain%owns_cell(c(1:dim))) cycle
                  if (.not. from_file) then
                     if (.not. lattice_keeps(lattice, x(1:dim))) cycle
                  end if
                  if (pass == 1) then
                     owned = owned + 1
                     cycle
                  end if
                  if (any(body%angular_velocity /= 0.0_rp)) v_grid(1:dim) = &
                     grid%frame%grid_vector(body%velocity(1:dim) + spin_velocity(body%angular_velocity, x - centre, dim))
                  call add_particle(x, volume)
               end do
               id_offset = id_offset + points
            end associate
         end do
      end do

   contains

      !> The particle of body b at world point x with volume `volume`, id id_offset + k.
      subroutine add_particle(x, volume)
         real(rp), intent(in) :: x(3), volume
         real(rp) :: pressure, rho
         associate (body => scene%bodies(b))
            sbar = 0.0_rp
            rho = density
            if (body%hydrostatic) then
               ! p = rho0 |g| (depth below the free surface); sbar = -p / rho on the normal components
               pressure = density * g_norm * max(0.0_rp, body%free_surface_level - dot_product(up(1:dim), x(1:dim)))
               if (eos_state) rho = eos_density(density, scene%materials(body%material_index)%bulk_modulus, pressure)
               sbar(1:3) = -pressure / rho
            end if
            call particles%add(x_grid(1:dim), v_grid(1:dim), density * volume, rho, sbar, body%material_index, &
                               id_offset + k)
         end associate
      end subroutine add_particle
   end subroutine seed_bodies

   !> omega x r (world frame), its first dim components (2-D: omega_z (-r_y, r_x)).
   pure function spin_velocity(omega, r, dim) result(v)
      real(rp), intent(in) :: omega(3), r(3)
      integer, intent(in) :: dim
      real(rp) :: v(dim)
      if (dim == 2) then
         v = omega(3) * [-r(2), r(1)]
      else
         v = [omega(2) * r(3) - omega(3) * r(2), omega(3) * r(1) - omega(1) * r(3), omega(1) * r(2) - omega(2) * r(1)]
      end if
   end function spin_velocity
end module particle_seeding
