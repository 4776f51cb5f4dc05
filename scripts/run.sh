#!/usr/bin/env bash
# Installs what is needed, builds cellsph (release) and runs the main job.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j "$(nproc)" >/dev/null
if [ $# -eq 0 ]; then set -- run; fi
exec build/release/cellsph "$@"
