!> Tests of src/io/checkpoint.f90: a run continued from a checkpoint on the same ranks is bitwise the
!> uninterrupted run; on another number of ranks equal to round-off; checkpoints of another scene or
!> format version are refused; only the newest checkpoints are kept. Both restarts also from an active
!> region that has moved with the particles (cuts that do not span the grid).
module test_checkpoint
   use kinds, only: rp, i8
   use mpi_f08, only: MPI_Comm, MPI_Comm_rank, MPI_Comm_size, MPI_Comm_split, MPI_Comm_free, MPI_Bcast, &
                      MPI_DOUBLE_PRECISION, MPI_UNDEFINED, MPI_COMM_NULL, operator(/=)
   use assertions, only: assertEqual, assertTrue, assertFalse, assertRelativelyEqual
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use run_diagnostics, only: diagnostics_t
   use run_progress, only: run_progress_t
   use xdmf_writer, only: output_entry_t
   use checkpoint, only: write_checkpoint, read_checkpoint, latest_checkpoint_path, checkpoint_format_version
   use input_text, only: int_text
   use output_directory, only: prepare_output_directory
   use output_layout, only: checkpoint_file
   use file_system, only: path_exists
   use hdf5_file, only: hdf5_file_t
   use test_scenes, only: water_scene, add_body
   implicit none
   private

   public :: test_restart_on_same_ranks_is_bitwise, test_restart_with_foal1_is_bitwise, test_restart_on_other_rank_count, &
             test_restart_with_apic_is_bitwise, test_apic_restart_on_other_rank_count, &
             test_restart_of_moved_region_is_bitwise, test_moved_region_on_other_rank_count, &
             test_checkpoint_of_other_scene_is_refused, test_other_format_version_is_refused, &
             test_only_newest_checkpoints_are_kept

   !> Steps before the checkpoint (not a multiple of the solver's re-sort interval of 20) and after it.
   integer, parameter :: steps_before = 37, steps_after = 50

contains

   !> A water column collapsing in a 4 m x 2 m box: particles cross rank boundaries, automatic dt.
   function column_scene(dir) result(scene)
      character(len=*), intent(in) :: dir
      type(scene_t) :: scene
      scene = water_scene(2, 0.05_rp, [4.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 9.81_rp)
      call add_body(scene, 1, [0.0_rp, 0.0_rp, 0.0_rp], [1.0_rp, 1.0_rp, 0.0_rp], 2, .false., 0.0_rp)
      scene%run%output_dir = dir
   end function column_scene

   !> A free block of water (no gravity) crossing the 4 m x 2 m box at (40, 10) m/s: the active region
   !> has been laid out anew before the checkpoint and is again after it, its slabs do not reach the
   !> grid's edges.
   function travelling_scene(dir) result(scene)
      character(len=*), intent(in) :: dir
      type(scene_t) :: scene
      scene = water_scene(2, 0.05_rp, [4.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 0.0_rp)
      call add_body(scene, 1, [0.5_rp, 0.5_rp, 0.0_rp], [1.0_rp, 1.0_rp, 0.0_rp], 2, .false., 0.0_rp)
      scene%bodies(1)%velocity = [40.0_rp, 10.0_rp, 0.0_rp]
      scene%run%output_dir = dir
   end function travelling_scene

   !> Run `steps_before` steps, write a checkpoint into `dir` (path returned), run `steps_after` more.
   subroutine run_with_checkpoint(scene, comm, solver, path, layouts)
      type(scene_t), intent(in) :: scene
      type(MPI_Comm), intent(in) :: comm
      type(solver_t), intent(inout) :: solver
      character(len=:), allocatable, intent(out) :: path
      integer, intent(out), optional :: layouts           !< of the active region, before the checkpoint
      type(status_t) :: status
      type(run_progress_t) :: progress
      type(output_entry_t) :: entry
      integer :: step
      call prepare_output_directory(scene%run%output_dir, .true., comm, status)
      call solver%init(scene, comm, status)
      do step = 1, steps_before
         call solver%advance()
      end do
      entry%index = 0
      entry%time = 0.0_rp
      entry%particles = 40000
      entry%grid_cells = [20, 20, 1]
      entry%grid_origin = [0.0_rp, 0.25_rp, 0.0_rp]
      call progress%add_output(entry)
      progress%next_output_time = 0.1_rp
      if (present(layouts)) layouts = solver%relayouts
      call write_checkpoint(solver, progress, scene%run%output_dir, 2, path, status)
      call assertTrue(status%ok, 'write_checkpoint: '//trim(status%message))
      do step = 1, steps_after
         call solver%advance()
      end do
   end subroutine run_with_checkpoint

   subroutine test_restart_on_same_ranks_is_bitwise(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_bitwise_restart(comm, column_scene('same_ranks'))
   end subroutine test_restart_on_same_ranks_is_bitwise

   !> The same with the FOAL1 smoothing, whose schemes keep work arrays between steps.
   subroutine test_restart_with_foal1_is_bitwise(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = column_scene('foal1')
      scene%materials(1)%stabilization = 'FOAL1'
      call check_bitwise_restart(comm, scene)
   end subroutine test_restart_with_foal1_is_bitwise

   !> The same with APIC: the affine matrices B_p are part of the state (checkpoint /particles/affine).
   subroutine test_restart_with_apic_is_bitwise(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = column_scene('apic')
      scene%run%transfer = 'apic'
      scene%run%fixed_dt = 1.0e-4_rp     ! APIC is not stable at this column's CFL step (docs/theory.md)
      call check_bitwise_restart(comm, scene)
   end subroutine test_restart_with_apic_is_bitwise

   !> APIC written on all ranks, continued on one rank fewer: the B_p travel with their particles.
   subroutine test_apic_restart_on_other_rank_count(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      scene = column_scene('apic_other_ranks')
      scene%run%transfer = 'apic'
      scene%run%fixed_dt = 1.0e-4_rp
      call check_restart_on_fewer_ranks(comm, scene)
   end subroutine test_apic_restart_on_other_rank_count

   !> The checkpoint of a moved active region (cuts that do not span the grid) continues bitwise.
   subroutine test_restart_of_moved_region_is_bitwise(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_bitwise_restart(comm, travelling_scene('moved_region'), region_moves=.true.)
   end subroutine test_restart_of_moved_region_is_bitwise

   subroutine check_bitwise_restart(comm, scene, region_moves)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      logical, intent(in), optional :: region_moves
      type(solver_t) :: uninterrupted, restarted
      type(run_progress_t) :: progress
      type(status_t) :: status
      type(diagnostics_t) :: a, b
      character(len=:), allocatable :: path
      integer :: step, n, layouts_at_checkpoint

      call run_with_checkpoint(scene, comm, uninterrupted, path, layouts_at_checkpoint)
      if (present(region_moves)) &
         call assertTrue(layouts_at_checkpoint > 0, 'the region moved before the checkpoint')
      call restarted%init(scene, comm, status, seed_particles=.false.)
      call read_checkpoint(path, scene, restarted, progress, status)
      call assertTrue(status%ok, 'read_checkpoint: '//trim(status%message))
      call assertEqual(int(steps_before, i8), restarted%step, 'step restored')
      call assertEqual(0.1_rp, progress%next_output_time, 0.0_rp, 'next output time restored')
      call assertEqual(1, progress%output_count(), 'outputs restored')
      if (progress%output_count() == 1) then
         call assertEqual([20, 20, 1], progress%outputs(1)%grid_cells, 'output entry')
         call assertEqual(0.25_rp, progress%outputs(1)%grid_origin(2), 0.0_rp, 'output entry origin')
      end if
      do step = 1, steps_after
         call restarted%advance()
      end do

      a = uninterrupted%diagnostics()
      b = restarted%diagnostics()
      call assertEqual(a%time, b%time, 0.0_rp, 'time')
      call assertEqual(a%dt, b%dt, 0.0_rp, 'dt')
      call assertEqual(a%kinetic_energy, b%kinetic_energy, 0.0_rp, 'kinetic energy, bitwise')
      call assertEqual(a%fluid_volume, b%fluid_volume, 0.0_rp, 'fluid volume, bitwise')
      call assertEqual(a%max_speed, b%max_speed, 0.0_rp, 'max speed, bitwise')
      call assertEqual(a%wall_corrections, b%wall_corrections, 'wall corrections')
      n = uninterrupted%particles%count
      call assertEqual(n, restarted%particles%count, 'particles on this rank')
      if (n == restarted%particles%count) then
         call assertEqual(uninterrupted%particles%x(:, 1:n), restarted%particles%x(:, 1:n), 0.0_rp, 'positions')
         call assertEqual(uninterrupted%particles%v(:, 1:n), restarted%particles%v(:, 1:n), 0.0_rp, 'velocities')
         call assertEqual(uninterrupted%particles%sbar(:, 1:n), restarted%particles%sbar(:, 1:n), 0.0_rp, 'stresses')
         call assertTrue(all(uninterrupted%particles%id(1:n) == restarted%particles%id(1:n)), 'same order')
         call assertEqual(uninterrupted%particles%n_affine, restarted%particles%n_affine, 'affine matrices carried')
         if (uninterrupted%particles%n_affine > 0) &
            call assertEqual(uninterrupted%particles%affine(:, 1:n), restarted%particles%affine(:, 1:n), 0.0_rp, &
                             'affine matrices (APIC)')
      end if
      call uninterrupted%free()
      call restarted%free()
   end subroutine check_bitwise_restart

   !> Written on all ranks of comm, continued on one rank fewer.
   subroutine test_restart_on_other_rank_count(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_restart_on_fewer_ranks(comm, column_scene('other_ranks'))
   end subroutine test_restart_on_other_rank_count

   !> The same with a moved active region: the fewer ranks lay a region out around the particles read.
   subroutine test_moved_region_on_other_rank_count(comm)
      type(MPI_Comm), intent(in) :: comm
      call check_restart_on_fewer_ranks(comm, travelling_scene('moved_other_ranks'))
   end subroutine test_moved_region_on_other_rank_count

   subroutine check_restart_on_fewer_ranks(comm, scene)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t), intent(in) :: scene
      type(solver_t) :: uninterrupted, restarted
      type(run_progress_t) :: progress
      type(status_t) :: status
      type(diagnostics_t) :: a, b
      type(MPI_Comm) :: fewer
      character(len=:), allocatable :: path
      real(rp) :: values(5)
      integer :: rank, n_ranks, step

      call MPI_Comm_rank(comm, rank)
      call MPI_Comm_size(comm, n_ranks)
      call run_with_checkpoint(scene, comm, uninterrupted, path)
      a = uninterrupted%diagnostics()
      call uninterrupted%free()

      call MPI_Comm_split(comm, merge(0, MPI_UNDEFINED, rank < n_ranks - 1), 0, fewer)
      values = 0.0_rp
      if (fewer /= MPI_COMM_NULL) then
         call restarted%init(scene, fewer, status, seed_particles=.false.)
         call read_checkpoint(path, scene, restarted, progress, status)
         call assertTrue(status%ok, 'read_checkpoint: '//trim(status%message))
         do step = 1, steps_after
            call restarted%advance()
         end do
         b = restarted%diagnostics()
         values = [b%time, b%total_mass, b%kinetic_energy, b%fluid_volume, b%max_speed]
         call assertEqual(a%particles, b%particles, 'particles')
         call restarted%free()
         call MPI_Comm_free(fewer)
      end if
      call MPI_Bcast(values, size(values), MPI_DOUBLE_PRECISION, 0, comm)
      call assertRelativelyEqual(a%time, values(1), 1.0e-12_rp, 'time')
      call assertRelativelyEqual(a%total_mass, values(2), 1.0e-12_rp, 'total mass')
      call assertRelativelyEqual(a%kinetic_energy, values(3), 1.0e-10_rp, 'kinetic energy')
      call assertRelativelyEqual(a%fluid_volume, values(4), 1.0e-10_rp, 'fluid volume')
      call assertRelativelyEqual(a%max_speed, values(5), 1.0e-10_rp, 'max speed')
      call assertEqual(0_i8, a%lost_particles, 'none lost')
   end subroutine check_restart_on_fewer_ranks

   subroutine test_checkpoint_of_other_scene_is_refused(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene, other
      type(solver_t) :: written, restarted, renamed
      type(run_progress_t) :: progress
      type(status_t) :: status
      character(len=:), allocatable :: path

      scene = column_scene('other_scene')
      call run_with_checkpoint(scene, comm, written, path)
      call written%free()

      other = water_scene(2, 0.1_rp, [4.0_rp, 2.0_rp, 0.0_rp], 2.0e6_rp, 9.81_rp)
      call add_body(other, 1, [0.0_rp, 0.0_rp, 0.0_rp], [1.0_rp, 1.0_rp, 0.0_rp], 2, .false., 0.0_rp)
      call restarted%init(other, comm, status, seed_particles=.false.)
      call read_checkpoint(path, other, restarted, progress, status)
      call assertFalse(status%ok, 'another cell size is refused')
      call assertTrue(index(status%message, 'was written for another grid') > 0, 'message: '//trim(status%message))
      call assertEqual(0, restarted%particles%count, 'nothing was adopted')
      call restarted%free()

      status = status_t()
      other = scene
      other%materials(1)%name = 'oil'
      other%bodies(1)%material = 'oil'
      call renamed%init(other, comm, status, seed_particles=.false.)
      call read_checkpoint(path, other, renamed, progress, status)
      call assertTrue(index(status%message, "material 1 is 'water' there and 'oil' in the scene") > 0, &
                      'message: '//trim(status%message))
      call renamed%free()
   end subroutine test_checkpoint_of_other_scene_is_refused

   subroutine test_other_format_version_is_refused(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(run_progress_t) :: progress
      type(status_t) :: status
      type(hdf5_file_t) :: file

      call file%create('future.h5', comm, status)
      call file%write_attribute('format', 'flotsam checkpoint', status)
      call file%write_attribute('format_version', 99, status)
      call file%write_attribute('complete', 1, status)
      call file%close(status)
      call file%create('other.h5', comm, status)
      call file%write_attribute('format', 'something else', status)
      call file%close(status)

      scene = column_scene('unused')
      call solver%init(scene, comm, status, seed_particles=.false.)
      call read_checkpoint('future.h5', scene, solver, progress, status)
      call assertTrue(index(status%message, 'checkpoint future.h5 has format version 99; this build of flotsam '// &
                            'reads version '//int_text(checkpoint_format_version)) > 0, 'message: '//trim(status%message))
      status = status_t()
      call read_checkpoint('other.h5', scene, solver, progress, status)
      call assertTrue(index(status%message, 'checkpoint other.h5 is not a Flotsam checkpoint') > 0, &
                      'message: '//trim(status%message))
      status = status_t()
      call read_checkpoint('missing.h5', scene, solver, progress, status)
      call assertTrue(index(status%message, 'cannot open checkpoint missing.h5: missing, truncated or not an HDF5 '// &
                            'file') > 0, 'message: '//trim(status%message))
      call solver%free()
   end subroutine test_other_format_version_is_refused

   subroutine test_only_newest_checkpoints_are_kept(comm)
      type(MPI_Comm), intent(in) :: comm
      type(scene_t) :: scene
      type(solver_t) :: solver
      type(run_progress_t) :: progress
      type(status_t) :: status
      character(len=:), allocatable :: path
      integer :: k, rank

      call MPI_Comm_rank(comm, rank)
      scene = column_scene('kept')
      call prepare_output_directory('kept', .true., comm, status)
      call solver%init(scene, comm, status)
      do k = 1, 4
         call solver%advance()
         call write_checkpoint(solver, progress, 'kept', 2, path, status)
      end do
      call assertTrue(status%ok, 'write_checkpoint: '//trim(status%message))
      call assertEqual(4, progress%checkpoints_written, 'numbered 1, 2, 3, 4')
      if (rank == 0) then
         call assertFalse(path_exists('kept/'//checkpoint_file(1)), 'first removed')
         call assertFalse(path_exists('kept/'//checkpoint_file(2)), 'second removed')
         call assertTrue(path_exists('kept/'//checkpoint_file(3)), 'third kept')
         call assertTrue(path_exists('kept/'//checkpoint_file(4)), 'fourth kept')
         call assertEqual('kept/'//checkpoint_file(4), latest_checkpoint_path('kept', status), 'latest')
         call assertTrue(status%ok, 'latest: '//trim(status%message))
      end if
      call solver%free()
   end subroutine test_only_newest_checkpoints_are_kept
end module test_checkpoint
