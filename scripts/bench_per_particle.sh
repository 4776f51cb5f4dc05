#!/usr/bin/env bash
# Per-particle power-of-two steps against the global minimum step (issue 3): the cases quoted in
# docs/physics.md "Time stepping". Usage: scripts/bench_per_particle.sh [BUILD_DIR] [THREADS]
# Each case runs `cellsph bench steps` (three runs: courant, per-particle, per-particle with every
# density computed). dt_max is set to the uniform limit min(alpha h / c, 0.125 h^2 / nu) (times 0.999),
# the best case for per-particle steps: a particle is then on level 0 unless its own velocity or force
# limit is finer; a larger dt_max loses up to 2x to the power-of-two rounding.
set -euo pipefail
build="${1:-build}"
threads="${2:-1}"
bin="$build/cellsph"
limit() {  # c h nu -> dt_max
  python3 -c "import sys; c,h,nu=map(float,sys.argv[1:]); print('%.6g' % (0.999*min(0.3*h/c, 0.125*h*h/nu)))" "$@"
}

# The paper's dam breaks (3D, 1600 particles, linear EOS k = c^2, mu = 50 Pa s, h = 0.05 m).
for k in 1 2 3; do
  stiff=$(python3 -c "print({1:20,2:40,3:70}[$k])")
  c=$(python3 -c "print($stiff**0.5)")
  echo "== paper-dam-break-$k (c = $c m/s), dt_max = uniform limit"
  "$bin" bench steps --scene "paper-dam-break-$k" --end 0.3 --sample 0.05 --dt-max "$(limit "$c" 0.05 0.05)" \
    --threads "$threads"
done
echo "== paper-dam-break-1, dt_max = 0.01 s (the default; the c limit falls between two levels)"
"$bin" bench steps --scene paper-dam-break-1 --end 0.3 --sample 0.05 --dt-max 0.01 --threads "$threads"

# Koshizuka & Oka's 2D dam break with the paper model at 0.04 m spacing (1250 particles), mu = 0.5 Pa s,
# plane walls behind the boundary particles (a soft fluid pushes through two layers), ratio EOS
# k = 1000 c^2 for a range of user sound speeds c (the scene's own is 62.6 m/s = 10 sqrt(2 g H)).
# Akinci walls: per-particle steps cannot use the scene's Adami walls (they need every fluid density).
for c in 62.61 20 8 4 3 2; do
  echo "== 2D dam break, paper model, c = $c m/s"
  "$bin" bench steps --scene dam-break-2d --set '/solver/model="paper"' --set '/boundary/model="akinci"' \
    --set /solver/artificial_viscosity/alpha=0 --set /spacing=0.04 --set /solver/support=0.08 --set /phases/0/viscosity=0.5 \
    --set '/boundary/planes=[{"normal":[0,1],"point":[0,0]},{"normal":[1,0],"point":[0,0]},{"normal":[-1,0],"point":[4,0]}]' \
    --set "/solver/eos/stiffness=$(python3 -c "print($c*$c*1000)")" --dt-max "$(limit "$c" 0.08 0.0005)" \
    --end 1.0 --sample 0.2 --threads "$threads" || echo "(unstable: see the message above)"
done
