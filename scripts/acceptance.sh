#!/usr/bin/env bash
# The acceptance tier (docs/testing.md): the checks that need many seeds, too long for every
# commit. Builds Release in build/ (as scripts/test.sh), then:
#   closed loop    the closedloop-labelled tests with AIRTWIN_TEST_TIER=acceptance: every shipped
#                  scenario over seeds 1-10 (9 of 10 must succeed) and the octagon with vision;
#                  10 000 steps of the Python env without memory growth
#   discrepancy    the discrepancy- and calibration-labelled tests in the acceptance tier (null
#                  data over three collection seeds; the shipped tracer set on 29 held-out
#                  Appendix D collections) once per test seed: each run draws new
#                  hidden-effect magnitudes (default test seeds 1 2 3)
#   sweep          `airtwin batch` of every shipped scenario over seeds 1-N (default 30), fast
#                  mode, in the default (physical) twin and in the mirror, and every scenario
#                  with vision over seeds 1-M (default 10: Table I's other mode), and with
#                  objects that differ (--vary-physics 0.1) and with a rig's latency of 0.1 s
#                  (loop.latency_s in copies of the files) over seeds 1-M; each
#                  scenario's success count must reach its floor (below)
#   physical       scripts/physical_twin_closed_loop.sh over seeds 1-P (default 10): the
#                  paper's pipeline on the physical twin (CFD air, physical drag, eq. (8)
#                  identified from the twin, the paper's CEM settings; the wall jet's formation
#                  and its front carried by the old air at their defaults) with the
#                  aggregation and the sorting (--multi), the paths again planning with the
#                  extended model from the discrepancy analysis of other seeds' closed-loop
#                  logs (--discrepancy), then the paths without the formation
#                  and with the front of still air, each identified there;
#                  floors: today's rates less one run in ten (docs/twin.md, "Closed loop in the
#                  physical twin")
#   gain           (with --gain) scripts/closed_loop_gain.sh: every catalogue effect hidden in
#                  the twin, found, and the octagon batch planned with and without the extension
# Writes OUT/summary.md (default results/acceptance/) with the figures and the stage times;
# docs/testing.md keeps the latest. Exit 1 when any check fails; the summary says which.
# Usage: bash scripts/acceptance.sh [--seeds N] [--vision-seeds M] [--physical-seeds P]
#                                   [--test-seeds "S1 S2 ..."] [--gain] [--out DIR]
#                                   [--stages "closed-loop discrepancy sweep physical"]
set -euo pipefail
cd "$(dirname "$0")/.."

seeds=30
vision_seeds=10
physical_seeds=10
test_seeds="1 2 3"
gain=0
stages="closed-loop discrepancy sweep physical"
out=results/acceptance
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) seeds=$2; shift 2 ;;
    --vision-seeds) vision_seeds=$2; shift 2 ;;
    --physical-seeds) physical_seeds=$2; shift 2 ;;
    --test-seeds) test_seeds=$2; shift 2 ;;
    --gain) gain=1; shift ;;
    --stages) stages=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    -h|--help) sed -n '2,31p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "acceptance.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for st in $stages; do
  case "$st" in
    closed-loop | discrepancy | sweep | physical) ;;
    *) echo "acceptance.sh: --stages: unknown stage '$st' (closed-loop, discrepancy, sweep, physical)" >&2
       exit 2 ;;
  esac
done
wants() { [[ " $stages " == *" $1 "* ]]; }
for n in "$seeds" "$vision_seeds" "$physical_seeds"; do
  case "$n" in
    '' | *[!0-9]* | 0) echo "acceptance.sh: a seed count must be a positive integer, got '$n'" >&2
                       exit 2 ;;
  esac
done

