# Scenes of the benchmark cases, shared by scripts/bench_instructions, bench_profile and bench_compare
# (sourced, not run). A case is the bench's water column (inputs/bench) of its dimension with one input
# changed for a variant: 2d 3d 2d-apic 2d-bspline2 2d-c0 2d-foal1 2d-nb 3d-apic 3d-bspline2 3d-c0 3d-foal1
# 3d-nb 2d-bspline2-apic 3d-bspline2-apic, and FOAL1 with the volume correction's shifting: 2d-shifting
# 3d-shifting, and on the tank at rest (inputs/bench/hydrostatic_tank.nml, 2-D) tank-shifting. Needs $root
# (the repository).
bench_case_names=(2d 2d-apic 2d-bspline2 2d-bspline2-apic 2d-c0 2d-foal1 2d-nb 3d 3d-apic 3d-bspline2 3d-bspline2-apic 3d-c0 3d-foal1 3d-nb 2d-shifting 3d-shifting tank-shifting)

# the scene of case $1 on stdout
scene_of() {
   local case=$1 dim=${1:0:2} base
   base="$root/inputs/bench/water_column_${dim}.nml"
   case $case in
   2d | 3d) cat "$base" ;;
   tank-shifting)
      sed "s/stabilization = 'none'/stabilization = 'FOAL1', volume_correction = 'shifting'/" \
         "$root/inputs/bench/hydrostatic_tank.nml" ;;
   *-bspline2-apic) sed -e "s/^&run /\&run transfer = 'apic', /" -e "s/^&grid /\&grid shape_function = 'bspline2', /" "$base" ;;
   *-apic) sed "s/^&run /\&run transfer = 'apic', /" "$base" ;;
   *-bspline2) sed "s/^&grid /\&grid shape_function = 'bspline2', /" "$base" ;;
   *-c0) sed "s/model = 'newtonian_fluid'/model = 'newtonian_fluid', stabilization = 'C0'/" "$base" ;;
   *-shifting) sed "s/model = 'newtonian_fluid'/model = 'newtonian_fluid', stabilization = 'FOAL1', volume_correction = 'shifting'/" "$base" ;;
   *-foal1) sed "s/model = 'newtonian_fluid'/model = 'newtonian_fluid', stabilization = 'FOAL1'/" "$base" ;;
   *-nb) sed "s/model = 'newtonian_fluid'/model = 'newtonian_fluid', stabilization = 'NB'/" "$base" ;;
   *) echo "unknown benchmark case '$case' (cases: ${bench_case_names[*]})" >&2; return 1 ;;
   esac
}
