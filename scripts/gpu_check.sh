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
#   must travel with the tree (the device tool's `carry`), and build/gpu/cellsph_gpu_check, if it was built
#   here with the configure line below, into gpu_bin/ (ignored; carry it too to skip the build there).
# There: scripts/gpu_check.sh        (about 2 min of build on 16 cores unless gpu_bin/ came; the runs took
#                                     20-40 s on an H200)
set -uo pipefail
cd "$(dirname "$0")/.."

if [ "${1:-}" = "--pack" ]; then
  rm -rf gpu_headers && mkdir -p gpu_headers
  cp -r /usr/include/nlohmann gpu_headers/
  cp /usr/include/nanoflann.hpp gpu_headers/
  du -sh gpu_headers
  if [ -x build/gpu/cellsph_gpu_check ]; then  # built here with the command below: it travels too
    rm -rf gpu_bin && mkdir -p gpu_bin && cp build/gpu/cellsph_gpu_check gpu_bin/ && du -sh gpu_bin
  fi
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

# A binary built here with the same command (cmake/gpu_check.cmake links libstdc++, libgcc and cudart
# statically) can travel in gpu_bin/ (ignored by git) and saves the build there; it is used when it
# starts there, else the sources are built.
BIN=build/gpu/cellsph_gpu_check
if [ -x gpu_bin/cellsph_gpu_check ] && { gpu_bin/cellsph_gpu_check --usage >/dev/null 2>&1; [ $? -eq 2 ]; }; then
  BIN=gpu_bin/cellsph_gpu_check
  echo "== prebuilt $BIN (built elsewhere; it starts here)"
else
  echo "== build (cmake/gpu_check.cmake, sm_90)"
  start=$(date +%s)
  cmake -S . -B build/gpu -G Ninja -DCMAKE_BUILD_TYPE=Release -DCELLSPH_GPU_CHECK=ON \
    -DCMAKE_CUDA_ARCHITECTURES=90 -DCELLSPH_HEADERS="$PWD/gpu_headers" >"$OUT/configure.txt" 2>&1 ||
    { cat "$OUT/configure.txt"; echo "FAIL configure"; exit 1; }
  timeout 300 cmake --build build/gpu -j "$JOBS" >"$OUT/build.txt" 2>&1 ||
    { tail -60 "$OUT/build.txt"; echo "FAIL build"; exit 1; }
  echo "built in $(( $(date +%s) - start )) s"
fi

echo "== compare and bench (tools/gpu_check.cpp)"
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-$(nproc)}
timeout 360 "$BIN" --steps 200 --dfsph-steps 50 --bench-steps 20 --sizes "$SIZES" \
  --dfsph-until "${GPU_CHECK_DFSPH_UNTIL:-0.5}" --dfsph-wall "${GPU_CHECK_DFSPH_WALL:-30}"
rc=$?
echo "gpu_check exit code $rc"

if command -v compute-sanitizer >/dev/null; then
  echo "== compute-sanitizer memcheck (short run; refused on some runtimes)"
  timeout 90 compute-sanitizer --tool memcheck --error-exitcode 9 "$BIN" --steps 3 --dfsph-steps 1 \
    --bench-steps 1 --sizes 20000 >"$OUT/memcheck.txt" 2>&1
  echo "memcheck exit code $? (9: errors found); last lines:"
  tail -15 "$OUT/memcheck.txt"
fi
exit $rc
