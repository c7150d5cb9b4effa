#!/usr/bin/env bash
# Runs flotsam on every bad scene of tests/input/bad/ (and on a scene file that does not exist) and
# checks that each run fails cleanly: non-zero exit, the expected message on stderr, printed once
# (by rank 0, not once per rank), and no output folder created.
#
# usage: run_bad_input.sh <path to flotsam> <path to mpiexec> [directory of bad scenes]
#
# Each bad scene starts with the line
#   ! expect: <text the error message must contain>
# and sets a relative output_dir, so each run happens in a fresh temporary working directory. More
# `! expect:` lines right after the first add texts the message must also contain; `! expect: exit N`
# asks for exit code N (mpiexec's: a rank that ended otherwise shows).
set -u

if [[ $# -lt 2 ]]; then
   echo "usage: $0 <flotsam executable> <mpiexec> [bad scene directory]" >&2
   exit 2
fi
flotsam=$(realpath "$1")
mpiexec=$2
bad_dir=$(realpath "${3:-$(dirname "$0")/bad}")
nranks=2
time_limit=120

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
# When a rank exits with a non-zero code, Open MPI's mpirun ends the job by signalling the ranks, and waits
# its SIGKILL timeout (1 s) twice even when all of them have exited: 2.5 s instead of 0.6 s per case here.
# Every rank of these cases stops on its own before anything is written, so not waiting changes nothing
# the cases check (a rank left behind was ended by mpirun before as well).
export OMPI_MCA_odls_base_sigkill_timeout=0

if [[ ! -x $flotsam ]]; then
   echo "no flotsam executable at $1" >&2
   exit 2
fi
shopt -s nullglob
scenes=("$bad_dir"/*.nml)
if [[ ${#scenes[@]} -eq 0 ]]; then
   echo "no bad scenes in $bad_dir" >&2
   exit 2
fi

work_root=$(mktemp -d "${TMPDIR:-/tmp}/flotsam_bad_input.XXXXXX")
trap 'rm -rf "$work_root"' EXIT

passed=0
failed=0

# check_case <name> <scene path> <expected substrings, one per line> <output dir the scene asks for>
check_case() {
   local name=$1 scene=$2 expects=$3 output_dir=$4 expect exit_code=''
   local work="$work_root/$name"
   mkdir -p "$work"
   local rc=0
   (cd "$work" && timeout "$time_limit" "$mpiexec" -np "$nranks" "$flotsam" "$scene" \
      >"$work_root/$name.out" 2>"$work_root/$name.err") || rc=$?

   local problems=()
   if [[ $rc -eq 0 ]]; then
      problems+=("exit code 0")
   elif [[ $rc -eq 124 ]]; then
      problems+=("timed out after ${time_limit} s (a rank left a collective?)")
   fi
   local messages
   messages=$(grep -c 'flotsam: error:' "$work_root/$name.err")
   if [[ $messages -ne 1 ]]; then
      problems+=("'flotsam: error:' printed $messages times instead of once")
   fi
   while IFS= read -r expect; do
      if [[ $expect =~ ^exit\ ([0-9]+)$ ]]; then
         exit_code=${BASH_REMATCH[1]}
      elif ! grep -qF -- "$expect" "$work_root/$name.err"; then
         problems+=("stderr lacks: $expect")
      fi
   done <<<"$expects"
   if [[ -n $exit_code && $rc -ne $exit_code ]]; then
      problems+=("exit code $rc instead of $exit_code")
   fi
   if [[ -e "$work/$output_dir" ]]; then
      problems+=("output folder $output_dir was created")
   fi

   if [[ ${#problems[@]} -eq 0 ]]; then
      echo "PASS $name"
      passed=$((passed + 1))
   else
      local joined
      joined=$(printf '%s; ' "${problems[@]}")
      echo "FAIL $name: ${joined%; }"
      echo "     stderr: $(grep 'flotsam: error:' "$work_root/$name.err" | head -n 3)"
      [[ $messages -eq 0 ]] && sed 's/^/     | /' "$work_root/$name.err" | head -n 10
      failed=$((failed + 1))
   fi
}

# The output_dir a scene asks for ('output' if it gives none).
output_dir_of() {
   local dir
   dir=$(sed -n "s/^[^!]*output_dir *= *['\"]\\([^'\"]*\\)['\"].*/\\1/p" "$1" | head -n 1)
   echo "${dir:-output}"
}

for scene in "${scenes[@]}"; do
   name=$(basename "$scene" .nml)
   # the first line and the `! expect:` lines right after it
   expect=$(awk '!/^! *expect:/ { exit } { sub(/^! *expect: */, ""); print }' "$scene")
   if [[ -z $expect ]]; then
      echo "FAIL $name: first line is not '! expect: <message text>'"
      failed=$((failed + 1))
      continue
   fi
   check_case "$name" "$scene" "$expect" "$(output_dir_of "$scene")"
done

# A scene file that does not exist: the message names the file.
check_case missing_file "$work_root/does_not_exist.nml" "does_not_exist.nml: scene file not found" output

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
