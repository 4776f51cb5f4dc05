#!/usr/bin/env bash
# The CUDA backend's check on a GPU machine, in one command (docs/gpu.md). Builds the CUDA targets there
# from the sources (cmake/gpu_check.cmake: no Debian library needed), then runs tools/gpu_check.cpp:
# the device's neighbour rows against the CPU search (exactly equal), dam-break-3d (float) and
# dam-break-2d, hydrostatic-tank, two-phase, dam-break-2d-dfsph, dam-break-gate (a moving wall), channel-inflow
# (changing counts), floating-box (double) for 200 steps on both backends (positions within the stated
# tolerances), and
# the step benchmark at 10^5 and 10^6 fluid particles (10^7 with GPU_CHECK_SIZES), then compute-sanitizer's
# memcheck on a short run where the machine allows it. Everything it prints is kept in $OUT/gpu_check.txt
# (OUT defaults to ./gpu_check_out).
#
# Here (a machine with the Debian packages), first: scripts/gpu_check.sh --pack
#   copies the header-only libraries (nlohmann-json, nanoflann) into gpu_headers/ (ignored by git), which
#   must travel with the tree (the device tool's `carry`).
# There: scripts/gpu_check.sh        (about 2 min of build on 16 cores, then about 3 min of runs)
set -uo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--pack" ]; then
  rm -rf gpu_headers && mkdir -p gpu_headers
  cp -r /usr/include/nlohmann gpu_headers/
  cp /usr/include/nanoflann.hpp gpu_headers/
  du -sh gpu_headers
  exit 0
fi

OUT=${OUT:-gpu_check_out}
mkdir -p "$OUT"
exec > >(tee "$OUT/gpu_check.txt") 2>&1
JOBS=${JOBS:-$(nproc)}
SIZES=${GPU_CHECK_SIZES:-100000,1000000}
echo "== gpu_check $(date -u +%FT%TZ) on $(hostname), $(nproc) cores, commit $(git rev-parse --short HEAD 2>/dev/null || echo '?')"
nvidia-smi -L || true
nvcc --version | tail -2
cmake --version | head -1

echo "== build (cmake/gpu_check.cmake, sm_90)"
start=$(date +%s)
cmake -S . -B build/gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DCELLSPH_GPU_CHECK=ON \
  -DCMAKE_CUDA_ARCHITECTURES=90 -DCELLSPH_HEADERS="$PWD/gpu_headers" >"$OUT/configure.txt" 2>&1 ||
  { cat "$OUT/configure.txt"; echo "FAIL configure"; exit 1; }
timeout 300 cmake --build build/gpu -j "$JOBS" >"$OUT/build.txt" 2>&1 ||
  { tail -60 "$OUT/build.txt"; echo "FAIL build"; exit 1; }
echo "built in $(( $(date +%s) - start )) s"

echo "== compare and bench (tools/gpu_check.cpp)"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-$(nproc)}
timeout 300 build/gpu/cellsph_gpu_check --steps 200 --bench-steps 20 --sizes "$SIZES"
rc=$?
echo "gpu_check exit code $rc"

if command -v compute-sanitizer >/dev/null; then
  echo "== compute-sanitizer memcheck (short run; refused on some runtimes)"
  timeout 120 compute-sanitizer --tool memcheck --error-exitcode 9 build/gpu/cellsph_gpu_check --steps 3 \
    --bench-steps 1 --sizes 20000 >"$OUT/memcheck.txt" 2>&1
  echo "memcheck exit code $? (9: errors found); last lines:"
  tail -15 "$OUT/memcheck.txt"
fi
exit $rc
