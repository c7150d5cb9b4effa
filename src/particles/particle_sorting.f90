!> Keeps particles ordered by (material, cell): contiguous per-material slices for the constitutive
!> and stabilization loops, and cell order inside each slice so that grid access is local.
!> A counting sort: O(particles + materials * local cells).
module particle_sorting
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   implicit none
   private

   public :: sort_by_material_and_cell, update_cells, set_material_ranges, in_material_order

contains

   !> Set particles%cell to the local cell at the current position (every particle in an owned cell),
   !> keeping the order, and the material ranges.
   subroutine update_cells(grid, particles)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer :: p
      do p = 1, particles%count
         particles%cell(p) = grid%local_cell(grid%cell_of_position(particles%x(:, p)))
      end do
      call set_material_ranges(particles)
   end subroutine update_cells

   !> Sort by (material, particles%cell) and set the material ranges. particles%cell must be current
   !> (update_cells, or migrate_particles which sets it). Scratch: the destinations (4 bytes per
   !> particle) and the counts per key; the keys are recomputed rather than stored, and the particles
   !> are permuted in place.
   subroutine sort_by_material_and_cell(grid, particles)
      type(grid_t), intent(in) :: grid
      type(particle_set_t), intent(inout) :: particles
      integer, allocatable :: start(:), dest(:)
      integer :: p, n, n_keys, m, k

      n = particles%count
      n_keys = particles%n_materials * grid%cell_count
      allocate (dest(n), start(n_keys + 1))
      start = 0
      do p = 1, n
         k = key(p)
         start(k + 1) = start(k + 1) + 1
      end do
      ! start(k) = number of particles with a smaller key, then the running slot of key k
      start(1) = 0
      do m = 2, n_keys + 1
         start(m) = start(m) + start(m - 1)
      end do
      do p = 1, n
         k = key(p)
         start(k) = start(k) + 1
         dest(p) = start(k)
      end do

      call particles%permute(dest)

      call set_material_ranges(particles)

   contains

      pure integer function key(q)
         integer, intent(in) :: q
         key = (particles%material(q) - 1) * grid%cell_count + particles%cell(q)
      end function key
   end subroutine sort_by_material_and_cell

   !> material_first(m):material_last(m) = the slice of material m (empty slice: first = 1, last = 0): the
   !> first and the last particle of the material. They are the first of a run of equal materials and the
   !> last of one, so only where the material changes is anything written (one pass; the two passes that
   !> wrote at every particle were about 1 % of a step).
   subroutine set_material_ranges(particles)
      type(particle_set_t), intent(inout) :: particles
      integer :: p, m, n
      n = particles%count
      particles%material_first = huge(1)
      particles%material_last = 0
      if (n > 0) then
         associate (material => particles%material, first => particles%material_first, last => particles%material_last)
            first(material(1)) = 1
            do p = 2, n
               if (material(p) /= material(p - 1)) then
                  last(material(p - 1)) = max(last(material(p - 1)), p - 1)
                  first(material(p)) = min(first(material(p)), p)
               end if
            end do
            last(material(n)) = max(last(material(n)), n)
         end associate
      end if
      do m = 1, particles%n_materials
         if (particles%material_last(m) == 0) particles%material_first(m) = 1
      end do
   end subroutine set_material_ranges

   !> True if the particles after `sorted` (those appended to a set in material order, e.g. the arrivals
   !> of a migration) keep it in material order: each is of the same material as the one before it or a
   !> later one. Then every material's particles are still contiguous and set_material_ranges finds their
   !> slices without a sort.
   pure logical function in_material_order(particles, sorted)
      type(particle_set_t), intent(in) :: particles
      integer, intent(in) :: sorted
      integer :: p
      in_material_order = .true.
      do p = max(2, sorted + 1), particles%count
         if (particles%material(p) < particles%material(p - 1)) then
            in_material_order = .false.
            return
         end if
      end do
   end function in_material_order
end module particle_sorting
