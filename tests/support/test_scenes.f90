!> Scenes built in code for the tests: the same values a scene file would give, without a file.
module test_scenes
   use kinds, only: rp
   use scene_description, only: scene_t, body_spec_t, wall_spec_t, inlet_spec_t, wall_none, wall_slip, &
                                model_newtonian_fluid
   implicit none
   private

   public :: water_scene, add_body, tank_with_inlet, corner_column

contains

   !> A 2-D or 3-D box of `extent` with slip walls on every side, gravity -g along the last axis and
   !> one Newtonian fluid 'water' (rho0 = 1000, mu = 1e-3, bulk modulus `bulk_modulus`). No bodies yet.
   function water_scene(dim, cell_size, extent, bulk_modulus, g) result(scene)
      integer, intent(in) :: dim
      real(rp), intent(in) :: cell_size, extent(3), bulk_modulus, g
      type(scene_t) :: scene
      scene%grid%dim = dim
      scene%grid%cell_size = cell_size
      scene%grid%origin = 0.0_rp
      scene%grid%extent = extent
      scene%grid%ncells = 1
      scene%grid%ncells(1:dim) = nint(extent(1:dim) / cell_size)
      scene%grid%wall(:, 1:dim) = wall_slip
      scene%gravity = 0.0_rp
      scene%gravity(dim) = -g
      scene%run%end_time = 1.0_rp
      scene%run%output_interval = 0.1_rp
      scene%run%progress_interval = 0.0_rp
      scene%run%floor_size = product(extent(1:dim - 1))
      allocate (scene%materials(1), scene%bodies(0))
      scene%materials(1)%name = 'water'
      scene%materials(1)%model = model_newtonian_fluid
      scene%materials(1)%density = 1000.0_rp
      scene%materials(1)%bulk_modulus = bulk_modulus
      scene%materials(1)%viscosity = 1.0e-3_rp
   end function water_scene

   !> Append a body of material `material_index` filling lower..upper with ppc particles per cell and
   !> direction; hydrostatic stress below `surface` when `hydrostatic`.
   subroutine add_body(scene, material_index, lower, upper, ppc, hydrostatic, surface)
      type(scene_t), intent(inout) :: scene
      integer, intent(in) :: material_index, ppc
      real(rp), intent(in) :: lower(3), upper(3)
      logical, intent(in) :: hydrostatic
      real(rp), intent(in) :: surface
      type(body_spec_t) :: body
      body%material = scene%materials(material_index)%name
      body%material_index = material_index
      body%lower = lower
      body%upper = upper
      body%particles_per_cell = ppc
      body%hydrostatic = hydrostatic
      body%free_surface_level = surface
      scene%bodies = [scene%bodies, body]
   end subroutine add_body

   !> A square water column of side `side` in the lower left corner of a 2-D tank of `extent` with slip
   !> walls (cell 0.05 m, K = 2 MPa, g = 9.81, 2 x 2 particles per cell), stabilized by `scheme`.
   function corner_column(extent, side, scheme) result(scene)
      real(rp), intent(in) :: extent(2), side
      character(len=*), intent(in) :: scheme
      type(scene_t) :: scene
      scene = water_scene(2, 0.05_rp, [extent, 0.0_rp], 2.0e6_rp, 9.81_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [side, side, 0.0_rp], 2, .false., 0.0_rp)
      scene%materials(1)%stabilization = scheme
   end function corner_column

   !> A 2-D tank 3 m x 2 m (cell 0.1 m, K = 2 MPa, g = 10) with a floor and a right wall, filled through
   !> an opening of `height` at the foot of the left wall (a slip wall above it): water enters at
   !> `velocity` from t = 0 to `end_time`, 3 particles per cell.
   function tank_with_inlet(height, velocity, end_time) result(scene)
      real(rp), intent(in) :: height, velocity, end_time
      type(scene_t) :: scene
      scene = water_scene(2, 0.1_rp, [3.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 10.0_rp)
      scene%grid%wall = wall_none
      scene%grid%wall(1, 2) = wall_slip
      scene%grid%wall(2, 1) = wall_slip
      allocate (scene%walls(1), scene%inlets(1))
      scene%walls(1) = wall_spec_t(point=[0.0_rp, height, 0.0_rp], normal=[1.0_rp, 0.0_rp, 0.0_rp], &
                                   lower=[0.0_rp, height, 0.0_rp], upper=[0.0_rp, 2.0_rp, 0.0_rp])
      scene%inlets(1) = inlet_spec_t(material='water', material_index=1, point=[0.0_rp, 0.0_rp, 0.0_rp], &
                                     direction=[1.0_rp, 0.0_rp, 0.0_rp], height=height, velocity=velocity, &
                                     start_time=0.0_rp, end_time=end_time, particles_per_cell=3)
   end function tank_with_inlet
end module test_scenes
