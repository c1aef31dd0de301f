"""Record topics to an MCAP file in rosbag2's layout (readable by ``ros2 bag`` and Foxglove).

The :class:`Recorder` node subscribes generically (``raw=True``: the serialized CDR bytes
as they arrive) to a given set of topics and to every topic it discovers later, except
``exclude``. Each topic becomes an MCAP channel (``message_encoding="cdr"``, with
rosbag2's ``offered_qos_profiles`` metadata: the profiles its publishers offer, as
``ros2 bag record`` writes them) whose schema is the full ``ros2msg`` definition from
:mod:`ltl_human_motion.ros.msgdefs`. A topic is subscribed once it has a publisher, with
the QoS its publishers offer (rosbag2's rule: reliable if all are, transient local if all
are), so a latched topic (``/tf_static``, a body's URDF) is recorded with its last message
even if that was published before the recorder joined, and replays latched.

The file is written to a temporary file beside the target and renamed onto it by
:meth:`Recorder.close`; an interrupted run never leaves a truncated ``.mcap`` behind.
"""

from __future__ import annotations

import contextlib
import importlib
import threading
import time
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from mcap.writer import CompressionType, Writer
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.topic_endpoint_info import TopicEndpointInfo

from ltl_human_motion.atomic import atomic_path
from ltl_human_motion.ros.msgdefs import message_definition

DEFAULT_EXCLUDE = ("/rosout", "/parameter_events")


def message_class(full_type: str) -> Any:
    """The Python class of ``pkg/msg/Type``."""
    package, kind, name = full_type.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def _duration_yaml(name: str, duration: Duration) -> str:
    sec, nsec = divmod(int(duration.nanoseconds), 1_000_000_000)
    return f"  {name}:\n    sec: {sec}\n    nsec: {nsec}\n"


def qos_yaml(profiles: Iterable[QoSProfile]) -> str:
    """rosbag2's ``offered_qos_profiles`` metadata: a YAML list of publisher profiles."""
    out = []
    for q in profiles:
        out.append(
            f"- history: {q.history.short_key}\n  depth: {int(q.depth)}\n"
            f"  reliability: {q.reliability.short_key}\n"
            f"  durability: {q.durability.short_key}\n"
            + _duration_yaml("deadline", q.deadline) + _duration_yaml("lifespan", q.lifespan)
            + f"  liveliness: {q.liveliness.short_key}\n"
            + _duration_yaml("liveliness_lease_duration", q.liveliness_lease_duration)
            + f"  avoid_ros_namespace_conventions: "
              f"{str(bool(q.avoid_ros_namespace_conventions)).lower()}\n")
    return "".join(out)


def subscription_qos(offered: Iterable[QoSProfile], depth: int = 100) -> QoSProfile:
    """The profile that receives what every offered profile sends (``ros2 bag record``'s
    rule): reliable if all publishers are, transient local if all are (else best effort,
    volatile), keep last ``depth``."""
    offered = list(offered)
    reliable = bool(offered) and all(q.reliability == ReliabilityPolicy.RELIABLE
                                     for q in offered)
    latched = bool(offered) and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL
                                    for q in offered)
    return QoSProfile(depth=depth, history=HistoryPolicy.KEEP_LAST,
                      reliability=ReliabilityPolicy.RELIABLE if reliable
                      else ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if latched
                      else DurabilityPolicy.VOLATILE)


