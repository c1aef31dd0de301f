"""The synthesis service node: LTL specification in, verified motions out.

Service ``synthesize_motion`` (ltl_human_motion/srv/SynthesizeMotion, relative to the
node's namespace) calls ``ltl_human_motion.planning.synthesize``. The service sits in a
ReentrantCallbackGroup, so under a MultiThreadedExecutor several requests run at once and
a long synthesis never blocks the node's other callbacks (``max_concurrent`` bounds how
many synthesize at the same time; further requests wait for a slot).

Errors the user caused (any ``LtlHumanMotionError`` or ``ValueError``, e.g. a
``SpecError`` with line and column) come back as ``success=false`` with the message and
``error_line``/``error_column``; anything unexpected is logged with its traceback and
also returned as ``success=false``. The node keeps serving either way.

Motions go into a :class:`~ltl_human_motion.ros.motion_store.MotionStore` (memory, plus
``<store_dir>/<id>.npz`` when ``store_dir`` is set), and the ids are announced on the
latched topic ``motion_catalog`` (ltl_human_motion/msg/MotionCatalog).

Parameters: ``default_cell`` (str, "paper_cell"; used when a request leaves ``cell``
empty), ``store_dir`` (str, ""; read only), ``max_concurrent`` (int, 4; read only).
"""

from __future__ import annotations

import json
import threading
import time
import traceback
from collections.abc import Callable
from typing import Any

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from ltl_human_motion.errors import LtlHumanMotionError, SpecError
from ltl_human_motion.msg import MotionCatalog, PlanningStats
from ltl_human_motion.ros.common import LATCHED_QOS, resolve_cell
from ltl_human_motion.ros.motion_store import MotionStore
from ltl_human_motion.ros.params import ParamSpec, declare_parameters, positive
from ltl_human_motion.ros.playback import task_sequence_text
from ltl_human_motion.srv import SynthesizeMotion

SynthesizeFn = Callable[..., list]

_STATS_FIELDS = ("automaton_time", "sequence_time", "planning_time", "blending_time",
                 "verification_time", "total_time", "real_time_factor")


def _planning(name: str) -> Any:
    """``ltl_human_motion.planning.<name>`` (re-exported from ``planning.pipeline``)."""
    from ltl_human_motion import planning

    if hasattr(planning, name):
        return getattr(planning, name)
    from ltl_human_motion.planning import pipeline

    return getattr(pipeline, name)


def planning_synthesize(*args: Any, **kwargs: Any) -> list:
    """``ltl_human_motion.planning.synthesize``, looked up at call time."""
    return _planning("synthesize")(*args, **kwargs)


def synthesis_options(options_json: str) -> Any:
    """``planning.SynthesisOptions`` from the request's JSON object ("" for defaults)."""
    text = options_json.strip()
    if not text:
        return None
    try:
        values = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"options_json is not valid JSON: {exc}") from None
    if not isinstance(values, dict):
        raise ValueError(f"options_json must be a JSON object, got {type(values).__name__}")
    options_class = _planning("SynthesisOptions")
    if hasattr(options_class, "from_dict"):
        return options_class.from_dict(values)
    try:
        return options_class(**values)
    except TypeError as exc:
        raise ValueError(f"options_json: {exc}") from None


def stats_message(stats: Any, duration: float) -> PlanningStats:
    """PlanningStats from a motion's ``stats`` (an object or a dict; missing fields are 0)."""
    def get(name: str) -> Any:
        if isinstance(stats, dict):
            return stats.get(name)
        return getattr(stats, name, None)

    msg = PlanningStats()
    for name in _STATS_FIELDS:
        value = get(name)
        if isinstance(value, int | float):
            setattr(msg, name, float(value))
    expanded = get("nodes_expanded")
    if isinstance(expanded, int | float):
        msg.nodes_expanded = max(int(expanded), 0)
    if msg.real_time_factor == 0.0 and msg.total_time > 0:
        msg.real_time_factor = duration / msg.total_time
    return msg


