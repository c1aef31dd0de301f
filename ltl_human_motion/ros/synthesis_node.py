"""The synthesis service node: LTL specification in, verified motions out.

Service ``synthesize_motion`` (ltl_human_motion/srv/SynthesizeMotion, relative to the
node's namespace) calls ``ltl_human_motion.planning.synthesize``. A reactive
specification (one that reads inputs such as ``robot_in(R1)``, docs/reactive.md) is solved
instead and each move of its strategy planned and verified
(:func:`~ltl_human_motion.planning.strategy_motion.build_program`); the answer carries its
``strategy_id`` (saved as ``<store_dir>/<id>.strategy.npz``), which the reactive player
(:mod:`ltl_human_motion.ros.reactive_player`) plays live. An unrealizable one is refused
with the explanation.

Every request gets an answer. The service callback only checks the request against the
named limits below and queues it; ``max_concurrent`` worker threads of the node's own
synthesize, and each sends its response when done. A request that finds ``max_queued``
requests waiting is refused at once with "busy". (The executor's threads are never held
by a synthesis, so requests are taken from DDS as fast as they come; before, blocked
threads left them in the service's DDS history of depth 10, where later ones overwrote
them unanswered.) The service's history is :data:`SERVICE_HISTORY_DEPTH` deep, so a burst
of requests waits in DDS for the executor rather than being overwritten. Clients that
send many requests at once should give their own client a deep history too: replies are
kept in the client's history until its executor takes them.

Each request has a time budget: ``max_seconds`` in ``options_json`` (default
:data:`~ltl_human_motion.deadline.DEFAULT_MAX_SECONDS`); when it runs out the answer is
``success: false``, "time budget of N s exhausted in <stage>". Destroying the node
(Ctrl-C) cancels the running syntheses and answers the queued requests with "shutting
down", so the process exits within a second or two even mid-synthesis.

Errors the user caused (any ``LtlHumanMotionError`` or ``ValueError``, e.g. a
``SpecError`` with line and column) come back as ``success=false`` with the message and
``error_line``/``error_column``; anything unexpected is logged with its traceback and
also returned as ``success=false``. The node keeps serving either way.

Motions go into a :class:`~ltl_human_motion.planning.motion_store.MotionStore`: in memory up
to ``max_in_memory`` motions and ``max_memory_mb`` MB (older ones are evicted to
``<store_dir>/<id>.npz``, where every motion is saved), and the ids are announced on the
latched topic ``motion_catalog`` (ltl_human_motion/msg/MotionCatalog). ``store_dir`` ""
(the default) is ``$ROS_HOME/ltl_human_motion/motions`` (``~/.ros/...``); ``:memory:``
keeps motions in memory only (evicted ones are gone).

Parameters: ``default_cell`` (str, "paper_cell"; used when a request leaves ``cell``
empty), ``store_dir`` (str, ""; read only), ``max_concurrent`` (int, 4; read only),
``max_queued`` (int, 64; read only), ``max_in_memory`` (int, 32; read only),
``max_memory_mb`` (float, 256; read only), ``autostart`` (bool, true; read only),
``preload_library`` (bool, false; read only).

A lifecycle (managed) node, so that commissioning tools can bring it up in order: with
``autostart`` (the default) it configures and activates itself at once; with
``autostart: false`` it waits for ``<node>/change_state``. *Configure* loads the default
cell (and, with ``preload_library``, the motion library of the default stature, so the
first request does not wait for it); a cell that does not load fails the transition,
naming the cell. *Activate* starts serving and announcing the catalog; while not active
the service answers every request with ``success: false``, "not active". *Deactivate*
and *cleanup* go back.
"""

from __future__ import annotations

import json
import math
import queue
import threading
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import rclpy.logging
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.impl.rcutils_logger import RcutilsLogger
from rclpy.lifecycle import LifecycleNode, LifecycleState, TransitionCallbackReturn
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy

if TYPE_CHECKING:
    from ltl_human_motion.planning.pipeline import SynthesisOptions
    from ltl_human_motion.planning.result import SynthesisStats, SynthesizedMotion
    from ltl_human_motion.planning.strategy_motion import StrategyProgram

