!> Rigid walls: nodal velocity constraints and the particle safeguard (algorithms.md section 4).
!>
!> A wall is a plane with a unit normal pointing into the domain. `slip` is the paper's eq. 14:
!> unilateral and frictionless, v := v - (v.n) n only where v.n < 0. `no_slip` sets v := 0.
!> The box walls of `&box_walls` lie on the grid's outer node planes, so there the constrained nodes
!> are exactly the nodes on the wall.
module boundary_walls
   use kinds, only: rp, name_len
   use scene_description, only: grid_spec_t, wall_none, wall_slip, wall_no_slip
   use background_grid, only: grid_t
   use particle_set, only: particle_set_t
   implicit none
   private

   type, public :: wall_t
      real(rp) :: normal(3) = 0.0_rp       !< unit normal pointing into the domain
      real(rp) :: point(3) = 0.0_rp        !< a point on the wall (grid frame)
      logical :: no_slip = .false.
      integer :: axis = 0                  !< k if the normal is +-e_k (box walls), else 0
      integer, allocatable :: nodes(:)     !< local nodes this rank constrains
   end type wall_t

   public :: build_box_walls, apply_wall_constraints, keep_particles_inside

contains

   !> One wall per box side that is not `none`, with the local nodes lying on it.
   subroutine build_box_walls(spec, grid, walls)
      type(grid_spec_t), intent(in) :: spec
      type(grid_t), intent(in) :: grid
      type(wall_t), allocatable, intent(out) :: walls(:)
      type(wall_t) :: wall
      integer :: k, side, plane, i, j, l, n, g(3), extent(3)
      character(len=name_len) :: condition

      allocate (walls(0))
      do k = 1, grid%dim
         do side = 1, 2
            condition = spec%wall(side, k)
            if (condition == wall_none) cycle
            wall%normal = 0.0_rp
            wall%normal(k) = merge(1.0_rp, -1.0_rp, side == 1)
            wall%point = grid%origin
            plane = merge(0, grid%global_cells(k), side == 1)
            wall%point(k) = grid%origin(k) + plane * grid%h
            wall%no_slip = condition == wall_no_slip
            wall%axis = k
            if (condition /= wall_slip .and. condition /= wall_no_slip) cycle
            if (plane < grid%node_lo(k) .or. plane > grid%node_hi(k)) then
               allocate (wall%nodes(0))
            else
               extent = grid%n_nodes
               extent(k) = 1
               allocate (wall%nodes(product(extent)))
               n = 0
               do l = 0, extent(3) - 1
                  do j = 0, extent(2) - 1
                     do i = 0, extent(1) - 1
                        g = grid%node_lo + [i, j, l]
                        g(k) = plane
                        n = n + 1
                        wall%nodes(n) = grid%local_node(g(1:grid%dim))
                     end do
                  end do
               end do
            end if
            walls = [walls, wall]
            deallocate (wall%nodes)
         end do
      end do
   end subroutine build_box_walls

   !> Constrain nodal velocities (eq. 14 for slip walls; zero for no-slip walls). Walls are applied in
   !> turn, which is exact at a corner of two orthogonal walls (algorithms.md section 4.1).
   pure subroutine apply_wall_constraints(walls, dim, velocity)
      type(wall_t), intent(in) :: walls(:)
      integer, intent(in) :: dim
      real(rp), intent(inout) :: velocity(:, :)
      integer :: w, i, node
      real(rp) :: vn
      do w = 1, size(walls)
         associate (n => walls(w)%normal(1:dim))
            do i = 1, size(walls(w)%nodes)
               node = walls(w)%nodes(i)
               if (walls(w)%no_slip) then
                  velocity(:, node) = 0.0_rp
               else
                  vn = dot_product(velocity(:, node), n)
                  if (vn < 0.0_rp) velocity(:, node) = velocity(:, node) - vn * n
               end if
            end do
         end associate
      end do
   end subroutine apply_wall_constraints

   !> Particle safeguard (algorithms.md section 4.2): a particle found behind a wall is put back onto
   !> it and loses its velocity component into the wall. Returns how many corrections were made.
   subroutine keep_particles_inside(walls, particles, corrections)
      type(wall_t), intent(in) :: walls(:)
      type(particle_set_t), intent(inout) :: particles
      integer, intent(inout) :: corrections
      integer :: w, p, d
      real(rp) :: distance, vn
      d = particles%dim
      do w = 1, size(walls)
         if (walls(w)%axis > 0) then
            call keep_inside_axis_wall(walls(w), particles, corrections)
            cycle
         end if
         associate (n => walls(w)%normal(1:d), x0 => walls(w)%point(1:d))
            do p = 1, particles%count
               distance = dot_product(particles%x(:, p) - x0, n)
               if (distance < 0.0_rp) then
                  particles%x(:, p) = particles%x(:, p) - distance * n
                  vn = dot_product(particles%v(:, p), n)
                  if (vn < 0.0_rp) particles%v(:, p) = particles%v(:, p) - vn * n
                  corrections = corrections + 1
               end if
            end do
         end associate
      end do
   end subroutine keep_particles_inside

   !> The safeguard for a wall normal to axis k: the same operation without the dot products.
   subroutine keep_inside_axis_wall(wall, particles, corrections)
      type(wall_t), intent(in) :: wall
      type(particle_set_t), intent(inout) :: particles
      integer, intent(inout) :: corrections
      integer :: p, k
      real(rp) :: sense, x0
      k = wall%axis
      sense = wall%normal(k)
      x0 = wall%point(k)
      do p = 1, particles%count
         if (sense * (particles%x(k, p) - x0) < 0.0_rp) then
            particles%x(k, p) = x0
            if (sense * particles%v(k, p) < 0.0_rp) particles%v(k, p) = 0.0_rp
            corrections = corrections + 1
         end if
      end do
   end subroutine keep_inside_axis_wall
end module boundary_walls
