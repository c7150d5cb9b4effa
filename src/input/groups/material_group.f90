!> The `&material` group (docs/input.md): a constitutive model and its parameters, its stabilization and
!> volume correction. Here: the type and defaults of its variables (material_spec_t), the model keywords,
!> the reader's rows (material_variables), the namelist read, the scene.nml text (material_value) and
!> what its volume correction selects (shifts_particles, relaxes_to_eos), its look-up by name
!> (find_material) and its checks (validate_material; check_shape_function_combination with &grid).
module material_group
   use kinds, only: rp, name_len
   use input_text, only: real_text, quoted, logical_text, canonical_keyword, quoted_list, group_context, ordinal
   use scene_variables, only: variable_info_t, text_len, take_text
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use error_status, only: status_t
   use input_checks, only: check_real
   use grid_group, only: grid_spec_t
   implicit none
   private

   public :: validate_material, check_shape_function_combination, find_material, read_material_group, &
             material_value, shifts_particles, relaxes_to_eos

   !> Accepted `&material stabilization=` keywords in their canonical spelling (compared without case).
   character(len=*), parameter, public :: stabilization_keywords(*) = [character(len=5) :: 'none', 'C0', 'NB', 'FOAL1']
   !> Accepted `&material oscillation_rule=` and `smoothed_variables=` keywords (FOAL1 options).
   character(len=*), parameter, public :: oscillation_rule_keywords(*) = [character(len=3) :: 'OR', 'AND']
   character(len=*), parameter, public :: smoothed_variables_keywords(*) = [character(len=8) :: 'stress', 'pressure']
   !> Accepted `&material volume_correction=` keywords (docs/volume-conservation.md).
   character(len=*), parameter, public :: volume_correction_keywords(*) = &
      [character(len=23) :: 'none', 'shifting', 'eos_relaxation', 'shifting+eos_relaxation']
   !> Material model keywords (`&material model=`).
   character(len=*), parameter, public :: model_newtonian_fluid = 'newtonian_fluid'
   character(len=*), parameter, public :: model_linear_elastic = 'linear_elastic'
   character(len=*), parameter, public :: model_rigid = 'rigid'   ! moves as one rigid body per &body

   !> Accepted `&material model=` keywords (stored lower case).
   character(len=*), parameter, public :: model_keywords(*) = &
      [character(len=15) :: model_newtonian_fluid, model_linear_elastic, model_rigid]
   !> `&material`: one constitutive model and its parameters.
   type, public :: material_spec_t
      character(len=name_len) :: name = ''
      character(len=name_len) :: model = ''
      real(rp) :: density = 0.0_rp            !< reference density [kg/m^3]
      real(rp) :: bulk_modulus = 0.0_rp       !< fluid K [Pa]
      real(rp) :: viscosity = 0.0_rp          !< fluid dynamic viscosity mu [Pa s]
      real(rp) :: youngs_modulus = 0.0_rp     !< solid E [Pa]
      real(rp) :: poisson_ratio = 0.0_rp      !< solid nu [-]
      character(len=name_len) :: stabilization = 'none'   !< anti-locking / smoothing scheme
      logical :: volumetric_only = .false.    !< C0: average only the volumetric parts (B-bar-like)
      character(len=name_len) :: oscillation_rule = 'OR'  !< FOAL1: 'OR' or 'AND' of the two cells' flags
      real(rp) :: gamma_max = 1.0_rp          !< FOAL1: flux tuning coefficient in [0, 1]
      character(len=name_len) :: smoothed_variables = 'stress'   !< FOAL1: 'stress' (all components) or 'pressure'
      logical :: cell_averaging = .true.      !< FOAL1: replace particle values by the cell average first
      !> Fluid volume consistency (docs/volume-conservation.md): 'none', 'shifting', 'eos_relaxation' or
      !> 'shifting+eos_relaxation' (read with shifts_particles / relaxes_to_eos)
      character(len=name_len) :: volume_correction = 'none'
      real(rp) :: shifting_coefficient = 0.02_rp   !< shifting: D in dx = -D h^2 grad(excess occupancy), per step
      real(rp) :: eos_relaxation_rate = 0.01_rp    !< eos_relaxation: fraction of p - p_EOS(rho) removed per step
   end type material_spec_t

   !> The group's variables in the order docs/input.md and scene.nml give them.
   type(variable_info_t), parameter, public :: material_variables(*) = [ &
      variable_info_t('material', 'name', 'string', .true.), &
      variable_info_t('material', 'model', 'string', .true.), &
      variable_info_t('material', 'density', 'real', .true.), &
      variable_info_t('material', 'bulk_modulus', 'real', .false.), &
      variable_info_t('material', 'viscosity', 'real', .false.), &
      variable_info_t('material', 'youngs_modulus', 'real', .false.), &
      variable_info_t('material', 'poisson_ratio', 'real', .false.), &
      variable_info_t('material', 'stabilization', 'string', .false.), &
      variable_info_t('material', 'volumetric_only', 'logical', .false.), &
      variable_info_t('material', 'oscillation_rule', 'string', .false.), &
      variable_info_t('material', 'gamma_max', 'real', .false.), &
      variable_info_t('material', 'smoothed_variables', 'string', .false.), &
      variable_info_t('material', 'cell_averaging', 'logical', .false.), &
      variable_info_t('material', 'volume_correction', 'string', .false.), &
      variable_info_t('material', 'shifting_coefficient', 'real', .false.), &
      variable_info_t('material', 'eos_relaxation_rate', 'real', .false.)]

   !> Above this shifting coefficient the explicit occupancy diffusion is no longer stable (2-D bilinear
   !> grid Laplacian, docs/volume-conservation.md).
   real(rp), parameter :: max_shifting_coefficient = 0.25_rp
