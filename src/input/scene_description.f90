!> What a scene declares: the values read from the namelist groups of a scene file (documented group by
!> group in docs/input.md), one entry per group, and the tables and points its files hold. Only what is
!> declared is modelled. Each group's variables (their types and defaults, the reader's rows, the
!> namelist read, the scene.nml text) are declared in its module of src/input/groups/.
module scene_description
   use kinds, only: rp, path_len
   use time_table, only: time_table_t
   use run_group, only: run_control_t, writes_particle_field, particle_field_names, field_precision_keywords
   use grid_group, only: grid_spec_t, wall_none, wall_slip, wall_no_slip, wall_friction
   use material_group, only: material_spec_t, model_newtonian_fluid, model_linear_elastic, model_rigid, &
                             shifts_particles, relaxes_to_eos
   use body_group, only: body_spec_t
   use motion_spec, only: motion_spec_t, motion_none, motion_solitary_wave, motion_table
   use wall_group, only: wall_spec_t
   use structure_group, only: structure_spec_t, structure_shape
   use inlet_group, only: inlet_spec_t, has_velocity_file, opening_tangent, opening_far_end
   use gauge_group, only: gauge_spec_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, &
                          gauge_wall_pressure
   use panel_group, only: panel_spec_t, panel_surface, panel_load_cell
   use damping_zone_group, only: damping_zone_spec_t
   use contact_group, only: contact_spec_t
   implicit none
   private

   ! each group's type, keywords and helpers live in its module (src/input/groups/), named here for the
   ! scene's users
   public :: run_control_t, writes_particle_field, particle_field_names, field_precision_keywords
   public :: grid_spec_t, wall_none, wall_slip, wall_no_slip, wall_friction
   public :: material_spec_t, model_newtonian_fluid, model_linear_elastic, model_rigid, shifts_particles, &
             relaxes_to_eos
   public :: body_spec_t
   public :: motion_spec_t, motion_none, motion_solitary_wave, motion_table
   public :: wall_spec_t
   public :: structure_spec_t, structure_shape
   public :: inlet_spec_t, has_velocity_file, opening_tangent, opening_far_end
   public :: gauge_spec_t, gauge_pressure, gauge_level, gauge_connected_level, gauge_velocity, gauge_wall_pressure
   public :: panel_spec_t, panel_surface, panel_load_cell, damping_zone_spec_t
   public :: contact_spec_t

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
      type(panel_spec_t), allocatable :: panels(:)     !< `&panel` groups (panels.csv)
      type(contact_spec_t), allocatable :: contacts(:)
      type(damping_zone_spec_t), allocatable :: damping_zones(:)   !< `&damping_zone` groups
   end type scene_t
end module scene_description
