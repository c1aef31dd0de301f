"""The reactive worker live in ROS, as one function (the demo's ``react`` stage).

:class:`ReactiveStack` brings up, in one rclpy context of this process, the synthesis
node, one worker's reactive player (namespace ``/human_<id>``) and, optionally, the
worker's occupancy node (reading the player) and a coexistence node. Requests and
observations go through a client node in its own context, so every call crosses DDS.

:func:`run_react_demo`:

1. calls ``/synthesize_motion`` with the reactive specification
   (:data:`~ltl_human_motion.tasks.reactive.DEMO_SPEC`: fetch O1, walk to the bench R1,
   wait while the robot is in R1, assemble when it has left) and gets a strategy id;
2. starts the simulated UR5e of ``config/ur_react_r1.yaml`` (its own process, RTDE on
   127.0.0.1:30004), whose arm works in R1 for about 9 s of each cycle; the coexistence
   node drives it with the real ur_rtde client and publishes the joint state it reads;
3. plays the strategy on ``/human_1/play_motion``; the player reads ``robot_in(R1)`` from
   that joint state and the arm's capsules;
4. watches ``/human_1/task_state`` until the worker, having waited at the bench while the
   arm was in R1, starts assembling after it left; writes ``react_demo.json``.

The stage's coexistence node keeps a slider of at least :data:`DEMO_MIN_SLIDER`: with
the SSM minimum (1 %) an arm beside a worker who waits for it nearly stops, and the
worker would wait for ever (the robot then breaks the assumption ``G F !robot_in(R1)``;
see docs/reactive.md).
"""

from __future__ import annotations

import json
import math
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
import rclpy
from rclpy.context import Context
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.msg import TaskState
from ltl_human_motion.planning.motion_store import MotionStore
from ltl_human_motion.ros.client import ClientSession, wait_until
from ltl_human_motion.ros.coexistence_node import UR_JOINT_NAMES
from ltl_human_motion.ros.common import STREAM_QOS, SpinThread, stamp_seconds
from ltl_human_motion.ros.launch_support.middleware import apply_middleware_defaults
from ltl_human_motion.ros.reactive_player import ReactivePlayer
from ltl_human_motion.ros.synthesis_node import SynthesisNode
from ltl_human_motion.srv import PlayMotion, SynthesizeMotion

__all__ = ["DEMO_MIN_SLIDER", "Q_IN", "Q_OUT", "REACT_ROBOT_CONFIG", "JointStateStandIn",
           "ReactiveStack", "RobotInR1Run", "run_react_demo"]

ROOT = Path(__file__).resolve().parents[2]
#: The robot of the stage: its arm works in R1, then away from it.
REACT_ROBOT_CONFIG = ROOT / "config" / "ur_react_r1.yaml"
#: Lowest speed slider of the stage's coexistence node.
DEMO_MIN_SLIDER = 0.5
#: Joint positions (6,) rad of the UR5e of :data:`REACT_ROBOT_CONFIG`: the arm in R1
#: (``in_r1``), and away from it (``away``).
Q_IN = np.radians([-4.0, -100.0, -100.0, -70.0, 90.0, 0.0])
Q_OUT = np.radians([-70.0, -90.0, -90.0, -90.0, 90.0, 0.0])


class JointStateStandIn:
    """Publishes a UR's joint state on ``/joint_states`` at ``rate`` Hz, stamped when
    published, as the coexistence node does with what it reads over RTDE (for tests and
    benchmarks that choose when the robot moves).

    Parameters
    ----------
    node : rclpy Node
        Publishes (spun elsewhere, e.g. a ClientSession's node).
    q : ndarray, shape (6,)
        Joint positions to start with, rad.
    """

    def __init__(self, node: Any, q: np.ndarray, rate: float = 50.0) -> None:
        self._names = list(UR_JOINT_NAMES)
        self.node = node
        self.pub = node.create_publisher(JointState, "/joint_states", STREAM_QOS)
        self.period = 1.0 / rate
        self.q = np.asarray(q, dtype=np.float64)
        #: Stamp (s) of the first message with the latest ``q`` (None until sent).
        self.changed: float | None = None
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="joint-states", daemon=True)
        self._thread.start()

    def move(self, q: np.ndarray) -> None:
        """Publish ``q`` (6,) rad from the next message on."""
        with self._lock:
            self.q, self.changed = np.asarray(q, dtype=np.float64), None

    def _run(self) -> None:
        while not self._stop.is_set():
            with self._lock:
                msg = JointState(name=self._names, position=[float(v) for v in self.q])
                msg.header.stamp = self.node.get_clock().now().to_msg()
                self.pub.publish(msg)
                if self.changed is None:
                    self.changed = stamp_seconds(msg.header.stamp)
            time.sleep(self.period)

    def close(self) -> None:
        """Stop publishing."""
        self._stop.set()
        self._thread.join(2.0)


