!> The layer above low.
module high_thing
   implicit none
   integer, parameter :: high_value = 1
end module high_thing