class Recorder(Node):
    """Writes the messages of a set of topics to ``path`` (MCAP, rosbag2 layout).

    Parameters
    ----------
    path : path
        The ``.mcap`` file to write (folders are created).
    topics : mapping of str to str, optional
        Topics to record, name -> type (``pkg/msg/Type``): each is subscribed as soon as
        it has a publisher (at once if it has one now), with that publisher's QoS.
    discover : bool
        Also record every topic that appears later (polled every ``discovery_period`` s).
    exclude : iterable of str
        Topics never recorded.
    """

    def __init__(self, path: str | Path, *, topics: Mapping[str, str] | None = None,
                 discover: bool = True, exclude: Iterable[str] = DEFAULT_EXCLUDE,
                 discovery_period: float = 0.5, node_name: str = "recorder",
                 **node_kwargs: Any) -> None:
        super().__init__(node_name, **node_kwargs)
        self.path = Path(path)
        self._exclude = set(exclude)
        self._lock = threading.Lock()
        self._stack = contextlib.ExitStack()
        tmp = self._stack.enter_context(atomic_path(self.path))
        self._file = self._stack.enter_context(open(tmp, "wb"))
        self._writer = Writer(self._file, compression=CompressionType.ZSTD)
        self._writer.start(profile="ros2", library="ltl_human_motion recorder")
        self._channels: dict[str, int] = {}
        self._schemas: dict[str, int] = {}
        self._recorded_subs: dict[str, Any] = {}
        self.counts: dict[str, int] = {}
        self.first_ns: dict[str, int] = {}
        self.last_ns: dict[str, int] = {}
        self._closed = False
        self._group = MutuallyExclusiveCallbackGroup()
        self._discover_all = discover
        self._pending: dict[str, str] = {}
        self.follow(topics or {})
        self._discovery = self.create_timer(discovery_period, self._discover,
                                            callback_group=self._group)

    def follow(self, topics: Mapping[str, str]) -> None:
        """Record ``topics`` (name -> type): those with a publisher now at once, the others
        when one appears."""
        for name, type_name in topics.items():
            if name not in self._recorded_subs and name not in self._exclude:
                self._pending[name] = type_name
        self._subscribe_published(list(self._pending.items()))

    def _discover(self) -> None:
        found = list(self._pending.items())
        if self._discover_all:
            found += [(name, types[0]) for name, types in self.get_topic_names_and_types()
                      if types and name not in self._pending]
        self._subscribe_published(found)

    def _subscribe_published(self, topics: list[tuple[str, str]]) -> None:
        for name, type_name in topics:
            if name in self._recorded_subs or name in self._exclude:
                continue
            infos = self.get_publishers_info_by_topic(name)
            if not infos:
                continue
            self._pending.pop(name, None)
            try:
                self._subscribe(name, type_name, infos)
            except (ImportError, AttributeError, FileNotFoundError, ValueError) as exc:
                self._exclude.add(name)
                self.get_logger().warning(f"not recording {name} ({type_name}): {exc}")

    def _subscribe(self, topic: str, type_name: str, publishers: list[TopicEndpointInfo]
                   ) -> None:
        offered = [i.qos_profile for i in publishers]
        msg_class = message_class(type_name)
        with self._lock:
            if self._closed or topic in self._recorded_subs:
                return
            schema_id = self._schemas.get(type_name)
            if schema_id is None:
                schema_id = self._writer.register_schema(
                    name=type_name, encoding="ros2msg",
                    data=message_definition(type_name).encode("utf-8"))
                self._schemas[type_name] = schema_id
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="cdr", schema_id=schema_id,
                metadata={"offered_qos_profiles": qos_yaml(offered)})
            self.counts[topic] = 0
        self._recorded_subs[topic] = self.create_subscription(
            msg_class, topic, lambda data, t=topic: self._on_message(t, data),
            subscription_qos(offered), raw=True, callback_group=self._group)

    def _on_message(self, topic: str, data: bytes) -> None:
        stamp = time.time_ns()
        with self._lock:
            if self._closed:
                return
            seq = self.counts[topic]
            self._writer.add_message(channel_id=self._channels[topic], log_time=stamp,
                                     data=data, publish_time=stamp, sequence=seq)
            self.counts[topic] = seq + 1
            self.first_ns.setdefault(topic, stamp)
            self.last_ns[topic] = stamp

    def summary(self) -> dict[str, dict[str, float]]:
        """Per topic: message count and mean rate (Hz) over the recorded span."""
        with self._lock:
            out = {}
            for topic, n in sorted(self.counts.items()):
                span = (self.last_ns.get(topic, 0) - self.first_ns.get(topic, 0)) * 1e-9
                out[topic] = {"count": n, "rate_hz": (n - 1) / span if n > 1 and span > 0
                              else 0.0}
            return out

    def close(self) -> Path:
        """Finish the MCAP file and move it onto ``path``; returns ``path``."""
        with self._lock:
            if self._closed:
                return self.path
            self._closed = True
            self._discovery.cancel()
            self._writer.finish()
        self._stack.close()
        return self.path

    def abort(self) -> None:
        """Drop the partial recording (the target path is left untouched)."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
        try:
            raise RuntimeError("recording aborted")
        except RuntimeError as exc:
            self._stack.__exit__(type(exc), exc, exc.__traceback__)
