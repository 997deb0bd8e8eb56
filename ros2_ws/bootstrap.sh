#!/usr/bin/env bash
# Set the workspace up, idempotently and quickly when nothing changed:
#   1. a venv at ros2_ws/.venv with the pinned wheels of ros2_ws/requirements.txt
#   2. the CMake include-path fix of the ros-jazzy wheels (after every install)
#   3. colcon build of src/ into ros2_ws/build and ros2_ws/install
# Each step is skipped when the stamp of its inputs has not changed.
set -euo pipefail
ws="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
top="$(dirname "$ws")"
venv="$ws/.venv"
py="${PYTHON:-python3}"

hash_of() { cat "$@" | sha256sum | cut -d' ' -f1; }

# Run a step with its output in a log, printing the elapsed time every 20 s so a long first
# set-up is visibly alive: with_progress LABEL LOG COMMAND...
with_progress() {
  local label="$1" log="$2" t0=$SECONDS pid rc
  shift 2
  "$@" >"$log" 2>&1 &
  pid=$!
  while kill -0 "$pid" 2>/dev/null; do
    sleep 1
    if (( (SECONDS - t0) % 20 == 0 )) && kill -0 "$pid" 2>/dev/null; then
      echo "[bootstrap] $label: $((SECONDS - t0)) s ..." >&2
    fi
  done
  wait "$pid" && rc=0 || rc=$?
  echo "[bootstrap] $label: done in $((SECONDS - t0)) s" >&2
  return "$rc"
}

req_hash=$(hash_of "$ws/requirements.txt" "$ws/fix_cmake_paths.py")
if [ ! -x "$venv/bin/python" ] || [ "$(cat "$venv/.req_stamp" 2>/dev/null)" != "$req_hash" ]; then
  echo "[bootstrap] installing the pinned wheels into $venv (first time: 1-3 min; log: $ws/pip_install.log)" >&2
  [ -x "$venv/bin/python" ] || "$py" -m venv "$venv"
  with_progress "pip install" "$ws/pip_install.log" "$venv/bin/python" -m pip install --disable-pip-version-check \
    --no-input -r "$ws/requirements.txt" \
    || { grep -v '^WARNING: Location' "$ws/pip_install.log" | tail -n 30 >&2; exit 1; }
  "$venv/bin/python" "$ws/fix_cmake_paths.py" "$venv" >&2
  echo "$req_hash" > "$venv/.req_stamp"
  rm -f "$ws/install/.src_stamp"   # new wheels: rebuild the workspace
fi

# Rebuild only when a file under src/ (or the colcon defaults) changed.
src_hash=$( (cd "$top" && find src "$ws/colcon_defaults.yaml" -type f -not -name '*.pyc' \
  -not -path '*/__pycache__/*' -print0 | sort -z | xargs -0 sha256sum) | sha256sum | cut -d' ' -f1)
if [ "$(cat "$ws/install/.src_stamp" 2>/dev/null)" != "$src_hash" ]; then
  echo "[bootstrap] colcon build of src/ into ros2_ws/install (first time: 1-5 min on a busy 2-core machine;" \
    "log: $ws/colcon_build.log)" >&2
  (
    cd "$top"
    # shellcheck disable=SC1091
    . "$venv/bin/activate"
    export CMAKE_PREFIX_PATH="$VIRTUAL_ENV" AMENT_PREFIX_PATH="$VIRTUAL_ENV"
    export COLCON_DEFAULTS_FILE="$ws/colcon_defaults.yaml" COLCON_HOME="$ws/.colcon" COLCON_LOG_PATH="$ws/log"
    # A version bump leaves the old egg-info beside the new one (importlib.metadata may then read
    # the old version): the build writes the current one again.
    rm -rf "$ws"/install/rail_monitor/lib/python3*/site-packages/rail_monitor-*.egg-info
    with_progress "colcon build" "$ws/colcon_build.log" colcon build --cmake-args -DBUILD_TESTING=OFF \
      "-DPython3_EXECUTABLE=$venv/bin/python" || { tail -n 40 "$ws/colcon_build.log" >&2; exit 1; }
  )
  echo "$src_hash" > "$ws/install/.src_stamp"
fi