# Success floors over seeds 1-N, as fractions of N: the rates measured over seeds 1-30
# (docs/controller.md: octagon 26/30, the others 30/30; static friction that holds,
# 2026-11-27) less one run in thirty. Sorting with vision: measured 20/20 before that change.
# The tracer set changed on 2026-11-29 (C_D 0.35, mu_k 0.4, C_L 0.2 before): every rate below
# but the mirror's (eq. (8) as physics: the set's parameters play no part there) is the new
# set's, measured by the same batches as this script runs.
floor_of() {
  case "$1" in
    # The default twin, the physical one (docs/twin.md, "The physical twin by default"), with
    # the sweep clearance (docs/controller.md, "The re-aim's sweep"): seeds 1-30 with the tracer
    # set since 2026-11-29 gave 30/30 for the line, the square, the octagon and the aggregation,
    # 29/30 for the letter A (seed 20 stalled) and the sorting (seed 24); floors at those rates
    # less one in ten (regression floors). (The set before: 29/30 for the letter A and the
    # octagon, 27-28/30 for the sorting.)
    line | square | letter_A | octagon | aggregation) echo 0.9 ;;
    sorting) echo 0.85 ;;
    # With vision, seeds 1-10, this sweep's camera without noise: every scenario 10/10 with the
    # tracer set since 2026-11-29 (the camera's low noise, docs/twin.md: the sorting 9/10); less
    # one in ten. (The set before, 2026-11-28: the octagon 9/10, the sorting 8/10.)
    line_vision | square_vision | letter_A_vision | octagon_vision | aggregation_vision) echo 0.9 ;;
    sorting_vision) echo 0.9 ;;
    # Objects that differ (--vary-physics 0.1: each object's mass, drag, friction and lift
    # within +-10 % of its type's; docs/twin.md), seeds 1-10 as the vision sweep's: measured
    # 2026-11-29 with the tracer set since, the octagon and the aggregation 10/10, the line and
    # the sorting 9/10, the square and the letter A 8/10 (all stalled: line 4, square 3 and 4,
    # letter A 4 and 9; the sorting's seed 2 not); less one in ten. Regression floors.
    octagon_varied | aggregation_varied) echo 0.9 ;;
    line_varied | sorting_varied) echo 0.8 ;;
    square_varied | letter_A_varied) echo 0.7 ;;
    # The mirror (--air model --drag eq8, the constructed table), seeds 1-30 with the paper's
    # CEM in the path files: line, square and sorting 30/30 (the sorting also with the paper's
    # Sigma0, 2026-11-29), the letter A 29/30 (seed 3), the octagon 30/30 (26/30 before the
    # blind search's rescue); the aggregation 22/30 with its file's mu0 of 30 cm
    # (2026-11-29; 30/30 from mu0 25 cm, Sigma0 60 cm^2): its failed runs end at the 150 s limit
    # with 0-23 of the 25 in the zone.
    line_mirror | square_mirror | octagon_mirror) echo 0.9 ;;
    letter_A_mirror) echo 0.85 ;;
    sorting_mirror) echo 0.9 ;;
    aggregation_mirror) echo 0.7 ;;
    # The physical twin over seeds 1-10 (docs/twin.md), the model identified in the same twin,
    # less one run in ten. Regression floors, not targets. Measured 2026-11-29 with the tracer
    # set since (commit af345c6), the defaults (the formation at the pulses' times x 0.5, the
    # front carried): line 6, square 1, letter A 2, octagon 0 of 10 (the set before: 2, 0, 0, 0).
    line_physical) echo 0.5 ;;
    square_physical) echo 0 ;;
    letter_A_physical) echo 0.1 ;;
    octagon_physical) echo 0 ;;
    # The multi-object tasks there (--multi): the aggregation as the file ships it (mu0 30 cm)
    # 0/10 (the identified eq. (8) sees no push toward the point below the nozzle move a tracer
    # from 30 cm), from the nearer, wider start (mu0 25 cm, Sigma0 60 cm^2) 10/10; with the
    # paper's settings 0/10; the sorting 0/10 (the set before: 2/10; none stalled; not looked
    # into).
    aggregation_physical) echo 0 ;;
    aggregation_near_physical) echo 0.9 ;;
    aggregation_paper_physical) echo 0 ;;
    sorting_physical) echo 0 ;;
    # Without the formation (--no-formation): line 3, square 0, letter A 2, octagon 1 of 10
    # (the set before: 2, 0, 0, 1).
    line_physical_no_formation) echo 0.2 ;;
    square_physical_no_formation) echo 0 ;;
    letter_A_physical_no_formation) echo 0.1 ;;
    octagon_physical_no_formation) echo 0 ;;
    # With the front of still air (--still-front): line 3, square 1, letter A 0, octagon 1 (the
    # set before: 1, 0, 0, 2).
    line_physical_still_front) echo 0.2 ;;
    square_physical_still_front) echo 0 ;;
    letter_A_physical_still_front) echo 0 ;;
    octagon_physical_still_front) echo 0 ;;
    # Planning with the extended model from the discrepancy analysis of closed-loop logs of
    # seeds 101-105 (--discrepancy): line and square 10/10, letter A 9/10 (seed 10 stalled),
    # octagon 9/10 (seed 7 stalled); the issue's target 9 of 10 is their floor.
    line_physical_extended | square_physical_extended) echo 0.9 ;;
    letter_A_physical_extended | octagon_physical_extended) echo 0.9 ;;
    # The aggregations planned with it: as shipped 10/10, from the nearer, wider start 10/10;
    # the paper's settings 0/10 (its air moves nothing: no log can tell). The sorting with the
    # extended model of its own logs: 9/10 (seed 6), as with the set before.
    aggregation_physical_extended | aggregation_near_physical_extended) echo 0.9 ;;
    aggregation_paper_physical_extended) echo 0 ;;
    sorting_physical_extended) echo 0.8 ;;
    # With 0.1 s from each observation to its aim (loop.latency_s; docs/twin.md, "A rig's
    # latency"), seeds 1-10 as the vision sweep's: measured 2026-11-29 with the tracer set since,
    # every scenario 10/10 (the set before: the sorting 9/10, 5/10 at 0.25 s); less one in ten.
    line_latency | square_latency | letter_A_latency | octagon_latency) echo 0.9 ;;
    aggregation_latency | sorting_latency) echo 0.9 ;;
  esac
}
scenarios="line square letter_A octagon aggregation sorting"

