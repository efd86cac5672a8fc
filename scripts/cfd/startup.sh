#!/usr/bin/env bash
# The jet's start-up and stop (docs/cfd.md, "The jet's start-up", "The jet's stop"): transient
# axisymmetric RANS of the rig's jet switched on over a still floor, and (--stop) switched off again
# from the start-up's final fields; written by scripts/cfd/startup.py, solved by pimpleFoam and
# converted into data/cfd/<case>.{json,_floor.csv,_axis.csv} (startup_tilt00_d40, stop_tilt00_d40).
# Resumable: an interrupted run restarts from its last written time (every 0.5 s simulated); a
# finished case (its data/cfd/ JSON exists) is skipped. The stop case needs the start-up's raw
# fields in the work directory (the start-up is run again, ~2 h, when they are missing).
# Usage: bash scripts/cfd/startup.sh [--stop] [--pulse MS ...] [--work DIR] [--commit]
#   --stop       the stop case too (after the start-up)
#   --pulse MS   a pulse case too: the jet open for MS milliseconds (20 < MS <= 2000), what a point
#                beside a sweeping jet receives (repeatable; pulse<MS>ms_tilt00_d40)
#   --work DIR   raw cases (default: cfd-work/ at the repository top; not versioned)
#   --commit     git-commit each case's converted files in data/cfd/ (only those paths)
set -uo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
top="$(cd "$here/../.." && pwd)"
work="$top/cfd-work"
out="$top/data/cfd"
commit=0
stop=0
pulses=()
py=/usr/bin/python3

while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --commit) commit=1; shift ;;
    --stop) stop=1; shift ;;
    --pulse)
      [[ "${2:-}" =~ ^[0-9]+$ ]] || { echo "startup.sh: --pulse: expected milliseconds, got '${2:-}'" >&2; exit 2; }
      pulses+=("$2"); shift 2 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "startup.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

export WM_PROJECT_DIR=/usr/share/openfoam
for tool in blockMesh checkMesh pimpleFoam; do
  if ! command -v "$tool" >/dev/null 2>&1 || [ ! -d "$WM_PROJECT_DIR/etc" ]; then
    echo "startup.sh: OpenFOAM not found (no $tool); run bash scripts/setup.sh --cfd" >&2
    exit 1
  fi
done
if ! "$py" -c 'import numpy' >/dev/null 2>&1; then
  echo "startup.sh: $py with numpy not found; run bash scripts/setup.sh --cfd" >&2
  exit 1
fi
nice_cmd=(nice -n 19)
# shellcheck source=scripts/cfd/commit_data.sh
source "$here/commit_data.sh"

# run_case NAME: writes (and for the start-up meshes), solves, converts and commits one case.
run_case() {
  local name="$1"
  local case_dir="$work/$name"
  if [ ! -f "$case_dir/.meshed" ]; then
    rm -rf "$case_dir"
    mkdir -p "$case_dir"
    if [ "$name" = stop_tilt00_d40 ]; then
      echo "startup.sh: $("$py" "$here/startup.py" write-stop "$work/startup_tilt00_d40" "$case_dir")" || exit 1
    else
      if [[ "$name" == pulse* ]]; then
        ms=${name#pulse}; ms=$((10#${ms%%ms_*}))
        echo "startup.sh: $("$py" "$here/startup.py" write-pulse "$case_dir" "$ms")" || exit 1
      else
        echo "startup.sh: $("$py" "$here/startup.py" write "$case_dir")" || exit 1
      fi
      for tool in blockMesh checkMesh; do
        if ! (cd "$case_dir" && "${nice_cmd[@]}" "$tool" > "log.$tool" 2>&1); then
          echo "startup.sh: $tool failed, see $case_dir/log.$tool" >&2
          exit 1
        fi
      done
    fi
    touch "$case_dir/.meshed"
  fi

  if [ ! -f "$case_dir/.solved" ]; then
    # each (re)start keeps its own log; pimpleFoam resumes from the latest written time
    n=$(find "$case_dir" -maxdepth 1 -name 'log.pimpleFoam*' | wc -l)
    log="log.pimpleFoam.$n"
    t0=$(date +%s)
    (cd "$case_dir" && "${nice_cmd[@]}" pimpleFoam > "$log" 2>&1) &
    pid=$!
    while kill -0 "$pid" 2>/dev/null; do
      sleep 60
      kill -0 "$pid" 2>/dev/null && echo "startup.sh: $("$py" "$here/startup.py" progress "$case_dir")"
    done
    if ! wait "$pid"; then
      echo "startup.sh: pimpleFoam failed, see $case_dir/$log" >&2
      tail -5 "$case_dir/$log" >&2
      exit 1
    fi
    echo "$(( $(date +%s) - t0 ))" >> "$case_dir/wall_time_s"
    touch "$case_dir/.solved"
  fi

  echo "startup.sh: $("$py" "$here/startup.py" convert "$case_dir" "$out")" || exit 1
  if [ "$commit" = 1 ]; then
    files=()
    for f in "$out/$name".json "$out/$name"_*.csv; do
      files+=("${f#"$top"/}")
    done
    msg=$(commit_data "$top" "CFD data: $name" \
      "A transient of the rig's jet from scripts/cfd/startup.sh (docs/cfd.md)." "${files[@]}") || exit 1
    echo "startup.sh: $msg"
  fi
}

pulse_names=()
for ms in "${pulses[@]}"; do pulse_names+=("$(printf 'pulse%03dms_tilt00_d40' "$((10#$ms))")"); done
todo=0
for n in "${pulse_names[@]}"; do [ -f "$out/$n.json" ] || todo=1; done
if [ -f "$out/startup_tilt00_d40.json" ] && { [ "$stop" = 0 ] || [ -f "$out/stop_tilt00_d40.json" ]; } &&
   [ "$todo" = 0 ]; then
  echo "startup.sh: done before (${out#"$top"/}/); nothing to do"
  exit 0
fi
if [ ! -f "$out/startup_tilt00_d40.json" ] ||
   { [ "$stop" = 1 ] && [ ! -d "$work/startup_tilt00_d40/10" ]; }; then
  [ -f "$out/startup_tilt00_d40.json" ] && echo "startup.sh: the start-up's raw fields are gone; running it again"
  rm -f "$work/startup_tilt00_d40/.solved"
  run_case startup_tilt00_d40
fi
[ "$stop" = 1 ] && [ ! -f "$out/stop_tilt00_d40.json" ] && run_case stop_tilt00_d40
for n in "${pulse_names[@]}"; do
  [ -f "$out/$n.json" ] || run_case "$n"
done
exit 0
