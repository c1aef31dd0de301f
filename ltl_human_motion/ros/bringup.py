"""Start a whole node set in one process (one multi-threaded executor), optionally recording.

``Bringup`` reads a bringup file
(:mod:`~ltl_human_motion.ros.launch_support.bringup_config`), hands it to its rclpy
context as ``--params-file`` (as ``ros2 launch`` does for each node), and
creates the nodes it lists. In one process the nodes share state instead of copying it:
the synthesis node's :class:`MotionStore` is the players' store, and each human's skeleton
publisher and occupancy node share one :class:`Playback` clock.
"""

from __future__ import annotations

import gc
import sys
import threading
import time
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.node import Node
from rclpy.parameter import Parameter

from ltl_human_motion.planning.motion_store import MotionStore
from ltl_human_motion.planning.playback import Playback
from ltl_human_motion.ros.common import SpinThread
from ltl_human_motion.ros.launch_support.bringup_config import (
    BringupConfig,
    NodeSpec,
    check_namespace,
    load_bringup_config,
    namespace_overrides,
    node_namespace,
)
from ltl_human_motion.ros.launch_support.middleware import apply_middleware_defaults
from ltl_human_motion.ros.occupancy_node import STREAM_SWITCH_INTERVAL, OccupancyNode
from ltl_human_motion.ros.recorder import Recorder
from ltl_human_motion.ros.skeleton_publisher import SkeletonPublisher
from ltl_human_motion.ros.synthesis_node import SynthesisNode