from ltl_human_motion.deadline import DEFAULT_MAX_SECONDS, Deadline
from ltl_human_motion.errors import LtlHumanMotionError, SpecError
from ltl_human_motion.ltl.limits import MAX_SPEC_CHARS
from ltl_human_motion.motion.library import MAX_LIBRARY_STATURE, MIN_LIBRARY_STATURE
from ltl_human_motion.msg import MotionCatalog, PlanningStats
from ltl_human_motion.planning.motion_store import MotionStore, default_store_dir
from ltl_human_motion.planning.playback import task_sequence_text
from ltl_human_motion.ros.common import LATCHED_QOS, resolve_cell
from ltl_human_motion.ros.diagnostics import OK, WARN, Status, attach_diagnostics
from ltl_human_motion.ros.params import ParamSpec, declare_parameters, positive
from ltl_human_motion.ros.reactive_player import strategy_path
from ltl_human_motion.srv import SynthesizeMotion

SynthesizeFn = Callable[..., list]

#: Limits of one request, each refused with its name (issue 17: ``variants=4294967295``
#: grew the node to 11 GB). A motion is about 1 MB, so 16 variants stay near 16 MB.
MAX_VARIANTS = 16
#: Repetitions of the accepting cycle; each adds a full pass of the task sequence.
MAX_CYCLES = 8
#: Characters of ``options_json`` (its keys and values fit in a few hundred).
MAX_OPTIONS_CHARS = 4096
#: Characters of an inline cell; the shipped cells are under 10 kB.
MAX_INLINE_CELL_CHARS = 1_000_000
#: Strategies kept in memory for players in the same process (older ones stay on disk).
MAX_PROGRAMS_IN_MEMORY = 16
#: Depth of the service's DDS request history (the default of 10 overwrote requests).
SERVICE_HISTORY_DEPTH = 1000

_STATS_FIELDS = ("automaton_time", "sequence_time", "planning_time", "blending_time",
                 "verification_time", "total_time", "real_time_factor")


def planning_synthesize(spec: str, cell: Any, **kwargs: Any) -> list[SynthesizedMotion]:
    """:func:`ltl_human_motion.planning.pipeline.synthesize`, imported on the first request
    (the planning stack loads trimesh and the compiled kernels)."""
    from ltl_human_motion.planning.pipeline import synthesize

    return list(synthesize(spec, cell, **kwargs))


def synthesis_options(options_json: str) -> SynthesisOptions | None:
    """``planning.SynthesisOptions`` from the request's JSON object ("" for defaults)."""
    text = options_json.strip()
    if not text:
        return None
    if len(text) > MAX_OPTIONS_CHARS:
        raise ValueError(f"options_json has {len(text)} characters; at most "
                         f"{MAX_OPTIONS_CHARS} are allowed (MAX_OPTIONS_CHARS)")
    try:
        values = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"options_json is not valid JSON: {exc}") from None
    except RecursionError:
        raise ValueError("options_json nests too deeply; expected a flat JSON object") \
            from None
    if not isinstance(values, dict):
        raise ValueError(f"options_json must be a JSON object, got {type(values).__name__}")
    from ltl_human_motion.planning.pipeline import SynthesisOptions

    return SynthesisOptions.from_dict(values)


def stats_message(stats: SynthesisStats, duration: float) -> PlanningStats:
    """PlanningStats from a motion's ``stats`` (:attr:`SynthesizedMotion.stats`;
    non-numeric fields are 0)."""
    msg = PlanningStats()
    for name in _STATS_FIELDS:
        value = getattr(stats, name)
        if isinstance(value, int | float):
            setattr(msg, name, float(value))
    expanded = stats.nodes_expanded
    if isinstance(expanded, int | float):
        msg.nodes_expanded = max(int(expanded), 0)
    if msg.real_time_factor == 0.0 and msg.total_time > 0:
        msg.real_time_factor = duration / msg.total_time
    return msg


@dataclass(eq=False)
class _Job:
    """A queued request: the executor's response object and, once sent, its header."""

    request: Any
    response: Any
    received: float
    header: Any = None
    deadline: Deadline | None = None


