#!/usr/bin/env bash
# The OpenFOAM campaign of the rig's jet (docs/cfd.md): writes, meshes, solves, samples and converts
# every case into data/cfd/. Resumable: a case whose data/cfd/<case>.json exists is skipped; an
# interrupted case restarts cleanly (from its finished mesh or solution when those are complete).
# Usage: bash scripts/cfd/run_all.sh [--work DIR] [--only CASE] [--list] [--np 1|2] [--commit]
#                                    [--model kEpsilon|kOmegaSST|realizableKE]
#   --work DIR   raw cases (default: cfd-work/ at the repository top; not versioned)
#   --only CASE  run one case (names from --list)
#   --list       list the cases in run order, with their state
#   --np N       MPI ranks for the solver: 1 (serial, default) or 2 (hierarchical decomposition)
#   --commit     git-commit each finished case's files in data/cfd/ (only those paths)
#   --model M    RAS model: kEpsilon (default, the campaign) or, for the turbulence-model study
#                (tilts 22.5, 45, 0; mesh 1, 20 mm inlet), kOmegaSST (cases *_sst) or realizableKE
#                (cases *_rke), their data in data/cfd/turbulence/<model>/
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
top="$(cd "$here/../.." && pwd)"
work="$top/cfd-work"
out="$top/data/cfd"
only=""
list=0
np=1
commit=0
model=kEpsilon
py=/usr/bin/python3

while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --only) only="$2"; shift 2 ;;
    --list) list=1; shift ;;
    --np) np="$2"; shift 2 ;;
    --commit) commit=1; shift ;;
    --model) model="$2"; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0"; exit 0 ;;
    *) echo "run_all.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$np" in 1|2) ;; *) echo "run_all.sh: --np must be 1 or 2" >&2; exit 2 ;; esac
case "$model" in
  kEpsilon) ;;
  kOmegaSST|realizableKE) out="$out/turbulence/$model" ;;
  *) echo "run_all.sh: unknown --model '$model' (expected kEpsilon, kOmegaSST or realizableKE)" >&2; exit 2 ;;
esac

export WM_PROJECT_DIR=/usr/share/openfoam
for tool in blockMesh surfaceFeatureExtract snappyHexMesh checkMesh simpleFoam postProcess; do
  if ! command -v "$tool" >/dev/null 2>&1 || [ ! -d "$WM_PROJECT_DIR/etc" ]; then
    echo "run_all.sh: OpenFOAM not found (no $tool); run bash scripts/setup.sh --cfd" >&2
    exit 1
  fi
done
if ! "$py" -c 'import numpy' >/dev/null 2>&1; then
  echo "run_all.sh: $py with numpy not found; run bash scripts/setup.sh --cfd" >&2
  exit 1
fi
if [ "$np" = 2 ] && ! command -v mpirun >/dev/null 2>&1; then
  echo "run_all.sh: mpirun not found; run bash scripts/setup.sh --cfd" >&2
  exit 1
fi

if [ "$model" = kEpsilon ]; then
  mapfile -t cases < <("$py" "$here/cfdcase.py" list)
else
  mapfile -t cases < <("$py" "$here/cfdcase.py" list "$model")
