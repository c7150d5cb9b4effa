!> The time tables of `&inlet velocity_file` (docs/input.md): rank 0 reads them while it checks the scene,
!> as it reads `&body points_file`; they travel to the other ranks with the scene (scene%inlet_tables).
module inlet_table
   use kinds, only: rp, name_len
   use error_status, only: status_t
   use scene_description, only: scene_t, has_velocity_file
   use input_text, only: int_text, real_text, group_context
   use csv_table, only: beside
   use time_table, only: read_time_table
   implicit none
   private

   public :: load_inlet_tables

contains

   !> Rank 0, after validate_scene: read the table of every `&inlet velocity_file` (columns t, velocity and,
   !> with height_from_file, height) into scene%inlet_tables, check its values (velocity >= 0; 0 < height <=
   !> the opening's height), set velocity_file to the absolute path of the file read and velocity_checksum
   !> (a given checksum must match). `label` names the scene in messages; a relative velocity_file is
   !> relative to the folder of the scene file.
   subroutine load_inlet_tables(scene, label, status)
      type(scene_t), intent(inout) :: scene
      character(len=*), intent(in) :: label
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where, path
      character(len=name_len), allocatable :: columns(:)
      character(len=1024) :: message
      integer :: i, r

      if (.not. allocated(scene%inlets)) return
      if (allocated(scene%inlet_tables)) deallocate (scene%inlet_tables)
      allocate (scene%inlet_tables(size(scene%inlets)))
      allocate (character(len=0) :: where, path)
      do i = 1, size(scene%inlets)
         associate (inlet => scene%inlets(i), table => scene%inlet_tables(i))
            if (.not. has_velocity_file(inlet)) cycle
            where = group_context(label, 'inlet', i, "material '"//trim(inlet%material)//"'")// &
                    ": variable velocity_file = '"//trim(inlet%velocity_file)//"'"
            path = beside(scene%source_file, trim(inlet%velocity_file))
            if (inlet%height_from_file) then
               columns = [character(len=name_len) :: 'velocity', 'height']
            else
               columns = [character(len=name_len) :: 'velocity']
            end if
            call read_time_table(path, columns, table, message)
            if (len_trim(message) > 0) then
               call status%fail(where//': '//trim(message))
               return
            end if
            do r = 1, size(table%time)
               if (.not. table%values(1, r) >= 0.0_rp) then
                  call status%fail(where//': '//trim(table%path)//': line '//int_text(table%line(r))// &
                                   ': velocity must be >= 0 (fluid flows in), got '//real_text(table%values(1, r)))
               else if (inlet%height_from_file) then
                  if (.not. (table%values(2, r) > 0.0_rp .and. table%values(2, r) <= inlet%height)) &
                     call status%fail(where//': '//trim(table%path)//': line '//int_text(table%line(r))// &
                                      ': height must be > 0 and at most the opening''s height = '// &
                                      real_text(inlet%height)//', got '//real_text(table%values(2, r)))
               end if
               if (.not. status%ok) return
            end do
            if (len_trim(inlet%velocity_checksum) > 0 .and. inlet%velocity_checksum /= table%checksum) then
               call status%fail(where//': '//trim(table%path)//": the table does not match velocity_checksum = '"// &
                                trim(inlet%velocity_checksum)//"' (the file gives '"//table%checksum// &
                                "'): the file changed since the scene was written")
               return
            end if
            inlet%velocity_file = table%path
            inlet%velocity_checksum = table%checksum
         end associate
      end do
   end subroutine load_inlet_tables
end module inlet_table
