#!/usr/bin/env bash
# The built-in 2D dam break (dam-break-2d) at several particle spacings against the surge front of
# Koshizuka & Oka (1996): one run per spacing, then scripts/dam_break_front.py on each, then a summary.
#
# Usage: scripts/dam_break_convergence.sh [BUILD_DIR [SPACING ...]]
#   BUILD_DIR  where the cellsph program is (default build/release, as scripts/run.sh builds it)
#   SPACING    particle spacings in m (default 0.1 0.05 0.02 0.01; 0.01 m takes about 30 s on 2 cores)
# Environment: OUT (output folder, default dam-break-front), EXTRA (more options for every run, e.g.
#   EXTRA="--set /boundary/model=akinci --set /boundary/slip=free"), SCENE (a scene file instead of the
#   built-in dam-break-2d).
#
# Each spacing s keeps the scene's set-up scaled as its file is: support 2 s (water's viscosity does not
# scale; the artificial viscosity's alpha multiplies h c, so it scales by itself; docs/physics.md). Exits 1
# if any spacing misses a published point by more than 10%.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-build/release}"
shift || true
spacings=("$@")
[ ${#spacings[@]} -eq 0 ] && spacings=(0.1 0.05 0.02 0.01)
out="${OUT:-dam-break-front}"
cellsph="$build/cellsph"
[ -x "$cellsph" ] || { echo "$cellsph: not found (build first: scripts/run.sh, or pass the build folder)" >&2; exit 2; }

summary=()
status=0
for s in "${spacings[@]}"; do
  support=$(awk -v s="$s" 'BEGIN { if (s + 0 <= 0) exit 1; printf "%.10g", 2 * s }') ||
    { echo "spacing '$s': expected a positive number" >&2; exit 2; }
  dir="$out/spacing-$s"
  echo "== spacing $s m (support $support m) -> $dir"
  # shellcheck disable=SC2086  # EXTRA is a list of options
  "$cellsph" run "${SCENE:-dam-break-2d}" --until 0.7 --fps 200 --format csv --out "$dir" --quiet \
    --set "/spacing=$s" --set "/solver/support=$support" ${EXTRA:-}
  if verdict=$(python3 "$root/scripts/dam_break_front.py" "$dir" "$s"); then :; else status=1; fi
  echo "$verdict"
  summary+=("spacing $s m: $(echo "$verdict" | tail -1)")
done
echo "== summary (Koshizuka & Oka 1996, 13 points up to T = 3, limit 10%)"
printf '%s\n' "${summary[@]}"
exit $status
