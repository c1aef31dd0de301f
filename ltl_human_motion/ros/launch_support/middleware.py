"""Middleware defaults set before a ROS context starts: loopback discovery and our Fast DDS
profile. Plain Python (no rclpy import), so scripts and launch files can use it first.

* ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` keeps DDS discovery on 127.0.0.1.
* ``FASTDDS_DEFAULT_PROFILES_FILE`` points at :data:`FASTDDS_PROFILES_FILE`, whose
  ``service`` profile lets a service response wait up to 5 s for discovery of the client
  instead of Fast DDS's 100 ms (see the file and docs/ros.md).

Neither is touched when the user has set it, and the profile only applies to Fast DDS.
"""

from __future__ import annotations

import os
from collections.abc import MutableMapping
from pathlib import Path

FASTDDS_PROFILES_FILE = Path(__file__).parents[1] / "fastdds_profiles.xml"

_PROFILE_VARIABLES = ("FASTDDS_DEFAULT_PROFILES_FILE", "FASTRTPS_DEFAULT_PROFILES_FILE")


def apply_middleware_defaults(environ: MutableMapping[str, str] | None = None
                              ) -> dict[str, str]:
    """Set the middleware defaults in ``environ`` (default ``os.environ``) where unset.

    Must run before the first ``rclpy.init`` of the process: Fast DDS reads its profiles
    once. Returns the variables it set (name to value), so callers can log them.
    """
    env = os.environ if environ is None else environ
    applied: dict[str, str] = {}
    if not env.get("ROS_AUTOMATIC_DISCOVERY_RANGE"):
        applied["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    rmw = env.get("RMW_IMPLEMENTATION", "") or "rmw_fastrtps_cpp"
    if rmw.startswith("rmw_fastrtps") and not any(env.get(v) for v in _PROFILE_VARIABLES):
        applied["FASTDDS_DEFAULT_PROFILES_FILE"] = str(FASTDDS_PROFILES_FILE)
    env.update(applied)
    return applied
