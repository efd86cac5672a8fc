#!/usr/bin/env bash
# Fuzzes every parser with libFuzzer (fuzz/README.md, docs/fuzzing.md): configures a clang build
# folder with AIRTWIN_FUZZ=ON (ASan + UBSan + libFuzzer's coverage; ccache when present), builds
# the targets, and runs each for a set number of executions on a scratch copy of its seed corpus
# (tests/fuzz/<target>/ is left as it is unless --merge is given). Prints a table target /
# executions / seconds / result and exits 1 when any target found something (a crash, an
# exception other than InputError, a sanitizer report, a leak, a timeout or running out of
# memory), naming the target and the input that did it (kept under DIR/fuzz-artifacts/<target>/).
# Usage: bash scripts/fuzz.sh [--runs N] [--targets "a b"] [--build-dir DIR] [--seed S]
#                             [--timeout S] [--rss-limit-mb M] [--jobs J] [--merge]
#   --runs N         executions per target (default 1000000)
#   --targets "a b"  which targets (default: every fuzz/<target>_fuzz.cc)
#   --build-dir DIR  the clang build folder (default build-fuzz)
#   --seed S         libFuzzer's random seed (default 1: the same inputs every time)
#   --timeout S      seconds one input may take before it counts as a hang (default 20)
#   --rss-limit-mb M memory limit of a target in MB (default 2048)
#   --jobs J         build jobs (default: the number of cores)
#   --merge          afterwards, add the inputs that reached new code to tests/fuzz/<target>/
set -euo pipefail
cd "$(dirname "$0")/.."

runs=1000000
targets=""
build_dir=build-fuzz
seed=1
timeout=20
rss_limit_mb=2048
jobs=$(nproc 2>/dev/null || echo 2)
merge=0
usage() { sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; }
need_value() {
  if [ $# -lt 2 ] || [ -z "$2" ]; then
    echo "fuzz.sh: $1 needs a value (see --help)" >&2
    exit 2
  fi
}
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) need_value "$@"; runs=$2; shift 2 ;;
    --targets) need_value "$@"; targets=$2; shift 2 ;;
    --build-dir) need_value "$@"; build_dir=$2; shift 2 ;;
    --seed) need_value "$@"; seed=$2; shift 2 ;;
    --timeout) need_value "$@"; timeout=$2; shift 2 ;;
    --rss-limit-mb) need_value "$@"; rss_limit_mb=$2; shift 2 ;;
    --jobs) need_value "$@"; jobs=$2; shift 2 ;;
    --merge) merge=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "fuzz.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for pair in "runs:$runs" "seed:$seed" "timeout:$timeout" "rss-limit-mb:$rss_limit_mb" "jobs:$jobs"; do
  if ! [[ ${pair#*:} =~ ^[0-9]+$ ]]; then
    echo "fuzz.sh: --${pair%%:*} expects a whole number, got '${pair#*:}'" >&2
    exit 2
  fi
done

# The targets: every fuzz/<name>_fuzz.cc, or the ones asked for (each must exist).
all_targets=$(find fuzz -maxdepth 1 -name '*_fuzz.cc' -printf '%f\n' | sed 's/_fuzz\.cc$//' | sort)
if [ -z "$targets" ]; then targets=$all_targets; fi
for t in $targets; do
  if ! grep -qx "$t" <<<"$all_targets"; then
    echo "fuzz.sh: no target '$t'; the targets are: $(tr '\n' ' ' <<<"$all_targets")" >&2
    exit 2
  fi
done

if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ not found (bash scripts/setup.sh installs clang and libclang-rt-14-dev)" >&2
  exit 1
fi
launcher=()
if command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  # Paths relative to the checkout in ccache's hashes: another clone of the same sources hits.
  export CCACHE_BASEDIR="$PWD"
  # With -g ccache also hashes the build folder's path (it is in the debug information), so no
  # other clone or folder would hit; a hit's debug information then names the folder that
  # filled the cache, which only changes the directory shown in stack traces.
  export CCACHE_NOHASHDIR=1
fi

# Configure and build the targets only (the libraries they link, not the app, tests or bench).
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_COMPILER=clang \
  -DCMAKE_CXX_COMPILER=clang++ -DAIRTWIN_FUZZ=ON -DAIRTWIN_BUILD_TESTS=OFF \
  -DAIRTWIN_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
build_targets=()
for t in $targets; do build_targets+=("${t}_fuzz"); done
cmake --build "$build_dir" -j"$jobs" --target "${build_targets[@]}"

# Scratch: the corpora the runs grow, and the temporary folder of the targets that write their
# input to a file. Removed at exit; findings and logs stay in the build folder.
scratch=$(mktemp -d "${TMPDIR:-/tmp}/airtwin_fuzz_run.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
artifacts="$build_dir/fuzz-artifacts"
logs="$build_dir/fuzz-logs"
mkdir -p "$logs"

names=()
executions=()
seconds=()
results=()
failed=0
for t in $targets; do
  corpus="$scratch/corpus/$t"
  mkdir -p "$corpus" "$scratch/tmp/$t" "$artifacts/$t"
  if [ -d "tests/fuzz/$t" ]; then cp -r "tests/fuzz/$t/." "$corpus/"; fi
  log="$logs/$t.log"
  echo "== $t: $runs executions"
  start=$(date +%s.%N)
  status=0
  TMPDIR="$scratch/tmp/$t" \
    UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    "$build_dir/fuzz/${t}_fuzz" -runs="$runs" -seed="$seed" -timeout="$timeout" \
    -rss_limit_mb="$rss_limit_mb" -print_final_stats=1 -artifact_prefix="$artifacts/$t/" \
    "$corpus" >"$log" 2>&1 || status=$?
  end=$(date +%s.%N)
  done_runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  names+=("$t")
  executions+=("${done_runs:-?}")
  seconds+=("$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')")
  if [ "$status" = 0 ]; then
    results+=(ok)
  else
    failed=1
    # libFuzzer names the kind of finding in its artifact's file name (crash-, leak-, timeout-,
    # oom-, slow-unit-) and prints where it wrote it.
    input=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$log" | tail -1)
    kind=$(basename "${input:-failed-}" | sed 's/-.*//')
    results+=("${kind:-failed}: ${input:-no input saved} (log: $log)")
    echo "fuzz.sh: $t: ${kind:-failed}; the input: ${input:-none}; the report: $log" >&2
    grep -m1 -E 'ERROR: |runtime error|fuzz: ' "$log" >&2 || tail -5 "$log" >&2
  fi
  if [ "$merge" = 1 ]; then
    mkdir -p "tests/fuzz/$t"
    "$build_dir/fuzz/${t}_fuzz" -merge=1 -timeout="$timeout" -rss_limit_mb="$rss_limit_mb" \
      "tests/fuzz/$t" "$corpus" >>"$log" 2>&1 || echo "fuzz.sh: $t: merge failed (log: $log)" >&2
  fi
done

echo
echo "== fuzzing: $runs executions per target, seed $seed"
printf '%-20s %12s %9s  %s\n' target executions seconds result
for i in "${!names[@]}"; do
  printf '%-20s %12s %9s  %s\n' "${names[$i]}" "${executions[$i]}" "${seconds[$i]}" "${results[$i]}"
done
exit "$failed"
