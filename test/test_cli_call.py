"""``ltl-human-motion call`` against a real ``ltl-human-motion bringup`` in another process.

The bringup runs as the user starts it (``python -m ltl_human_motion bringup``, real DDS on
loopback, the session's ROS_DOMAIN_ID); ``call`` runs as a third process; the test watches
the worker's task state to see that ``--play`` started the motion it printed.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

pytest.importorskip("rclpy")
pytest.importorskip("ltl_human_motion.srv")

from ltl_human_motion.msg import TaskState

from ltl_human_motion.planning.exports import load_npz
from ltl_human_motion.ros.client import ClientSession, wait_until

ROOT = Path(__file__).resolve().parents[1]
MOTION_ID = re.compile(r"^motion_[0-9a-f]{6,}$")


def _env(**extra: str) -> dict[str, str]:
    return {**os.environ, "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST", **extra}


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("call_store")


@pytest.fixture(scope="module")
def bringup(store: Path) -> Iterator[subprocess.Popen]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "ltl_human_motion", "bringup", str(ROOT / "config" /
                                                                  "bringup.yaml"),
         "--store-dir", str(store)],
        env=_env(ROS_HOME=str(store.parent)), stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL)
    yield proc
    proc.terminate()
    try:
        proc.wait(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait()


def _call(*args: str, domain: str | None = None) -> subprocess.CompletedProcess:
    env = _env() if domain is None else _env(ROS_DOMAIN_ID=domain)
    return subprocess.run([sys.executable, "-m", "ltl_human_motion", "call", *args], env=env,
                          capture_output=True, text=True, timeout=600)


def test_call_prints_the_motion_and_plays_it(bringup: subprocess.Popen, store: Path) -> None:
    with ClientSession("call_test_watcher") as watcher:
        state = watcher.watch(TaskState, "/human_1/task_state", keep=1)
        done = _call("--spec", "F grasp(O1)", "--cell", "paper_cell", "--play", "--wait", "120")
        assert done.returncode == 0, done.stderr[-3000:]
        lines = done.stdout.splitlines()
        m = re.fullmatch(r"motion 0: (\S+)  \((\d+\.\d) s\): (.+)", lines[0])
        assert m, done.stdout
        motion_id, duration, sequence = m.group(1), float(m.group(2)), m.group(3)
        assert MOTION_ID.match(motion_id)
        assert sequence.startswith("grasp(O1)")
        stored = load_npz(store / f"{motion_id}.npz")     # the bringup's motion store
        assert sequence == " ; ".join(stored.sequence)
        assert duration == pytest.approx(stored.duration, abs=0.05)
        assert lines[-1].startswith(f"playing {motion_id} on /human_1")
        wait_until(lambda: state.last is not None and state.last.motion_id == motion_id
                   and state.last.playback_state == "playing", 15.0,
                   f"/human_1/task_state to play {motion_id}")
        assert state.last.motion_duration == pytest.approx(duration, abs=0.05)


def test_call_json_with_variants(bringup: subprocess.Popen, store: Path) -> None:
    done = _call("--spec", "F grasp(O1) & F grasp(O2)", "--cell", "paper_cell",
                 "--variants", "2", "--json", "--wait", "120")
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout)
    assert len(result["motion_ids"]) == 2 and len(set(result["motion_ids"])) == 2
    assert all(MOTION_ID.match(i) for i in result["motion_ids"])
    for motion_id, sequence, duration in zip(result["motion_ids"], result["sequences"],
                                             result["durations"]):
        stored = load_npz(store / f"{motion_id}.npz")
        assert sequence == " ; ".join(stored.sequence)
        assert duration == pytest.approx(stored.duration)
        assert {"grasp(O1)", "grasp(O2)"} <= set(stored.sequence)
    assert result["played"] is None
    assert all(1 <= r <= 15 for r in result["reba_max"])


def test_call_with_a_reactive_spec_prints_its_strategy(bringup: subprocess.Popen,
                                                        store: Path) -> None:
    spec = "(G F !robot_in(R1)) -> (G(robot_in(R1) -> X !assemble(R1)) & G F assemble(R1))"
    done = _call("--spec", spec, "--cell", "paper_cell", "--wait", "120")
    assert done.returncode == 0, done.stderr[-3000:]
    m = re.match(r"strategy: (strategy_[0-9a-f]{12}) over (.+) \(a reactive", done.stdout)
    assert m, done.stdout
    assert "assemble(R1)" in m.group(2) and "wait(0.15)" in m.group(2)
    assert (store / f"{m.group(1)}.strategy.npz").is_file()


def test_a_refused_spec_is_a_clear_error(bringup: subprocess.Popen) -> None:
    done = _call("--spec", "F grasp(O9)", "--cell", "paper_cell", "--wait", "120")
    assert done.returncode == 2
    assert "refused" in done.stderr and "unknown object 'O9'" in done.stderr
    assert "Traceback" not in done.stderr and done.stdout == ""


def test_without_a_bringup_the_call_says_so() -> None:
    lonely = str((int(os.environ["ROS_DOMAIN_ID"]) + 37) % 101 + 100)
    done = _call("--spec", "S2", "--wait", "1.5", domain=lonely)
    assert done.returncode == 2
    assert "no node offers /synthesize_motion (waited 1.5 s)" in done.stderr
    assert "ltl-human-motion bringup" in done.stderr and f"ROS_DOMAIN_ID={lonely}" in done.stderr
    assert "Traceback" not in done.stderr
