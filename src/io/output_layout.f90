!> Names of everything a run writes in its output folder (docs/output.md):
!>
!>   diagnostics.csv                  one row per output time
!>   particles.xmf, grid.xmf          XDMF time series for ParaView (rank 0)
!>   fields/fields_<NNNNNN>.h5        particle and grid fields of output number NNNNNN (0 = initial state)
!>   checkpoints/checkpoint_<NNNNNN>.h5   full state for --restart (the last `checkpoints_kept`)
!>   checkpoints/latest               the file name of the newest complete checkpoint
!>
!> Files are written under `<name>.tmp` and renamed when complete, so a name that exists is complete.
module output_layout
   implicit none
   private

   character(len=*), parameter, public :: fields_folder = 'fields'
   character(len=*), parameter, public :: checkpoint_folder = 'checkpoints'
   character(len=*), parameter, public :: particles_xdmf = 'particles.xmf'
   character(len=*), parameter, public :: grid_xdmf = 'grid.xmf'
   character(len=*), parameter, public :: latest_checkpoint = 'latest'
   character(len=*), parameter, public :: temporary_suffix = '.tmp'

   public :: fields_file, checkpoint_file

contains

   !> Path of the fields file of output `index`, relative to the output folder.
   pure function fields_file(index) result(path)
      integer, intent(in) :: index
      character(len=:), allocatable :: path
      character(len=16) :: number
      write (number, '(i6.6)') index
      path = fields_folder//'/fields_'//trim(number)//'.h5'
   end function fields_file

   !> Path of checkpoint number `sequence`, relative to the output folder.
   pure function checkpoint_file(sequence) result(path)
      integer, intent(in) :: sequence
      character(len=:), allocatable :: path
      character(len=16) :: number
      write (number, '(i6.6)') sequence
      path = checkpoint_folder//'/checkpoint_'//trim(number)//'.h5'
   end function checkpoint_file
end module output_layout