jobs=$(nproc 2>/dev/null || echo 2)
mkdir -p "$out"
summary="$out/summary.md"
failures=()
rows=()
t_all=$(date +%s)
stage() {  # name, command...: runs it, records its wall time and status
  local name=$1 t0 status=ok
  shift
  echo "== $name"
  t0=$(date +%s)
  if ! "$@"; then
    status=FAILED
    failures+=("$name")
  fi
  rows+=("| $name | $(($(date +%s) - t0)) | $status |")
}

build() {
  local launcher=()
  if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null &&
    cmake --build build -j"$jobs"
}

closed_loop() {
  AIRTWIN_TEST_TIER=acceptance ctest --test-dir build -j"$jobs" -L '^closedloop$' \
    --output-on-failure --timeout 3600 &&
    # The Python env's 10 000 steps without memory growth (CI's unit tier takes 600).
    AIRTWIN_TEST_TIER=acceptance ctest --test-dir build -R '^python_test_memory$' \
      --output-on-failure --timeout 3600
}

discrepancy() {
  local s status=0
  for s in $test_seeds; do
    echo "-- test seed $s"
    AIRTWIN_TEST_TIER=acceptance AIRTWIN_TEST_SEED=$s ctest --test-dir build -j"$jobs" \
      -L '^(discrepancy|calibration)$' --output-on-failure --timeout 3600 || {
      status=1
      failures+=("discrepancy at AIRTWIN_TEST_SEED=$s")
    }
  done
  return $status
}

sweep_rows=()
# batch DIR LABEL FLAGS SCENARIO...: runs the batch, then checks each scenario's floor (a
# SCENARIO is a shipped name or a file)
check_batch() {
  local dir=$1 label=$2 n=$3 flags=$4
  shift 4
  local files=()
  for s in "$@"; do
    case "$s" in
      *.yaml) files+=("$s") ;;  # a scenario file of its own
      *) files+=("scenes/$s.yaml") ;;
    esac
  done
  # shellcheck disable=SC2086
  ./build/airtwin batch "${files[@]}" --seeds "$n" --jobs "$jobs" $flags --quiet --out "$dir" || return 1
  check_report "$dir" "$label"
}

# check_report DIR LABEL: each scenario of the batch in DIR against its floor
check_report() {
  local dir=$1 label=$2
  local status=0 line name ok runs failed stalled floor
  while IFS=$'\t' read -r name ok runs failed stalled; do
    floor=$(floor_of "$name$label")
    local need
    need=$(awk -v f="$floor" -v n="$runs" 'BEGIN{v=f*n; c=int(v); if (c<v) c++; print c}')
    local verdict=ok
    if [ "$ok" -lt "$need" ]; then
      verdict=FAILED
      status=1
      failures+=("sweep $name$label: $ok/$runs < $need")
    fi
    sweep_rows+=("| $name$label | $ok/$runs | $need | ${failed:--} | ${stalled:--} | $verdict |")
  done < <(/usr/bin/env python3 - "$dir/report.json" <<'EOF'
import json, sys
for s in json.load(open(sys.argv[1]))["scenarios"]:
    print("%s\t%d\t%d\t%s\t%s" % (s["scenario"], s["successes"], s["runs"],
                                  " ".join(str(x) for x in s["failed_seeds"]),
                                  " ".join(str(x) for x in s.get("stalled_seeds", []))))
EOF
  )
  return $status
}

