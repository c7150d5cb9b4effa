!> Which MPI-IO implementation the run's collective HDF5 writes go through (docs/output.md).
!>
!> Open MPI 4.1's default MPI-IO component, OMPIO, can drop ranks' parts of a collective write
!> (open-mpi/ompi#12718; seen here as checkpoints with per-rank counts of 0). Each process reads its
!> MCA parameters from its environment in MPI_Init, so setting OMPI_MCA_io=romio321 just before
!> MPI_Init selects ROMIO for this process even under plain `mpirun`. A value the user set is kept
!> (overwrite = 0); under another MPI the variable means nothing.
module mpi_io_choice
   use iso_c_binding, only: c_int, c_char, c_null_char
   implicit none
   private

   public :: prefer_romio

   interface
      integer(c_int) function c_setenv(name, value, overwrite) bind(c, name='setenv')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: name(*), value(*)
         integer(c_int), value :: overwrite
      end function c_setenv
   end interface

contains

   !> Call before MPI_Init.
   subroutine prefer_romio()
      integer(c_int) :: ignored
      ignored = c_setenv('OMPI_MCA_io'//c_null_char, 'romio321'//c_null_char, 0_c_int)
   end subroutine prefer_romio
end module mpi_io_choice
