!> What a scene declares: the values read from the namelist groups of a scene file
!> (documented group by group in docs/input.md). Only what is declared is modelled.
module scene_description
   use kinds, only: rp, path_len, name_len
   use shape_geometry, only: shape_t, box_corners
   use time_table, only: time_table_t
   use run_group, only: run_control_t, writes_particle_field, particle_field_names, field_precision_keywords
   use material_group, only: material_spec_t, model_newtonian_fluid, model_linear_elastic, model_rigid, &
                             shifts_particles, relaxes_to_eos
   use inlet_group, only: inlet_spec_t, has_velocity_file, opening_tangent, opening_far_end
   use contact_group, only: contact_spec_t
   use gauge_group, only: gauge_spec_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, &
                          gauge_wall_pressure
   implicit none
   private

   ! the groups whose variables live in their own module (src/input/groups/), named here for the scene's users
   public :: run_control_t, writes_particle_field, particle_field_names, field_precision_keywords
   public :: material_spec_t, model_newtonian_fluid, model_linear_elastic, model_rigid, shifts_particles, &
             relaxes_to_eos
   public :: inlet_spec_t, has_velocity_file, opening_tangent, opening_far_end
   public :: contact_spec_t
   public :: gauge_spec_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, gauge_wall_pressure

   !> Wall condition keywords of the box sides (`&box_walls`).
   character(len=*), parameter, public :: wall_none = 'none'
   character(len=*), parameter, public :: wall_slip = 'slip'      ! [Y17] eq. 14, unilateral, frictionless
   character(len=*), parameter, public :: wall_no_slip = 'no_slip'
   !> Unilateral with Coulomb friction (`&wall`, `&box_walls`, `&structure` with `friction` = mu).
   character(len=*), parameter, public :: wall_friction = 'friction'

   !> `&wall motion=` and `&structure motion=` keywords: fixed, the piston stroke of a solitary wave (Goring 1978), a
   !> displacement read from a time table (docs/input.md).
   character(len=*), parameter, public :: motion_none = 'none'
   character(len=*), parameter, public :: motion_solitary_wave = 'solitary_wave'
   character(len=*), parameter, public :: motion_table = 'table'

   !> `&grid` and `&box_walls`: the scene box (world frame), the grid that covers it, and the box's walls.
   !> The grid may be rotated against the world by `rotation` about z, pivoting on `origin` (the paper's
   !> theta_g); it is axis-aligned in its own frame and covers the rotated box with whole cells.
   type, public :: grid_spec_t
      integer :: dim = 2                      !< 2 (plane strain) or 3
      real(rp) :: cell_size = 0.0_rp          !< cell edge h [m]
      real(rp) :: origin(3) = 0.0_rp          !< lower corner of the scene box (world frame) [m]
      real(rp) :: extent(3) = 0.0_rp          !< edge lengths of the scene box [m], whole multiples of cell_size
      real(rp) :: rotation = 0.0_rp           !< grid rotation theta_g, counter-clockwise about z [degrees]
      !> 'linear' (multilinear, 2**dim nodes per particle) or 'bspline2' (quadratic B-spline, 3**dim nodes)
      character(len=name_len) :: shape_function = 'linear'
      integer :: ncells(3) = 1                !< derived: extent / cell_size (1 on unused axes)
      !> wall condition per side: (1, k) lower side, (2, k) upper side of axis k
      character(len=name_len) :: wall(2, 3) = wall_none
      !> name of each side's wall in loads.csv (`&box_walls x_min_name` ...); resolved default 'x_min' ...
      !> for a side that is a wall, '' for an open side
      character(len=name_len) :: wall_name(2, 3) = ''
      real(rp) :: wall_friction = 0.0_rp      !< Coulomb mu of the sides whose condition is 'friction'
   end type grid_spec_t

   !> A prescribed rigid translation of a `&wall` or a `&structure` (wall_motion; docs/input.md): the
   !> namelist variables motion, motion_start, wave_height, water_depth, motion_file, motion_checksum and
   !> (a structure's solitary wave) motion_direction.
   type, public :: motion_spec_t
      character(len=name_len) :: kind = motion_none   !< `motion`: 'none', 'solitary_wave' or 'table'
      real(rp) :: start = 0.0_rp              !< `motion_start`, solitary_wave: the stroke starts [s]
      real(rp) :: wave_height = 0.0_rp        !< solitary_wave: wave height A [m]
      real(rp) :: water_depth = 0.0_rp        !< solitary_wave: still-water depth h [m]
      !> `motion_file`, table: CSV of the displacement (t, x, y[, z]); resolved to an absolute path
      character(len=path_len) :: file = ''
      !> `motion_checksum`, table: checksum of the numbers read from the file (16 hex digits); given: must match
      character(len=16) :: checksum = ''
      !> `motion_direction`, a structure's solitary_wave: the direction of the stroke, any length (a wall
      !> moves along its normal)
      real(rp) :: direction(3) = 0.0_rp
   end type motion_spec_t

   !> `&wall`: a plane wall (a segment in 2-D, a planar patch in 3-D), world frame. The wall is the part
   !> of the plane through `point` with inward unit normal `normal` that lies inside the box lower..upper
   !> (unbounded by default). The solver turns the `&box_walls` sides into walls of this kind.
   type, public :: wall_spec_t
      real(rp) :: point(3) = 0.0_rp           !< a point of the wall [m]
      real(rp) :: normal(3) = 0.0_rp          !< normal pointing into the fluid, any length (made unit by make_wall)
      real(rp) :: lower(3) = -huge(1.0_rp)    !< extent of the wall: lower corner of its bounding box [m]
      real(rp) :: upper(3) = huge(1.0_rp)     !< upper corner [m]
      character(len=name_len) :: condition = wall_slip
      real(rp) :: friction = 0.0_rp           !< Coulomb coefficient mu of condition 'friction' [-]
      character(len=name_len) :: name = ''    !< name in loads.csv; resolved default 'wall_<k>'
      !> point the moment of the wall's load is taken about [m]; huge: not given, resolved to the component
      !> of `point`
      real(rp) :: moment_point(3) = huge(1.0_rp)
      type(motion_spec_t) :: motion           !< a prescribed rigid translation (motion, motion_start, ...)
   end type wall_spec_t

   !> `&structure`: a rigid obstacle of any shape and orientation (world frame) whose surface constrains
   !> the material like a wall (unilateral; slip, no-slip or Coulomb friction); fixed, or translated by a
   !> prescribed motion.
   type, public :: structure_spec_t
      character(len=name_len) :: name = ''    !< name in loads.csv; resolved default 'structure_<k>'
      type(shape_t) :: shape                  !< the obstacle (shape_geometry: negative distance inside)
      !> box: corners lower..upper as an alternative to centre and size (huge: not given; resolved into
      !> the shape and cleared)
      real(rp) :: lower(3) = huge(1.0_rp)
      real(rp) :: upper(3) = huge(1.0_rp)
      character(len=name_len) :: condition = wall_slip
      real(rp) :: friction = 0.0_rp           !< Coulomb coefficient mu of condition 'friction' [-]
      !> point the moment of its load is taken about [m]; huge: not given, resolved to the shape's centre
      real(rp) :: moment_point(3) = huge(1.0_rp)
      type(motion_spec_t) :: motion           !< a prescribed rigid translation (as a &wall's)
   end type structure_spec_t

   public :: writes_particle_field, structure_shape

   !> `&body`: a solid shape of one material filled with particles (docs/input.md): a box (`lower`/`upper`,
   !> or `centre`/`size` in `shape`), a circle, polygon, sphere, cylinder or extruded polygon (`shape`), or
   !> the particles of a file of points (`points_file`). Every value is kept as the scene gives it (the
   !> scene record writes it back); body_lattice derives the lattice and bounds.
   type, public :: body_spec_t
      character(len=name_len) :: name = ''    !< name in bodies.csv; resolved default 'body_<k>'
      character(len=name_len) :: material = ''
      integer :: material_index = 0           !< derived: position in scene%materials
      real(rp) :: lower(3) = 0.0_rp           !< box: lower corner [m] (lower = upper: not given)
      real(rp) :: upper(3) = 0.0_rp           !< box: upper corner [m]
      !> shape%kind and, except lower/upper, the shape's variables as given (shape_geometry)
      type(shape_t) :: shape
      !> file of points (CSV or HDF5) the body's particles are read from; resolved to an absolute path
      character(len=path_len) :: points_file = ''
      !> checksum of the points read from points_file (16 hex digits); given: must match the file
      character(len=16) :: points_checksum = ''
      integer :: particles_per_cell = 2       !< particles per cell per direction
      real(rp) :: velocity(3) = 0.0_rp        !< initial velocity [m/s]
      !> initial angular velocity [rad/s] about the centre of the body's bounding box (2-D: component 3)
      real(rp) :: angular_velocity(3) = 0.0_rp
      logical :: hydrostatic = .false.        !< start from the hydrostatic stress of a fluid at rest
      real(rp) :: free_surface_level = 0.0_rp !< height of the free surface along -gravity [m]
   end type body_spec_t

   !> The points of a `&body points_file` (empty for the other bodies): world positions and volumes.
   type, public :: body_points_t
      real(rp), allocatable :: position(:, :)  !< (dim, n) [m]
      real(rp), allocatable :: volume(:)       !< (n) [m^3, m^2 in 2-D]
   end type body_points_t

   !> A whole scene.
   type, public :: scene_t
      character(len=path_len) :: source_file = ''
      type(run_control_t) :: run
      type(grid_spec_t) :: grid
      real(rp) :: gravity(3) = 0.0_rp         !< `&gravity acceleration=` [m/s^2]
      type(material_spec_t), allocatable :: materials(:)
      type(body_spec_t), allocatable :: bodies(:)
      !> per body, the points of its points_file (read by rank 0, broadcast with the scene)
      type(body_points_t), allocatable :: body_points(:)
      type(wall_spec_t), allocatable :: walls(:)      !< `&wall` groups (the `&box_walls` sides are in grid)
      !> per wall, the table of its motion_file (read by rank 0, broadcast with the scene; empty otherwise)
      type(time_table_t), allocatable :: wall_tables(:)
      type(structure_spec_t), allocatable :: structures(:)   !< `&structure` groups
      !> per structure, the table of its motion_file (as wall_tables)
      type(time_table_t), allocatable :: structure_tables(:)
      type(inlet_spec_t), allocatable :: inlets(:)
      !> per inlet, the table of its velocity_file (read by rank 0, broadcast with the scene; no rows: none)
      type(time_table_t), allocatable :: inlet_tables(:)
      type(gauge_spec_t), allocatable :: gauges(:)
      type(contact_spec_t), allocatable :: contacts(:)
   end type scene_t

contains

   !> The shape of a `&structure` (validated) in a `dim`-D scene: a box given by its corners lower..upper
   !> as centre and size (resolve_scene stores it so).
   pure function structure_shape(structure, dim) result(shape)
      type(structure_spec_t), intent(in) :: structure
      integer, intent(in) :: dim
      type(shape_t) :: shape
      shape = structure%shape
      if (structure%lower(1) < huge(1.0_rp)) shape = box_corners(shape, structure%lower, structure%upper, dim)
   end function structure_shape

end module scene_description