class ReactiveStack:
    """Synthesis node, reactive player (and occupancy, coexistence nodes) in one context.

    Parameters
    ----------
    store_dir : path
        Folder of the strategies (``<id>.strategy.npz``) and motions.
    human_id : str
    playback_rate : float
    coexistence : dict, optional
        Parameters of a coexistence node to add (it connects to ``robot_host``); with it
        an occupancy node streams the worker's occupancy from the player.
    """

    def __init__(self, store_dir: str | Path, *, human_id: str = "1",
                 playback_rate: float = 1.0, coexistence: dict[str, Any] | None = None) -> None:
        apply_middleware_defaults()
        self.context = Context()
        rclpy.init(context=self.context)
        self.nodes: list[Any] = []
        self.spinner: SpinThread | None = None
        try:
            store = MotionStore(store_dir)
            self.synthesis = SynthesisNode(store=store, context=self.context)
            self.player = ReactivePlayer(
                context=self.context, namespace=f"/human_{human_id}", parameter_overrides=[
                    Parameter("human_id", value=human_id),
                    Parameter("store_dir", value=str(store.directory)),
                    Parameter("playback_rate", value=float(playback_rate))])
            self.nodes = [self.synthesis, self.player]
            self.coexistence = None
            if coexistence is not None:
                from ltl_human_motion.ros.coexistence_node import CoexistenceNode
                from ltl_human_motion.ros.occupancy_node import OccupancyNode

                self.nodes.append(OccupancyNode(
                    playback=self.player.view, context=self.context,
                    namespace=f"/human_{human_id}",
                    parameter_overrides=[Parameter("human_id", value=human_id)]))
                self.coexistence = CoexistenceNode(context=self.context, parameter_overrides=[
                    Parameter(k, value=v) for k, v in coexistence.items()])
                self.nodes.append(self.coexistence)
            self.spinner = SpinThread(self.nodes, self.context, 4)
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        """Stop spinning, destroy the nodes, shut the context down (idempotent)."""
        if self.spinner is not None:
            self.spinner.stop()
            self.spinner = None
        for node in reversed(self.nodes):
            node.destroy_node()
        self.nodes = []
        rclpy.try_shutdown(context=self.context)


def _inputs(msg: TaskState) -> dict[str, bool]:
    return dict(zip(msg.input_names, (bool(v) for v in msg.input_values)))


class RobotInR1Run:
    """The live loop with the simulated UR5e of :data:`REACT_ROBOT_CONFIG` (a context
    manager): holds the machine-wide lock of port 30004, brings up a
    :class:`ReactiveStack` with a coexistence node (slider at least
    :data:`DEMO_MIN_SLIDER`) and a client session; :meth:`start_robot` starts the
    simulated controller (its cycle begins with the move into R1) once the strategy is
    made, so that the arm is in R1 when the worker reaches the bench.
    """

    def __init__(self, store_dir: str | Path, *, human_id: str = "1",
                 playback_rate: float = 3.0, client_name: str = "react_client") -> None:
        self.store_dir, self.human_id = Path(store_dir), human_id
        self.playback_rate, self.client_name = playback_rate, client_name
        self.stack: ReactiveStack | None = None
        self.session: ClientSession | None = None
        self.sim: Any = None
        self._lock: Any = None

    def __enter__(self) -> RobotInR1Run:
        from ltl_human_motion.ros.coexistence_demo import (
            node_parameters_from_robot_config,
            rtde_port_lock,
        )

        params = node_parameters_from_robot_config(REACT_ROBOT_CONFIG)
        params.update(min_slider=DEMO_MIN_SLIDER, forget_after=1.0)
        self._lock = rtde_port_lock(timeout=300.0)
        self._lock.__enter__()
        try:
            self.stack = ReactiveStack(self.store_dir, human_id=self.human_id,
                                       playback_rate=self.playback_rate, coexistence=params)
            self.session = ClientSession(self.client_name)
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def synthesize(self, spec: str, timeout: float = 600.0) -> SynthesizeMotion.Response:
        """Call ``/synthesize_motion`` on the paper cell."""
        return self.session.call(SynthesizeMotion, "/synthesize_motion",
                                 SynthesizeMotion.Request(spec=spec, cell="paper_cell"),
                                 timeout=timeout, resend_after=min(30.0, timeout))

    def start_robot(self) -> None:
        """Start the simulated UR; return once the coexistence node reads it over RTDE."""
        from ltl_human_motion.ros.coexistence_demo import start_sim_when_free

        self.sim = start_sim_when_free(REACT_ROBOT_CONFIG, timeout=60.0)
        node = self.stack.coexistence
        wait_until(lambda: node.latest is not None and node.latest.connected, 20.0,
                   "the coexistence node to connect to the simulated UR over RTDE")

    def play(self, strategy_id: str) -> PlayMotion.Response:
        """Play ``strategy_id`` on ``/human_<id>/play_motion``."""
        return self.session.call(PlayMotion, f"/human_{self.human_id}/play_motion",
                                 PlayMotion.Request(command="play", motion_id=strategy_id),
                                 timeout=20.0, resend_after=5.0)

    def __exit__(self, *exc: object) -> None:
        if self.session is not None:
            self.session.close()
            self.session = None
        if self.stack is not None:
            self.stack.close()
            self.stack = None
        if self.sim is not None:
            self.sim.stop()
            self.sim = None
        if self._lock is not None:
            self._lock.__exit__(None, None, None)
            self._lock = None


