!> Tests of the load names and gauges of src/input/: `read_scene` resolves the default names, moment
!> points and gauge radii, and every rank receives them (the gauges travel with the scene); an override
!> selects a wall or gauge by name; a name clash fails on every rank with the same message.
module test_scene_reader
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Barrier
   use kinds, only: rp
   use assertions, only: assertEqual, assertTrue, assertFalse
   use error_status, only: status_t
   use scene_description, only: scene_t, writes_particle_field
   use scene_reader, only: read_scene, scene_override_t
   use scene_record, only: scene_namelist_text
   implicit none
   private

   public :: test_default_names_are_resolved, test_gauges_arrive_on_every_rank, test_override_selects_wall_by_name, &
             test_name_clash_fails_on_every_rank, test_resolved_text_reads_back, test_particle_fields_list

   !> The scene of every test: named and unnamed box sides, walls, bodies and an inlet, three gauge kinds
   !> and a gauge that shares a wall's name (gauges.csv is a file of its own).
   character(len=*), parameter :: scene_file = 'load_names.nml'
   character(len=*), parameter :: scene_lines(*) = [character(len=110) :: &
      "&run end_time = 1.0, output_dir = 'out_load_names', load_interval = 0.002 /", &
      "&grid dim = 2, cell_size = 0.1, extent = 3.0, 2.0, rotation = 30.0 /", &
      "&box_walls x_min = 'slip', x_max = 'no_slip', y_min = 'slip', x_min_name = 'left' /", &
      "&material name = 'water', model = 'newtonian_fluid', density = 1000.0, bulk_modulus = 2.0e6 /", &
      "&material name = 'block', model = 'linear_elastic', density = 500.0, youngs_modulus = 1.0e6 /", &
      "&body material = 'water', lower = 0.0, 0.0, upper = 1.0, 1.0 /", &
      "&body name = 'debris', material = 'block', lower = 1.5, 0.0, upper = 1.7, 0.2 /", &
      "&wall point = 2.5, 0.0, normal = -1.0, 0.0, lower = 2.5, 0.0, upper = 2.5, 1.0 /", &
      "&wall name = 'pier', point = 2.0, 0.5, normal = -1.0, 0.0, moment_point = 2.0, 0.0 /", &
      "&wall point = 1.0, 0.5, normal = 1.0, 0.0, moment_point(2) = 0.25 /", &
      "&inlet material = 'water', point = 0.0, 1.2, direction = 1.0, 0.0, height = 0.3, velocity = 1.0 /", &
      "&gauge name = 'p_pier', kind = 'Pressure', point = 2.0, 0.3 /", &
      "&gauge name = 'level_mid', kind = 'level', point = 1.5, 0.0 /", &
      "&gauge name = 'v_jet', kind = 'velocity', point = 0.5, 1.3, radius = 0.25 /", &
      "&gauge name = 'left', kind = 'pressure', point = 0.0, 0.5 /"]

