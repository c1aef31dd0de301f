"""Shared pytest set-up: isolate DDS traffic of this test session.

Every session gets its own ROS_DOMAIN_ID (random in 100..200, unless the caller set one)
and keeps discovery on loopback, before any test initializes rclpy; subprocesses inherit
both through ``os.environ``.
"""

from __future__ import annotations

import os
import random

import pytest

os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randint(100, 200)))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "pipeline: needs the full synthesis pipeline (planning.synthesize)")
