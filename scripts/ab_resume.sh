#!/usr/bin/env bash
# A/B timing of two variants of one run, resumed from the same checkpoint in alternating rounds, so that
# both see the same spells of a machine whose speed drifts (docs/benchmarks.md: this project's VM moves by a
# fifth within minutes, more than most changes worth measuring). A variant is the saved scene with edits
# (JSON pointers into run.json's scene, which a resume reads instead of --set) and, optionally, another
# build. Each round copies the run folder afresh, so every resume starts from the same state.
# Usage: scripts/ab_resume.sh RUN_DIR UNTIL ROUNDS EDITS_A EDITS_B [BUILD_A] [BUILD_B] [THREADS]
#   RUN_DIR  a folder of `cellsph run --out` with checkpoint.bin and run.json
#   UNTIL    the simulated time each resume runs to
#   EDITS_*  ';'-separated POINTER=JSON edits of the scene ('' for none); strings in JSON quotes
#   BUILD_*  build folders holding cellsph (default build/release; BUILD_B defaults to BUILD_A)
#   e.g. scripts/ab_resume.sh dfsph3d 0.56 3 '/solver/dfsph/min_iterations=2' '/solver/dfsph/min_iterations=1'
#        scripts/ab_resume.sh dfsph3d 0.56 3 '' '' build/old build/release
# Prints each resume's wall and CPU seconds, steps and the run's solver and time-split lines, then the mean
# wall and CPU seconds of each variant and B over A.
set -euo pipefail
me="ab_resume.sh"
if [[ $# -lt 5 || $# -gt 8 ]]; then
  sed -n '7,13p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
run="$1" until="$2" rounds="$3" edits_a="$4" edits_b="$5"
build_a="${6:-build/release}"
build_b="${7:-$build_a}"
threads="${8:-2}"
for f in checkpoint.bin run.json; do
  [[ -f "$run/$f" ]] || { echo "$me: RUN_DIR '$run' has no $f (a folder of cellsph run --out)" >&2; exit 2; }
done
for b in "$build_a" "$build_b"; do
  [[ -x "$b/cellsph" ]] || { echo "$me: no program at $b/cellsph (build it first)" >&2; exit 2; }
done
python3 - "$until" "$rounds" "$threads" <<'PY' || exit 2
import sys
u, r, t = sys.argv[1:]
try:
    ok = float(u) > 0
except ValueError:
    ok = False
if not ok:
    sys.exit(f"ab_resume.sh: UNTIL must be a time > 0, got '{u}'")
if not (r.isdigit() and int(r) >= 1):
    sys.exit(f"ab_resume.sh: ROUNDS must be a whole number >= 1, got '{r}'")
if not (t.isdigit() and int(t) >= 1):
    sys.exit(f"ab_resume.sh: THREADS must be a whole number >= 1, got '{t}'")
PY
export OMP_WAIT_POLICY="${OMP_WAIT_POLICY:-passive}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

# Applies EDITS to the scene of DIR/run.json; exits 2 naming a pointer whose parent is missing or a
# value that is not JSON.
edit_scene() {
  python3 - "$1/run.json" "$2" <<'PY'
import json, sys
path, edits = sys.argv[1], sys.argv[2]
run = json.load(open(path))
for edit in filter(None, (e.strip() for e in edits.split(";"))):
    pointer, eq, value = edit.partition("=")
    if not eq or not pointer.startswith("/"):
        sys.exit(f"ab_resume.sh: edit '{edit}' is not POINTER=JSON (e.g. /solver/dfsph/min_iterations=1)")
    try:
        v = json.loads(value)
    except json.JSONDecodeError:
        sys.exit(f"ab_resume.sh: edit '{edit}': value '{value}' is not JSON (quote strings: '\"zero\"')")
    keys = [k.replace("~1", "/").replace("~0", "~") for k in pointer[1:].split("/")]
    node = run["scene"]
    for k in keys[:-1]:
        try:
            node = node[int(k)] if isinstance(node, list) else node[k]
        except (KeyError, IndexError, ValueError, TypeError):
            sys.exit(f"ab_resume.sh: edit '{edit}': the scene has no '{k}' on the way to {pointer}")
    last = keys[-1]
    if isinstance(node, list):
        if not (last.isdigit() and int(last) < len(node)):
            sys.exit(f"ab_resume.sh: edit '{edit}': '{last}' is not an index of the list at {pointer}")
        node[int(last)] = v
    elif isinstance(node, dict):
        node[last] = v
    else:
        sys.exit(f"ab_resume.sh: edit '{edit}': the scene's value before '{last}' holds no keys")
json.dump(run, open(path, "w"), indent=1)
PY
}

declare -A walls cpus
for v in A B; do walls[$v]=""; cpus[$v]=""; done
for k in $(seq 1 "$rounds"); do
  for v in A B; do
    if [[ $v == A ]]; then edits="$edits_a" bin="$build_a/cellsph"; else edits="$edits_b" bin="$build_b/cellsph"; fi
    rm -rf "$work/run"
    cp -r "$run" "$work/run"
    edit_scene "$work/run" "$edits" || exit 2
    if ! /usr/bin/time -o "$work/time" -f "%e %U %S" "$bin" run --resume "$work/run" --until "$until" \
        --threads "$threads" > "$work/out" 2>&1; then
      echo "$me: round $k, variant $v failed:" >&2
      tail -5 "$work/out" >&2
      exit 1
    fi
    read -r e u s < "$work/time"
    c=$(python3 -c "print(round($u + $s, 2))")
    n=$(grep -o 'wall, [0-9]* steps' "$work/out" | grep -o '[0-9]*' || echo "?")
    walls[$v]+="$e "
    cpus[$v]+="$c "
    printf 'round %d %s: %6.2f s wall %7.2f s CPU %5s steps\n' "$k" "$v" "$e" "$c" "$n"
    grep -E '^ +(time split|dfsph|iisph)' "$work/out" | sed 's/^ */           /' || true
  done
done
python3 - "${walls[A]}" "${walls[B]}" "${cpus[A]}" "${cpus[B]}" <<'PY'
import sys
wa, wb, ca, cb = ([float(x) for x in s.split()] for s in sys.argv[1:])
mean = lambda xs: sum(xs) / len(xs)
print(f"A: mean {mean(wa):.3f} s wall ({min(wa):.2f}-{max(wa):.2f}), {mean(ca):.2f} s CPU")
print(f"B: mean {mean(wb):.3f} s wall ({min(wb):.2f}-{max(wb):.2f}), {mean(cb):.2f} s CPU")
print(f"B / A: {mean(wb) / mean(wa):.3f} wall, {mean(cb) / mean(ca):.3f} CPU")
PY