sweep() {
  local status=0
  # shellcheck disable=SC2086
  check_batch "$out/batch" "" "$seeds" "" $scenarios || status=1
  # shellcheck disable=SC2086
  check_batch "$out/batch_vision" _vision "$vision_seeds" --vision $scenarios || status=1
  # shellcheck disable=SC2086
  check_batch "$out/batch_varied" _varied "$vision_seeds" "--vary-physics 0.1" $scenarios ||
    status=1
  check_batch "$out/batch_mirror" _mirror "$seeds" \
    "--air model --drag eq8 --table models/data/constructed_field_table.csv" $scenarios || status=1
  # The files with a rig's latency of 0.1 s: copies with loop.latency_s set.
  local name files=()
  mkdir -p "$out/latency_scenes"
  for name in $scenarios; do
    if grep -q '^loop:' "scenes/$name.yaml"; then
      sed 's/^loop:.*/loop:\n  latency_s: 0.1/' "scenes/$name.yaml" > "$out/latency_scenes/$name.yaml"
    else
      { cat "scenes/$name.yaml"; printf 'loop:\n  latency_s: 0.1\n'; } \
        > "$out/latency_scenes/$name.yaml"
    fi
    files+=("$out/latency_scenes/$name.yaml")
  done
  check_batch "$out/batch_latency" _latency "$vision_seeds" "" "${files[@]}" || status=1
  return $status
}

physical() {
  local status=0
  bash scripts/physical_twin_closed_loop.sh --seeds "$physical_seeds" --multi --discrepancy \
    --out "$out/physical" > "$out/physical.txt" || return 1
  check_report "$out/physical/batch" _physical || status=1
  check_report "$out/physical/batch_extended" _physical_extended || status=1
  check_report "$out/physical/batch_multi" _physical || status=1
  check_report "$out/physical/batch_multi_extended" _physical_extended || status=1
  check_report "$out/physical/batch_sorting_extended" _physical_extended || status=1
  # The same twin without the wall jet's formation, the model identified there.
  bash scripts/physical_twin_closed_loop.sh --seeds "$physical_seeds" --no-formation \
    --out "$out/physical_no_formation" > "$out/physical_no_formation.txt" || return 1
  check_report "$out/physical_no_formation/batch" _physical_no_formation || status=1
  # ... and with the new wall jet's front as in still air (not carried by the old air).
  bash scripts/physical_twin_closed_loop.sh --seeds "$physical_seeds" --still-front \
    --out "$out/physical_still_front" > "$out/physical_still_front.txt" || return 1
  check_report "$out/physical_still_front/batch" _physical_still_front || status=1
  return $status
}

gain_stage() {
  bash scripts/closed_loop_gain.sh --airtwin build/airtwin --jobs "$jobs" "$out/gain" |
    tee "$out/gain.txt"
}

stage "release build" build
if wants closed-loop; then stage "closed loop" closed_loop; fi
if wants discrepancy; then stage discrepancy discrepancy; fi
if wants sweep; then stage sweep sweep; fi
if wants physical; then stage "physical twin" physical; fi
if [ "$gain" = 1 ]; then stage gain gain_stage; fi

{
  echo "# Acceptance tier, $(date -u '+%Y-%m-%d') ($(git rev-parse --short HEAD 2>/dev/null || echo '?'))"
  echo
  echo "Test seeds (hidden-effect magnitudes): $test_seeds; sweep seeds 1-$seeds, vision 1-$vision_seeds."
  echo
  echo "| scenario | success | floor | failed seeds | of them stalled | verdict |"
  echo "|---|---|---|---|---|---|"
  printf '%s\n' "${sweep_rows[@]}"
  echo
  echo "| stage | seconds | status |"
  echo "|---|---|---|"
  printf '%s\n' "${rows[@]}"
  echo "| total | $(($(date +%s) - t_all)) | $([ ${#failures[@]} = 0 ] && echo ok || echo FAILED) |"
  if [ ${#failures[@]} -gt 0 ]; then
    echo
    echo "Failed:"
    printf -- '- %s\n' "${failures[@]}"
  fi
  if [ -f "$out/gain.txt" ] && [ "$gain" = 1 ]; then
    echo
    echo "Closed-loop gain (scripts/closed_loop_gain.sh):"
    echo
    sed 's/^/    /' "$out/gain.txt"
  fi
} > "$summary"
cat "$summary"
[ ${#failures[@]} = 0 ]
