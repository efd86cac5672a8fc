#!/usr/bin/env bash
# Serial vs 2 MPI ranks for simpleFoam under nice 19 on a meshed case of the campaign (docs/cfd.md).
# Runs short solves alternately serial and with 2 ranks (hierarchical decomposition), so both see
# the same background load, and prints seconds per iteration (after the first 5) with the load average.
# Usage: bash scripts/cfd/bench_np.sh CASE [--work DIR] [--iters N] [--rounds R]
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
top="$(cd "$here/../.." && pwd)"
work="$top/cfd-work"
iters=40
rounds=2
[ $# -ge 1 ] || { sed -n '2,5p' "$0"; exit 2; }
name="$1"; shift
while [ $# -gt 0 ]; do
  case "$1" in
    --work) work="$2"; shift 2 ;;
    --iters) iters="$2"; shift 2 ;;
    --rounds) rounds="$2"; shift 2 ;;
    *) echo "bench_np.sh: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
export WM_PROJECT_DIR=/usr/share/openfoam
command -v simpleFoam >/dev/null || { echo "bench_np.sh: OpenFOAM not found; run bash scripts/setup.sh --cfd" >&2; exit 1; }
src="$work/$name"
[ -f "$src/.meshed" ] || { echo "bench_np.sh: $src is not a meshed case (run run_all.sh --only $name first)" >&2; exit 1; }

b="$work/bench-np"
rm -rf "$b"
mkdir -p "$b"
cp -r "$src/constant" "$src/system" "$b/"
# the initial fields, not a solution: take them from the generator
/usr/bin/python3 "$here/cfdcase.py" fields "$name" "$b" >/dev/null
sed -i "s/^endTime .*/endTime $iters;/; s/^writeInterval .*/writeInterval 100000;/" "$b/system/controlDict"
(cd "$b" && nice -n 19 decomposePar -force > log.decomposePar 2>&1)

rate() {  # seconds per iteration from iteration 5 to the last, from ClockTime
  awk '/^Time = /{it=$3} /ClockTime/{for(i=1;i<=NF;i++) if($i=="ClockTime") c[it]=$(i+2)}
       END{n=0; for(k in c) if(k+0>n) n=k+0; if (n>5) printf "%.3f", (c[n]-c[5])/(n-5); else print "nan"}' "$1"
}

for r in $(seq 1 "$rounds"); do
  for mode in 1 2; do
    l0=$(cut -d' ' -f1 /proc/loadavg)
    t0=$(date +%s)
    if [ "$mode" = 1 ]; then
      (cd "$b" && nice -n 19 simpleFoam > log.serial.$r 2>&1)
      log="$b/log.serial.$r"
    else
      (cd "$b" && nice -n 19 mpirun --allow-run-as-root -np 2 simpleFoam -parallel > log.parallel.$r 2>&1)
      log="$b/log.parallel.$r"
      rm -rf "$b"/processor*/[1-9]*
    fi
    t1=$(date +%s)
    l1=$(cut -d' ' -f1 /proc/loadavg)
    echo "round $r, ranks $mode: $(rate "$log") s/iteration, $((t1 - t0)) s for $iters iterations, load $l0 -> $l1"
  done
done
rm -rf "$b"