class SynthesisNode(Node):
    """Serves ``synthesize_motion`` and announces stored motions on ``motion_catalog``.

    Parameters
    ----------
    store : MotionStore, optional
        Share a store with players in the same process; by default one is made from the
        ``store_dir`` parameter.
    synthesize_fn : callable, optional
        Replaces ``planning.synthesize`` (same signature).
    """

    def __init__(self, *, store: MotionStore | None = None,
                 synthesize_fn: SynthesizeFn | None = None, node_name: str = "synthesis_node",
                 **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        declare_parameters(self, [
            ParamSpec("default_cell", "paper_cell", "Cell used when a request leaves cell empty",
                      lambda v: None if v.strip() else "expected a cell name"),
            ParamSpec("store_dir", "", "Folder for <motion_id>.npz ('' keeps motions in memory)",
                      read_only=True),
            ParamSpec("max_concurrent", 4, "Syntheses allowed to run at the same time",
                      positive, read_only=True),
        ])
        store_dir = self.get_parameter("store_dir").value
        self.store = store if store is not None else MotionStore(store_dir or None)
        self._synthesize = synthesize_fn or planning_synthesize
        self._slots = threading.BoundedSemaphore(self.get_parameter("max_concurrent").value)
        self._catalog_lock = threading.Lock()
        self._catalog_pub = self.create_publisher(MotionCatalog, "motion_catalog", LATCHED_QOS)
        self._service = self.create_service(SynthesizeMotion, "synthesize_motion",
                                            self._on_request,
                                            callback_group=ReentrantCallbackGroup())
        self.requests_served = 0
        self.in_flight = 0
        self._count_lock = threading.Lock()
        self._publish_catalog()
        self.get_logger().info(
            f"serving {self._service.service_name} (store: "
            f"{self.store.directory or 'memory'})")

    def _on_request(self, request: SynthesizeMotion.Request,
                    response: SynthesizeMotion.Response) -> SynthesizeMotion.Response:
        started = time.perf_counter()
        with self._count_lock:
            self.in_flight += 1
        try:
            with self._slots:
                motions, cell = self._run(request)
            self._fill(response, motions)
            self._fill_ergonomics(response, motions, cell, int(request.cycles) or 1)
            self.get_logger().info(
                f"synthesized {len(motions)} motion(s) in {time.perf_counter() - started:.2f} s:"
                f" {', '.join(response.motion_ids)}")
        except (LtlHumanMotionError, ValueError) as exc:
            self._fail(response, exc)
            self.get_logger().warning(f"synthesis request rejected: {exc}")
        except Exception as exc:   # keep serving; report the failure to the caller
            self.get_logger().error(
                f"synthesis failed unexpectedly: {exc!r}\n{traceback.format_exc()}")
            response.success = False
            response.error_message = f"internal error ({type(exc).__name__}): {exc}"
        finally:
            with self._count_lock:
                self.in_flight -= 1
                self.requests_served += 1
        return response

    def _run(self, request: SynthesizeMotion.Request) -> tuple[list, Any]:
        spec = request.spec
        if not spec.strip():
            raise SpecError("the specification is empty")
        cell_text = request.cell.strip() or self.get_parameter("default_cell").value
        cell = resolve_cell(cell_text)
        kwargs: dict[str, Any] = {
            "variants": int(request.variants) or 1,
            "seed": int(request.seed),
            "cycles": int(request.cycles) or 1,
            "stature": float(request.stature) or 1.75,
        }
        options = synthesis_options(request.options_json)
        if options is not None:
            kwargs["options"] = options
        motions = list(self._synthesize(spec, cell, **kwargs))
        if not motions:
            raise ValueError("synthesis returned no motion")
        return motions, cell

    def _fill(self, response: SynthesizeMotion.Response, motions: list) -> None:
        for motion in motions:
            motion_id = self.store.add(motion)
            duration = float(motion.motion.duration)
            response.motion_ids.append(motion_id)
            response.task_sequences.append(task_sequence_text(motion))
            response.durations.append(duration)
            response.stats.append(stats_message(getattr(motion, "stats", None), duration))
        response.success = True
        self._publish_catalog()

    @staticmethod
    def _fill_ergonomics(response: SynthesizeMotion.Response, motions: list, cell: Any,
                         cycles: int) -> None:
        """Cycle time and worst REBA/RULA per motion (:mod:`ltl_human_motion.ros.ergonomics`)."""
        from ltl_human_motion.ros.ergonomics import cell_masses, response_figures
        masses = cell_masses(cell)
        for motion in motions:
            cycle_time, reba_max, rula_max = response_figures(motion, masses, cycles)
            response.cycle_times.append(cycle_time)
            response.reba_max.append(reba_max)
            response.rula_max.append(rula_max)

    @staticmethod
    def _fail(response: SynthesizeMotion.Response, exc: Exception) -> None:
        response.success = False
        response.error_message = str(exc) or type(exc).__name__
        line = getattr(exc, "line", None)
        column = getattr(exc, "column", None)
        response.error_line = int(line) if isinstance(line, int) else 0
        response.error_column = int(column) if isinstance(column, int) else 0

    def _publish_catalog(self) -> None:
        with self._catalog_lock:
            msg = MotionCatalog()
            msg.header.stamp = self.get_clock().now().to_msg()
            for info in self.store.infos():
                msg.motion_ids.append(info.motion_id)
                msg.task_sequences.append(info.task_sequence)
                msg.durations.append(info.duration)
            msg.store_dir = str(self.store.directory or "")
            self._catalog_pub.publish(msg)
