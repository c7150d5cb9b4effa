!> Names of everything a run writes in its output folder (docs/output.md):
!>
!>   scene.nml                        the resolved scene (provenance); scene_<k>.nml: before a restart changed it
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
   !> The time series of loads, gauges, panels and bodies (load_records, docs/output.md).
   character(len=*), parameter, public :: loads_csv = 'loads.csv'
   character(len=*), parameter, public :: gauges_csv = 'gauges.csv'
   character(len=*), parameter, public :: bodies_csv = 'bodies.csv'
   character(len=*), parameter, public :: panels_csv = 'panels.csv'
   !> The resolved scene of the run (provenance).
   character(len=*), parameter, public :: scene_nml = 'scene.nml'

   public :: fields_file, checkpoint_file, previous_scene_nml

contains

   !> Path of the fields file of output `index`, relative to the output folder.
   pure function fields_file(index) result(path)
      integer, intent(in) :: index
      character(len=:), allocatable :: path
      path = fields_folder//'/fields_'//six_digits(index)//'.h5'
   end function fields_file

   !> Path of checkpoint number `sequence`, relative to the output folder.
   pure function checkpoint_file(sequence) result(path)
      integer, intent(in) :: sequence
      character(len=:), allocatable :: path
      path = checkpoint_folder//'/checkpoint_'//six_digits(sequence)//'.h5'
   end function checkpoint_file

   !> The k-th scene.nml a continued run with a changed scene replaced: scene_<k>.nml (k = 1, 2, ...).
   pure function previous_scene_nml(k) result(path)
      integer, intent(in) :: k
      character(len=:), allocatable :: path
      character(len=16) :: buffer
      write (buffer, '(i0)') k
      path = 'scene_'//trim(buffer)//'.nml'
   end function previous_scene_nml

   !> 42 -> '000042' (more digits when needed).
   pure function six_digits(number) result(text)
      integer, intent(in) :: number
      character(len=:), allocatable :: text
      character(len=16) :: buffer
      write (buffer, '(i6.6)') number
      text = trim(adjustl(buffer))
   end function six_digits
end module output_layout
