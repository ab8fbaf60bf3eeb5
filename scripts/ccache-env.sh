# Sourced by the build scripts: compile through ccache when it is installed, so that a
# rebuild (or CI on a fresh clone of the same tree) recompiles only what changed. The cache
# keys use paths relative to the checkout, so clones in other directories share entries.
MLMAP_LAUNCHER=()
if command -v ccache > /dev/null 2>&1 && [ -z "${MLMAP_NO_CCACHE:-}" ]; then
  export CCACHE_BASEDIR="$PWD"
  export CCACHE_NOHASHDIR=1
  MLMAP_LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
