#!/usr/bin/env bash
# A re-aim of the rig's jet in 3-D (docs/cfd.md, "A re-aim in 3-D"): the jet held steady at one
# tilt, turned at the servos' speed to another and held there (a visit: held briefly and turned
# back; cases sharing the tilts share the mesh and steady ends); written by scripts/cfd/reaim.py,
# meshed by snappyHexMesh, solved by simpleFoam (the two end tilts, steady) and pimpleFoam (the
# re-aim from the first one's fields), converted into data/cfd/<case>.{json,_floor.csv}.
# Resumable: each stage leaves a marker in the work directory; an interrupted transient restarts
# from its last written time (every 0.1 s simulated); a finished case (its JSON exists) is skipped.
# Usage: bash scripts/cfd/reaim.sh [--np 1|2] [--work DIR] [--commit] [--list]
#   --np N       ranks for the solvers (default 2)
#   --work DIR   raw cases (default: cfd-work/ at the repository top; not versioned)
#   --commit     git-commit each case's converted files in data/cfd/ (only those paths)
#   --list       the cases and whether they are done
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
top="$(cd "$here/../.." && pwd)"
work="$top/cfd-work"
out="$top/data/cfd"
commit=0
np=2
list=0
py=/usr/bin/python3

while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --commit) commit=1; shift ;;
    --np) np="${2:-}"; shift 2 ;;
    --list) list=1; shift ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "reaim.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$np" in 1|2) ;; *) echo "reaim.sh: --np: expected 1 or 2, got '$np'" >&2; exit 2 ;; esac

mapfile -t cases < <("$py" "$here/reaim.py" list)
if [ "$list" = 1 ]; then
  for line in "${cases[@]}"; do
    read -r name from to _ <<<"$line"
    state="to do"
    [ -f "$out/$name.json" ] && state="done"
    printf '%-24s %5s -> %5s deg: %s\n' "$name" "$from" "$to" "$state"
  done
  exit 0
fi

export WM_PROJECT_DIR=/usr/share/openfoam
for tool in blockMesh surfaceFeatureExtract snappyHexMesh checkMesh simpleFoam pimpleFoam decomposePar \
            reconstructPar; do
  if ! command -v "$tool" >/dev/null 2>&1 || [ ! -d "$WM_PROJECT_DIR/etc" ]; then
    echo "reaim.sh: OpenFOAM not found (no $tool); run bash scripts/setup.sh --cfd" >&2
    exit 1
  fi
done
if ! "$py" -c 'import numpy' >/dev/null 2>&1; then
  echo "reaim.sh: $py with numpy not found; run bash scripts/setup.sh --cfd" >&2
  exit 1
fi
if [ "$np" = 2 ] && ! command -v mpirun >/dev/null 2>&1; then
  echo "reaim.sh: mpirun not found; run bash scripts/setup.sh --cfd" >&2
  exit 1
fi
nice_cmd=(nice -n 19)
# shellcheck source=scripts/cfd/commit_data.sh
source "$here/commit_data.sh"
mkdir -p "$work" "$out"

# tool DIR LOG CMD...: one OpenFOAM tool in DIR, its output in DIR/log.LOG.
tool() {
  local dir="$1" log="$2"; shift 2
  if ! (cd "$dir" && "${nice_cmd[@]}" "$@" > "log.$log" 2>&1); then
    echo "reaim.sh: $1 failed, see $dir/log.$log" >&2
    tail -5 "$dir/log.$log" >&2
    exit 1
  fi
}

# solver DIR APP PROGRESS: APP (serial or on np ranks) in DIR, progress lines every minute.
solver() {
  local dir="$1" app="$2" progress="$3" n log pid t0
  n=$(find "$dir" -maxdepth 1 -name "log.$app*" | wc -l)
  log="log.$app"
  [ "$n" = 0 ] || log="log.$app.$n"
  t0=$(date +%s)
  if [ "$np" = 2 ]; then
    [ -d "$dir/processor0" ] || tool "$dir" decomposePar decomposePar -force
    (cd "$dir" && "${nice_cmd[@]}" mpirun --allow-run-as-root -np 2 "$app" -parallel > "$log" 2>&1) &
  else
    (cd "$dir" && "${nice_cmd[@]}" "$app" > "$log" 2>&1) &
  fi
  pid=$!
  while kill -0 "$pid" 2>/dev/null; do
    sleep 60
    kill -0 "$pid" 2>/dev/null && echo "reaim.sh: $(basename "$dir"): $("$py" "$here/$progress" progress "$dir")"
  done
  if ! wait "$pid"; then
    echo "reaim.sh: $app failed, see $dir/$log" >&2
    tail -5 "$dir/$log" >&2
    exit 1
  fi
  echo "$(( $(date +%s) - t0 ))" >> "$dir/wall_time_s"
}

