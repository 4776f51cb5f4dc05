#!/bin/bash
# `cellsph run` across MPI ranks against the same run in one process (docs/distributed.md): every file a
# run writes (frames, probes.csv, frames.csv, checkpoint.bin) must have the same bytes for 2, 3 and 4 ranks
# as for one process, a run checkpointed on some ranks must resume on others to the same bytes, what the
# step across ranks does not run yet is refused once with the keys named, and an unstable run stops on every
# rank with the single-process diagnosis. The reference is the single-process program (no MPI at all).
# Usage: cli_mpi_run_test.sh CELLSPH MPIEXEC CASE   (CASE: bits, resume, refusals, unstable, signal)
set -u
# Open MPI refuses to start as root (CI runs as root) unless told.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
cellsph=$1
mpiexec=$2
case_name=$3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0

fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}

ranks() {  # ranks N ARGS...: cellsph ARGS on N ranks, one thread each
  local n=$1
  shift
  OMP_NUM_THREADS=1 "$mpiexec" -n "$n" --oversubscribe "$cellsph" "$@"
}

# same NAME NP ARGS...: the run of ARGS in one process (2 threads) and on NP ranks write the same bytes.
same() {
  local name=$1 np=$2
  shift 2
  "$cellsph" run "$@" --out "one_$name" --threads 2 --quiet 2>/dev/null || fail "$name: one process: exit $?"
  ranks "$np" run "$@" --out "np${np}_$name" --threads 1 --quiet 2>/dev/null || fail "$name: $np ranks: exit $?"
  local files
  files=$(find "one_$name" -type f | wc -l)
  [ "$files" -ge 3 ] || fail "$name: only $files files written"
  if diff -r "one_$name" "np${np}_$name" >diff.txt; then
    echo "ok: $name on $np ranks: the same $files files"
  else
    fail "$name on $np ranks: $(head -c 600 diff.txt)"
  fi
}

coarse=(--set /spacing=0.04 --set /solver/support=0.08)

