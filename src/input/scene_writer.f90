!> The resolved scene as namelist text (docs/output.md, "scene.nml"): every variable of every group
!> with the value the run uses, after the overrides and the resolution of derived defaults, so that
!> reading the text back gives the same scene. Reals are written with the shortest text that reads back
!> exactly (real_text). `&run overwrite` is left out: it is an action on the output folder, not part of
!> the scene, and a run started again from the text must not replace results silently.
module scene_writer
   use kinds, only: rp
   use scene_description, only: scene_t
   use input_text, only: int_text, real_text
   implicit none
   private

   public :: scene_namelist_text

   character(len=*), parameter :: indent = '   '

contains

   !> The whole scene, one namelist group after the other, lines ended by new_line('a').
   function scene_namelist_text(scene) result(text)
      type(scene_t), intent(in) :: scene
      character(len=:), allocatable :: text
      integer :: k

      associate (run => scene%run, grid => scene%grid)
         text = '&run'//new_line('a')
         call add(text, 'end_time', real_text(run%end_time))
         call add(text, 'cfl', real_text(run%cfl))
         call add(text, 'dt', real_text(run%fixed_dt))
         call add(text, 'output_interval', real_text(run%output_interval))
         call add(text, 'output_dir', quoted(run%output_dir))
         call add(text, 'update_scheme', quoted(run%update_scheme))
         call add(text, 'flip_fraction', real_text(run%flip_fraction))
         call add(text, 'theta', real_text(run%theta))
         call add(text, 'max_steps', int_text(run%max_steps))
         call add(text, 'progress_interval', real_text(run%progress_interval))
         call add(text, 'floor_size', real_text(run%floor_size))
         call add(text, 'particle_output', logical_text(run%particle_output))
         call add(text, 'grid_output', logical_text(run%grid_output))
         call add(text, 'field_precision', quoted(run%field_precision))
         call add(text, 'particle_fields', quoted(run%particle_fields))
         call add(text, 'checkpoint_interval_steps', int_text(run%checkpoint_interval_steps))
         call add(text, 'checkpoint_interval_wall', real_text(run%checkpoint_interval_wall))
         call add(text, 'checkpoints_kept', int_text(run%checkpoints_kept))
         call add(text, 'speed_limit', real_text(run%speed_limit))
         call add(text, 'rebalance_threshold', real_text(run%rebalance_threshold))
         call add(text, 'rebalance_interval', int_text(run%rebalance_interval))
         call add(text, 'load_interval', real_text(run%load_interval))
         text = text//'/'//new_line('a')//new_line('a')//'&grid'//new_line('a')
         call add(text, 'dim', int_text(grid%dim))
         call add(text, 'cell_size', real_text(grid%cell_size))
         call add(text, 'origin', reals(grid%origin))
         call add(text, 'extent', reals(grid%extent))
         call add(text, 'rotation', real_text(grid%rotation))
         text = text//'/'//new_line('a')//new_line('a')//'&box_walls'//new_line('a')
         call add(text, 'x_min', quoted(grid%wall(1, 1)))
         call add(text, 'x_max', quoted(grid%wall(2, 1)))
         call add(text, 'y_min', quoted(grid%wall(1, 2)))
         call add(text, 'y_max', quoted(grid%wall(2, 2)))
         call add(text, 'z_min', quoted(grid%wall(1, 3)))
         call add(text, 'z_max', quoted(grid%wall(2, 3)))
         call add(text, 'x_min_name', quoted(grid%wall_name(1, 1)))
         call add(text, 'x_max_name', quoted(grid%wall_name(2, 1)))
         call add(text, 'y_min_name', quoted(grid%wall_name(1, 2)))
         call add(text, 'y_max_name', quoted(grid%wall_name(2, 2)))
         call add(text, 'z_min_name', quoted(grid%wall_name(1, 3)))
         call add(text, 'z_max_name', quoted(grid%wall_name(2, 3)))
         text = text//'/'//new_line('a')//new_line('a')//'&gravity'//new_line('a')
         call add(text, 'acceleration', reals(scene%gravity))
         text = text//'/'//new_line('a')
      end associate

      if (allocated(scene%materials)) then
         do k = 1, size(scene%materials)
            associate (m => scene%materials(k))
               text = text//new_line('a')//'&material'//new_line('a')
               call add(text, 'name', quoted(m%name))
               call add(text, 'model', quoted(m%model))
               call add(text, 'density', real_text(m%density))
               call add(text, 'bulk_modulus', real_text(m%bulk_modulus))
               call add(text, 'viscosity', real_text(m%viscosity))
               call add(text, 'youngs_modulus', real_text(m%youngs_modulus))
               call add(text, 'poisson_ratio', real_text(m%poisson_ratio))
               call add(text, 'stabilization', quoted(m%stabilization))
               call add(text, 'volumetric_only', logical_text(m%volumetric_only))
               call add(text, 'oscillation_rule', quoted(m%oscillation_rule))
               call add(text, 'gamma_max', real_text(m%gamma_max))
               call add(text, 'smoothed_variables', quoted(m%smoothed_variables))
               call add(text, 'cell_averaging', logical_text(m%cell_averaging))
               call add(text, 'volume_correction', quoted(m%volume_correction))
               call add(text, 'shifting_coefficient', real_text(m%shifting_coefficient))
               call add(text, 'eos_relaxation_rate', real_text(m%eos_relaxation_rate))
               text = text//'/'//new_line('a')
            end associate
         end do
      end if
      if (allocated(scene%bodies)) then
         do k = 1, size(scene%bodies)
            associate (b => scene%bodies(k))
               text = text//new_line('a')//'&body'//new_line('a')
               call add(text, 'name', quoted(b%name))
               call add(text, 'material', quoted(b%material))
               call add(text, 'lower', reals(b%lower))
               call add(text, 'upper', reals(b%upper))
               call add(text, 'particles_per_cell', int_text(b%particles_per_cell))
               call add(text, 'velocity', reals(b%velocity))
               call add(text, 'hydrostatic', logical_text(b%hydrostatic))
               call add(text, 'free_surface_level', real_text(b%free_surface_level))
               text = text//'/'//new_line('a')
            end associate
         end do
      end if
      if (allocated(scene%walls)) then
         do k = 1, size(scene%walls)
            associate (w => scene%walls(k))
               text = text//new_line('a')//'&wall'//new_line('a')
               call add(text, 'name', quoted(w%name))
               call add(text, 'point', reals(w%point))
               call add(text, 'normal', reals(w%normal))
               call add(text, 'lower', reals(w%lower))
               call add(text, 'upper', reals(w%upper))
               call add(text, 'condition', quoted(w%condition))
               call add(text, 'moment_point', reals(w%moment_point))
               text = text//'/'//new_line('a')
            end associate
         end do
      end if
      if (allocated(scene%inlets)) then
         do k = 1, size(scene%inlets)
            associate (i => scene%inlets(k))
               text = text//new_line('a')//'&inlet'//new_line('a')
               call add(text, 'name', quoted(i%name))
               call add(text, 'material', quoted(i%material))
               call add(text, 'point', reals(i%point))
               call add(text, 'direction', reals(i%direction))
               call add(text, 'height', real_text(i%height))
               call add(text, 'width', real_text(i%width))
               call add(text, 'velocity', real_text(i%velocity))
               call add(text, 'start_time', real_text(i%start_time))
               call add(text, 'end_time', real_text(i%end_time))
               call add(text, 'particles_per_cell', int_text(i%particles_per_cell))
               call add(text, 'hydrostatic', logical_text(i%hydrostatic))
               text = text//'/'//new_line('a')
            end associate
         end do
      end if
      if (allocated(scene%gauges)) then
         do k = 1, size(scene%gauges)
            associate (g => scene%gauges(k))
               text = text//new_line('a')//'&gauge'//new_line('a')
               call add(text, 'name', quoted(g%name))
               call add(text, 'kind', quoted(g%kind))
               call add(text, 'point', reals(g%point))
               call add(text, 'radius', real_text(g%radius))
               text = text//'/'//new_line('a')
            end associate
         end do
      end if
   end function scene_namelist_text

   !> Append the line `   name = value`.
   subroutine add(text, name, value)
      character(len=:), allocatable, intent(inout) :: text
      character(len=*), intent(in) :: name, value
      text = text//indent//name//' = '//value//new_line('a')
   end subroutine add

   !> A namelist string constant: in single quotes, a quote inside doubled.
   pure function quoted(value) result(text)
      character(len=*), intent(in) :: value
      character(len=:), allocatable :: text
      integer :: i
      text = "'"
      do i = 1, len_trim(value)
         if (value(i:i) == "'") then
            text = text//"''"
         else
            text = text//value(i:i)
         end if
      end do
      text = text//"'"
   end function quoted

   pure function logical_text(value) result(text)
      logical, intent(in) :: value
      character(len=:), allocatable :: text
      if (value) then
         text = '.true.'
      else
         text = '.false.'
      end if
   end function logical_text

   !> "1.0, 0.0, -9.81"
   function reals(values) result(text)
      real(rp), intent(in) :: values(:)
      character(len=:), allocatable :: text
      integer :: k
      text = real_text(values(1))
      do k = 2, size(values)
         text = text//', '//real_text(values(k))
      end do
   end function reals
end module scene_writer