contains

   !> Read one `&material ... /` (text) over `spec`'s values (scene_reader's read_group).
   subroutine read_material_group(spec, ios, message, text)
      type(material_spec_t), intent(inout) :: spec
      integer, intent(out) :: ios
      character(len=*), intent(inout) :: message
      character(len=*), intent(in) :: text
      character(len=text_len) :: name, model, stabilization, oscillation_rule, smoothed_variables, volume_correction
      real(rp) :: density, bulk_modulus, viscosity, youngs_modulus, poisson_ratio, gamma_max, shifting_coefficient, &
                  eos_relaxation_rate
      logical :: volumetric_only, cell_averaging
      namelist /material/ name, model, density, bulk_modulus, viscosity, youngs_modulus, poisson_ratio, stabilization, &
         volumetric_only, oscillation_rule, gamma_max, smoothed_variables, cell_averaging, volume_correction, &
         shifting_coefficient, eos_relaxation_rate

      name = spec%name
      model = spec%model
      density = spec%density
      bulk_modulus = spec%bulk_modulus
      viscosity = spec%viscosity
      youngs_modulus = spec%youngs_modulus
      poisson_ratio = spec%poisson_ratio
      stabilization = spec%stabilization
      volumetric_only = spec%volumetric_only
      oscillation_rule = spec%oscillation_rule
      gamma_max = spec%gamma_max
      smoothed_variables = spec%smoothed_variables
      cell_averaging = spec%cell_averaging
      volume_correction = spec%volume_correction
      shifting_coefficient = spec%shifting_coefficient
      eos_relaxation_rate = spec%eos_relaxation_rate
      read (text, nml=material, iostat=ios, iomsg=message)
      call take_text('name', name, spec%name, ios, message)
      call take_text('model', model, spec%model, ios, message, fold='lower')
      call take_text('stabilization', stabilization, spec%stabilization, ios, message)
      call take_text('oscillation_rule', oscillation_rule, spec%oscillation_rule, ios, message)
      call take_text('smoothed_variables', smoothed_variables, spec%smoothed_variables, ios, message, fold='lower')
      call take_text('volume_correction', volume_correction, spec%volume_correction, ios, message, fold='lower')
      if (ios /= 0) return
      spec%density = density
      spec%bulk_modulus = bulk_modulus
      spec%viscosity = viscosity
      spec%youngs_modulus = youngs_modulus
      spec%poisson_ratio = poisson_ratio
      spec%stabilization = canonical_keyword(adjustl(spec%stabilization), stabilization_keywords)
      spec%volumetric_only = volumetric_only
      spec%oscillation_rule = canonical_keyword(adjustl(spec%oscillation_rule), oscillation_rule_keywords)
      spec%gamma_max = gamma_max
      spec%cell_averaging = cell_averaging
      spec%shifting_coefficient = shifting_coefficient
      spec%eos_relaxation_rate = eos_relaxation_rate
   end subroutine read_material_group

   !> The value of variable `name` as scene.nml writes it (it reads back to the same value).
   function material_value(material, name) result(text)
      type(material_spec_t), intent(in) :: material
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      select case (name)
      case ('name')
         text = quoted(material%name)
      case ('model')
         text = quoted(material%model)
      case ('density')
         text = real_text(material%density)
      case ('bulk_modulus')
         text = real_text(material%bulk_modulus)
      case ('viscosity')
         text = real_text(material%viscosity)
      case ('youngs_modulus')
         text = real_text(material%youngs_modulus)
      case ('poisson_ratio')
         text = real_text(material%poisson_ratio)
      case ('stabilization')
         text = quoted(material%stabilization)
      case ('volumetric_only')
         text = logical_text(material%volumetric_only)
      case ('oscillation_rule')
         text = quoted(material%oscillation_rule)
      case ('gamma_max')
         text = real_text(material%gamma_max)
      case ('smoothed_variables')
         text = quoted(material%smoothed_variables)
      case ('cell_averaging')
         text = logical_text(material%cell_averaging)
      case ('volume_correction')
         text = quoted(material%volume_correction)
      case ('shifting_coefficient')
         text = real_text(material%shifting_coefficient)
      case ('eos_relaxation_rate')
         text = real_text(material%eos_relaxation_rate)
      case default
         text = ''
      end select
   end function material_value

   !> The material's volume correction includes shifting (docs/volume-conservation.md).
   pure logical function shifts_particles(material)
      type(material_spec_t), intent(in) :: material
      shifts_particles = index(material%volume_correction, 'shifting') > 0
   end function shifts_particles

   !> The material's volume correction includes the EOS relaxation: its fluid also starts in EOS states.
   pure logical function relaxes_to_eos(material)
      type(material_spec_t), intent(in) :: material
      relaxes_to_eos = index(material%volume_correction, 'eos_relaxation') > 0
   end function relaxes_to_eos

   subroutine validate_material(materials, m, path, status)
      type(material_spec_t), intent(in) :: materials(:)
      integer, intent(in) :: m
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      character(len=:), allocatable :: where
      integer :: other
      logical :: incompressible

      associate (material => materials(m))
         if (len_trim(material%name) == 0) then
            call status%fail(group_context(path, 'material', m)//': variable name is required')
            return
         end if
         where = group_context(path, 'material', m, "name '"//trim(material%name)//"'")
         other = find_material(materials(1:m - 1), material%name)
         if (other > 0) then
            call status%fail(where//": variable name '"//trim(material%name)//"' is already used by the "// &
                             ordinal(other)//' &material')
            return
         end if
         if (all(material%model /= model_keywords)) then
            call status%fail(where//': variable model must be one of '//quoted_list(model_keywords)//", got '"// &
                             trim(material%model)//"'")
            return
         end if
         call check_real(where, 'density', material%density, status, greater_than=0.0_rp)
         select case (trim(material%model))
         case (model_newtonian_fluid)
            call check_real(where, 'bulk_modulus', material%bulk_modulus, status, greater_than=0.0_rp)
            call check_real(where, 'viscosity', material%viscosity, status, at_least=0.0_rp)
         case (model_linear_elastic)
            call check_real(where, 'youngs_modulus', material%youngs_modulus, status, greater_than=0.0_rp)
            incompressible = .false.
            if (ieee_is_finite(material%poisson_ratio)) incompressible = material%poisson_ratio >= 0.5_rp
            if (.not. incompressible) then
               call check_real(where, 'poisson_ratio', material%poisson_ratio, status, greater_than=-1.0_rp, &
                               less_than=0.5_rp)
            else
               ! nu = 0.5 is incompressible: the bulk modulus E / (3 (1 - 2 nu)) would be infinite.
               call status%fail(where//': variable poisson_ratio must be < 0.5 (0.5 is incompressible: use a '// &
                                'smaller ratio or a newtonian_fluid), got '//real_text(material%poisson_ratio))
            end if
         end select
         if (all(material%stabilization /= stabilization_keywords)) then
            call status%fail(where//': variable stabilization must be one of '//quoted_list(stabilization_keywords)// &
                             ", got '"//trim(material%stabilization)//"'")
         else if (material%model == model_rigid .and. material%stabilization /= 'none') then
            call status%fail(where//": variable stabilization must be 'none' for model '"//model_rigid// &
                             "' (a rigid body has no strain to filter), got '"//trim(material%stabilization)//"'")
         end if
         if (all(material%oscillation_rule /= oscillation_rule_keywords)) then
            call status%fail(where//': variable oscillation_rule must be one of '// &
                             quoted_list(oscillation_rule_keywords)//", got '"//trim(material%oscillation_rule)//"'")
         end if
         if (all(material%smoothed_variables /= smoothed_variables_keywords)) then
            call status%fail(where//': variable smoothed_variables must be one of '// &
                             quoted_list(smoothed_variables_keywords)//", got '"//trim(material%smoothed_variables)//"'")
         end if
         call check_real(where, 'gamma_max', material%gamma_max, status, at_least=0.0_rp, at_most=1.0_rp)
         if (all(material%volume_correction /= volume_correction_keywords)) then
            call status%fail(where//': variable volume_correction must be one of '// &
                             quoted_list(volume_correction_keywords)//", got '"//trim(material%volume_correction)//"'")
         else if (material%volume_correction /= 'none' .and. material%model /= model_newtonian_fluid) then
            call status%fail(where//": variable volume_correction = '"//trim(material%volume_correction)// &
                             "' is for fluids (model = '"//model_newtonian_fluid//"'), got model = '"// &
                             trim(material%model)//"'")
         end if
         call check_real(where, 'shifting_coefficient', material%shifting_coefficient, status, greater_than=0.0_rp, &
                         at_most=max_shifting_coefficient)
         call check_real(where, 'eos_relaxation_rate', material%eos_relaxation_rate, status, greater_than=0.0_rp, &
                         at_most=1.0_rp)
      end associate
   end subroutine validate_material

   !> The schemes of a material that a shape function does not combine with (docs/theory.md section 1.1):
   !> the volume correction's occupancy and open volumes integrate the multilinear hat of a node over its
   !> two cells, which bspline2 replaces by a wider support [R].
   subroutine check_shape_function_combination(material, m, grid, path, status)
      type(material_spec_t), intent(in) :: material
      integer, intent(in) :: m
      type(grid_spec_t), intent(in) :: grid
      character(len=*), intent(in) :: path
      type(status_t), intent(inout) :: status
      if (grid%shape_function == 'linear') return
      if (material%volume_correction /= 'none') &
         call status%fail(group_context(path, 'material', m, "name '"//trim(material%name)//"'")// &
                          ": variable volume_correction = '"//trim(material%volume_correction)// &
                          "' needs &grid shape_function = 'linear', got '"//trim(grid%shape_function)//"'")
   end subroutine check_shape_function_combination

   !> Index of the material called `name` (exact match); 0 if there is none.
   pure integer function find_material(materials, name) result(found)
      type(material_spec_t), intent(in) :: materials(:)
      character(len=*), intent(in) :: name
      integer :: m
      found = 0
      do m = 1, size(materials)
         if (materials(m)%name == name) then
            found = m
            return
         end if
      end do
   end function find_material
end module material_group
