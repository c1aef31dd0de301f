#!/usr/bin/env bash
# The main job, with all set-up first: synthesize the paper's S1 and S2, write the
# figures, tables and animation, then run the ROS 2 loop (service call, playback,
# occupancy stream, MCAP recording) and the robot-coexistence loop. Output: out/demo/.
# Extra arguments go to `ltl-human-motion demo`.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$ROOT/scripts/setup.sh"
# shellcheck disable=SC1091
. "$ROOT/scripts/env.sh"
cd "$ROOT"
exec python -m ltl_human_motion demo --out "$ROOT/out/demo" "$@"
