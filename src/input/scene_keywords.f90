!> The keywords each scene variable with a fixed set of values accepts (docs/input.md), in one place for
!> the reader (which canonicalises their spelling), the validation and the components that act on them.
module scene_keywords
   use scene_description, only: wall_none, wall_slip, wall_no_slip, wall_friction, motion_none, motion_solitary_wave, &
                                motion_table, model_newtonian_fluid, model_linear_elastic, model_rigid
   use material_group, only: stabilization_keywords, oscillation_rule_keywords, smoothed_variables_keywords, &
                             volume_correction_keywords
   implicit none
   private

   ! the keyword lists of a group with a module of its own (src/input/groups/), named here with the others
   public :: stabilization_keywords, oscillation_rule_keywords, smoothed_variables_keywords, volume_correction_keywords

   !> Accepted `&grid shape_function=` keywords (stored lower case; docs/theory.md section 1.1).
   character(len=*), parameter, public :: shape_function_keywords(*) = [character(len=8) :: 'linear', 'bspline2']
   !> Accepted `&run update_scheme=` keywords (stored upper case).
   character(len=*), parameter, public :: update_scheme_keywords(*) = [character(len=4) :: 'USL', 'MUSL']
   !> Accepted `&run transfer=` keywords (stored lower case).
   character(len=*), parameter, public :: transfer_keywords(*) = [character(len=8) :: 'flip_pic', 'apic']
   !> Accepted `&wall motion=` keywords (stored lower case).
   character(len=*), parameter, public :: motion_keywords(*) = [character(len=13) :: motion_none, &
                                                                motion_solitary_wave, motion_table]

   !> Accepted `&box_walls` keywords (stored lower case).
   character(len=*), parameter, public :: wall_keywords(*) = [character(len=8) :: wall_none, wall_slip, wall_no_slip, &
                                                              wall_friction]
   !> Accepted `&structure condition=` keywords (stored lower case).
   character(len=*), parameter, public :: wall_condition_keywords(*) = [character(len=8) :: wall_slip, wall_no_slip, &
                                                                        wall_friction]
   !> `&wall condition = 'free'`: a wall that constrains nothing and reports a zero load (free_condition).
   character(len=*), parameter, public :: wall_free = 'free'
   !> Accepted `&wall condition=` keywords.
   character(len=*), parameter, public :: wall_group_condition_keywords(*) = [character(len=8) :: &
                                                                              wall_condition_keywords, wall_free]
   !> Accepted `&material model=` keywords (stored lower case).
   character(len=*), parameter, public :: model_keywords(*) = &
      [character(len=15) :: model_newtonian_fluid, model_linear_elastic, model_rigid]
end module scene_keywords