contains

   !> Rank 0 writes the scene file; every rank waits for it.
   subroutine write_scene_file(comm)
      type(MPI_Comm), intent(in) :: comm
      integer :: rank, unit, i
      call MPI_Comm_rank(comm, rank)
      if (rank == 0) then
         open (newunit=unit, file=scene_file, status='replace', action='write')
         do i = 1, size(scene_lines)
            write (unit, '(a)') trim(scene_lines(i))
         end do
         close (unit)
      end if
      call MPI_Barrier(comm)
   end subroutine write_scene_file

   subroutine test_default_names_are_resolved(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(status_t) :: status

      call write_scene_file(comm)
      call read_scene(scene_file, comm, scene, status)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      call assertEqual(0.002_rp, scene%run%load_interval, 'load_interval')
      call assertEqual('left', trim(scene%grid%wall_name(1, 1)), 'x_min named')
      call assertEqual('x_max', trim(scene%grid%wall_name(2, 1)), 'x_max default')
      call assertEqual('y_min', trim(scene%grid%wall_name(1, 2)), 'y_min default')
      call assertEqual('', trim(scene%grid%wall_name(2, 2)), 'open side y_max has no name')
      call assertEqual(3, size(scene%walls), 'walls')
      call assertEqual('wall_1', trim(scene%walls(1)%name), 'wall 1 default')
      call assertEqual('pier', trim(scene%walls(2)%name), 'wall 2 named')
      call assertEqual('wall_3', trim(scene%walls(3)%name), 'wall 3 default')
      call assertEqual(scene%walls(1)%point, scene%walls(1)%moment_point, 'moment point defaults to point')
      call assertEqual([2.0_rp, 0.0_rp, 0.0_rp], scene%walls(2)%moment_point, 'moment point given')
      call assertEqual([1.0_rp, 0.25_rp, 0.0_rp], scene%walls(3)%moment_point, 'components not given are point''s')
      call assertEqual('inlet_1', trim(scene%inlets(1)%name), 'inlet default')
      call assertEqual('body_1', trim(scene%bodies(1)%name), 'body 1 default')
      call assertEqual('debris', trim(scene%bodies(2)%name), 'body 2 named')
   end subroutine test_default_names_are_resolved

   subroutine test_gauges_arrive_on_every_rank(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(status_t) :: status

      call write_scene_file(comm)
      call read_scene(scene_file, comm, scene, status)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      call assertEqual(4, size(scene%gauges), 'gauges')
      if (size(scene%gauges) /= 4) return
      call assertEqual('p_pier', trim(scene%gauges(1)%name), 'name')
      call assertEqual('pressure', trim(scene%gauges(1)%kind), 'kind in lower case')
      call assertEqual('level', trim(scene%gauges(2)%kind), 'kind')
      call assertEqual('velocity', trim(scene%gauges(3)%kind), 'kind')
      call assertEqual('left', trim(scene%gauges(4)%name), 'a gauge may share a wall''s name')
      call assertEqual([2.0_rp, 0.3_rp, 0.0_rp], scene%gauges(1)%point, 'point')
      call assertEqual(0.1_rp, scene%gauges(1)%radius, 'pressure radius defaults to cell_size')
      call assertEqual(0.05_rp, scene%gauges(2)%radius, 'level radius defaults to cell_size / 2')
      call assertEqual(0.25_rp, scene%gauges(3)%radius, 'radius given')
   end subroutine test_gauges_arrive_on_every_rank

   subroutine test_override_selects_wall_by_name(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(status_t) :: status
      type(scene_override_t) :: overrides(2)

      call write_scene_file(comm)
      overrides(1) = scene_override_t("&wall name = 'wall_3', condition = 'no_slip' /", .true.)
      overrides(2) = scene_override_t("&gauge name = 'v_jet', radius = 0.5 /", .true.)
      call read_scene(scene_file, comm, scene, status, overrides)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      call assertEqual('slip', trim(scene%walls(1)%condition), 'wall 1 unchanged')
      call assertEqual('slip', trim(scene%walls(2)%condition), 'wall pier unchanged')
      call assertEqual('no_slip', trim(scene%walls(3)%condition), 'wall 3 selected by its default name')
      call assertEqual(0.5_rp, scene%gauges(3)%radius, 'gauge v_jet changed')
      call assertEqual(0.1_rp, scene%gauges(1)%radius, 'gauge p_pier unchanged')

      overrides(1) = scene_override_t("&gauge name = 'p_wall', radius = 0.5 /", .true.)
      call read_scene(scene_file, comm, scene, status, overrides(1:1))
      call assertFalse(status%ok, 'override of a gauge the scene does not have')
      call assertTrue(index(status%message, "the scene has no &gauge with name = 'p_wall'") > 0, status%message)
   end subroutine test_override_selects_wall_by_name

   subroutine test_name_clash_fails_on_every_rank(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(status_t) :: status
      type(scene_override_t) :: overrides(1)

      call write_scene_file(comm)
      overrides(1) = scene_override_t("&body material = 'block', name = 'pier' /", .true.)
      call read_scene(scene_file, comm, scene, status, overrides)
      call assertFalse(status%ok, 'a body named like a wall')
      call assertEqual(scene_file//" with --set 1: group &body (2nd, material 'block'): variable name 'pier' is "// &
                       'already used by the 2nd &wall', trim(status%message), 'message')
      call assertFalse(allocated(scene%gauges), 'no scene on failure')
   end subroutine test_name_clash_fails_on_every_rank

   !> The resolved scene's text (scene.nml of the output folder), read as a scene file, gives the same
   !> scene: the same text again, and the values that were derived (names, radii, moment points) as given.
   subroutine test_resolved_text_reads_back(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene, again
      type(status_t) :: status
      type(scene_override_t) :: overrides(1)
      character(len=:), allocatable :: text
      integer :: rank, unit

      call write_scene_file(comm)
      overrides(1) = scene_override_t("&material name = 'block', poisson_ratio = 0.1234567890123 / "// &
                                      "&run field_precision = 'Single', particle_fields = 'pressure, id' /", .true.)
      call read_scene(scene_file, comm, scene, status, overrides)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      text = scene_namelist_text(scene)
      call MPI_Comm_rank(comm, rank)
      if (rank == 0) then
         open (newunit=unit, file='resolved_scene.nml', status='replace', action='write')
         write (unit, '(a)', advance='no') text
         close (unit)
      end if
      call MPI_Barrier(comm)
      call read_scene('resolved_scene.nml', comm, again, status)
      call assertTrue(status%ok, 'the resolved text reads as a scene: '//trim(status%message))
      if (.not. status%ok) return
      call assertTrue(scene_namelist_text(again) == text, 'the same text again')
      call assertEqual('single', trim(again%run%field_precision), 'field_precision')
      call assertEqual('pressure,id', trim(again%run%particle_fields), 'particle_fields without blanks')
      call assertEqual(0.1234567890123_rp, again%materials(2)%poisson_ratio, 'a real exactly')
      call assertEqual(scene%run%output_interval, again%run%output_interval, 'resolved output_interval')
      call assertEqual(scene%gauges(1)%radius, again%gauges(1)%radius, 'resolved gauge radius')
      call assertEqual(scene%walls(3)%moment_point, again%walls(3)%moment_point, 'resolved moment point')
      call assertEqual(scene%inlets(1)%end_time, again%inlets(1)%end_time, 'inlet end_time (huge: never closes)')
      call assertEqual(scene%grid%rotation, again%grid%rotation, 'rotation')
      call assertEqual('wall_3', trim(again%walls(3)%name), 'default name written')
      call assertEqual(0, index(text, 'overwrite'), 'overwrite is not part of the text')
   end subroutine test_resolved_text_reads_back

   !> `&run particle_fields`: names without blanks, in any case; 'all' (the default) selects every one.
   subroutine test_particle_fields_list(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(status_t) :: status
      type(scene_override_t) :: overrides(1)

      call write_scene_file(comm)
      call read_scene(scene_file, comm, scene, status)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      call assertEqual('all', trim(scene%run%particle_fields), 'default')
      call assertEqual('double', trim(scene%run%field_precision), 'default precision')
      call assertTrue(writes_particle_field(scene%run, 'stress'), 'all: stress')
      overrides(1) = scene_override_t("&run particle_fields = ' Velocity , Mean_Stress,rank' /", .true.)
      call read_scene(scene_file, comm, scene, status, overrides)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      call assertEqual('velocity,mean_stress,rank', trim(scene%run%particle_fields), 'normalised')
      call assertTrue(writes_particle_field(scene%run, 'velocity'), 'first')
      call assertTrue(writes_particle_field(scene%run, 'mean_stress'), 'middle')
      call assertTrue(writes_particle_field(scene%run, 'rank'), 'last')
      call assertFalse(writes_particle_field(scene%run, 'stress'), 'stress not chosen')
      call assertFalse(writes_particle_field(scene%run, 'mean'), 'no prefix match')
      overrides(1) = scene_override_t("&run particle_fields = 'velocity,pressur' /", .true.)
      call read_scene(scene_file, comm, scene, status, overrides)
      call assertFalse(status%ok, 'unknown field refused')
      call assertTrue(index(status%message, "group &run: variable particle_fields: unknown field 'pressur'") > 0, &
                      trim(status%message))
   end subroutine test_particle_fields_list
end module test_scene_reader
