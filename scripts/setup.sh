#!/usr/bin/env bash
# One-command set-up, idempotent: venv, pinned dependencies (incl. ROS 2 wheels), the
# wheels' CMake fix, the interface build (colcon), test data. Re-runs reuse what is built:
# each step records a hash of its inputs and is skipped when nothing changed.
#
# Usage: scripts/setup.sh [--test-data]
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
VENV="$ROOT/.venv"
BUILD="$ROOT/.build"
PY="${PYTHON:-python3.11}"
command -v "$PY" >/dev/null 2>&1 || PY=python3
mkdir -p "$BUILD"
log() { printf '[setup %s] %s\n' "$(date +%H:%M:%S)" "$*" >&2; }
stamp_ok() { [ -f "$BUILD/$1.stamp" ] && [ "$(cat "$BUILD/$1.stamp")" = "$2" ]; }
stamp_set() { echo "$2" > "$BUILD/$1.stamp"; }
hash_of() { cat "$@" 2>/dev/null | sha256sum | cut -c1-16; }

# 1. Virtual environment and pinned dependencies.
if [ ! -x "$VENV/bin/python" ]; then
  log "creating $VENV"
  "$PY" -m venv "$VENV"
  rm -f "$BUILD"/*.stamp
fi
REQ_HASH=$(hash_of requirements.txt)
if ! stamp_ok requirements "$REQ_HASH"; then
  log "installing pinned dependencies (requirements.txt)"
  "$VENV/bin/python" -m pip install -q --upgrade pip==26.0.1 >/dev/null 2>&1 \
    || "$VENV/bin/python" -m pip install -q --upgrade pip
  "$VENV/bin/python" -m pip install -q -r requirements.txt
  stamp_set requirements "$REQ_HASH"
fi
PKG_HASH=$(hash_of setup.py pyproject.toml)
if ! stamp_ok editable "$PKG_HASH"; then
  log "installing ltl_human_motion (editable)"
  "$VENV/bin/python" -m pip install -q --no-deps --no-build-isolation -e .
  stamp_set editable "$PKG_HASH"
fi

# 2. Fix the ROS wheels' CMake exports (paths of the manylinux build container).
INC=$("$VENV/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['include'])")
NP=$("$VENV/bin/python" -c "import numpy; print(numpy.get_include())")
FIX_FILES=$(grep -rl '/opt/python/cp311-cp311' "$VENV"/share/*/cmake 2>/dev/null || true)
if [ -n "$FIX_FILES" ]; then
  log "fixing CMake export paths in $(echo "$FIX_FILES" | wc -l) files"
  echo "$FIX_FILES" | xargs sed -i \
    -e "s#/opt/python/cp311-cp311/include/python3.11#$INC#g" \
    -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$NP#g"
fi

# 3. Build the interfaces (and tf2_msgs where the environment lacks it) with colcon.
IFACE_HASH=$(hash_of package.xml CMakeLists.txt msg/*.msg srv/*.srv compat/tf2_msgs/msg/* \
  compat/tf2_msgs/CMakeLists.txt compat/tf2_msgs/package.xml compat/hri_msgs/msg/* \
  compat/hri_msgs/CMakeLists.txt compat/hri_msgs/package.xml compat/diagnostic_msgs/msg/* \
  compat/diagnostic_msgs/CMakeLists.txt compat/diagnostic_msgs/package.xml requirements.txt)
if ! stamp_ok interfaces "$IFACE_HASH" || [ ! -f "$BUILD/install/setup.bash" ]; then
  log "building interfaces with colcon"
  (
    export VIRTUAL_ENV="$VENV" PATH="$VENV/bin:$PATH"
    export AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV"
    export _ROS_WHEELS_BOOTSTRAP_COMPLETE=1
    export LD_LIBRARY_PATH="$VENV/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
    # CMake refuses include paths inside the source folder, and the venv lives in the
    # repo, so the package is staged into a workspace of its own under .build/src.
    STAGE="$BUILD/src"
    rm -rf "$STAGE" "$BUILD/install" "$BUILD/build"
    mkdir -p "$STAGE/ltl_human_motion"
    cp -r package.xml CMakeLists.txt setup.py resource msg srv nodes launch config \
      ltl_human_motion "$STAGE/ltl_human_motion/"
    find "$STAGE" -name __pycache__ -prune -exec rm -rf {} +
    if ! "$VENV/bin/python" -c "import tf2_msgs.msg" >/dev/null 2>&1; then
      cp -r compat/tf2_msgs "$STAGE/tf2_msgs"
    fi
    if ! "$VENV/bin/python" -c "import hri_msgs.msg" >/dev/null 2>&1; then
      cp -r compat/hri_msgs "$STAGE/hri_msgs"
    fi
    if ! "$VENV/bin/python" -c "import diagnostic_msgs.msg" >/dev/null 2>&1; then
      cp -r compat/diagnostic_msgs "$STAGE/diagnostic_msgs"
    fi
    "$VENV/bin/colcon" --log-base "$BUILD/log" build \
      --merge-install --base-paths "$STAGE" --build-base "$BUILD/build" --install-base "$BUILD/install" \
      --cmake-args -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$VENV/bin/python" \
      >"$BUILD/colcon.log" 2>&1 \
      || { tail -40 "$BUILD/colcon.log" >&2; log "colcon build failed (log: $BUILD/colcon.log)"; exit 1; }
  )
  stamp_set interfaces "$IFACE_HASH"
fi

# 4. Test data from the registries (only with --test-data): genuine CMU BVH files.
if [ "${1:-}" = "--test-data" ] && [ ! -f /usr/share/assimp/models/BVH/01_01.bvh ]; then
  if [ "$(id -u)" = "0" ] && command -v apt-get >/dev/null; then
    log "installing Debian's assimp-testmodels (CMU BVH test files)"
    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq assimp-testmodels) \
      >"$BUILD/apt.log" 2>&1 || log "could not install assimp-testmodels (see $BUILD/apt.log)"
  else
    log "assimp-testmodels missing and not root: BVH loader tests on real files will be skipped"
  fi
fi
log "ready"