fi
total=${#cases[@]}

if [ "$list" = 1 ]; then
  for line in "${cases[@]}"; do
    read -r name tilt level d <<<"$line"
    state="to do"
    [ -f "$out/$name.json" ] && state="done"
    printf '%-22s tilt %5s deg, mesh %s, inlet %s m: %s\n' "$name" "$tilt" "$level" "$d" "$state"
  done
  exit 0
fi
if [ -n "$only" ] && ! printf '%s\n' "${cases[@]}" | grep -q "^$only "; then
  echo "run_all.sh: unknown case '$only' (see --list)" >&2
  exit 2
fi

mkdir -p "$work" "$out"
nice_cmd=(nice -n 19)
# shellcheck source=scripts/cfd/commit_data.sh
source "$here/commit_data.sh"

# runs an OpenFOAM tool in the case folder, its output to log.<name>; fails loudly
run_tool() {
  local logname="$1"; shift
  if ! (cd "$case_dir" && "${nice_cmd[@]}" "$@" > "log.$logname" 2>&1); then
    echo "$tag: $1 failed, see $case_dir/log.$logname" >&2
    tail -5 "$case_dir/log.$logname" >&2
    return 1
  fi
}

commit_case() {
  local name="$1" files=()
  for f in "$out/$name".json "$out/$name".f32 "$out/$name"_*.csv; do
    [ -f "$f" ] && files+=("${f#"$top"/}")
  done
  local body="Floor field, jet centreline and wall-jet profiles of case $name from scripts/cfd/run_all.sh (docs/cfd.md)."
  [ "$model" != kEpsilon ] && body="Floor field, jet centreline and wall-jet profiles of case $name, RAS model $model, from scripts/cfd/run_all.sh --model $model (docs/cfd.md, sensitivity to the turbulence model)."
  echo "$tag: $(commit_data "$top" "CFD data: $name" "$body" "${files[@]}")"
}

solve() {
  local name="$1" t0 t1 pid
  rm -rf "$case_dir"/processor* "$case_dir"/[1-9]* "$case_dir/postProcessing" "$case_dir/log.simpleFoam"
  # the initial and boundary fields from the current generator (a resumed case may have older ones)
  "$py" "$here/cfdcase.py" fields "$name" "$case_dir" >/dev/null || return 1
  t0=$(date +%s)
  if [ "$np" = 2 ]; then
    run_tool decomposePar decomposePar -force || return 1
    (cd "$case_dir" && "${nice_cmd[@]}" mpirun --allow-run-as-root -np 2 simpleFoam -parallel \
      > log.simpleFoam 2>&1) &
  else
    (cd "$case_dir" && "${nice_cmd[@]}" simpleFoam > log.simpleFoam 2>&1) &
  fi
  pid=$!
  while kill -0 "$pid" 2>/dev/null; do
    sleep 30
    kill -0 "$pid" 2>/dev/null && echo "$tag: $("$py" "$here/cfdcase.py" progress "$case_dir")"
  done
  if ! wait "$pid"; then
    echo "$tag: simpleFoam failed, see $case_dir/log.simpleFoam" >&2
    tail -5 "$case_dir/log.simpleFoam" >&2
    return 1
  fi
  if [ "$np" = 2 ]; then
    run_tool reconstructPar reconstructPar -latestTime || return 1
    rm -rf "$case_dir"/processor*
  fi
  t1=$(date +%s)
  printf '{"wall_time_s": %d, "ranks": %d, "mesh_time_s": %s}\n' "$((t1 - t0))" "$np" \
    "$(cat "$case_dir/mesh_time_s" 2>/dev/null || echo null)" > "$case_dir/run.json"
  echo "$tag: $("$py" "$here/cfdcase.py" progress "$case_dir"), $((t1 - t0)) s"
  touch "$case_dir/.solved"
}

run_case() {
  local name="$1" tilt="$2" level="$3" d="$4" t0
  case_dir="$work/$name"
  if [ -f "$case_dir/.meshed" ]; then
    echo "$tag: mesh from an earlier run"
  else
    rm -rf "$case_dir"
    mkdir -p "$case_dir"
    t0=$(date +%s)
    echo "$tag: meshing"
    "$py" "$here/cfdcase.py" write "$name" "$case_dir" || return 1
    run_tool blockMesh blockMesh || return 1
    run_tool surfaceFeatureExtract surfaceFeatureExtract || return 1
    run_tool snappyHexMesh snappyHexMesh -overwrite || return 1
    run_tool checkMesh checkMesh || return 1
    echo "$tag: $("$py" "$here/cfdcase.py" fields "$name" "$case_dir")" || return 1
    echo "$(( $(date +%s) - t0 ))" > "$case_dir/mesh_time_s"
    echo "$tag: meshed in $(cat "$case_dir/mesh_time_s") s"
    touch "$case_dir/.meshed"
  fi
  if [ ! -f "$case_dir/.solved" ]; then
    solve "$name" || return 1
  fi
  echo "$tag: sampling"
  rm -rf "$case_dir/postProcessing"
  "$py" "$here/cfdcase.py" sampledict "$name" "$case_dir" || return 1
  run_tool postProcess postProcess -func sampleAll -latestTime || return 1
  echo "$tag: $("$py" "$here/cfdcase.py" convert "$name" "$case_dir" "$out")" || return 1
  [ "$commit" = 1 ] && commit_case "$name"
  return 0
}

failed=0
i=0
for line in "${cases[@]}"; do
  i=$((i + 1))
  read -r name tilt level d <<<"$line"
  [ -n "$only" ] && [ "$name" != "$only" ] && continue
  tag="[$i/$total] tilt $tilt deg, mesh $level, inlet $(awk -v d="$d" 'BEGIN{printf "%g", d*1000}') mm"
  [ "$model" != kEpsilon ] && tag="$tag, $model"
  if [ -f "$out/$name.json" ]; then
    echo "$tag: done before, skipped"
    continue
  fi
  echo "$tag: start $(date '+%H:%M:%S')"
  if ! run_case "$name" "$tilt" "$level" "$d"; then
    echo "$tag: FAILED" >&2
    failed=$((failed + 1))
  fi
done
if [ "$failed" -gt 0 ]; then
  echo "run_all.sh: $failed case(s) failed" >&2
  exit 1
fi
echo "run_all.sh: all done; data in ${out#"$top"/}/"
