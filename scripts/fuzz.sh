#!/usr/bin/env bash
# Builds the libFuzzer harnesses of fuzz/ with clang (ASan + UBSan, -DCELLSPH_FUZZ=ON, in build/fuzz) and
# runs each one after the other for SECONDS (default 60) from its seed corpus fuzz/corpus/NAME/. Fails
# (exit 1) on any crash, hang (an input slower than 10 s), leak, memory blow-up (over 2 GiB) or sanitizer
# report, printing the input that did it; docs/fuzzing.md says how to replay it.
#   scripts/fuzz.sh [SECONDS] [NAME...]      e.g. scripts/fuzz.sh 3600 scene   (NAME: scene, points_csv, ...)
# Environment: FUZZ_RUNS=N also stops a harness after N executions; FUZZ_SEED=S fixes libFuzzer's seed
# (default: a new one each run; scripts/test.sh fixes it); FUZZ_WORK=DIR keeps the logs, the
# corpus each run grew and any failing input there (default: a temporary folder, removed when all pass).
set -euo pipefail
cd "$(dirname "$0")/.."
SECS=${1:-60}
shift || true
NAMES=("$@")
if ((${#NAMES[@]} == 0)); then
  for f in fuzz/*_fuzz.cpp; do NAMES+=("$(basename "$f" _fuzz.cpp)"); done
fi

# Debug: assertions (nlohmann's among them) stay on; fuzz/CMakeLists.txt adds -O1.
LAUNCHER=()
command -v ccache >/dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build/fuzz -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_COMPILER=clang++ -DCELLSPH_FUZZ=ON \
  "${LAUNCHER[@]}" >/dev/null
targets=()
for n in "${NAMES[@]}"; do targets+=("${n}_fuzz"); done
cmake --build build/fuzz -j "${JOBS:-$(nproc)}" --target "${targets[@]}"

WORK=${FUZZ_WORK:-$(mktemp -d -t cellsph-fuzz.XXXXXX)}
mkdir -p "$WORK"
export TMPDIR=$WORK  # the frames_index harness's scratch folder
export OMP_NUM_THREADS=1
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export LSAN_OPTIONS=suppressions=$PWD/fuzz/lsan.supp  # Assimp's own leaks (fuzz/lsan.supp says which)
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
RUNS=()
[ -n "${FUZZ_RUNS:-}" ] && RUNS=(-runs="$FUZZ_RUNS")
[ -n "${FUZZ_SEED:-}" ] && RUNS+=(-seed="$FUZZ_SEED")

failed=0
summary=""
for n in "${NAMES[@]}"; do
  mkdir -p "$WORK/corpus/$n"
  log=$WORK/$n.log
  echo "== fuzz $n: ${SECS} s =="
  start=$(date +%s)
  rc=0
  build/fuzz/fuzz/${n}_fuzz "$WORK/corpus/$n" "fuzz/corpus/$n" -max_total_time="$SECS" "${RUNS[@]}" \
    -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$WORK/$n-" >"$log" 2>&1 || rc=$?
  secs=$(($(date +%s) - start))
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -1)
  line="$n: ${execs:-?} executions in ${secs} s, ${cov:-no coverage line}"
  if ((rc != 0)); then
    failed=1
    line="$line: FAILED (exit $rc)"
    tail -60 "$log"
    ls "$WORK/$n-"* 2>/dev/null | sed 's/^/failing input: /' || true
  fi
  echo "$line"
  summary+="$line"$'\n'
done
echo "== fuzz summary =="
printf '%s' "$summary"
if ((failed)); then
  echo "fuzz: FAILED; logs and inputs in $WORK" >&2
  exit 1
fi
[ -z "${FUZZ_WORK:-}" ] && rm -rf "$WORK"
exit 0