class SynthesisNode(LifecycleNode):
    """Serves ``synthesize_motion`` and announces stored motions on ``motion_catalog``.

    Parameters
    ----------
    store : MotionStore, optional
        Share a store with players in the same process; by default one is made from the
        ``store_dir``, ``max_in_memory`` and ``max_memory_mb`` parameters.
    synthesize_fn : callable, optional
        Replaces ``planning.synthesize`` (same signature).
    programs : dict, optional
        Where strategies of reactive specifications are kept by id (pass the same dict to
        a :class:`~ltl_human_motion.ros.reactive_player.ReactivePlayer` in this process).
    """

    def __init__(self, *, store: MotionStore | None = None,
                 synthesize_fn: SynthesizeFn | None = None, node_name: str = "synthesis_node",
                 programs: dict[str, StrategyProgram] | None = None,
                 **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        #: Strategies of reactive specifications by id (share with a ReactivePlayer).
        self.programs: dict[str, StrategyProgram] = programs if programs is not None else {}
        declare_parameters(self, [
            ParamSpec("default_cell", "paper_cell", "Cell used when a request leaves cell empty",
                      lambda v: None if v.strip() else "expected a cell name"),
            ParamSpec("store_dir", "", "Folder for <motion_id>.npz ('' = $ROS_HOME/"
                      "ltl_human_motion/motions, ':memory:' = memory only)", read_only=True),
            ParamSpec("max_concurrent", 4, "Syntheses allowed to run at the same time",
                      positive, read_only=True),
            ParamSpec("max_queued", 64, "Requests allowed to wait for a slot; more are "
                      "refused at once with 'busy'", positive, read_only=True),
            ParamSpec("max_in_memory", 32, "Motions kept in memory (older ones are evicted "
                      "to store_dir)", positive, read_only=True),
            ParamSpec("max_memory_mb", 256.0, "Megabytes of motions kept in memory",
                      positive, read_only=True),
            ParamSpec("autostart", True, "Configure and activate at once (false: wait for "
                      "the lifecycle's change_state)", read_only=True),
            ParamSpec("preload_library", False, "Configure also loads the motion library of "
                      "the default stature", read_only=True),
        ])
        p = self.get_parameter
        store_dir = p("store_dir").value
        if store is None:
            directory = None if store_dir == ":memory:" else (store_dir or default_store_dir())
            store = MotionStore(directory, max_in_memory=int(p("max_in_memory").value),
                                max_bytes=int(float(p("max_memory_mb").value) * 1e6))
        self.store = store
        self._synthesize = synthesize_fn or planning_synthesize
        self.max_queued = int(p("max_queued").value)
        self._queue: queue.Queue[_Job | None] = queue.Queue()
        self._pending: dict[int, _Job] = {}           # id(response) -> job, until sent
        self._running: set[_Job] = set()
        self._jobs_lock = threading.Lock()
        self._stopping = threading.Event()
        self._catalog_lock = threading.Lock()
        self._catalog_pub = self.create_lifecycle_publisher(MotionCatalog, "motion_catalog",
                                                            LATCHED_QOS)
        self._active = False
        qos = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=SERVICE_HISTORY_DEPTH,
                         reliability=ReliabilityPolicy.RELIABLE)
        self._service = self.create_service(SynthesizeMotion, "synthesize_motion",
                                            self._on_request, qos_profile=qos,
                                            callback_group=ReentrantCallbackGroup())
        # The executor sends what the callback returns; a queued request's response is
        # sent by the worker instead, once done (see _deferred_send).
        self._send_now = self._service.send_response
        self._service.send_response = self._deferred_send  # type: ignore[method-assign]
        self.requests_served = 0
        self.requests_refused = 0
        self.in_flight = 0
        self._count_lock = threading.Lock()
        self._workers = [threading.Thread(target=self._work, name=f"synthesis-{i}", daemon=True)
                         for i in range(int(p("max_concurrent").value))]
        for worker in self._workers:
            worker.start()
        attach_diagnostics(self, self.diagnostics)
        if p("autostart").value:
            self.trigger_configure()
            self.trigger_activate()

    # ------------------------------------------------------------------ lifecycle
    def on_configure(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Load the default cell (and the library with ``preload_library``)."""
        cell = self.get_parameter("default_cell").value
        try:
            resolve_cell(cell)
            if self.get_parameter("preload_library").value:
                from ltl_human_motion.planning.pipeline import get_library
                get_library()
        except Exception as exc:   # any failure to load: the transition fails, named
            self.get_logger().error(f"configure failed: default_cell {cell!r}: "
                                    f"{type(exc).__name__}: {exc}")
            return TransitionCallbackReturn.FAILURE
        return super().on_configure(state)

    def on_activate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Serve requests and announce the catalog."""
        result = super().on_activate(state)
        self._active = True
        self._publish_catalog()
        where = self.store.directory or "memory only"
        self.get_logger().info(
            f"serving {self._service.service_name}; motions stored in {where} (in memory: "
            f"{self.store.max_in_memory} motions, {self.store.max_bytes / 1e6:g} MB)")
        return result

    def on_deactivate(self, state: LifecycleState) -> TransitionCallbackReturn:
        """Refuse new requests ("not active"); those queued or running still finish."""
        self._active = False
        return super().on_deactivate(state)

    @property
    def active(self) -> bool:
        """True while the node serves requests (lifecycle state active)."""
        return self._active

    # ------------------------------------------------------------------ requests
    @property
    def queued(self) -> int:
        """Requests waiting for a worker."""
        return self._queue.qsize()

    def diagnostics(self) -> list[Status]:
        """The synthesis queue for ``/diagnostics``: WARN when full (new requests are
        refused as busy)."""
        queued, running = self.queued, len(self._running)
        full = queued >= self.max_queued
        message = f"{queued} queued, {running} running" + (" (full: refusing)" if full else "")
        return [Status("synthesis queue", WARN if full else OK, message, {
            "queued": str(queued), "max_queued": str(self.max_queued),
            "running": str(running), "workers": str(len(self._workers)),
            "served": str(self.requests_served), "refused": str(self.requests_refused)})]

    def _on_request(self, request: SynthesizeMotion.Request,
                    response: SynthesizeMotion.Response) -> SynthesizeMotion.Response:
        """Executor thread: refuse at once (busy, limits) or queue; never synthesize."""
        with self._count_lock:
            self.in_flight += 1
        try:
            if self._stopping.is_set():
                raise _RefusalError("the synthesis node is shutting down")
            if not self._active:
                raise _RefusalError("the synthesis node is not active (lifecycle); "
                                    "activate it with its change_state service")
            _check_limits(request)
            with self._jobs_lock:
                if self._queue.qsize() >= self.max_queued:
                    raise _RefusalError(f"busy: {self._queue.qsize()} requests are waiting "
                                   f"(max_queued {self.max_queued}); try again later")
                self._pending[id(response)] = _Job(request, response, time.perf_counter())
        except (LtlHumanMotionError, ValueError) as exc:
            self._fail(response, exc)
            self._finished(refused=isinstance(exc, _RefusalError))
            self.get_logger().warning(f"synthesis request refused: {exc}",
                                      throttle_duration_sec=1.0)
        return response

    def _deferred_send(self, response: SynthesizeMotion.Response, header: Any) -> None:
        """Executor thread: a queued request's header arrives; hand the job to a worker."""
        with self._jobs_lock:
            job = self._pending.pop(id(response), None)
        if job is None:
            self._send_now(response, header)              # answered by the callback
            return
        job.header = header
        self._queue.put(job)

    def _work(self) -> None:
        while True:
            job = self._queue.get()
            if job is None:
                return
            if self._stopping.is_set():
                self._fail(job.response, _RefusalError("the synthesis node is shutting down"))
            else:
                self._serve(job)
            self._reply(job)

    def _worker_logger(self) -> RcutilsLogger:
        """The node's logger; once the node is stopping (Ctrl-C cancels the syntheses under
        way), one of another name that only prints: the context and its rosout publisher
        are gone by then ("Failed to publish log message to rosout")."""
        if self._stopping.is_set() or not self.context.ok():
            return rclpy.logging.get_logger(f"{self.get_logger().name}.shutdown")
        return self.get_logger()

    def _serve(self, job: _Job) -> None:
        response = job.response
        job.deadline = Deadline(_max_seconds(job.request.options_json))
        with self._jobs_lock:
            self._running.add(job)
        try:
            program = self._run_reactive(job.request, job.deadline)
            if program is not None:
                self._fill_strategy(response, program)
                self._worker_logger().info(
                    f"synthesized strategy {program.strategy_id} ({len(program.clips)} "
                    f"verified moves) in {time.perf_counter() - job.received:.2f} s")
                return
            motions, cell = self._run(job.request, job.deadline)
            self._fill(response, motions)
            self._fill_ergonomics(response, motions, cell, int(job.request.cycles) or 1)
            self._worker_logger().info(
                f"synthesized {len(motions)} motion(s) in "
                f"{time.perf_counter() - job.received:.2f} s: {', '.join(response.motion_ids)}")
        except (LtlHumanMotionError, ValueError) as exc:
            self._fail(response, exc)
            self._worker_logger().warning(f"synthesis request rejected: {exc}")
        except RecursionError:
            self._fail(response, ValueError("the request nests too deeply to be read"))
            self._worker_logger().warning("synthesis request rejected: nested too deeply")
        except Exception as exc:   # keep serving; report the failure to the caller
            self._worker_logger().error(
                f"synthesis failed unexpectedly: {exc!r}\n{traceback.format_exc()}")
            response.success = False
            response.error_message = f"internal error ({type(exc).__name__}): {exc}"
        finally:
            with self._jobs_lock:
                self._running.discard(job)

    def _reply(self, job: _Job) -> None:
        try:
            self._send_now(job.response, job.header)
        except Exception as exc:   # a destroyed service or a gone client
            self._worker_logger().warning(f"cannot send a synthesis response: {exc}")
        self._finished(refused=False)

    def _finished(self, refused: bool) -> None:
        with self._count_lock:
            self.in_flight -= 1
            self.requests_served += 1
            self.requests_refused += int(refused)

    def _run(self, request: SynthesizeMotion.Request, deadline: Deadline) -> tuple[list, Any]:
        spec = request.spec
        if not spec.strip():
            raise SpecError("the specification is empty")
        cell_text = request.cell.strip() or self.get_parameter("default_cell").value
        cell = resolve_cell(cell_text)
        deadline.check("reading the cell")
        kwargs: dict[str, Any] = {
            "variants": int(request.variants) or 1,
            "seed": int(request.seed),
            "cycles": int(request.cycles) or 1,
            "stature": float(request.stature) or 1.75,
        }
        options = synthesis_options(request.options_json)
        if options is None:
            from ltl_human_motion.planning.pipeline import SynthesisOptions
            options = SynthesisOptions()
        kwargs["options"] = replace(options, deadline=deadline)
        motions = list(self._synthesize(spec, cell, **kwargs))
        if not motions:
            raise ValueError("synthesis returned no motion")
        return motions, cell

    def _run_reactive(self, request: SynthesizeMotion.Request, deadline: Deadline
                      ) -> StrategyProgram | None:
        """The strategy of a reactive specification (one that reads inputs), with a
        verified motion per move; None for a plain specification."""
        from ltl_human_motion.ltl.spec import build_specification

        spec = request.spec
        if not spec.strip():
            return None
        cell_text = request.cell.strip() or self.get_parameter("default_cell").value
        cell = resolve_cell(cell_text)
        try:
            if not build_specification(spec, cell, reactive=True).inputs:
                return None
        except SpecError:
            return None                 # reported by the plain path, as before
        from ltl_human_motion.planning.pipeline import SynthesisOptions, get_library
        from ltl_human_motion.planning.strategy_motion import build_program, save_program

        options = synthesis_options(request.options_json) or SynthesisOptions()
        stature = float(request.stature) or 1.75
        program = build_program(spec, cell_text, cell, get_library(stature),
                                seed=int(request.seed), stature=stature,
                                options=replace(options, deadline=deadline))
        if self.store.directory is not None:
            save_program(program, strategy_path(self.store.directory, program.strategy_id))
        with self._catalog_lock:
            self.programs[program.strategy_id] = program
            while len(self.programs) > MAX_PROGRAMS_IN_MEMORY:
                self.programs.pop(next(iter(self.programs)))
        return program

    @staticmethod
    def _fill_strategy(response: SynthesizeMotion.Response, program: StrategyProgram) -> None:
        response.strategy_id = program.strategy_id
        response.task_sequences.append(" ; ".join(t.key for t in program.worker.tasks))
        response.success = True

    def _fill(self, response: SynthesizeMotion.Response, motions: list[SynthesizedMotion]) -> None:
        for motion in motions:
            motion_id = self.store.add(motion)
            duration = float(motion.motion.duration)
            response.motion_ids.append(motion_id)
            response.task_sequences.append(task_sequence_text(motion))
            response.durations.append(duration)
            response.stats.append(stats_message(motion.stats, duration))
        response.success = True
        self._publish_catalog()

    def destroy_node(self) -> None:
        """Cancel running syntheses, answer queued requests ("shutting down"), stop."""
        self._stopping.set()
        with self._jobs_lock:
            for job in self._running:
                if job.deadline is not None:
                    job.deadline.cancel("cancelled: the synthesis node is shutting down")
        for _ in self._workers:
            self._queue.put(None)
        end = time.monotonic() + SHUTDOWN_WAIT
        for worker in self._workers:
            worker.join(max(end - time.monotonic(), 0.0))
        super().destroy_node()

    @staticmethod
    def _fill_ergonomics(response: SynthesizeMotion.Response,
                         motions: list[SynthesizedMotion], cell: Any, cycles: int) -> None:
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
        if isinstance(exc, SpecError):
            response.error_line = exc.line or 0
            response.error_column = exc.column or 0

    def _publish_catalog(self) -> None:
        if not self._active:
            return                   # announced when activated
        with self._catalog_lock:
            msg = MotionCatalog()
            msg.header.stamp = self.get_clock().now().to_msg()
            for info in self.store.infos():
                msg.motion_ids.append(info.motion_id)
                msg.task_sequences.append(info.task_sequence)
                msg.durations.append(info.duration)
            msg.store_dir = str(self.store.directory or "")
            try:
                self._catalog_pub.publish(msg)
            except Exception:      # rclpy's RCLError: the context is gone
                if self.context.ok() and not self._stopping.is_set():
                    raise
                # a synthesis that finished as the node shut down (SIGINT): nobody is
                # left to tell, and its answer goes out (or is dropped) as any other's


#: Seconds destroy_node waits for the workers (issue 17: exit within 2 s of SIGINT); a
#: synthesis stage without checkpoints may outlast it, and its daemon thread then dies
#: with the process.
SHUTDOWN_WAIT = 1.0


class _RefusalError(ValueError):
    """A request refused before any work: busy, or the node shutting down."""


def _max_seconds(options_json: str) -> float:
    """The request's time budget: ``max_seconds`` of ``options_json``, else the default."""
    try:
        value = json.loads(options_json).get("max_seconds") if options_json.strip() else None
    except (ValueError, AttributeError, RecursionError):
        value = None          # the options are reported properly by synthesis_options
    if isinstance(value, int | float) and not isinstance(value, bool) and value > 0 \
            and math.isfinite(value):
        return float(value)
    return DEFAULT_MAX_SECONDS


def _check_limits(request: Any) -> None:
    """Refuse a request beyond the named limits (ValueError naming the limit)."""
    def refuse(what: str, value: object, limit: str, bound: object) -> None:
        raise ValueError(f"{what} {value} exceeds {limit} = {bound}")

    if not 0 <= request.variants <= MAX_VARIANTS:
        refuse("variants", request.variants, "MAX_VARIANTS", MAX_VARIANTS)
    if not 0 <= request.cycles <= MAX_CYCLES:
        refuse("cycles", request.cycles, "MAX_CYCLES", MAX_CYCLES)
    if len(request.spec) > MAX_SPEC_CHARS:
        refuse("a specification of", f"{len(request.spec)} characters", "MAX_SPEC_CHARS",
               MAX_SPEC_CHARS)
    if len(request.cell) > MAX_INLINE_CELL_CHARS:
        refuse("a cell of", f"{len(request.cell)} characters", "MAX_INLINE_CELL_CHARS",
               MAX_INLINE_CELL_CHARS)
    if len(request.options_json) > MAX_OPTIONS_CHARS:
        refuse("options_json of", f"{len(request.options_json)} characters",
               "MAX_OPTIONS_CHARS", MAX_OPTIONS_CHARS)
    stature = float(request.stature)
    if stature != 0.0 and not (math.isfinite(stature) and
                               MIN_LIBRARY_STATURE <= stature <= MAX_LIBRARY_STATURE):
        raise ValueError(f"stature {stature} m is outside [{MIN_LIBRARY_STATURE}, "
                         f"{MAX_LIBRARY_STATURE}] m (MIN/MAX_LIBRARY_STATURE; 0 = 1.75 m)")
