!> Tests of src/input/scene_record.f90: the resolved scene written as namelist text reads back as the
!> same scene, and every variable the reader knows is written with a value, each group once per entry.
module test_scene_record
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Barrier
   use assertions, only: assertEqual, assertTrue
   use error_status, only: status_t
   use scene_description, only: scene_t
   use scene_reader, only: read_scene, known_groups, group_variables
   use scene_record, only: scene_namelist_text, scene_namelist_groups, namelist_text_t
   implicit none
   private

   public :: test_record_reads_back_as_the_same_scene

   character(len=*), parameter :: nl = new_line('a')

contains

   !> A scene read from a file, written by scene_record and read again gives the same record; every
   !> variable the reader knows has a non-empty value, each group once per entry.
   subroutine test_record_reads_back_as_the_same_scene(comm)
      type(MPI_Comm), intent(in) :: comm
      character(len=*), parameter :: first = 'record_first.nml', second = 'record_second.nml'
      character(len=*), parameter :: lines(*) = [character(len=120) :: &
         "&run end_time = 1.0, output_dir = 'out_record', load_interval = 0.002, dt = 1e-4, max_steps = 7 /", &
         "&grid dim = 2, cell_size = 0.1, extent = 3.0, 2.0, rotation = 30.0 /", &
         "&box_walls x_min = 'slip', x_max = 'no_slip', y_min = 'slip', x_min_name = 'left' /", &
         "&gravity acceleration = 0.0, -9.81 /", &
         "&material name = 'water', model = 'newtonian_fluid', density = 1000.0, bulk_modulus = 2.0e6, ", &
         "          stabilization = 'FOAL1', volume_correction = 'shifting' /", &
         "&material name = 'block', model = 'linear_elastic', density = 500.0, youngs_modulus = 1.0e6 /", &
         "&body material = 'water', lower = 0.0, 0.0, upper = 1.0, 1.0, hydrostatic = T /", &
         "&body name = 'debris', material = 'block', lower = 1.5, 0.0, upper = 1.7, 0.2 /", &
         "&body name = 'log', material = 'block', shape = 'polygon', vertices = 2.0, 1.0, 2.4, 1.0, 2.2, 1.3 /", &
         "&body name = 'drum', material = 'block', shape = 'circle', centre = 2.5, 0.5, radius = 0.2 /", &
         "&wall name = 'pier', point = 2.0, 0.5, normal = -1.0, 0.0, moment_point = 2.0, 0.0 /", &
         "&inlet material = 'water', point = 0.0, 1.2, direction = 2.0, 0.0, height = 0.3, velocity = 1.0 /", &
         "&gauge name = 'p_pier', kind = 'pressure', point = 2.0, 0.3 /", &
         "&structure name = 'reef', shape = 'polygon', vertices = 2.2, 0.0, 2.8, 0.0, 2.5, 0.4,", &
         "           condition = 'friction', friction = 0.3 /", &
         "&structure lower = 2.0, 1.0, upper = 2.4, 1.2, rotation = 10.0 /"]
      type(scene_t) :: scene, again
      type(status_t) :: status
      type(namelist_text_t), allocatable :: groups(:)
      character(len=:), allocatable :: text, text_again, names(:)
      integer :: rank, unit, i, g, v

      call MPI_Comm_rank(comm, rank)
      if (rank == 0) then
         open (newunit=unit, file=first, status='replace', action='write')
         do i = 1, size(lines)
            write (unit, '(a)') trim(lines(i))
         end do
         close (unit)
      end if
      call MPI_Barrier(comm)
      call read_scene(first, comm, scene, status)
      call assertTrue(status%ok, 'read_scene: '//trim(status%message))
      if (.not. status%ok) return
      text = scene_namelist_text(scene)
      if (rank == 0) then
         open (newunit=unit, file=second, status='replace', action='write')
         write (unit, '(a)') text
         close (unit)
      end if
      call MPI_Barrier(comm)
      call read_scene(second, comm, again, status)
      call assertTrue(status%ok, 'read_scene of the record: '//trim(status%message))
      if (.not. status%ok) return
      text_again = scene_namelist_text(again)
      call assertEqual(text, text_again, 'the record of the record is the record')
      call assertEqual(0, index(text, ' = '//nl), 'every variable has a value')
      call assertTrue(index(text, "   direction = 1.0, 0.0, 0.0"//nl) > 0, 'resolved values: unit inlet direction')
      call assertTrue(index(text, "   name = 'body_1'"//nl) > 0, 'resolved values: default body name')
      call assertTrue(index(text, "   vertices = 2.2, 0.0, 2.8, 0.0, 2.5, 0.4"//nl) > 0, 'the vertices given, as a list')
      call assertTrue(index(text, "   name = 'structure_2'"//nl) > 0, 'resolved values: default structure name')
      call assertTrue(index(text, "   lower = 2.0, 1.0") == 0, 'a box by its corners is resolved into centre and size')

      groups = scene_namelist_groups(scene)
      call assertEqual(4 + 2 + 4 + 1 + 1 + 1 + 2, size(groups), 'singleton groups once, repeated ones per entry')
      call assertTrue(index(text, "   vertices = 2.0, 1.0, 2.4, 1.0, 2.2, 1.3"//nl) > 0, 'vertices as given')
      call assertTrue(index(text, "   vertices = ,"//nl) > 0, 'no vertices: a null value')
      do g = 1, size(known_groups)
         names = group_variables(trim(known_groups(g)))
         do i = 1, size(groups)
            if (index(groups(i)%text, '&'//trim(known_groups(g))//nl) /= 1) cycle
            ! &run overwrite is left out: an action on the output folder, not part of the scene
            call assertEqual(size(names) - count(names == 'overwrite'), count_lines(groups(i)%text) - 2, &
                             trim(known_groups(g))//': one line per variable')
            do v = 1, size(names)
               if (names(v) == 'overwrite') then
                  call assertEqual(0, index(groups(i)%text, nl//'   overwrite = '), 'overwrite is not written')
                  cycle
               end if
               call assertTrue(index(groups(i)%text, nl//'   '//trim(names(v))//' = ') > 0, &
                               trim(known_groups(g))//'%'//trim(names(v))//' is written')
            end do
         end do
      end do
   end subroutine test_record_reads_back_as_the_same_scene

   pure integer function count_lines(text) result(n)
      character(len=*), intent(in) :: text
      integer :: i
      n = 1
      do i = 1, len(text)
         if (text(i:i) == nl) n = n + 1
      end do
   end function count_lines
end module test_scene_record
