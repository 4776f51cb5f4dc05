#!/usr/bin/env bash
# Runs every `cellsph` command shown in README.md and docs/*.md, so the docs stay true.
# Usage: scripts/check_docs.sh BUILD_DIR
# Commands are taken from fenced code blocks: lines starting with build/release/cellsph,
# build/cellsph, PYTHONPATH=build/release/python (the Python module) or `mpirun -np N [--oversubscribe]
# build/release/cellsph` (runs across ranks: oversubscribed, and allowed as root as CI runs); comments
# after '#' dropped.
# They run in a scratch folder that links the repo's scenes/, scripts/ and the given build, after a small
# points.csv is made for the `neighbors` examples.
# Long runs are shortened by SHORTEN (appended to `run` commands that have no --until/--steps),
# `bench neighbors` or `bench sph` without --quick gets --quick, and cellsph_bench one short run of each
# benchmark, since CI has 2 cores.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$(cd "${1:?build dir}" && pwd)"
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/build"
ln -s "$build" "$scratch/build/release"
for b in cellsph cellsph_tests cellsph_bench; do ln -s "$build/$b" "$scratch/build/$b"; done
ln -s "$root/scenes" "$scratch/scenes"
ln -s "$root/scripts" "$scratch/scripts"
cd "$scratch"
{ echo "x,y,z"; for i in $(seq 0 199); do echo "$((i % 7)).$((i % 10)),$((i / 7 % 5)).$((i % 3)),$((i / 35)).5"; done; } > points.csv

n=0; fail=0
while IFS= read -r line; do
  cmd="${line%%#*}"
  cmd="$(echo "$cmd" | sed -e 's/[[:space:]]*$//')"
  [ -z "$cmd" ] && continue
  case "$cmd" in
    *" run"*) case "$cmd" in *--until*|*--steps*|*--help*) ;; *) cmd="$cmd --until 0.02" ;; esac ;;
  esac
  case "$cmd" in
    *"bench neighbors"*|*"bench sph"*) case "$cmd" in *--quick*) ;; *) cmd="$cmd --quick" ;; esac ;;
    # Google Benchmark: one short run of each benchmark (the later flags win), to check the filter and the code.
    build/release/cellsph_bench*|build/cellsph_bench*) cmd="$cmd --benchmark_min_time=0.01 --benchmark_repetitions=1" ;;
  esac
  case "$cmd" in
    mpirun\ *--oversubscribe*) cmd="OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 $cmd" ;;
    mpirun\ *) cmd="OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe ${cmd#mpirun }" ;;
  esac
  # Tour runs are long at full length; keep their options but cap the simulated time.
  cmd="$(echo "$cmd" | sed -E 's/--until ([0-9.]+)/--until 0.02/')"
  n=$((n + 1))
  echo "docs[$n]: $cmd"
  if ! bash -c "$cmd" </dev/null >"$scratch/out.txt" 2>&1; then
    echo "FAILED: $cmd"; tail -5 "$scratch/out.txt"; fail=$((fail + 1))
  fi
done < <(awk '/^```/{inb=!inb; next} inb && /^(build\/release\/cellsph|build\/cellsph|PYTHONPATH=build\/release\/python |mpirun -np [0-9]+ (--oversubscribe )?build\/release\/cellsph)/' "$root/README.md" "$root"/docs/*.md)
echo "docs: $((n - fail)) passed, $fail failed"
[ "$fail" -eq 0 ]