class Bringup:
    """The nodes of one bringup file, created in one rclpy context.

    Parameters
    ----------
    config : BringupConfig or path, optional
        Default ``config/bringup.yaml``.
    record : path, optional
        Write the node set's topics to this MCAP file (closed by :meth:`shutdown`).
    overrides : mapping, optional
        Parameters given to every node on top of the file (e.g. ``{"store_dir": ...}``).
    synthesize_fn : callable, optional
        Replaces ``planning.synthesize`` in the synthesis node.
    context : rclpy Context, optional
        An initialized context to use; by default the bringup makes and owns one.
    namespace : str, optional
        Run the node set under this namespace ('' = none), as the launch argument
        ``namespace:=`` does: its own catalog and marker topics move with it
        (:func:`~ltl_human_motion.ros.launch_support.bringup_config.namespace_overrides`); TF,
        ``/humans/...``, ``/joint_states`` and ``/diagnostics`` stay global.
    use_sim_time : bool, optional
        Every node on ``/clock`` (True) or the system clock (False), as the launch argument
        ``use_sim_time:=``; None keeps the file's value.
    """

    def __init__(self, config: BringupConfig | str | Path | None = None, *,
                 record: str | Path | None = None, overrides: Mapping[str, Any] | None = None,
                 synthesize_fn: Callable[..., list] | None = None,
                 context: Context | None = None, namespace: str = "",
                 use_sim_time: bool | None = None) -> None:
        self.config = config if isinstance(config, BringupConfig) \
            else load_bringup_config(config)
        self.namespace = check_namespace(namespace, "bringup namespace")
        self.use_sim_time = use_sim_time
        self._owns_context = context is None
        if context is None:
            apply_middleware_defaults()
            context = Context()
            rclpy.init(args=self.config.ros_args(), context=context)
        self.context = context
        self.overrides = dict(overrides or {})
        self.nodes: list[Node] = []
        self.playbacks: dict[str, Any] = {}      # per human: a Playback or a player's view
        self.store: MotionStore | None = None
        self.recorder: Recorder | None = None
        self._spinner: SpinThread | None = None
        self._record_spinner: SpinThread | None = None
        self._shut_down = False
        self._stop = threading.Event()
        self.mcap_path: Path | None = None
        try:
            if record is not None:
                # First, so it joins before the others publish anything; it subscribes
                # each topic once its publisher exists, with the QoS that one offers.
                self.recorder = Recorder(record, context=context)
            for spec in self.config.node_specs():
                self.nodes.append(self._make(spec, synthesize_fn))
            if self.recorder is not None:
                self.recorder.follow(self.config.topics(self.namespace))
            if any(isinstance(n, OccupancyNode) for n in self.nodes):
                # The occupancy stream thread waits less for the GIL, and what exists now
                # stays out of the collector's full passes (which hold the GIL).
                sys.setswitchinterval(min(sys.getswitchinterval(), STREAM_SWITCH_INTERVAL))
                gc.freeze()
        except BaseException:
            self.shutdown()
            raise

    def _kwargs(self, spec: NodeSpec) -> dict[str, Any]:
        values = {**namespace_overrides(self.config, spec, self.namespace), **self.overrides,
                  **spec.parameters}
        if self.use_sim_time is not None:
            values["use_sim_time"] = bool(self.use_sim_time)
        return {"namespace": node_namespace(self.namespace, spec) or None,
                "context": self.context,
                "parameter_overrides": [Parameter(k, value=v) for k, v in values.items()]}

    def _make(self, spec: NodeSpec, synthesize_fn: Callable[..., list] | None) -> Node:
        kwargs = self._kwargs(spec)
        if spec.executable == "synthesis_node":
            node = SynthesisNode(synthesize_fn=synthesize_fn, node_name=spec.name, **kwargs)
            self.store = node.store
            return node
        if spec.executable == "coexistence_node":
            from ltl_human_motion.ros.coexistence_node import (
                CONTROL_SWITCH_INTERVAL,
                CoexistenceNode,
            )

            sys.setswitchinterval(CONTROL_SWITCH_INTERVAL)   # its 125 Hz loop shares the GIL
            return CoexistenceNode(node_name=spec.name, **kwargs)
        human = spec.parameters["human_id"]
        if spec.executable == "reactive_player":
            from ltl_human_motion.ros.reactive_player import ReactivePlayer

            synthesis = next((n for n in self.nodes if isinstance(n, SynthesisNode)), None)
            player = ReactivePlayer(programs=synthesis.programs if synthesis else None,
                                    node_name=spec.name, **kwargs)
            self.playbacks[human] = player.view      # its occupancy node follows the strategy
            return player
        playback = self.playbacks.setdefault(human, Playback())
        if spec.executable == "skeleton_publisher":
            return SkeletonPublisher(store=self.store, playback=playback, node_name=spec.name,
                                     **kwargs)
        if spec.executable == "occupancy_node":
            return OccupancyNode(store=self.store, playback=playback, node_name=spec.name,
                                 **kwargs)
        if spec.executable == "ergonomics_node":
            from ltl_human_motion.ros.ergonomics import ErgonomicsNode
            return ErgonomicsNode(store=self.store, playback=playback, node_name=spec.name,
                                  **kwargs)
        raise ValueError(f"unknown node kind {spec.executable!r}")

    def node(self, executable: str, human_id: str | None = None) -> Node:
        """The first node of kind ``executable`` (for human ``human_id``)."""
        for node in self.nodes:
            kind = type(node).__name__
            wanted = {"synthesis_node": "SynthesisNode", "skeleton_publisher":
                      "SkeletonPublisher", "occupancy_node": "OccupancyNode",
                      "ergonomics_node": "ErgonomicsNode",
                      "coexistence_node": "CoexistenceNode",
                      "reactive_player": "ReactivePlayer"}[executable]
            if kind == wanted and (human_id is None
                                   or getattr(node, "human_id", None) == human_id):
                return node
        raise KeyError(f"no {executable} for human {human_id!r} in this bringup")

    @property
    def all_nodes(self) -> list[Node]:
        return ([self.recorder] if self.recorder is not None else []) + self.nodes

    def start(self) -> Bringup:
        """Spin all nodes on a background thread; returns self."""
        if self._spinner is None:
            self._spinner = SpinThread(self.nodes, self.context, self.config.executor_threads)
            if self.recorder is not None:
                self._record_spinner = SpinThread([self.recorder], self.context, 1)
        return self

    def spin(self, duration: float | None = None) -> None:
        """Run until Ctrl-C, SIGTERM, :meth:`request_stop`, context shutdown or
        ``duration`` seconds (blocks this thread; the nodes spin on background threads)."""
        self.start()
        stop_at = None if duration is None else time.monotonic() + duration
        try:
            while self.context.ok() and not self._stop.is_set() and (
                    stop_at is None or time.monotonic() < stop_at):
                self._stop.wait(0.05)
        except KeyboardInterrupt:
            pass

    def request_stop(self, *_: object) -> None:
        """Make :meth:`spin` return (usable as a signal handler)."""
        self._stop.set()

    def shutdown(self) -> Path | None:
        """Stop spinning, close the recording, destroy the nodes; returns the MCAP path.

        Idempotent; ``recorder.summary()`` stays available afterwards.
        """
        if self._shut_down:
            return self.mcap_path
        self._shut_down = True
        for spinner in (self._spinner, self._record_spinner):
            if spinner is not None:
                spinner.stop()
        self._spinner = self._record_spinner = None
        self.mcap_path = self.recorder.close() if self.recorder is not None else None
        for node in self.all_nodes:
            node.destroy_node()
        if self._owns_context:
            rclpy.try_shutdown(context=self.context)
        return self.mcap_path

    def __enter__(self) -> Bringup:
        return self

    def __exit__(self, *exc: object) -> None:
        self.shutdown()
