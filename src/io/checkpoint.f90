!> Checkpoints: the full state a run needs to continue, in one HDF5 file written by all ranks
!> (docs/output.md, "Checkpoints and restart").
!>
!> Saved: every particle's persistent state (position, velocity, mass, density, sbar, material, id, and
!> with APIC the affine matrix C_p as /particles/affine) in each rank's order, the rank each slab came
!> from, time, step, the next dt, the per-rank counters
!> (lost particles, wall corrections), the empty-node mass tolerance, and the run's progress (next
!> output time, the outputs written so far, the checkpoint number) and the decomposition (rank count
!> and slab boundaries, which load balancing may have moved). Restarting on the same number of ranks
!> adopts the written decomposition and restores every rank's particles in their order, so the
!> continued run is bitwise identical to an uninterrupted one; on another number the particles are
!> redistributed by position over a uniform split of an active box laid out around them, and
!> re-sorted (equal to round-off).
!>
!> It also stores the resolved scene of the run (scene_record): a restart compares it with the scene it
!> is given and refuses a change of anything but the settings restart_changeable lists
!> (scene_comparison), unless told to allow it.
!>
!> A checkpoint is written as `<name>.tmp`, synced to disk, and renamed only when complete; it carries
!> a format name and version, and an attribute `complete` written last. Reading checks all of these,
!> the scene's grid and materials and the stored scene, and reads everything before it changes the
!> solver: a bad file is refused as a whole.
module checkpoint
   use kinds, only: rp, i8, path_len
   use mpi_f08, only: MPI_Comm_size
   use error_status, only: status_t
   use scene_description, only: scene_t
   use mpm_solver, only: solver_t
   use rigid_bodies, only: rigid_state_width
   use domain_decomposition, only: valid_layout
   use world_frame, only: frame_t, place_grid
   use particle_sorting, only: update_cells
   use hdf5_file, only: hdf5_file_t, slab_t, distributed_slab, even_slab
   use xdmf_writer, only: output_entry_t
   use run_progress, only: run_progress_t
   use output_layout, only: checkpoint_folder, checkpoint_file, latest_checkpoint, temporary_suffix
   use file_system, only: rename_path, remove_file, path_exists
   use status_broadcast, only: agree_on_status, broadcast_status
   use input_text, only: int_text
   use scene_record, only: scene_namelist_text
   use scene_comparison, only: scene_change_t, compare_scene_texts, describe_changes
   use provenance, only: write_provenance_attributes, agreed_date
   implicit none
   private

   !> Identification of the file format; a reader accepts exactly this version.
   character(len=*), parameter, public :: checkpoint_format = 'flotsam checkpoint'
   !> 2: grid rotation; 3: cuts sized (ranks + 1) x 3 for any rank grid (load balancing); their ends, the
   !> active box, need not be the grid's (a version-3 file of the whole grid is read the same way);
   !> 4: the state of the load series; 5: the resolved scene (root attribute `scene`)
   integer, parameter, public :: checkpoint_format_version = 5
   !> The previous version: the same layout without the scene, read only with --allow-scene-change.
   integer, parameter :: unscened_format_version = 4
   !> Longest stored scene read back: an HDF5 attribute in the default (compact) storage holds at most 64 KiB.
   integer, parameter :: scene_text_len = 65536

   !> What a checkpoint holds for this rank, read in full before any of it is adopted.
   type :: saved_state_t
      real(rp) :: time = 0.0_rp, dt = 0.0_rp, reference_steps = 1.0_rp, mass_tolerance = 0.0_rp, next_output_time = 0.0_rp
      integer(i8) :: step = 0
      integer(i8) :: total = 0                    !< particles written
      integer(i8) :: unimproved_largest = 0       !< solver%unimproved_largest (same decomposition only)
      integer :: ranks_written = 1
      integer(i8), allocatable :: rank_counts(:), lost(:), corrections(:)   !< per rank written
      logical :: same_decomposition = .false.     !< written on as many ranks as read: cuts holds its layout
      integer, allocatable :: cuts(:)
      integer :: n = 0                            !< particles this rank read
      real(rp), allocatable :: x(:, :), v(:, :), mass(:), density(:), sbar(:, :)
      real(rp), allocatable :: affine(:, :)       !< APIC's C_p (dim**2, p); zero size without APIC
      integer, allocatable :: material(:)
      integer(i8), allocatable :: id(:)
   end type saved_state_t

   public :: write_checkpoint, read_checkpoint, latest_checkpoint_path