def run_react_demo(out_dir: str | Path, *, spec: str | None = None, human_id: str = "1",
                   playback_rate: float = 3.0, timeout: float = 60.0,
                   synthesis_timeout: float = 600.0) -> dict[str, Any]:
    """The reactive stage end to end; returns (and writes to ``react_demo.json``) a
    summary: ``success``, ``strategy_id``, ``steps`` (task, start on the node clock,
    inputs), ``waited_s`` (at the bench while the arm was in R1), ``reaction_s`` (from
    the stamp of the joint state that showed the arm out of R1 to the first frame of the
    assembly), ``min_separation_m`` and ``min_slider`` (the coexistence node's, while the
    worker played), ``synthesis_wall_time``, ``error``."""
    from ltl_human_motion.tasks.reactive import DEMO_SPEC

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    spec = spec or DEMO_SPEC
    summary: dict[str, Any] = {"spec": spec, "cell": "paper_cell", "success": False,
                               "error": "", "robot": str(REACT_ROBOT_CONFIG.relative_to(ROOT)),
                               "slider_floor": DEMO_MIN_SLIDER, "playback_rate": playback_rate}
    try:
        with RobotInR1Run(out / "store", human_id=human_id, playback_rate=playback_rate,
                          client_name="react_demo_client") as run:
            states = run.session.watch(TaskState, f"/human_{human_id}/task_state", keep=1)
            t0 = time.monotonic()
            response = run.synthesize(spec, synthesis_timeout)
            summary["synthesis_wall_time"] = round(time.monotonic() - t0, 3)
            if not response.success or not response.strategy_id:
                summary["error"] = response.error_message or "no strategy id in the answer"
                return summary
            summary["strategy_id"] = response.strategy_id
            summary["tasks"] = response.task_sequences[0]
            run.start_robot()
            played = run.play(response.strategy_id)
            if not played.success:
                summary["error"] = f"play_motion: {played.message}"
                return summary
            summary.update(_watch(run.stack, states, response.strategy_id, timeout))
    except Exception as exc:   # the stage reports, the demo goes on
        summary["error"] = f"{type(exc).__name__}: {exc}"
    finally:
        atomic_write_text(out / "react_demo.json", json.dumps(summary, indent=2) + "\n")
    return summary


def _watch(stack: ReactiveStack, states: Any, strategy_id: str, timeout: float
           ) -> dict[str, Any]:
    """Follow the task state until the worker assembles after a wait at the bench."""
    steps: list[dict[str, Any]] = []
    waited_from: float | None = None
    end = time.monotonic() + timeout
    result: dict[str, Any] = {"success": False, "steps": steps}
    separation, slider = float("inf"), 1.0
    while time.monotonic() < end:
        msg = states.last
        time.sleep(0.01)
        decision = stack.coexistence.latest if stack.coexistence is not None else None
        if decision is not None and decision.connected:
            if math.isfinite(decision.separation):
                separation = min(separation, decision.separation)
            slider = min(slider, decision.slider)
        if msg is None or msg.strategy_id != strategy_id:
            continue
        if not steps or steps[-1]["step"] != msg.strategy_step:
            steps.append({"step": msg.strategy_step, "task": msg.current_task,
                          "at": round(stamp_seconds(msg.header.stamp), 3),
                          "inputs": _inputs(msg), "state": msg.strategy_state})
            waiting = msg.current_task.startswith("wait(") and _inputs(msg).get("robot_in(R1)")
            if waiting and waited_from is None:
                waited_from = stamp_seconds(msg.header.stamp)
            if msg.current_task == "assemble(R1)" and waited_from is not None:
                start = stamp_seconds(msg.header.stamp)
                result["waited_s"] = round(start - waited_from, 3)
                reactions = [r for r in stack.player.reactions if r[1] >= start - 0.5]
                if reactions:
                    result["reaction_s"] = round(reactions[-1][1] - reactions[-1][0], 4)
                result["success"] = True
                break
    if math.isfinite(separation):
        result["min_separation_m"] = round(separation, 3)
        result["min_slider"] = round(slider, 3)
    compact = []
    for s in steps:                                  # runs of waits as one entry
        if compact and s["task"] == compact[-1]["task"] and s["task"].startswith("wait("):
            compact[-1]["repeats"] = compact[-1].get("repeats", 1) + 1
        else:
            compact.append(s)
    result["steps"] = compact
    if not result["success"]:
        result["error"] = (f"within {timeout:g} s the worker did not assemble after waiting "
                           "at the bench while the arm was in R1 (steps: "
                           + ", ".join(s["task"] for s in compact) + ")")
    return result
