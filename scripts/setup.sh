#!/usr/bin/env bash
# Installs the Debian packages cellsph needs to build, test and benchmark. Idempotent.
set -euo pipefail
PKGS=(g++ cmake ninja-build git pkg-config
      nlohmann-json3-dev libcli11-dev libnanoflann-dev libstb-dev libpng-dev
      libgtest-dev libgmock-dev libbenchmark-dev
      libopenvdb-dev libboost-dev libboost-iostreams-dev libassimp-dev
      python3-dev pybind11-dev python3-numpy
      libopenmpi-dev openmpi-bin
      ccache)
# With --test: what the tests use to check outputs with other people's tools (ffmpeg for the MP4,
# VTK's own .vtu reader through Debian's python3-vtk9), the Python module's tests (SciPy's cKDTree as
# the reference search, pytest, matplotlib for the plot of docs/python.md's tour), and clang with
# libFuzzer and its OpenMP for the fuzz harnesses (scripts/fuzz.sh). ccache is in the base list: scripts/run.sh
# and scripts/test.sh compile through it (scripts/lib/configure_release.sh), so the tree run.sh builds is
# the one test.sh continues, and a rerun on the same machine recompiles only what changed.
if [ "${1:-}" = "--test" ]; then
  PKGS+=(ffmpeg python3-vtk9 python3-scipy python3-pytest python3-matplotlib clang libclang-rt-14-dev libomp-dev)
fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" >/dev/null
fi
