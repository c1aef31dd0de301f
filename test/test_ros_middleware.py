"""Middleware defaults (loopback discovery, the Fast DDS service profile) and service calls
that survive a lost response, over real rclpy/DDS."""

from __future__ import annotations

import threading
import time
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

import pytest

from ltl_human_motion.ros.launch_support.middleware import (
    FASTDDS_PROFILES_FILE,
    apply_middleware_defaults,
)

NS = {"dds": "http://www.eprosima.com"}


def test_defaults_fill_only_what_the_user_left_unset() -> None:
    env: dict[str, str] = {}
    applied = apply_middleware_defaults(env)
    assert env == applied == {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST",
                              "FASTDDS_DEFAULT_PROFILES_FILE": str(FASTDDS_PROFILES_FILE)}
    user = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET",
            "FASTRTPS_DEFAULT_PROFILES_FILE": "/etc/my_profiles.xml"}
    assert apply_middleware_defaults(user) == {}
    assert user["ROS_AUTOMATIC_DISCOVERY_RANGE"] == "SUBNET"
    other_rmw = {"RMW_IMPLEMENTATION": "rmw_cyclonedds_cpp"}
    assert "FASTDDS_DEFAULT_PROFILES_FILE" not in apply_middleware_defaults(other_rmw)


def test_profile_lets_service_responses_wait_for_discovery() -> None:
    root = ET.parse(FASTDDS_PROFILES_FILE).getroot()
    writers = root.findall("dds:profiles/dds:data_writer", NS)
    assert [w.get("profile_name") for w in writers] == ["service"]
    blocking = writers[0].find("dds:qos/dds:reliability/dds:max_blocking_time", NS)
    seconds = int(blocking.findtext("dds:sec", "0", NS)) \
        + int(blocking.findtext("dds:nanosec", "0", NS)) * 1e-9
    assert seconds >= 1.0


@pytest.mark.ros
def test_the_test_session_runs_with_the_profile() -> None:
    import os
    assert os.environ.get("FASTDDS_DEFAULT_PROFILES_FILE") == str(FASTDDS_PROFILES_FILE) \
        or os.environ.get("FASTRTPS_DEFAULT_PROFILES_FILE")


@contextmanager
def _serving(name: str, service: str, callback: Callable[[Any, Any], Any]) -> Iterator[None]:
    """A SynthesizeMotion server ``name`` on ``service`` in a context of its own, whose
    callbacks may run concurrently."""
    rclpy = pytest.importorskip("rclpy")
    from ltl_human_motion.srv import SynthesizeMotion
    from rclpy.callback_groups import ReentrantCallbackGroup
    from rclpy.context import Context
    from rclpy.node import Node

    from ltl_human_motion.ros.common import SpinThread

    context = Context()
    rclpy.init(context=context)
    server = Node(name, context=context)
    server.create_service(SynthesizeMotion, service, callback,
                          callback_group=ReentrantCallbackGroup())
    spinner = SpinThread([server], context, 2)
    try:
        yield
    finally:
        spinner.stop()
        server.destroy_node()
        rclpy.try_shutdown(context=context)


@pytest.mark.ros
def test_a_resent_request_is_answered_when_the_first_answer_is_late() -> None:
    """The first request is held for 4 s; the client resends after 0.5 s and takes the
    answer to the second, well before the first comes back."""
    pytest.importorskip("rclpy")
    from ltl_human_motion.srv import SynthesizeMotion

    from ltl_human_motion.ros.client import ClientSession

    calls: list[float] = []
    lock = threading.Lock()

    def serve(request: Any, response: Any) -> Any:
        with lock:
            calls.append(time.monotonic())
            n = len(calls)
        if n == 1:
            time.sleep(4.0)
        response.success = True
        response.error_message = f"answer {n}"
        return response

    with _serving("resend_server", "/resend_test", serve), \
            ClientSession("resend_client") as session:
        started = time.monotonic()
        response = session.call(SynthesizeMotion, "/resend_test",
                                SynthesizeMotion.Request(spec="F a"), timeout=20.0,
                                resend_after=0.5)
        waited = time.monotonic() - started
    assert response.success
    assert response.error_message != "answer 1"
    assert len(calls) >= 2
    assert waited < 4.0


@pytest.mark.ros
def test_without_resend_a_silent_service_times_out_naming_it() -> None:
    pytest.importorskip("rclpy")
    from ltl_human_motion.srv import SynthesizeMotion

    from ltl_human_motion.ros.client import ClientSession

    release = threading.Event()

    def hold(request: Any, response: Any) -> Any:
        release.wait(10.0)
        return response

    try:
        with _serving("silent_server", "/silent_test", hold), \
                ClientSession("silent_client") as session:
            with pytest.raises(TimeoutError, match="/silent_test did not answer within 1 s"):
                session.call(SynthesizeMotion, "/silent_test", SynthesizeMotion.Request(),
                             timeout=1.0)
            release.set()
    finally:
        release.set()