contains

   !> Write checkpoint number progress%checkpoints_written + 1 of the solver's state into `dir`, make it
   !> the latest, and remove the ones older than the newest `kept`. `path` returns its name. Collective.
   subroutine write_checkpoint(solver, progress, dir, kept, path, status)
      type(solver_t), intent(in) :: solver
      type(run_progress_t), intent(inout) :: progress
      character(len=*), intent(in) :: dir
      integer, intent(in) :: kept
      character(len=:), allocatable, intent(out) :: path
      type(status_t), intent(inout) :: status
      type(hdf5_file_t) :: file
      integer :: sequence, m

      sequence = progress%checkpoints_written + 1
      path = trim(dir)//'/'//checkpoint_file(sequence)
      call file%create(path//temporary_suffix, solver%domain%comm, status)
      call file%write_attribute('format', checkpoint_format, status)
      call file%write_attribute('format_version', checkpoint_format_version, status)
      call file%write_attribute('sequence', sequence, status)
      call file%write_attribute('ranks', solver%domain%nranks, status)
      call file%write_attribute('cuts', reshape(solver%domain%cuts, [size(solver%domain%cuts)]), status)
      call file%write_attribute('dim', solver%grid%dim, status)
      call file%write_attribute('cells', solver%grid%global_cells, status)
      call file%write_attribute('origin', solver%grid%origin, status)
      call file%write_attribute('cell_size', solver%grid%h, status)
      call file%write_attribute('rotation', solver%grid%frame%rotation_degrees, status)
      call file%write_attribute('materials', size(solver%materials), status)
      do m = 1, size(solver%materials)
         call file%write_attribute('material_'//int_text(m), solver%materials(m)%model%name, status)
      end do
      call file%write_attribute('time', solver%time, status)
      call file%write_attribute('step', solver%step, status)
      call file%write_attribute('dt', solver%dt, status)
      call file%write_attribute('reference_steps', solver%reference_steps, status)
      call file%write_attribute('mass_tolerance', solver%mass_tolerance, status)
      call file%write_attribute('next_output_time', progress%next_output_time, status)
      call file%write_attribute('unimproved_largest', solver%unimproved_largest, status)
      ! program, date and the resolved scene a restart compares with (its `ranks` is above)
      call write_provenance_attributes(file, solver%scene, agreed_date(solver%domain%comm), status)
      call write_particles(solver, file, status)
      call write_series_state(solver, file, status)      ! after write_particles: it made the group ranks
      call write_outputs(solver, progress, file, status)
      ! last: a file without it was not finished (cannot happen after the rename, but costs nothing)
      call file%write_attribute('complete', 1, status)
      call file%close(status, flush=.true.)
      call agree_on_status(status, solver%domain%comm)
      if (.not. status%ok) return

      if (solver%domain%rank == 0) call publish(dir, path, sequence, kept, status)
      call broadcast_status(status, solver%domain%comm, 0)
      if (status%ok) progress%checkpoints_written = sequence
   end subroutine write_checkpoint

   !> Rank 0: rename the finished file, point `latest` at it, remove checkpoints older than `kept`.
   subroutine publish(dir, path, sequence, kept, status)
      character(len=*), intent(in) :: dir, path
      integer, intent(in) :: sequence, kept
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: pointer_path, old
      integer :: unit, ios, s
      if (.not. rename_path(path//temporary_suffix, path)) then
         call status%fail('cannot rename '//path//temporary_suffix//' to '//path)
         return
      end if
      pointer_path = trim(dir)//'/'//checkpoint_folder//'/'//latest_checkpoint
      open (newunit=unit, file=pointer_path//temporary_suffix, status='replace', action='write', iostat=ios)
      if (ios == 0) write (unit, '(a)', iostat=ios) checkpoint_name(path)
      if (ios == 0) close (unit, iostat=ios)
      if (ios == 0) then
         if (.not. rename_path(pointer_path//temporary_suffix, pointer_path)) ios = 1
      end if
      if (ios /= 0) then
         call status%fail('cannot write '//pointer_path)
         return
      end if
      ! older ones form a contiguous run of numbers below sequence - kept + 1
      do s = sequence - kept, 1, -1
         old = trim(dir)//'/'//checkpoint_file(s)
         if (.not. path_exists(old)) exit
         if (.not. remove_file(old)) exit
      end do
   end subroutine publish

   !> The file name of a checkpoint path (what `latest` holds).
   pure function checkpoint_name(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path(index(path, '/', back=.true.) + 1:)
   end function checkpoint_name

   !> The checkpoint that `dir`/checkpoints/latest names ('' with a failed status if there is none).
   !> Called by one rank.
   function latest_checkpoint_path(dir, status) result(path)
      character(len=*), intent(in) :: dir
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: path
      character(len=path_len) :: name
      character(len=:), allocatable :: pointer_path
      integer :: unit, ios
      path = ''
      pointer_path = trim(dir)//'/'//checkpoint_folder//'/'//latest_checkpoint
      open (newunit=unit, file=pointer_path, status='old', action='read', iostat=ios)
      if (ios == 0) read (unit, '(a)', iostat=ios) name
      if (ios == 0) close (unit)
      if (ios /= 0) then
         call status%fail('--restart latest: no checkpoint recorded in '//pointer_path)
         return
      end if
      path = trim(dir)//'/'//checkpoint_folder//'/'//trim(name)
   end function latest_checkpoint_path

   !> /particles in each rank's order and /ranks: the slab sizes and counters of every rank.
   subroutine write_particles(solver, file, status)
      type(solver_t), intent(in) :: solver
      type(hdf5_file_t), intent(inout) :: file
      type(status_t), intent(inout) :: status
      type(slab_t) :: slab, one
      integer :: n, m

      n = solver%particles%count
      slab = distributed_slab(solver%domain%comm, n)
      call file%write_attribute('particles', slab%total, status)
      call file%create_group('particles', status)
      associate (particles => solver%particles)
         ! straight from the particle arrays (contiguous column ranges; a rank without particles still
         ! passes one slot, of which it writes none)
         m = max(n, 1)
         call file%write_slab('particles/x', slab, particles%x(:, 1:m), status)
         call file%write_slab('particles/v', slab, particles%v(:, 1:m), status)
         call file%write_slab('particles/mass', slab, particles%mass(1:m), status)
         call file%write_slab('particles/density', slab, particles%density(1:m), status)
         call file%write_slab('particles/sbar', slab, particles%sbar(:, 1:m), status)
         call file%write_slab('particles/material', slab, particles%material(1:m), status)
         call file%write_slab('particles/id', slab, particles%id(1:m), status)
         if (particles%n_affine > 0) call file%write_slab('particles/affine', slab, particles%affine(:, 1:m), status)
      end associate
      one = distributed_slab(solver%domain%comm, 1)
      call file%create_group('ranks', status)
      call file%write_slab('ranks/particles', one, [int(n, i8)], status)
      call file%write_slab('ranks/lost_particles', one, [int(solver%lost_particles, i8)], status)
      call file%write_slab('ranks/wall_corrections', one, [int(solver%wall_corrections, i8)], status)
   end subroutine write_particles

   !> /outputs: what every output so far wrote (rank 0 holds the list).
   subroutine write_outputs(solver, progress, file, status)
      type(solver_t), intent(in) :: solver
      type(run_progress_t), intent(in) :: progress
      type(hdf5_file_t), intent(inout) :: file
      type(status_t), intent(inout) :: status
      type(slab_t) :: slab
      integer :: n, e
      real(rp), allocatable :: reals(:, :)
      integer(i8), allocatable :: integers(:, :)
      n = progress%output_count()
      if (solver%domain%rank /= 0) n = 0
      slab = distributed_slab(solver%domain%comm, n)
      allocate (reals(4, max(n, 1)), integers(6, max(n, 1)))
      do e = 1, n
         associate (entry => progress%outputs(e))
            reals(:, e) = [entry%time, entry%grid_origin]
            integers(:, e) = [int(entry%index, i8), entry%step, entry%particles, int(entry%grid_cells, i8)]
         end associate
      end do
      call file%create_group('outputs', status)
      call file%write_slab('outputs/time_and_grid_origin', slab, reals, status)
      ! integers as reals: exact below 2**53
      call file%write_slab('outputs/index_step_particles_grid_cells', slab, real(integers, rp), status)
   end subroutine write_outputs

   !> Restore the solver's state and the run's progress from checkpoint `path` for `scene`. The solver
   !> must be set up for the scene without particles (solver%init(..., seed_particles=.false.)).
   !> Nothing is changed unless the whole file was read and accepted. A scene that differs from the
   !> stored one in more than restart_changeable is refused, unless `allow_scene_change`; then
   !> `scene_warning` lists the differences ('' when there are none). Collective.
   subroutine read_checkpoint(path, scene, solver, progress, status, allow_scene_change, scene_warning)
      character(len=*), intent(in) :: path
      type(scene_t), intent(in) :: scene
      type(solver_t), intent(inout) :: solver
      type(run_progress_t), intent(out) :: progress
      type(status_t), intent(inout) :: status
      logical, intent(in), optional :: allow_scene_change
      character(len=:), allocatable, intent(out), optional :: scene_warning
      type(hdf5_file_t) :: file
      type(saved_state_t) :: state
      type(slab_t) :: all_ranks
      character(len=:), allocatable :: where, warning
      logical :: allow
      integer :: version

      allow = .false.
      if (present(allow_scene_change)) allow = allow_scene_change
      warning = ''
      where = 'checkpoint '//trim(path)
      call file%open(path, solver%domain%comm, status)
      if (.not. status%ok) then
         call status%reset()
         call status%fail('cannot open '//where//': missing, truncated or not an HDF5 file')
         return
      end if
      call check_format(file, where, version, status)
      call check_scene(file, scene, where, status)
      call check_scene_changes(file, version, scene, where, allow, warning, status)
      if (present(scene_warning)) scene_warning = warning
      call read_counts(file, where, state, progress, status)
      if (status%ok) call read_rank_tables(file, where, state, all_ranks, status)
      if (.not. status%ok) then
         call file%close(status)
         return
      end if
      call read_particles(file, solver, scene, where, state, status)
      call read_outputs(file, progress, status)
      call read_series_state(solver, file, all_ranks, state%same_decomposition, status)
      if (status%ok .and. state%n > 0) then
         if (any(state%material(1:state%n) < 1 .or. state%material(1:state%n) > size(solver%materials))) &
            call status%fail(where//' holds a particle of an unknown material')
      end if
      call file%close(status)
      call agree_on_status(status, solver%domain%comm)
      if (.not. status%ok) return

      call adopt_state(state, scene, where, solver, status)
      if (.not. status%ok) return
      progress%next_output_time = state%next_output_time
      progress%restarted = .true.
      progress%restart_step = state%step
   end subroutine read_checkpoint

   !> The format name and version and the mark of a complete file. Version 4 (no stored scene) is
   !> still read; check_scene_changes decides what to do with it.
   subroutine check_format(file, where, version, status)
      type(hdf5_file_t), intent(in) :: file
      character(len=*), intent(in) :: where
      integer, intent(out) :: version
      type(status_t), intent(inout) :: status
      character(len=64) :: text
      integer :: complete
      text = ''
      version = -1
      complete = 0
      call file%read_attribute('format', text, status)
      if (status%ok .and. text /= checkpoint_format) call status%fail(where//' is not a Flotsam checkpoint')
      call file%read_attribute('format_version', version, status)
      if (status%ok .and. version /= checkpoint_format_version .and. version /= unscened_format_version) then
         call status%fail(where//' has format version '//int_text(version)//'; this build of flotsam reads version '// &
                          int_text(checkpoint_format_version))
      end if
      call file%read_attribute('complete', complete, status)
      if (status%ok .and. complete /= 1) call status%fail(where//' is incomplete')
   end subroutine check_format

   !> Time, step, dt and the other scalars, and the counts of ranks and particles written.
   subroutine read_counts(file, where, state, progress, status)
      type(hdf5_file_t), intent(in) :: file
      character(len=*), intent(in) :: where
      type(saved_state_t), intent(inout) :: state
      type(run_progress_t), intent(inout) :: progress
      type(status_t), intent(inout) :: status
      call file%read_attribute('time', state%time, status)
      call file%read_attribute('step', state%step, status)
      call file%read_attribute('dt', state%dt, status)
      ! the step in steps of the blend's reference CFL number (files of 2026-12-03 name it blend_exponent;
      ! absent in older files: 1, the blend per step)
      state%reference_steps = 1.0_rp
      if (file%has_attribute('reference_steps')) then
         call file%read_attribute('reference_steps', state%reference_steps, status)
      else if (file%has_attribute('blend_exponent')) then
         call file%read_attribute('blend_exponent', state%reference_steps, status)
      end if
      call file%read_attribute('mass_tolerance', state%mass_tolerance, status)
      call file%read_attribute('next_output_time', state%next_output_time, status)
      ! the load balancing's memory of a fruitless layout search (absent in files of before 2026-11-27: none)
      if (file%has_attribute('unimproved_largest')) &
         call file%read_attribute('unimproved_largest', state%unimproved_largest, status)
      call file%read_attribute('sequence', progress%checkpoints_written, status)
      call file%read_attribute('ranks', state%ranks_written, status)
      call file%read_attribute('particles', state%total, status)
      if (status%ok .and. (state%ranks_written < 1 .or. state%total < 0)) call status%fail(where//' has invalid counts')
   end subroutine read_counts

   !> Every written rank's particle count and counters (all_ranks: the slab of all of them).
   subroutine read_rank_tables(file, where, state, all_ranks, status)
      type(hdf5_file_t), intent(in) :: file
      character(len=*), intent(in) :: where
      type(saved_state_t), intent(inout) :: state
      type(slab_t), intent(out) :: all_ranks
      type(status_t), intent(inout) :: status
      associate (ranks => state%ranks_written)
         allocate (state%rank_counts(ranks), state%lost(ranks), state%corrections(ranks))
         all_ranks = slab_t(0, ranks, ranks)
      end associate
      call file%read_slab('ranks/particles', all_ranks, state%rank_counts, status)
      call file%read_slab('ranks/lost_particles', all_ranks, state%lost, status)
      call file%read_slab('ranks/wall_corrections', all_ranks, state%corrections, status)
      if (status%ok .and. sum(state%rank_counts) /= state%total) call status%fail(where//' has inconsistent particle counts')
   end subroutine read_rank_tables

   !> The particles this rank reads: on the same number of ranks the slab it wrote, in the writer's
   !> decomposition (rebalanced or not; ranks keep their numbers in any rank grid), else an even share.
   subroutine read_particles(file, solver, scene, where, state, status)
      type(hdf5_file_t), intent(in) :: file
      type(solver_t), intent(in) :: solver
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: where
      type(saved_state_t), intent(inout) :: state
      type(status_t), intent(inout) :: status
      type(slab_t) :: slab
      integer :: rank, n_ranks, m

      rank = solver%domain%rank
      call MPI_Comm_size(solver%domain%comm, n_ranks)
      state%same_decomposition = state%ranks_written == n_ranks
      if (state%same_decomposition) then
         allocate (state%cuts(size(solver%domain%cuts)))
         call file%read_attribute('cuts', state%cuts, status)
         if (status%ok) then
            if (.not. valid_layout(reshape(state%cuts, shape(solver%domain%cuts)), solver%domain%global_cells, &
                                   solver%domain%dim, n_ranks, solver%domain%min_width)) &
               call status%fail(where//' has an invalid decomposition')
         end if
         slab = slab_t(sum(state%rank_counts(1:rank)), state%rank_counts(rank + 1), state%total)
      else
         slab = even_slab(state%total, rank, n_ranks)
      end if
      state%n = int(slab%count)
      m = max(state%n, 1)
      allocate (state%x(scene%grid%dim, m), state%v(scene%grid%dim, m), state%mass(m), state%density(m), &
                state%sbar(solver%particles%n_sigma, m), state%material(m), state%id(m))
      call file%read_slab('particles/x', slab, state%x, status)
      call file%read_slab('particles/v', slab, state%v, status)
      call file%read_slab('particles/mass', slab, state%mass, status)
      call file%read_slab('particles/density', slab, state%density, status)
      call file%read_slab('particles/sbar', slab, state%sbar, status)
      call file%read_slab('particles/material', slab, state%material, status)
      call file%read_slab('particles/id', slab, state%id, status)
      ! APIC's C_p; zero (the velocity uniform around each particle) if the run before had no APIC, which
      ! only --allow-scene-change lets a restart change
      allocate (state%affine(merge(scene%grid%dim**2, 0, scene%run%transfer == 'apic'), m))
      state%affine = 0.0_rp
      if (size(state%affine, 1) > 0) then
         if (file%has('particles/affine')) call file%read_slab('particles/affine', slab, state%affine, status)
      end if
   end subroutine read_particles

   !> The checkpoint was accepted: its decomposition (same ranks), particles, time, step and counters
   !> become the solver's. Collective.
   subroutine adopt_state(state, scene, where, solver, status)
      type(saved_state_t), intent(in) :: state
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: where
      type(solver_t), intent(inout) :: solver
      type(status_t), intent(inout) :: status
      integer :: rank, p

      rank = solver%domain%rank
      if (state%same_decomposition) then
         call solver%set_layout(reshape(state%cuts, shape(solver%domain%cuts)), status)
         if (.not. status%ok) return
      end if
      call solver%particles%init(scene%grid%dim, size(scene%materials), max(state%n, 1024), &
                                 affine=size(state%affine, 1) > 0, spin=solver%particles%n_spin > 0, &
                                 strain_rate=solver%particles%n_rate > 0)
      do p = 1, state%n
         call solver%particles%add(state%x(:, p), state%v(:, p), state%mass(p), state%density(p), state%sbar(:, p), &
                                   state%material(p), state%id(p), state%affine(:, p))
      end do
      call solver%check_particle_memory(status)
      if (.not. status%ok) return
      solver%time = state%time
      solver%step = state%step
      solver%dt = state%dt
      solver%reference_steps = state%reference_steps
      solver%mass_tolerance = state%mass_tolerance
      if (state%same_decomposition) then
         solver%unimproved_largest = state%unimproved_largest
         solver%lost_particles = int(state%lost(rank + 1))
         solver%wall_corrections = int(state%corrections(rank + 1))
         ! keep each rank's order: the continued run is then bitwise identical to an uninterrupted one
         if (any([(solver%grid%owned_local_cell(state%x(:, p)) == 0, p = 1, state%n)])) &
            call status%fail(where//': a particle lies outside the cells of the rank that wrote it')
         call agree_on_status(status, solver%domain%comm)
         if (.not. status%ok) return
         call update_cells(solver%grid, solver%particles)
      else
         solver%lost_particles = merge(int(sum(state%lost)), 0, rank == 0)
         solver%wall_corrections = merge(int(sum(state%corrections)), 0, rank == 0)
         ! the active box around the particles read, each sent to its owner
         call solver%cover_particles(status)
      end if
   end subroutine adopt_state

   !> The scene the checkpoint's run used (stored by write_scene_text) against `scene`: a difference
   !> outside restart_changeable is refused, or with `allow` reported in `warning`. A checkpoint of
   !> format version 4 stores no scene: refused, or with `allow` accepted with a warning.
   subroutine check_scene_changes(file, version, scene, where, allow, warning, status)
      type(hdf5_file_t), intent(in) :: file
      integer, intent(in) :: version
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: where
      logical, intent(in) :: allow
      character(len=:), allocatable, intent(inout) :: warning
      type(status_t), intent(inout) :: status
      type(scene_change_t), allocatable :: changes(:)
      character(len=:), allocatable :: stored, refused

      if (.not. status%ok) return
      if (version == unscened_format_version) then
         if (allow) then
            warning = where//' stores no scene (format version '//int_text(version)//', an older flotsam): the '// &
                      'scene was not compared (--allow-scene-change)'
         else
            call status%fail(where//' stores no scene (format version '//int_text(version)//', written by an older '// &
                             'flotsam), so a changed scene cannot be detected; pass --allow-scene-change to continue '// &
                             'it with this scene')
         end if
         return
      end if
      call read_scene_text(file, stored, status)
      if (.not. status%ok) return
      call compare_scene_texts(stored, where//' (its scene)', scene_namelist_text(scene), 'the scene', changes, status)
      if (.not. status%ok) return
      refused = describe_changes(changes, allowed=.false.)
      if (len(refused) == 0) return
      if (allow) then
         warning = 'continuing with a changed scene (--allow-scene-change): '//refused
      else
         call status%fail(where//' was written for another scene: '//refused//' (a restart may change only &run '// &
                          'end_time, max_steps, speed_limit and the output, checkpoint and balancing settings; '// &
                          '--allow-scene-change continues with the changed scene)')
      end if
   end subroutine check_scene_changes

   !> The resolved scene the checkpoint's run used: its root attribute `scene` (provenance, written by
   !> scene_record's scene_namelist_text).
   subroutine read_scene_text(file, text, status)
      type(hdf5_file_t), intent(in) :: file
      character(len=:), allocatable, intent(out) :: text
      type(status_t), intent(inout) :: status
      character(len=scene_text_len) :: stored
      stored = ''
      call file%read_attribute('scene', stored, status)
      text = trim(stored)
   end subroutine read_scene_text

   !> What the series of loads.csv, gauges.csv and bodies.csv carry from row to row (load_records): the
   !> last row's time, each rank's wall impulse since then (ranks/load_impulse, one column per rank),
   !> the bodies' momentum and 2-D angle at that row. With them a restart on the same ranks continues
   !> the rows bit for bit. Data of zero size is not written.
   subroutine write_series_state(solver, file, status)
      type(solver_t), intent(in) :: solver
      type(hdf5_file_t), intent(inout) :: file
      type(status_t), intent(inout) :: status
      call file%write_attribute('last_load_row_time', solver%loads%last_row_time, status)
      if (solver%bodies%count() > 0) then
         call file%write_attribute('body_momentum', reshape(solver%bodies%previous_momentum, &
                                                            [size(solver%bodies%previous_momentum)]), status)
         call file%write_attribute('body_angle', solver%bodies%previous_angle, status)
      end if
      ! the rigid bodies' state (the same on every rank): mass, inertia, centre, motion, rotation
      if (solver%rigid%active) call file%write_attribute('rigid_bodies', solver%rigid%state(), status)
      if (size(solver%loads%impulse) > 0) then
         call file%write_slab('ranks/load_impulse', distributed_slab(solver%domain%comm, 1), &
                              reshape(solver%loads%impulse, [size(solver%loads%impulse), 1]), status)
      end if
   end subroutine write_series_state

   !> The state write_series_state saved. On the ranks that wrote it each rank takes its own impulse;
   !> on another number of ranks rank 0 takes their sum (a row sums over the ranks anyway).
   subroutine read_series_state(solver, file, all_ranks, same_decomposition, status)
      type(solver_t), intent(inout) :: solver
      type(hdf5_file_t), intent(inout) :: file
      type(slab_t), intent(in) :: all_ranks
      logical, intent(in) :: same_decomposition
      type(status_t), intent(inout) :: status
      real(rp), allocatable :: flat(:), per_rank(:, :)
      integer :: r
      call file%read_attribute('last_load_row_time', solver%loads%last_row_time, status)
      if (size(solver%loads%impulse) > 0) then
         allocate (per_rank(size(solver%loads%impulse), all_ranks%total))
         call file%read_slab('ranks/load_impulse', all_ranks, per_rank, status)
         if (status%ok) then
            if (same_decomposition) then
               solver%loads%impulse = reshape(per_rank(:, solver%domain%rank + 1), shape(solver%loads%impulse))
            else
               solver%loads%impulse = 0.0_rp
               if (solver%domain%rank == 0) then
                  do r = 1, size(per_rank, 2)
                     solver%loads%impulse = solver%loads%impulse + reshape(per_rank(:, r), shape(solver%loads%impulse))
                  end do
               end if
            end if
         end if
      end if
      if (solver%bodies%count() > 0) then
         allocate (flat(size(solver%bodies%previous_momentum)))
         call file%read_attribute('body_momentum', flat, status)
         if (status%ok) solver%bodies%previous_momentum = reshape(flat, shape(solver%bodies%previous_momentum))
         call file%read_attribute('body_angle', solver%bodies%previous_angle, status)
      end if
      if (solver%rigid%active) then
         if (allocated(flat)) deallocate (flat)
         allocate (flat(rigid_state_width * size(solver%rigid%bodies)))
         call file%read_attribute('rigid_bodies', flat, status)
         if (status%ok) call solver%rigid%set_state(flat)
      end if
   end subroutine read_series_state

   !> The checkpoint must come from a scene with the same grid and materials.
   subroutine check_scene(file, scene, where, status)
      type(hdf5_file_t), intent(in) :: file
      type(scene_t), intent(in) :: scene
      character(len=*), intent(in) :: where
      type(status_t), intent(inout) :: status
      integer :: dim, cells(3), n_materials, m
      real(rp) :: origin(3), cell_size, rotation, grid_origin(3)
      integer :: grid_cells(3)
      type(frame_t) :: frame
      character(len=64) :: name
      real(rp), parameter :: same = 1.0e-12_rp     ! relative to the cell size: round-off only
      dim = 0
      cells = 0
      origin = 0.0_rp
      cell_size = 0.0_rp
      rotation = 0.0_rp
      n_materials = 0
      call file%read_attribute('dim', dim, status)
      call file%read_attribute('cells', cells, status)
      call file%read_attribute('origin', origin, status)
      call file%read_attribute('cell_size', cell_size, status)
      call file%read_attribute('rotation', rotation, status)
      call file%read_attribute('materials', n_materials, status)
      if (.not. status%ok) return
      call place_grid(scene%grid, frame, grid_origin, grid_cells)
      if (dim /= scene%grid%dim) then
         call status%fail(where//' was written for a '//int_text(dim)//'-D scene, this scene is '// &
                          int_text(scene%grid%dim)//'-D')
      else if (any(cells /= grid_cells) .or. any(abs(origin - grid_origin) > same * cell_size) .or. &
               abs(cell_size - scene%grid%cell_size) > same * cell_size .or. abs(rotation - scene%grid%rotation) > 0.0_rp) then
         call status%fail(where//' was written for another grid (&grid cell_size, origin, extent or rotation differ)')
      else if (n_materials /= size(scene%materials)) then
         call status%fail(where//' was written for '//int_text(n_materials)//' materials, the scene has '// &
                          int_text(size(scene%materials)))
      end if
      do m = 1, min(n_materials, size(scene%materials))
         if (.not. status%ok) return
         name = ''
         call file%read_attribute('material_'//int_text(m), name, status)
         if (status%ok .and. name /= scene%materials(m)%name) then
            call status%fail(where//": material "//int_text(m)//" is '"//trim(name)//"' there and '"// &
                             trim(scene%materials(m)%name)//"' in the scene")
         end if
      end do
   end subroutine check_scene

   !> Every rank reads the whole list of outputs.
   subroutine read_outputs(file, progress, status)
      type(hdf5_file_t), intent(in) :: file
      type(run_progress_t), intent(inout) :: progress
      type(status_t), intent(inout) :: status
      integer(i8), allocatable :: dims(:)
      real(rp), allocatable :: reals(:, :), integers(:, :)
      type(output_entry_t) :: entry
      type(slab_t) :: slab
      integer :: e
      dims = file%dataset_dims('outputs/time_and_grid_origin', status)
      if (.not. status%ok) return
      if (size(dims) /= 2) then
         call status%fail('checkpoint '//file%path//': outputs/time_and_grid_origin has the wrong shape')
         return
      end if
      slab = slab_t(0, dims(2), dims(2))
      allocate (reals(4, max(1_i8, dims(2))), integers(6, max(1_i8, dims(2))))
      call file%read_slab('outputs/time_and_grid_origin', slab, reals, status)
      call file%read_slab('outputs/index_step_particles_grid_cells', slab, integers, status)
      if (.not. status%ok) return
      do e = 1, int(dims(2))
         entry%time = reals(1, e)
         entry%grid_origin = reals(2:4, e)
         entry%index = nint(integers(1, e))
         entry%step = nint(integers(2, e), i8)
         entry%particles = nint(integers(3, e), i8)
         entry%grid_cells = nint(integers(4:6, e))
         call progress%add_output(entry)
      end do
   end subroutine read_outputs
end module checkpoint
