"""The synthesis service over real DDS.

The service mechanics (errors, concurrency, clients that die) are tested with a
scripted synthesizer that checks the spec with the real LTL parser and sleeps
``seed`` milliseconds to stand in for a long synthesis. test_ros_pipeline.py calls the
real ``planning.synthesize`` over the service (in a module of its own, so that no
scripted server answers on the same service name at the same time).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

rclpy = pytest.importorskip("rclpy")

from ltl_human_motion.msg import MotionCatalog  # noqa: E402
from ltl_human_motion.srv import SynthesizeMotion  # noqa: E402
from ros_fakes import (  # noqa: E402
    SYNTHESIS_ONLY_BRINGUP,
    scripted_synthesize,
)

from ltl_human_motion.ros.bringup import Bringup  # noqa: E402
from ltl_human_motion.ros.client import ClientSession, wait_until  # noqa: E402
from ltl_human_motion.ros.common import LATCHED_QOS  # noqa: E402

pytestmark = pytest.mark.ros

ROOT = Path(__file__).resolve().parents[1]
SERVICE = "/synthesize_motion"
BAD_SPEC = "grasp(O1) & (F assemble(R1)"       # unbalanced: error at line 1, column 28


def slow_synthesize(spec: str, cell: object, **kwargs: object) -> list:
    """The scripted synthesizer, sleeping ``seed`` ms; seed 666 fails unexpectedly."""
    seed = int(kwargs.get("seed", 0))
    if seed == 666:
        raise RuntimeError("simulated crash inside the planner")
    time.sleep(seed / 1000.0)
    return scripted_synthesize(spec, cell, **kwargs)


@pytest.fixture(scope="module")
def synthesis_only(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("config") / "synthesis_only.yaml"
    path.write_text(SYNTHESIS_ONLY_BRINGUP)
    return path


@pytest.fixture(scope="module")
def server(synthesis_only: Path):
    bringup = Bringup(synthesis_only, synthesize_fn=slow_synthesize,
                      overrides={"store_dir": ""}).start()
    yield bringup.node("synthesis_node")
    bringup.shutdown()


@pytest.fixture(scope="module")
def client(server: object):
    with ClientSession("test_synthesis_client") as session:
        yield session


def request(spec: str = "S2", seed: int = 0, **fields: object) -> SynthesizeMotion.Request:
    return SynthesizeMotion.Request(spec=spec, cell="paper_cell", seed=seed, **fields)


def call(client: ClientSession, req: SynthesizeMotion.Request,
         timeout: float = 15.0) -> SynthesizeMotion.Response:
    return client.call(SynthesizeMotion, SERVICE, req, timeout=timeout)


def test_success_returns_ids_sequences_and_stats(client: ClientSession) -> None:
    catalog = client.watch(MotionCatalog, "/motion_catalog", keep=1, qos=LATCHED_QOS)
    reply = call(client, request(variants=2))
    assert reply.success, reply.error_message
    assert len(reply.motion_ids) == len(set(reply.motion_ids)) == 2
    assert list(reply.task_sequences) == ["grasp(O1)", "grasp(O1)"]
    assert all(d == pytest.approx(2.0) for d in reply.durations)
    assert reply.stats[0].nodes_expanded == 7
    assert reply.stats[0].real_time_factor == pytest.approx(2.0 / 0.01)
    wait_until(lambda: catalog.last is not None
               and set(reply.motion_ids) <= set(catalog.last.motion_ids), 5.0,
               "the ids on /motion_catalog")


def test_bad_spec_reports_position_and_server_keeps_serving(client: ClientSession) -> None:
    reply = call(client, request(spec=BAD_SPEC))
    assert not reply.success
    assert (reply.error_line, reply.error_column) == (1, 28)
    assert "line 1, column 28" in reply.error_message and "expected ')'" in reply.error_message
    assert not reply.motion_ids
    unknown = call(client, request(spec="grasp(O7)"))
    assert not unknown.success and "O7" in unknown.error_message
    assert unknown.error_column == 7
    assert call(client, request()).success


def test_bad_inputs_are_rejected_with_a_message(client: ClientSession) -> None:
    cases = {
        "empty": (request(spec="  "), "empty"),
        "cell": (SynthesizeMotion.Request(spec="S2", cell="no_such_cell"), "no_such_cell"),
        "json": (request(options_json="{not json"), "options_json"),
        "option": (request(options_json='{"warp_speed": 9}'), "warp_speed"),
        "stature": (request(stature=3.5), "stature"),
    }
    for name, (req, needle) in cases.items():
        reply = call(client, req)
        assert not reply.success, name
        assert needle in reply.error_message, (name, reply.error_message)
        assert (reply.error_line, reply.error_column) == (0, 0) or name == "empty"


def test_unexpected_exception_is_reported_and_logged(client: ClientSession,
                                                     server: object) -> None:
    before = server.requests_served
    reply = call(client, request(seed=666))
    assert not reply.success
    assert reply.error_message.startswith("internal error (RuntimeError)")
    assert server.requests_served == before + 1
    assert call(client, request()).success


def test_ten_concurrent_calls_all_complete(client: ClientSession) -> None:
    """Ten 0.3 s syntheses at once: four run at a time (max_concurrent), all complete."""
    replies: list[SynthesizeMotion.Response] = []
    errors: list[BaseException] = []

    def one() -> None:
        try:
            replies.append(call(client, request(seed=300), timeout=20.0))
        except BaseException as exc:  # collected and reported below
            errors.append(exc)

    started = time.monotonic()
    threads = [threading.Thread(target=one) for _ in range(10)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=30.0)
    elapsed = time.monotonic() - started
    assert not errors, errors
    assert len(replies) == 10 and all(r.success for r in replies)
    assert len({r.motion_ids[0] for r in replies}) == 10
    assert elapsed < 10 * 0.3, f"calls were serialized ({elapsed:.2f} s)"


def test_long_synthesis_does_not_block_other_requests(client: ClientSession) -> None:
    slow: list[SynthesizeMotion.Response] = []
    thread = threading.Thread(target=lambda: slow.append(call(client, request(seed=2500))))
    thread.start()
    time.sleep(0.3)
    started = time.monotonic()
    fast = call(client, request(seed=0))
    fast_time = time.monotonic() - started
    thread.join(timeout=15.0)
    assert fast.success and fast_time < 1.5, f"fast call took {fast_time:.2f} s"
    assert slow and slow[0].success


CLIENT_CODE = textwrap.dedent("""\
    import json, sys, threading
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from ltl_human_motion.srv import SynthesizeMotion
    rclpy.init()
    node = rclpy.create_node("subprocess_client")
    client = node.create_client(SynthesizeMotion, "/synthesize_motion")
    if not client.wait_for_service(timeout_sec=15.0):
        print("NO SERVICE", flush=True)
        sys.exit(3)
    future = client.call_async(SynthesizeMotion.Request(
        spec="S2", cell="paper_cell", seed=int(sys.argv[1])))
    print("SENT", flush=True)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    executor.spin_until_future_complete(future, timeout_sec=20.0)
    reply = future.result()
    print(json.dumps({"success": reply.success, "ids": list(reply.motion_ids)}), flush=True)
    node.destroy_node()
    rclpy.shutdown()
    """)


def _start_client(seed: int) -> subprocess.Popen:
    env = {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    return subprocess.Popen([sys.executable, "-c", CLIENT_CODE, str(seed)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_killed_and_restarted_client_does_not_disturb_the_server(
        client: ClientSession, server: object) -> None:
    doomed = _start_client(seed=2000)
    try:
        line = doomed.stdout.readline().strip()
        assert line == "SENT", line + doomed.stderr.read()[-2000:]
        wait_until(lambda: server.in_flight > 0, 10.0, "the doomed request at the server")
        doomed.send_signal(signal.SIGKILL)
        doomed.wait(timeout=10)
    finally:
        if doomed.poll() is None:
            doomed.kill()
        doomed.stdout.close()
        doomed.stderr.close()
    # A new client process is served while the orphaned request is still running.
    fresh = _start_client(seed=0)
    out, err = fresh.communicate(timeout=40)
    assert fresh.returncode == 0, err[-2000:]
    result = json.loads(out.strip().splitlines()[-1])
    assert result["success"] and len(result["ids"]) == 1
    wait_until(lambda: server.in_flight == 0, 10.0, "the orphaned request to finish")
    assert call(client, request()).success
