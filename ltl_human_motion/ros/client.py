"""Client-side helpers: call a service with a bounded wait, and watch topics.

Used by the demo loop, the tests and the benchmark, so the wait/send/spin block is written
once. The node must be spun by an executor on another thread (e.g.
:class:`~ltl_human_motion.ros.common.SpinThread`), since these helpers block.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import rclpy
from rclpy.client import Client
from rclpy.context import Context
from rclpy.node import Node
from rclpy.qos import QoSProfile
from rclpy.serialization import deserialize_message

from ltl_human_motion.ros.common import STREAM_QOS, SpinThread
from ltl_human_motion.ros.launch_support.middleware import apply_middleware_defaults


def call_service(client: Client, request: Any, timeout: float,
                 wait_for_service: float = 10.0, resend_after: float | None = None) -> Any:
    """Send ``request`` and return the response.

    Parameters
    ----------
    resend_after : float, optional
        For idempotent services: send the request again whenever no response has come for
        this many seconds, and take the first response that arrives. A response lost by
        the middleware (a server that had not yet discovered this client drops it) then
        costs this long instead of the whole ``timeout``.

    Raises
    ------
    TimeoutError
        If the service does not appear within ``wait_for_service`` s or does not answer
        within ``timeout`` s (the message names the service).
    """
    if not client.wait_for_service(timeout_sec=wait_for_service):
        raise TimeoutError(f"service {client.service_name} not available after "
                           f"{wait_for_service:g} s")
    done = threading.Event()
    futures = []
    deadline = time.monotonic() + timeout
    try:
        while True:
            future = client.call_async(request)
            future.add_done_callback(lambda _f: done.set())
            futures.append(future)
            remaining = deadline - time.monotonic()
            wait = remaining if resend_after is None else min(remaining, resend_after)
            if done.wait(max(wait, 0.0)):
                return next(f for f in futures if f.done()).result()
            if time.monotonic() >= deadline:
                raise TimeoutError(f"service {client.service_name} did not answer within "
                                   f"{timeout:g} s ({len(futures)} request(s) sent)")
    finally:
        for f in futures:
            if not f.done():
                client.remove_pending_request(f)


def wait_until(predicate: Callable[[], bool], timeout: float, what: str,
               period: float = 0.02) -> None:
    """Poll ``predicate`` until true; TimeoutError naming ``what`` after ``timeout`` s."""
    end = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > end:
            raise TimeoutError(f"timed out after {timeout:g} s waiting for {what}")
        time.sleep(period)


@dataclass
class TopicLog:
    """What one watched topic delivered: receive times and the latest ``keep`` messages.

    Messages are kept serialized and deserialized when read (:attr:`messages`), so
    watching a busy topic costs the watcher little.
    """

    topic: str
    msg_type: Any
    keep: int = 1
    times: list[float] = field(default_factory=list)
    raw: list[bytes] = field(default_factory=list)

    @property
    def count(self) -> int:
        return len(self.times)

    def rate(self, skip: int = 0) -> float:
        """Mean receive rate (Hz) after the first ``skip`` messages."""
        t = self.times[skip:]
        return (len(t) - 1) / (t[-1] - t[0]) if len(t) > 1 and t[-1] > t[0] else 0.0

    @property
    def messages(self) -> list[Any]:
        """The kept messages, oldest first (deserialized now)."""
        return [deserialize_message(data, self.msg_type) for data in list(self.raw)[-self.keep:]]

    @property
    def last(self) -> Any:
        raw = self.raw[-1:] if self.raw else []
        return deserialize_message(raw[0], self.msg_type) if raw else None


class TopicWatcher:
    """Subscribes ``node`` to topics and logs what arrives (thread-safe)."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self.logs: dict[str, TopicLog] = {}
        self._lock = threading.Lock()

    def watch(self, msg_type: Any, topic: str, keep: int = 1,
              qos: QoSProfile = STREAM_QOS) -> TopicLog:
        """Log ``topic``; ``keep`` = how many of the latest messages to keep (0 = count)."""
        log = TopicLog(topic, msg_type, keep=keep)
        self.logs[topic] = log
        self.node.create_subscription(msg_type, topic, lambda m, lg=log: self._on(lg, m), qos,
                                      raw=True)
        return log

    def _on(self, log: TopicLog, data: bytes) -> None:
        with self._lock:
            log.times.append(time.monotonic())
            if log.keep:
                log.raw.append(data)
                if len(log.raw) > 2 * log.keep:
                    del log.raw[:-log.keep]

    def summary(self) -> dict[str, dict[str, float]]:
        with self._lock:
            return {t: {"count": lg.count, "rate_hz": round(lg.rate(), 2)}
                    for t, lg in sorted(self.logs.items())}


class ClientSession:
    """One node in a context of its own, spun on a background thread.

    Its traffic to nodes of other contexts goes through DDS, as from another process.
    Use as a context manager, or call :meth:`close`.
    """

    def __init__(self, name: str = "client") -> None:
        apply_middleware_defaults()
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node(name, context=self.context)
        self.watcher = TopicWatcher(self.node)
        self._clients: dict[tuple[Any, str], Client] = {}
        self._spinner = SpinThread([self.node], self.context, 1)

    def watch(self, msg_type: Any, topic: str, keep: int = 1,
              qos: QoSProfile = STREAM_QOS) -> TopicLog:
        """Log what ``topic`` delivers (see :class:`TopicWatcher`)."""
        return self.watcher.watch(msg_type, topic, keep, qos)

    def _client(self, srv_type: Any, name: str) -> Client:
        key = (srv_type, name)
        if key not in self._clients:
            self._clients[key] = self.node.create_client(srv_type, name)
        return self._clients[key]

    def service_ready(self, srv_type: Any, name: str, wait: float) -> bool:
        """Whether service ``name`` is offered within ``wait`` seconds."""
        return self._client(srv_type, name).wait_for_service(timeout_sec=wait)

    def call(self, srv_type: Any, name: str, request: Any, timeout: float = 10.0,
             resend_after: float | None = None) -> Any:
        """Call service ``name`` (the client is made once per name and type); see
        :func:`call_service` for ``resend_after``."""
        return call_service(self._client(srv_type, name), request, timeout,
                            resend_after=resend_after)

    def close(self) -> None:
        """Stop spinning, destroy the node, shut the context down."""
        self._spinner.stop()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)

    def __enter__(self) -> ClientSession:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
