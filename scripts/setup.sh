#!/usr/bin/env bash
# One entry point from nothing to a working `.venv/bin/viscoadh`:
#   1. create .venv (Python 3.11) in the repository root,
#   2. install the pinned requirements (ROS 2 Jazzy wheels, numerics, test tools),
#   3. point the ROS wheels' exported CMake include paths at this venv,
#   4. build msg_defs (viscoadh_msgs) with plain CMake and install it into the venv,
#   5. install this package (editable) so the repository code is what runs,
#   6. compile the numba kernels into their on-disk cache.
# Each step is skipped when a stamp file in .venv says its inputs (hashed) did not change, so a
# re-run with nothing changed takes seconds. Environment: PYTHON (default python3.11),
# VISCOADH_NO_LOCK=1 to resolve without requirements-lock.txt (only to regenerate the lock).
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"  # globs and hashes below are relative to the repository root
VENV="$ROOT/.venv"
PY="$VENV/bin/python"
PYTHON="${PYTHON:-python3.11}"

say() { printf '[setup] %s\n' "$*"; }
die() { printf '[setup] error: %s\n' "$*" >&2; exit 1; }

# sha256 over the contents of the given files (paths relative to ROOT), in the given order.
hash_files() { cat "$@" | sha256sum | cut -d' ' -f1; }
stamp_ok() { [[ -f "$VENV/.stamp-$1" && "$(cat "$VENV/.stamp-$1")" == "$2" ]]; }
stamp_set() { printf '%s\n' "$2" > "$VENV/.stamp-$1"; }

# The machine's pip config lists local wheel folders that may be absent; pip warns once per
# package about each. Drop only those lines so real warnings and errors stay visible.
pip_quiet() {
  "$PY" -m pip "$@" 2>&1 | { grep -v "^WARNING: Location 'file://" || true; }
  return "${PIPESTATUS[0]}"
}

# 1. venv -----------------------------------------------------------------------------------
if [[ ! -x "$PY" ]]; then
  command -v "$PYTHON" >/dev/null || die "$PYTHON not found (set PYTHON to a CPython 3.11 interpreter)"
  say "creating $VENV with $("$PYTHON" --version 2>&1)"
  "$PYTHON" -m venv "$VENV"
fi
pyver="$("$PY" -c 'import sys; print("%d.%d" % sys.version_info[:2])')"
[[ "$pyver" == "3.11" ]] || die "$VENV runs Python $pyver; the pinned ROS wheels need 3.11 (rm -rf .venv; PYTHON=python3.11)"

# 2. requirements ---------------------------------------------------------------------------
lock_args=(-c "$ROOT/requirements-lock.txt")
req_inputs=(requirements.txt requirements-lock.txt)
if [[ "${VISCOADH_NO_LOCK:-}" == 1 ]]; then
  lock_args=()
  req_inputs=(requirements.txt)
fi
req_hash="$(hash_files "${req_inputs[@]}")"
if stamp_ok requirements "$req_hash"; then
  say "requirements: up to date"
else
  say "installing pinned requirements (first time: about a minute)"
  pip_quiet install --disable-pip-version-check -q -r "$ROOT/requirements.txt" "${lock_args[@]}"
  stamp_set requirements "$req_hash"
  rm -f "$VENV/.stamp-msgs"  # new wheels may bring new CMake files: rebuild the interfaces
fi

# 3. CMake include paths of the wheels --------------------------------------------------------
# The wheels' exported targets name the include folders of the machine that built them
# (/opt/python/cp311-cp311/...); CMake refuses targets whose include folders are missing.
py_include="$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
np_include="$("$PY" -c 'import numpy; print(numpy.get_include())')"
mapfile -t foreign < <(grep -rlE '/opt/python/cp3[0-9]+-cp3[0-9]+/' "$VENV/share" --include='*.cmake' || true)
if ((${#foreign[@]})); then
  say "pointing ${#foreign[@]} CMake export files at this venv's Python and NumPy headers"
  sed -i -E \
    -e "s#/opt/python/cp3[0-9]+-cp3[0-9]+/include/python3\.[0-9]+#${py_include}#g" \
    -e "s#/opt/python/cp3[0-9]+-cp3[0-9]+/lib/python3\.[0-9]+/site-packages/numpy/_core/include#${np_include}#g" \
    "${foreign[@]}"
  if grep -lE '/opt/python/cp3[0-9]+-cp3[0-9]+/' "${foreign[@]}"; then
    die "unrecognised /opt/python paths left in the CMake files listed above"
  fi
fi

# 4. msg_defs -> viscoadh_msgs in the venv ---------------------------------------------------
msg_hash="$(hash_files msg_defs/CMakeLists.txt msg_defs/package.xml msg_defs/msg/*.msg msg_defs/srv/*.srv)"
if stamp_ok msgs "$msg_hash" && "$PY" -c 'import viscoadh_msgs.msg' 2>/dev/null; then
  say "viscoadh_msgs: up to date"
else
  say "building msg_defs (viscoadh_msgs) with CMake into the venv"
  command -v cmake >/dev/null || die "cmake not found (apt-get install cmake g++)"
  build="$VENV/build/viscoadh_msgs"
  rm -rf "$build" && mkdir -p "$VENV/build"
  # Only this venv: a sourced apt ROS in the caller's shell must not leak into the build.
  env -u AMENT_PREFIX_PATH -u CMAKE_PREFIX_PATH -u COLCON_PREFIX_PATH \
    AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" PATH="$VENV/bin:$PATH" \
    bash -euo pipefail -c '
      cmake -S "$1/msg_defs" -B "$2" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
        -DCMAKE_INSTALL_PREFIX="$3" -DPython3_EXECUTABLE="$3/bin/python" -Wno-dev >"$2.log" 2>&1 \
        || { tail -n 40 "$2.log" >&2; exit 1; }
      cmake --build "$2" -j "$(nproc)" >>"$2.log" 2>&1 || { tail -n 40 "$2.log" >&2; exit 1; }
      cmake --install "$2" >>"$2.log" 2>&1 || { tail -n 40 "$2.log" >&2; exit 1; }
    ' _ "$ROOT" "$build" "$VENV" || die "msg_defs build failed (full log: $build.log)"
  env -u AMENT_PREFIX_PATH -u PYTHONPATH "$PY" -c \
    'from viscoadh_msgs.msg import ContactState, IndentationCommand; from viscoadh_msgs.srv import SimulateHistory, PredictPullOff' \
    || die "viscoadh_msgs was built but does not import from $PY"
  stamp_set msgs "$msg_hash"
fi

# 5. this package ---------------------------------------------------------------------------
pkg_hash="$(hash_files setup.py setup.cfg package.xml)"
if stamp_ok package "$pkg_hash" && [[ -x "$VENV/bin/viscoadh" ]]; then
  say "viscoadh_ros: up to date (editable)"
else
  say "installing viscoadh_ros (editable)"
  pip_quiet install --disable-pip-version-check -q --no-deps --no-build-isolation -e "$ROOT"
  [[ -x "$VENV/bin/viscoadh" ]] || die "$VENV/bin/viscoadh missing after install"
  stamp_set package "$pkg_hash"
fi
# 6. numba's on-disk cache -----------------------------------------------------------------
# Compile every kernel once here (seconds when the cache is fresh), so the first node start or
# test after a fresh clone does not spend ~10 s compiling inside a timeout.
say "compiling the numba kernels (cached after the first time)"
"$PY" -c 'from viscoadh_ros.core._kernels import warm_up; warm_up()' || die "numba kernels failed to compile"
say "ready: $VENV/bin/viscoadh"
