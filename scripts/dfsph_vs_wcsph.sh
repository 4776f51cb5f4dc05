#!/usr/bin/env bash
# Wall time per simulated second of DFSPH against WCSPH on `dam-break-3d-dfsph` (issue 12's 3x target),
# measured so that both see the same spells of a shared machine: the two runs advance in alternating
# segments (each resumed from its own checkpoint), and the segments' wall and CPU seconds are summed.
# A virtual machine whose speed drifts by 20% from one minute to the next (docs/benchmarks.md) moves two
# whole runs made one after the other apart by that much; alternating segments shares the drift out.
# Each segment also loads and writes a checkpoint (the same bytes for both models): the script measures
# that cost with resumes that take no step (the fastest of three per model) and prints the ratio with it
# taken out of every segment, beside the raw one.
# Usage: scripts/dfsph_vs_wcsph.sh [BUILD_DIR] [SECONDS] [SEGMENTS] [THREADS] [-- EXTRA --set ARGS]
#   e.g. scripts/dfsph_vs_wcsph.sh build/release 1 10 2
#        scripts/dfsph_vs_wcsph.sh build/release 1 10 2 -- --set /phases/0/viscosity=10
# The WCSPH run is the scene switched to WCSPH as docs/benchmarks.md describes (c = 10 sqrt(2 g H) by
# the ratio EOS, artificial viscosity 0.01, Courant 0.3, the scene's Verlet skin and reordering).
set -euo pipefail
build="${1:-build/release}"
until="${2:-1}"
segments="${3:-10}"
threads="${4:-2}"
shift $(($# < 4 ? $# : 4))
extra=()
if [[ "${1:-}" == "--" ]]; then
  shift
  extra=("$@")
fi
bin="$build/cellsph"
[[ -x "$bin" ]] || { echo "dfsph_vs_wcsph.sh: no program at $bin (build it first)" >&2; exit 2; }
python3 - "$until" "$segments" 2>/dev/null <<'PY' || { echo "dfsph_vs_wcsph.sh: SECONDS must be > 0 and SEGMENTS a whole number >= 1" >&2; exit 2; }
import sys
u, s = float(sys.argv[1]), sys.argv[2]  # a ValueError (not a number) fails too
assert u > 0 and s.isdigit() and int(s) >= 1
PY
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
wcsph=(--set /solver/model=wcsph --set /solver/dfsph=null
  --set '/solver/eos={"kind":"ratio","stiffness":1962000,"clamp_negative":true}'
  --set '/solver/artificial_viscosity={"alpha":0.01}' --set /time/courant=0.3)
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
declare -A wall cpu steps
for m in dfsph wcsph; do wall[$m]=0; cpu[$m]=0; steps[$m]=0; done
for k in $(seq 1 "$segments"); do
  t=$(python3 -c "print(repr($until * $k / $segments))")
  for m in dfsph wcsph; do
    if [[ $k == 1 ]]; then
      args=(run dam-break-3d-dfsph --until "$t" --threads "$threads" --fps 1 --format csv --out "$work/$m" "${extra[@]}")
      [[ $m == wcsph ]] && args+=("${wcsph[@]}")
    else
      args=(run --resume "$work/$m" --until "$t" --threads "$threads")
    fi
    if ! /usr/bin/time -o "$work/time" -f "%e %U %S" "$bin" "${args[@]}" > "$work/out" 2>&1; then
      echo "dfsph_vs_wcsph.sh: the $m segment to t = $t s failed:" >&2
      tail -5 "$work/out" >&2
      exit 1
    fi
    read -r e u s < "$work/time"
    n=$(grep -o 'wall, [0-9]* steps' "$work/out" | grep -o '[0-9]*')
    wall[$m]=$(python3 -c "print(${wall[$m]} + $e)")
    cpu[$m]=$(python3 -c "print(${cpu[$m]} + $u + $s)")
    steps[$m]=$((${steps[$m]} + n))
    printf '%-6s to t = %-8s %7.2f s wall %8.2f s CPU %6d steps\n' "$m" "$t" "$e" "$(python3 -c "print($u + $s)")" "$n"
  done
done
# The load and write of a segment alone: resumes to the time already reached (no step).
declare -A io
for m in dfsph wcsph; do
  io[$m]=1e9
  for _ in 1 2 3; do
    /usr/bin/time -o "$work/time" -f "%e" "$bin" run --resume "$work/$m" --until "$until" --threads "$threads" \
      > "$work/out" 2>&1
    io[$m]=$(python3 -c "print(min(${io[$m]}, $(cat "$work/time")))")
  done
done
for m in dfsph wcsph; do
  printf '%-6s total: %.1f s wall, %.1f s CPU, %d steps; a segment'"'"'s load and write alone: %.2f s wall\n' \
    "$m" "${wall[$m]}" "${cpu[$m]}" "${steps[$m]}" "${io[$m]}"
done
python3 -c "
w, d, s = ${wall[wcsph]}, ${wall[dfsph]}, $segments
print('WCSPH / DFSPH: %.2fx wall, %.2fx CPU; %.2fx wall without the segments\' loads and writes' %
      (w / d, ${cpu[wcsph]} / ${cpu[dfsph]}, (w - s * ${io[wcsph]}) / (d - s * ${io[dfsph]})))"
