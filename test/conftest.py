"""Shared pytest set-up: isolate DDS traffic of this test session; repeatable hypothesis.

Every session gets its own ROS_DOMAIN_ID (random in 100..200, unless the caller set one),
keeps discovery on loopback and loads the package's Fast DDS profile, before any test
initializes rclpy; subprocesses inherit all three through ``os.environ``.

Property-based tests draw the same examples on every run (profile ``deterministic``), so
CI is repeatable; ``HYPOTHESIS_PROFILE=explore`` draws new ones to hunt for bugs, and
``--hypothesis-profile=thorough`` runs many more (the fuzz tests scale with it).
"""

from __future__ import annotations

import os
import random
import tempfile
from collections.abc import Iterator

import pytest
from hypothesis import settings

from ltl_human_motion.ros.launch_support.middleware import apply_middleware_defaults

settings.register_profile("deterministic", derandomize=True, database=None, deadline=None)
settings.register_profile("explore", deadline=None)
# The fuzz tests (test_fuzz_*.py) draw settings().max_examples // FUZZ_DIVISOR examples:
# 25 in CI (deterministic), 500 with --hypothesis-profile=thorough.
settings.register_profile("thorough", derandomize=False, database=None, deadline=None,
                          max_examples=2000)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))

os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(100, 200)))
# Motions stored under $ROS_HOME (the synthesis node's default) stay out of the user's home.
os.environ.setdefault("ROS_HOME", tempfile.mkdtemp(prefix="lhm-test-ros-home-"))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
apply_middleware_defaults()


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "pipeline: needs the full synthesis pipeline (planning.synthesize)")


# ---------------------------------------------------------------------- robot fixtures
@pytest.fixture(scope="module")
def sim() -> Iterator[object]:
    """The simulated UR controller on 127.0.0.1 for one test module (test/robot_sim.py);
    the distance kernel is loaded first, as a node does at start-up, so the arm's
    trajectory starts when the test does."""
    from robot_sim import start_sim

    from ltl_human_motion.kernel.segments import compiled

    compiled()
    handle = start_sim()
    yield handle
    handle.stop()


@pytest.fixture(scope="module")
def receive(sim: object) -> Iterator[object]:
    """A real ur_rtde receive interface on the module's simulator."""
    rtde_receive = pytest.importorskip("rtde_receive")
    from robot_sim import HOST

    r = rtde_receive.RTDEReceiveInterface(HOST)
    yield r
    r.disconnect()
