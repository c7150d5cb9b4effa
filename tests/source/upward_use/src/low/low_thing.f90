!> Points up on purpose: low uses a module of high.
module low_thing
   use high_thing, only: high_value
   implicit none
end module low_thing
