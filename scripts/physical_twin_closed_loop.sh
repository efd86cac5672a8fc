#!/usr/bin/env bash
# The paper's pipeline on the physical twin, as on the rig (docs/twin.md, "Closed loop in the
# physical twin"): the twin in the CFD's air with physical drag; the Appendix D collection; eq. (8)
# identified from it in the CFD-fitted field model; then the path scenarios and the octagon with
# the paper's own CEM settings (section V-B/C: the scenario files' retuned Sigma0 put back to
# 20.9 cm^2), seeds 1..N, planning with that model. Ends with the batch report (success rates,
# median times and path errors) to set beside Table I.
# Usage: bash scripts/physical_twin_closed_loop.sh [--seeds N] [--physics TYPE:k=v,...]
#        [--no-formation | --formation-time-scale X] [--still-front] [--model FILE]
#        [--airtwin PATH] [--out DIR]
#   --no-formation  each object gets the reached orientation's whole air at once (airtwin's
#                --no-air-formation; by default the air forms, at half the CFD pulses' times)
#   --formation-time-scale X  the formation's times: the pulses' times X (airtwin's
#                --air-formation-time-scale; default 0.5)
#   --still-front  the new wall jet's front as in still air (airtwin's --air-front-co-flow 0;
#                by default it is carried by the old air)
#   --model FILE plan with this identified model instead of collecting and identifying one
set -euo pipefail
cd "$(dirname "$0")/.."

seeds=10
physics="tracer:cd=0.35,mu_k=0.4,mu_s_ratio=1.4,cl=0.2"
airtwin=build/airtwin
out=results/physical_twin_closed_loop
formation=()
model=""
while [ $# -gt 0 ]; do
  case "$1" in
    --seeds) seeds="$2"; shift 2 ;;
    --no-formation) formation+=(--no-air-formation); shift ;;
    --formation-time-scale) formation+=(--air-formation-time-scale "$2"); shift 2 ;;
    --still-front) formation+=(--air-front-co-flow 0); shift ;;
    --model) model="$2"; shift 2 ;;
    --physics) physics="$2"; shift 2 ;;
    --airtwin) airtwin="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    *) echo "physical_twin_closed_loop.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
[ -x "$airtwin" ] || { echo "physical_twin_closed_loop.sh: no airtwin binary at $airtwin (build first)" >&2; exit 1; }

table=models/data/cfd_fitted_field_model.json
twin=(--air cfd --drag physical --object-physics "$physics" "${formation[@]}")
mkdir -p "$out/scenes"
rm -rf "$out/batch"

# Appendix D in the twin (collection seed 202) and eq. (8)'s terms identified from it.
if [ -n "$model" ]; then
  [ -f "$model" ] || { echo "physical_twin_closed_loop.sh: --model: no file $model" >&2; exit 1; }
  cp "$model" "$out/tracer_model.json"
else
  "$airtwin" collect --object tracer --tilts 0,22.5 --per-tilt 50 --seed 202 "${twin[@]}" \
    --out "$out/collection.csv" > "$out/collect.log" 2>&1
  "$airtwin" identify "$out/collection.csv" --object tracer --table "$table" --terms 1,v,vair \
    --out "$out/tracer_model.json" | sed -n 2,3p
fi

# The paper's CEM settings: the files differ from the code's defaults (the paper's) only where
# they retune Sigma0 for the mirror twin; the octagon already uses the defaults.
for name in line square letter_A octagon; do
  grep -v '^  variance0_m2:' "scenes/$name.yaml" > "$out/scenes/$name.yaml"
done

"$airtwin" batch "$out"/scenes/{line,square,letter_A,octagon}.yaml --seeds "$seeds" --quiet \
  "${twin[@]}" --table "$table" --model "$out/tracer_model.json" --out "$out/batch"
cat "$out/batch/report.md"
