#!/usr/bin/env bash
# Run the test suite, doing all set-up first (idempotent; a warm run reuses everything).
# Extra arguments go to a single pytest run, e.g. scripts/test.sh -k ltl -x
#
# Without arguments the suite runs in two pytest processes: everything else, then the
# tests that drive the real ur_rtde client (C++) against the simulated UR controller.
# ur_rtde 1.6.5 has been seen to crash its host process while reconnecting on a loaded
# machine; if that second process dies from a signal (not from a failed assertion), it is
# run once more and the crash is reported.
#
# A test that fails with a TimeoutError (a DDS peer or a simulated controller not seen in
# time on a loaded machine) is run once more (pytest-rerunfailures; reported as "R" in the
# summary); any other failure fails the run at once.
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$ROOT/scripts/setup.sh" --test-data
# shellcheck disable=SC1091
. "$ROOT/scripts/env.sh"
cd "$ROOT"
if [ "$#" -gt 0 ]; then
  exec python -m pytest "$@"
fi
RTDE_TESTS=(test/test_robot_rtde.py test/test_robot_reconnect.py test/test_robot_coexistence.py
            test/test_study_rtde.py
            test/test_ros_coexistence.py)
RETRY=(--reruns 1 --only-rerun TimeoutError)
ignore=()
for t in "${RTDE_TESTS[@]}"; do ignore+=("--ignore=$t"); done
set +e
python -m pytest -p no:cacheprovider "${RETRY[@]}" "${ignore[@]}"
rc_main=$?
python -m pytest -p no:cacheprovider "${RETRY[@]}" "${RTDE_TESTS[@]}"
rc_rtde=$?
if [ "$rc_rtde" -ge 128 ]; then
  echo "scripts/test.sh: the ur_rtde test process died from signal $((rc_rtde - 128));" \
       "running those tests once more" >&2
  python -m pytest -p no:cacheprovider "${RETRY[@]}" "${RTDE_TESTS[@]}"
  rc_rtde=$?
fi
set -e
echo "scripts/test.sh: main suite exit $rc_main, ur_rtde suite exit $rc_rtde" >&2
[ "$rc_main" -eq 0 ] && [ "$rc_rtde" -eq 0 ]