# steady_dir MESH TILT: where the steady run blowing at TILT on case MESH's mesh lives.
steady_dir() {
  printf '%s/%s_steady_t%04.1f' "$work" "$1" "$2"
}

# steady MESH TILT: the steady run blowing at TILT on case MESH's mesh (a copy of the mesh's
# directory; cases with the same tilts share it).
steady() {
  local name="$1" tilt="$2" dir mesh_dir="$work/${1}_mesh" msg
  dir="$(steady_dir "$1" "$2")"
  [ -f "$dir/.solved" ] && return 0
  if [ ! -f "$dir/.fields" ]; then
    rm -rf "$dir"
    mkdir -p "$dir"
    cp -r "$mesh_dir/constant" "$mesh_dir/system" "$mesh_dir/case.json" "$dir/"
    msg=$("$py" "$here/reaim.py" steady "$name" "$dir" "$tilt") || exit 1
    echo "reaim.sh: $(basename "$dir"): $msg"
    touch "$dir/.fields"
  fi
  solver "$dir" simpleFoam cfdcase.py
  if [ "$np" = 2 ]; then
    tool "$dir" reconstructPar reconstructPar -latestTime
    rm -rf "$dir"/processor*
  fi
  echo "reaim.sh: $(basename "$dir"): $("$py" "$here/cfdcase.py" progress "$dir")"
  printf '{"tilt_deg": %s, "wall_time_s": %s, "ranks": %d, "log": "%s"}\n' "$tilt" \
    "$(awk '{s += $1} END {print s}' "$dir/wall_time_s")" "$np" \
    "$("$py" "$here/cfdcase.py" progress "$dir" | sed 's/"//g')" > "$dir/run.json"
  touch "$dir/.solved"
}

# run_case NAME FROM TO MESH: the case NAME on the mesh (and steady ends) of case MESH.
run_case() {
  local name="$1" from="$2" to="$3" mesh="$4" mesh_dir="$work/${4}_mesh" dir="$work/$1" t0 msg
  if [ ! -f "$mesh_dir/.meshed" ]; then
    rm -rf "$mesh_dir"
    mkdir -p "$mesh_dir"
    t0=$(date +%s)
    msg=$("$py" "$here/reaim.py" write "$mesh" "$mesh_dir") || exit 1
    echo "reaim.sh: $msg"
    tool "$mesh_dir" blockMesh blockMesh
    tool "$mesh_dir" surfaceFeatureExtract surfaceFeatureExtract
    tool "$mesh_dir" snappyHexMesh snappyHexMesh -overwrite
    tool "$mesh_dir" checkMesh checkMesh
    echo "reaim.sh: meshed in $(( $(date +%s) - t0 )) s: $(grep -m1 'cells:' "$mesh_dir/log.checkMesh" | xargs)"
    touch "$mesh_dir/.meshed"
  fi
  # the first tilt's steady state (the transient's start); the second's (the reference of the
  # transient's end) after the transient
  steady "$mesh" "$from"
  if [ ! -f "$dir/.written" ]; then
    rm -rf "$dir"
    msg=$("$py" "$here/reaim.py" transient "$name" "$(steady_dir "$mesh" "$from")" "$dir") || exit 1
    echo "reaim.sh: $msg"
    touch "$dir/.written"
  fi
  if [ ! -f "$dir/.solved" ]; then
    solver "$dir" pimpleFoam reaim.py
    touch "$dir/.solved"
  fi
  steady "$mesh" "$to"
  msg=$("$py" "$here/reaim.py" convert "$name" "$dir" "$out" "$(steady_dir "$mesh" "$from")" \
    "$(steady_dir "$mesh" "$to")") || exit 1
  echo "reaim.sh: $msg"
  if [ "$commit" = 1 ]; then
    local files=("${out#"$top"/}/$name.json" "${out#"$top"/}/${name}_floor.csv")
    msg=$(commit_data "$top" "CFD data: $name" \
      "A 3-D re-aim or visit of the rig's jet from scripts/cfd/reaim.sh (docs/cfd.md)." "${files[@]}") || exit 1
    echo "reaim.sh: $msg"
  fi
}

for line in "${cases[@]}"; do
  read -r name from to mesh <<<"$line"
  if [ -f "$out/$name.json" ]; then
    echo "reaim.sh: $name done before; skipped"
    continue
  fi
  run_case "$name" "$from" "$to" "$mesh"
done
exit 0
