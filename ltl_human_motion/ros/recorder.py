"""Record topics to an MCAP file in rosbag2's layout (readable by ``ros2 bag`` and Foxglove).

The :class:`Recorder` node subscribes generically (``raw=True``: the serialized CDR bytes
as they arrive) to a given set of topics and to every topic it discovers later, except
``exclude``. Each topic becomes an MCAP channel (``message_encoding="cdr"``, with
rosbag2's ``offered_qos_profiles`` metadata) whose schema is the full ``ros2msg``
definition from :mod:`ltl_human_motion.ros.msgdefs`. Latched topics (transient-local
publishers, e.g. ``/tf_static``) are subscribed transient-local, so their last message is
recorded even if it was published before the recorder joined.

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
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile

from ltl_human_motion.atomic import atomic_path
from ltl_human_motion.ros.common import LATCHED_QOS, TF_QOS
from ltl_human_motion.ros.msgdefs import message_definition

DEFAULT_EXCLUDE = ("/rosout", "/parameter_events")


def message_class(full_type: str) -> Any:
    """The Python class of ``pkg/msg/Type``."""
    package, kind, name = full_type.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def qos_yaml(latched: bool) -> str:
    """rosbag2's ``offered_qos_profiles`` metadata for one publisher profile."""
    durability = "transient_local" if latched else "volatile"
    depth = 1 if latched else 100
    return (
        f"- history: keep_last\n  depth: {depth}\n  reliability: reliable\n"
        f"  durability: {durability}\n"
        "  deadline:\n    sec: 9223372036\n    nsec: 854775807\n"
        "  lifespan:\n    sec: 9223372036\n    nsec: 854775807\n"
        "  liveliness: automatic\n"
        "  liveliness_lease_duration:\n    sec: 9223372036\n    nsec: 854775807\n"
        "  avoid_ros_namespace_conventions: false\n")


class Recorder(Node):
    """Writes the messages of a set of topics to ``path`` (MCAP, rosbag2 layout).

    Parameters
    ----------
    path : path
        The ``.mcap`` file to write (folders are created).
    topics : mapping of str to str, optional
        Topics to subscribe at once, name -> type (``pkg/msg/Type``).
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
        for name, type_name in (topics or {}).items():
            self._subscribe(name, type_name, latched=name == "/tf_static"
                            or name.endswith("motion_catalog"))
        self._discovery = (self.create_timer(discovery_period, self._discover,
                                             callback_group=self._group) if discover else None)

    def _discover(self) -> None:
        for name, types in self.get_topic_names_and_types():
            if name in self._recorded_subs or name in self._exclude or not types:
                continue
            infos = self.get_publishers_info_by_topic(name)
            if not infos:
                continue
            latched = any(i.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
                          for i in infos)
            try:
                self._subscribe(name, types[0], latched)
            except (ImportError, AttributeError, FileNotFoundError, ValueError) as exc:
                self._exclude.add(name)
                self.get_logger().warning(f"not recording {name} ({types[0]}): {exc}")

    def _subscribe(self, topic: str, type_name: str, latched: bool) -> None:
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
                metadata={"offered_qos_profiles": qos_yaml(latched)})
            self.counts[topic] = 0
        qos = LATCHED_QOS if latched else QoSProfile(depth=100, reliability=TF_QOS.reliability)
        self._recorded_subs[topic] = self.create_subscription(
            msg_class, topic, lambda data, t=topic: self._on_message(t, data), qos, raw=True,
            callback_group=self._group)

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
            if self._discovery is not None:
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
