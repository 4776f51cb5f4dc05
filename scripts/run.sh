#!/usr/bin/env bash
# Installs what is needed, builds cellsph (release) and runs the main job.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/lib/configure_release.sh
# Only the program: the tests, benchmarks and Python module are scripts/test.sh's to build.
cmake --build build/release -j "$(nproc)" --target cellsph_app >/dev/null
if [ $# -eq 0 ]; then set -- run; fi
exec build/release/cellsph "$@"
