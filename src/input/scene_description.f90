!> What a scene declares: the values read from the namelist groups of a scene file
!> (documented group by group in docs/input.md). Only what is declared is modelled.
module scene_description
   use kinds, only: rp, i8, path_len, name_len
   use shape_geometry, only: shape_t, box_corners
   use time_table, only: time_table_t
   use gauge_group, only: gauge_spec_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, &
                          gauge_wall_pressure
   implicit none
   private

   ! the groups whose variables live in their own module (src/input/groups/), named here for the scene's users
   public :: gauge_spec_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, gauge_wall_pressure

   !> The particle datasets `&run particle_fields` may name (position and connectivity are always written).
   character(len=*), parameter, public :: particle_field_names(*) = [character(len=11) :: 'velocity', 'mass', &
      'volume', 'density', 'stress', 'mean_stress', 'pressure', 'material', 'id', 'rank']
   !> `&run field_precision` keywords.
   character(len=*), parameter, public :: field_precision_keywords(*) = [character(len=6) :: 'double', 'single']

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

   !> Material model keywords (`&material model=`).
   character(len=*), parameter, public :: model_newtonian_fluid = 'newtonian_fluid'
   character(len=*), parameter, public :: model_linear_elastic = 'linear_elastic'
   character(len=*), parameter, public :: model_rigid = 'rigid'   ! moves as one rigid body per &body

   !> `&run`: time stepping, update scheme and output control.
   type, public :: run_control_t
      real(rp) :: end_time = -1.0_rp          !< simulated time to reach [s] (required)
      real(rp) :: cfl = 0.5_rp                !< Courant number of the automatic time step
      real(rp) :: fixed_dt = 0.0_rp           !< fixed time step [s]; 0 selects the CFL step
      real(rp) :: output_interval = 0.0_rp    !< simulated time between diagnostics rows [s]; 0: end_time/100
      character(len=path_len) :: output_dir = 'output'
      logical :: overwrite = .false.          !< allow replacing a previous run in output_dir
      character(len=name_len) :: update_scheme = 'MUSL'  !< 'MUSL' (default) or 'USL'
      !> velocity transfer: 'flip_pic' (the FLIP/PIC blend, default) or 'apic' (affine, docs/theory.md)
      character(len=name_len) :: transfer = 'flip_pic'
      real(rp) :: flip_fraction = 0.95_rp     !< 1: pure FLIP, 0: pure PIC (default: docs/theory.md)
      !> the scene file or an override assigns flip_fraction: refused with 'apic', which has no blend
      logical :: flip_fraction_given = .false.
      real(rp) :: theta = 1.0_rp              !< theta of the nodal velocity used for kinematics
      integer(i8) :: max_steps = huge(1_i8)   !< stop after this many steps
      real(rp) :: progress_interval = 5.0_rp  !< wall seconds between progress lines on stderr; <= 0: none
      real(rp) :: floor_size = 0.0_rp         !< tank floor width (2-D) / area (3-D) for h_eq; 0: from grid
      logical :: particle_output = .true.     !< write particle fields (HDF5 + XDMF) at every output time
      logical :: grid_output = .true.         !< write grid fields of the active box at every output time
      !> precision of the real datasets of the fields files: 'double' or 'single' (positions stay double)
      character(len=name_len) :: field_precision = 'double'
      !> particle datasets written: comma-separated names of particle_field_names, or 'all'; position always
      character(len=path_len) :: particle_fields = 'all'
      integer(i8) :: checkpoint_interval_steps = 0   !< steps between checkpoints; 0: not by steps
      real(rp) :: checkpoint_interval_wall = 3600.0_rp  !< wall seconds between checkpoints; 0: not by time
      integer :: checkpoints_kept = 2         !< newest checkpoints kept on disk
      real(rp) :: speed_limit = 0.0_rp        !< particle speed taken as a blow-up [m/s]; 0: 10 x fastest wave
      !> rebalance when the largest rank holds more than this multiple of the mean particles per rank; 0: never
      real(rp) :: rebalance_threshold = 1.02_rp
      integer :: rebalance_interval = 20      !< steps between balance checks (also at every output time)
      !> simulated time between rows of loads.csv, gauges.csv and bodies.csv [s]; 0: every step. Loads are
      !> averages over the interval (impulse / length), gauges and body states samples at the row's time.
      real(rp) :: load_interval = 1.0e-3_rp
   end type run_control_t

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

   !> `&inlet`: an opening through which fluid enters at a constant speed, or at the speed (and height) of
   !> a time table `velocity_file` (a hydrograph; algorithms.md section 4.3).
   !> The opening lies in the plane through `point` normal to `direction` (the flow direction, world
   !> frame); it spans `height` along t = (-d_y, d_x, 0) from `point` and, in 3-D, `width` along z.
   type, public :: inlet_spec_t
      character(len=name_len) :: name = ''    !< name in loads.csv; resolved default 'inlet_<k>'
      character(len=name_len) :: material = ''
      integer :: material_index = 0           !< derived: position in scene%materials
      real(rp) :: point(3) = 0.0_rp           !< lower end of the opening [m]
      real(rp) :: direction(3) = 0.0_rp       !< flow direction (made unit when resolved)
      real(rp) :: height = 0.0_rp             !< size of the opening along t [m] (H of rho v H)
      real(rp) :: width = 0.0_rp              !< 3-D: size of the opening along z [m]
      real(rp) :: velocity = 0.0_rp           !< inflow speed v0 [m/s]; 0: not given (velocity_file)
      !> a time table (t, velocity[, height]) of the inflow; '' none. Resolved: the absolute path
      character(len=path_len) :: velocity_file = ''
      character(len=16) :: velocity_checksum = ''   !< time_table checksum of the table's numbers ('' not given)
      !> the fluid enters with the table's column `height` (<= height, the opening's size) instead of height
      logical :: height_from_file = .false.
      real(rp) :: start_time = 0.0_rp         !< the inlet opens [s]
      real(rp) :: end_time = huge(1.0_rp)     !< the inlet closes and acts as a wall [s]
      integer :: particles_per_cell = 2       !< particles per cell per direction
      logical :: hydrostatic = .false.        !< new particles carry the hydrostatic pressure below the stream top
   end type inlet_spec_t

   public :: opening_tangent, opening_far_end, has_velocity_file, shifts_particles, relaxes_to_eos, writes_particle_field, &
             structure_shape

   !> `&material`: one constitutive model and its parameters.
   type, public :: material_spec_t
      character(len=name_len) :: name = ''
      character(len=name_len) :: model = ''
      real(rp) :: density = 0.0_rp            !< reference density [kg/m^3]
      real(rp) :: bulk_modulus = 0.0_rp       !< fluid K [Pa]
      real(rp) :: viscosity = 0.0_rp          !< fluid dynamic viscosity mu [Pa s]
      real(rp) :: youngs_modulus = 0.0_rp     !< solid E [Pa]
      real(rp) :: poisson_ratio = 0.0_rp      !< solid nu [-]
      character(len=name_len) :: stabilization = 'none'   !< anti-locking / smoothing scheme
      logical :: volumetric_only = .false.    !< C0: average only the volumetric parts (B-bar-like)
      character(len=name_len) :: oscillation_rule = 'OR'  !< FOAL1: 'OR' or 'AND' of the two cells' flags
      real(rp) :: gamma_max = 1.0_rp          !< FOAL1: flux tuning coefficient in [0, 1]
      character(len=name_len) :: smoothed_variables = 'stress'   !< FOAL1: 'stress' (all components) or 'pressure'
      logical :: cell_averaging = .true.      !< FOAL1: replace particle values by the cell average first
      !> Fluid volume consistency (docs/volume-conservation.md): 'none', 'shifting', 'eos_relaxation' or
      !> 'shifting+eos_relaxation' (read with shifts_particles / relaxes_to_eos)
      character(len=name_len) :: volume_correction = 'none'
      real(rp) :: shifting_coefficient = 0.02_rp   !< shifting: D in dx = -D h^2 grad(excess occupancy), per step
      real(rp) :: eos_relaxation_rate = 0.01_rp    !< eos_relaxation: fraction of p - p_EOS(rho) removed per step
   end type material_spec_t

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

   !> `&contact`: bodies of two solid materials (or of one, against each other), or of a solid material and
   !> a `&structure`, in contact with their own velocity fields, separating and sliding with Coulomb
   !> friction (docs/contact.md).
   type, public :: contact_spec_t
      character(len=name_len) :: between(2) = ''   !< two material names (may be the same), or a material and a structure
      real(rp) :: friction = 0.0_rp                !< Coulomb coefficient mu >= 0
      integer :: material_index(2) = 0             !< derived: positions in scene%materials (0: a structure)
      integer :: structure_index(2) = 0            !< derived: positions in scene%structures (0: a material)
   end type contact_spec_t

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

   !> The material's volume correction includes shifting (docs/volume-conservation.md).
   pure logical function shifts_particles(material)
      type(material_spec_t), intent(in) :: material
      shifts_particles = index(material%volume_correction, 'shifting') > 0
   end function shifts_particles

   !> The material's volume correction includes the EOS relaxation: its fluid also starts in EOS states.
   pure logical function relaxes_to_eos(material)
      type(material_spec_t), intent(in) :: material
      relaxes_to_eos = index(material%volume_correction, 'eos_relaxation') > 0
   end function relaxes_to_eos

   !> `&run particle_fields` asks for particle dataset `name` ('all' asks for every one).
   pure logical function writes_particle_field(run, name)
      type(run_control_t), intent(in) :: run
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: item
      integer :: start, comma
      writes_particle_field = .false.
      start = 1
      do
         comma = index(run%particle_fields(start:), ',')
         if (comma == 0) then
            item = trim(adjustl(run%particle_fields(start:)))
         else
            item = trim(adjustl(run%particle_fields(start:start + comma - 2)))
         end if
         if (item == 'all' .or. item == name) then
            writes_particle_field = .true.
            return
         end if
         if (comma == 0) return
         start = start + comma
      end do
   end function writes_particle_field

   !> The shape of a `&structure` (validated) in a `dim`-D scene: a box given by its corners lower..upper
   !> as centre and size (resolve_scene stores it so).
   pure function structure_shape(structure, dim) result(shape)
      type(structure_spec_t), intent(in) :: structure
      integer, intent(in) :: dim
      type(shape_t) :: shape
      shape = structure%shape
      if (structure%lower(1) < huge(1.0_rp)) shape = box_corners(shape, structure%lower, structure%upper, dim)
   end function structure_shape

   !> The inlet's speed (and height) follow the time table of its velocity_file.
   pure logical function has_velocity_file(inlet)
      type(inlet_spec_t), intent(in) :: inlet
      has_velocity_file = len_trim(inlet%velocity_file) > 0
   end function has_velocity_file

   !> The in-plane direction along which an inlet's `height` runs: t = (-d_y, d_x, 0), d the unit
   !> flow direction.
   pure function opening_tangent(inlet) result(tangent)
      type(inlet_spec_t), intent(in) :: inlet
      real(rp) :: tangent(3), d(2)
      d = inlet%direction(1:2) / norm2(inlet%direction(1:2))
      tangent = [-d(2), d(1), 0.0_rp]
   end function opening_tangent

   !> The corner of an inlet's opening opposite `point`: point + height t (+ width e_z in 3-D).
   pure function opening_far_end(inlet, dim) result(far_end)
      type(inlet_spec_t), intent(in) :: inlet
      integer, intent(in) :: dim
      real(rp) :: far_end(3)
      far_end = inlet%point + inlet%height * opening_tangent(inlet)
      if (dim == 3) far_end(3) = far_end(3) + inlet%width
   end function opening_far_end
end module scene_description
