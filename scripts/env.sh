# Source this file (after scripts/setup.sh) to use the package from a shell:
#   . scripts/env.sh
# It activates the venv, overlays the built interfaces and keeps DDS on loopback.
_LHM_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export VIRTUAL_ENV="$_LHM_ROOT/.venv"
export PATH="$VIRTUAL_ENV/bin:$PATH"
export AMENT_PREFIX_PATH="$VIRTUAL_ENV${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$VIRTUAL_ENV${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
if [ -f "$_LHM_ROOT/.build/install/setup.bash" ]; then
  # colcon's setup scripts read unset variables: relax `set -u` while sourcing them.
  case $- in *u*) _LHM_NOUNSET=1; set +u ;; *) _LHM_NOUNSET= ;; esac
  # shellcheck disable=SC1091
  . "$_LHM_ROOT/.build/install/setup.bash"
  [ -n "$_LHM_NOUNSET" ] && set -u
  unset _LHM_NOUNSET
fi
# The source tree comes first so edits take effect without a rebuild; the generated
# msg/srv modules are found in the install space through pkgutil.extend_path.
export PYTHONPATH="$_LHM_ROOT${PYTHONPATH:+:$PYTHONPATH}"
# DDS discovery stays on 127.0.0.1 unless the user chose otherwise (SUBNET for a robot
# stack on another machine).
export ROS_AUTOMATIC_DISCOVERY_RANGE="${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}"
export RMW_IMPLEMENTATION="${RMW_IMPLEMENTATION:-rmw_fastrtps_cpp}"
# Service responses wait up to 5 s for discovery instead of 100 ms (see the file). A profile
# file of the user's own is kept.
if [ -z "${FASTDDS_DEFAULT_PROFILES_FILE:-}${FASTRTPS_DEFAULT_PROFILES_FILE:-}" ]; then
  export FASTDDS_DEFAULT_PROFILES_FILE="$_LHM_ROOT/ltl_human_motion/ros/fastdds_profiles.xml"
fi
export MPLBACKEND="${MPLBACKEND:-Agg}"
unset _LHM_ROOT
