# Sourced by scripts/run.sh and scripts/test.sh: configures build/release the same way in both, so that
# the tree scripts/run.sh builds is the tree scripts/test.sh builds on (a different compiler launcher or
# option would make CMake recompile everything). Where Debian's ccache is installed, compiles go through
# it: paths are taken relative to the checkout and the directory is left out of the hash, so a fresh
# clone in another folder of the same machine reuses the objects of the last build.
LAUNCHER=()
if command -v ccache >/dev/null; then
  export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=true
  LAUNCHER=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache
    -DCMAKE_CUDA_COMPILER_LAUNCHER=ccache)
fi
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release "${LAUNCHER[@]}" >/dev/null
