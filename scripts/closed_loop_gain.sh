#!/usr/bin/env bash
# The closed-loop gain of the discrepancy analysis, effect by effect (docs/discrepancy.md), in
# the mirror twin (--air model --drag eq8 with the constructed table: the truth is the model plus the hidden effect; the
# physical twin's own gain is scripts/fit_twin_models.sh's and physical_twin_closed_loop.sh's):
#   1. the twin collects Appendix D data with one hidden effect (100 tracer trials, 0.5 s lead-in);
#   2. `airtwin discrepancy` names the cause and writes extended_model.json, from the CSV alone;
#   3. a batch of the scenario over the seeds in the same twin, the controller planning with the
#      nominal model, then with the extended model (`--model`).
# Prints one table row per effect: what was found, success rate, median completion time and mean
# path error of both batches; everything else stays in OUT_DIR/<effect>/.
#
# Usage: scripts/closed_loop_gain.sh [--airtwin BIN] [--scenario FILE] [--seeds N] [--jobs J]
#                                    [--effects "E1 E2 ..."] OUT_DIR
# Defaults: build/airtwin, scenes/octagon.yaml, 10 seeds, all cores, the catalogue below.
set -euo pipefail

bin=build/airtwin
scenario=scenes/octagon.yaml
seeds=10
jobs=$(nproc)
# One magnitude per catalogue effect, inside the ranges the hidden-effect tests draw from.
effects="pressure_gradient:strength=13,length=0.2 response_delay:tau_s=0.6
flow_deflection:angle_deg=15 quadratic_drag:coefficient=1.0
floor_slope:angle_deg=4,direction_deg=120 stiction:ratio=1.7
nozzle_offset:pan_deg=8,tilt_deg=4 field_scale:factor=1.25
transport_lag:pace_s_per_m=0.8"

usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; }
while [[ $# -gt 0 ]]; do
  case "$1" in
    --airtwin) bin=$2; shift 2 ;;
    --scenario) scenario=$2; shift 2 ;;
    --seeds) seeds=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --effects) effects=$2; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    -*) echo "closed_loop_gain.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
  esac
done
if [[ $# -ne 1 ]]; then
  echo "closed_loop_gain.sh: expected one OUT_DIR (see --help)" >&2
  exit 2
fi
out=$1
[[ -x "$bin" ]] || { echo "closed_loop_gain.sh: no airtwin binary at $bin (build first)" >&2; exit 1; }
[[ -f "$scenario" ]] || { echo "closed_loop_gain.sh: no scenario file $scenario" >&2; exit 1; }
mkdir -p "$out"
# The mirror of the constructed table, in which docs/discrepancy.md's figures were measured.
constructed=models/data/constructed_field_table.csv
mirror=(--air model --drag eq8 --table "$constructed")

# success rate, median completion time (successful runs), mean path error from a batch's runs.csv.
summarise() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
    { n++; if ($col["success"] == 1) { ok++; t[ok] = $col["completion_time_s"] }
      if ($col["path_error_mean_cm"] != "") { e += $col["path_error_mean_cm"]; ne++ } }
    END {
      m = "-"
      if (ok > 0) {
        for (i = 1; i <= ok; ++i) for (j = i + 1; j <= ok; ++j) if (t[j] < t[i]) { x = t[i]; t[i] = t[j]; t[j] = x }
        m = (ok % 2) ? t[(ok + 1) / 2] : (t[ok / 2] + t[ok / 2 + 1]) / 2 }
      printf "%d/%d | %s | %s", ok, n, (m == "-" ? m : sprintf("%.0f s", m)),
             (ne > 0 ? sprintf("%.2f cm", e / ne) : "-") }' "$1"
}

echo "| hidden effect | found | nominal: success, median time, mean path error | extended: success, median time, mean path error |"
echo "|---|---|---|---|"
for effect in $effects; do
  name=${effect%%:*}
  dir=$out/$name
  mkdir -p "$dir"
  "$bin" collect --object tracer --per-tilt 50 --lead-in 0.5 --seed 1 --effect "$effect" \
    "${mirror[@]}" --quiet --out "$dir/data.csv" >/dev/null
  "$bin" discrepancy "$dir/data.csv" --table "$constructed" --seed 1 --quiet \
    --out "$dir/analysis" >/dev/null
  found=$(tr -d '\n' < "$dir/analysis/report.json" | sed -n 's/.*"found": *\[\([^]]*\)\].*/\1/p' | tr -d '" ')
  "$bin" batch "$scenario" --seeds "$seeds" --jobs "$jobs" --effect "$effect" "${mirror[@]}" \
    --quiet --out "$dir/nominal" >/dev/null
  "$bin" batch "$scenario" --seeds "$seeds" --jobs "$jobs" --effect "$effect" "${mirror[@]}" \
    --quiet --model "$dir/analysis/extended_model.json" --out "$dir/extended" >/dev/null
  echo "| $effect | ${found:-none} | $(summarise "$dir/nominal/runs.csv") | $(summarise "$dir/extended/runs.csv") |"
done