case "$case_name" in
  bits)
    # The default scene (Adami walls, summation density), checkpoint included, on 2, 3 and 4 ranks.
    for np in 2 3 4; do
      same "adami" "$np" dam-break-2d "${coarse[@]}" --until 0.15 --format csv,vtu --fps 20
    done
    # The other wall models, the continuity density, a 3D scene with the write-up's box, probes.
    same "dynamic" 3 dam-break-2d "${coarse[@]}" --set /boundary/model=dynamic --until 0.1 --format csv --fps 20
    same "akinci" 2 dam-break-2d "${coarse[@]}" --set /boundary/model=akinci --until 0.1 --format csv --fps 20
    same "continuity" 2 hydrostatic-tank --set /spacing=0.04 --steps 100 --format csv --fps 50
    same "box3d" 3 cuda-writeup --steps 40 --format csv --fps 2000
    same "probes" 3 lobovsky-2014 --set /spacing=0.008 --set /solver/support=0.016 --until 0.05 --format csv \
      --fps 50
    [ -s np3_probes/probes.csv ] || fail "probes: no probes.csv"
    # Moving walls: the gate (Adami's walls read the walls' accelerations) and the wave maker's paddle.
    same "gate" 3 dam-break-gate "${coarse[@]}" --until 0.2 --format csv --fps 20
    same "paddle" 2 wave-tank "${coarse[@]}" --until 0.3 --format csv --fps 10
    # The paper's model: two phases with interface tension (the colour normals are shared), the Laplace
    # drop (number density, tension), a paper dam break (its planes).
    same "paper_two_phase" 3 two-phase --until 0.1 --format csv --fps 20
    same "paper_laplace" 2 laplace-2d --until 0.03 --format csv --fps 100
    same "paper_dam_break" 2 paper-dam-break-1 --until 0.1 --format csv --fps 20
    # DFSPH: its sweeps share k and v, its errors are exact sums over the ranks; 2D on 4 ranks, the number
    # density, and the 3D dam break (without its reorder, which the ranks do not run) on 3.
    same "dfsph" 4 dam-break-2d-dfsph "${coarse[@]}" --until 0.2 --format csv --fps 20
    same "dfsph_number" 2 dam-break-2d-dfsph "${coarse[@]}" --set /solver/density=number --until 0.1 \
      --format csv --fps 20
    same "iisph" 3 dam-break-2d-dfsph "${coarse[@]}" --set /solver/model=iisph --set /solver/dfsph=null \
      --until 0.1 --format csv --fps 20
    same "dfsph_3d" 3 dam-break-3d-dfsph --set /neighbors/reorder_every=0 --set /spacing=0.05 \
      --set /solver/support=0.1 --until 0.06 --format csv --fps 50
    # A floating box: its particles' forces summed in id order on every rank, the same body stepped on each
    # (bodies.csv too); long enough that the curve's cut crosses the box.
    same "floating" 3 floating-box --set /spacing=0.02 --set /solver/support=0.04 --until 0.3 --format csv \
      --fps 10
    [ -s np3_floating/bodies.csv ] || fail "floating: no bodies.csv"
    # A rebalance at every rebuild of the domain (threshold 1e-6) moves particles between ranks far more
    # often: still the same bytes, and the summary counts the rebalances.
    same "rebalance" 3 dam-break-2d "${coarse[@]}" --set /parallel/rebalance_threshold=1e-6 --until 0.15 \
      --format csv --fps 20
    summary=$(ranks 3 run dam-break-2d "${coarse[@]}" --set /parallel/rebalance_threshold=1e-6 --until 0.15 \
      --format csv --fps 20 --out summary 2>&1)
    grep -q 'ranks: 3, domain rebuilt [1-9][0-9]* times, rebalanced [1-9][0-9]* times' <<<"$summary" ||
      fail "rebalance: no rebalance in the summary: $summary"
    ;;
  resume)
    # Checkpointed on 2 ranks at 0.1 s, resumed on 3 to 0.2 s: the frames and the last checkpoint of the run
    # in one process to 0.2 s (run.json keeps the first run's options, as a resume in one process does).
    "$cellsph" run dam-break-2d "${coarse[@]}" --until 0.2 --format csv --fps 20 --out one --quiet ||
      fail "one process: exit $?"
    ranks 2 run dam-break-2d "${coarse[@]}" --until 0.1 --format csv --fps 20 --out part --quiet ||
      fail "2 ranks: exit $?"
    ranks 3 run --resume part --until 0.2 --quiet || fail "resume on 3 ranks: exit $?"
    if diff -r -x run.json one part >diff.txt; then
      echo "ok: 2 ranks then 3 give the one-process files"
    else
      fail "resume: $(head -c 600 diff.txt)"
    fi
    ;;
  refusals)
    # The 3D DFSPH dam break reorders its arrays (the ranks keep the id order) and here takes the CG density
    # solve: both keys in one message.
    err=$(ranks 2 run dam-break-3d-dfsph --set /solver/dfsph/density_solver=cg --out refused 2>&1)
    rc=$?
    [ "$rc" -ne 0 ] || fail "CG on 2 ranks: exit 0"
    [ "$(grep -c 'across MPI ranks runs every model' <<<"$err")" = 1 ] || fail "not one message: $err"
    grep -q '/solver/dfsph/density_solver "cg"' <<<"$err" || fail "the solver is not named: $err"
    grep -q '/neighbors/reorder_every 25' <<<"$err" || fail "the reorder is not named: $err"
    [ ! -e refused ] || fail "CG: an output folder was made"
    err=$(ranks 2 neighbors 2>&1)
    [ "$(grep -c 'only `cellsph run` runs across ranks' <<<"$err")" = 1 ] || fail "neighbors: $err"
    out=$(ranks 2 doctor)
    [ "$(grep -c '^mpi: .* 2 ranks (this is rank 0)' <<<"$out")" = 1 ] || fail "doctor: $out"
    ;;
  unstable)
    # Gravity a million times too strong, upwards, and no walls: particles leave the domain within a few
    # steps, the first through the top (the curve's end, not rank 0's part: its rank tells rank 0).
    cat >unstable.json <<'EOF'
{
  "name": "unstable", "description": "test", "dimension": 2, "spacing": 0.05,
  "phases": [{"name": "water", "rest_density": 1000, "viscosity": 0.5}],
  "solver": {"model": "wcsph", "support": 0.1, "density_kernel": "cubic", "pressure_kernel": "cubic",
             "gravity": [0, 1e7], "eos": {"kind": "tait", "stiffness": 20000, "gamma": 7}},
  "time": {"end": 0.1, "stepping": "courant", "dt_max": 0.002},
  "fluids": [{"min": [0, 0], "max": [0.6, 0.6]}],
  "domain": {"min": [0, 0], "max": [1, 1]},
  "output": {"fps": 50, "formats": ["csv"]}
}
EOF
    "$cellsph" run unstable.json --out one --quiet 2>one.txt
    rc1=$?
    ranks 3 run unstable.json --out three --quiet 2>three.txt
    rc3=$?
    [ "$rc1" = 3 ] || fail "one process: exit $rc1, not 3: $(cat one.txt)"
    [ "$rc3" = 3 ] || fail "3 ranks: exit $rc3, not 3: $(cat three.txt)"
    expected=$(grep 'simulation stopped' one.txt)
    [ -n "$expected" ] || fail "one process: no diagnosis: $(cat one.txt)"
    [ "$(grep -c 'simulation stopped' three.txt)" = 1 ] || fail "3 ranks: not one diagnosis: $(cat three.txt)"
    grep -qF "$expected" three.txt || fail "3 ranks: another diagnosis: $(cat three.txt) against $expected"
    ;;
  signal)
    # SIGTERM to mpiexec (which passes it to every rank) once frame 2 is written: every rank stops after the
    # same step and the checkpoint is written; resumed on 3 ranks to 0.4 s, the files of one process.
    (ranks 2 run dam-break-2d --until 1.0 --fps 10 --format csv --out stopped --quiet 2>stop.txt) &
    launcher=$!
    for _ in $(seq 1 600); do
      [ -e stopped/frame_00002.csv ] || ! kill -0 "$launcher" 2>/dev/null && break
      sleep 0.1
    done
    # mpiexec alone (a rank signalled twice, by us and by mpiexec, would die at the second signal).
    pid=$(pgrep -f -- "^$mpiexec -n 2 --oversubscribe .* --out stopped" | head -1)
    [ -n "$pid" ] && kill -TERM "$pid" || fail "no mpiexec to signal"
    wait "$launcher"
    grep -q 'stopped by SIGTERM at t = .*checkpoint written' stop.txt || fail "no stop message: $(cat stop.txt)"
    [ "$(grep -c 'stopped by SIGTERM' stop.txt)" = 1 ] || fail "not one stop message: $(cat stop.txt)"
    grep -q 'to continue: mpirun -np 2 .* run --resume stopped' stop.txt || fail "resume line: $(cat stop.txt)"
    ranks 3 run --resume stopped --until 0.4 --quiet 2>/dev/null || fail "resume on 3 ranks: exit $?"
    "$cellsph" run dam-break-2d --until 0.4 --fps 10 --format csv --out one --quiet 2>/dev/null ||
      fail "one process: exit $?"
    if diff -r -x run.json one stopped >diff.txt; then
      echo "ok: stopped on 2 ranks, resumed on 3: the one-process files"
    else
      fail "signal: $(head -c 600 diff.txt)"
    fi
    ;;
  *)
    echo "unknown case $case_name"
    exit 2
    ;;
esac
[ "$failures" = 0 ] || exit 1
echo "all ok"
