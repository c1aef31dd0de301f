"""Probe the robot's RTDE port before ur_rtde connects, so a refusal reaches ROS logging.

Without a robot, ``ur_rtde`` (C++) prints a bare ``connect: Connection refused`` to the
process's stdout/stderr on every attempt, outside ROS logging, without saying which host.
The coexistence node therefore wraps its connection factories: before ur_rtde creates or
reconnects an interface, a TCP connect to ``host:port`` and RTDE's protocol version
request check that the controller answers (then the connection is closed). When it does
not, the node's logger says so with the host and port (throttled), ur_rtde is not called,
and the controller backs off as for any failed attempt. A robot that appears is
connected on the next attempt as before.
"""

from __future__ import annotations

import socket
import struct
from collections.abc import Callable
from typing import Any

#: UR's RTDE port (Universal Robots, "Real-Time Data Exchange (RTDE) Guide", port 30004).
RTDE_PORT = 30004
#: Seconds a probe waits for the TCP handshake (loopback or a cell network answers in ms).
PROBE_TIMEOUT = 1.0


#: RTDE's request-protocol-version package: header (size uint16, type ``V``) and version 2
#: (the RTDE guide's first package of a session; the controller answers at once).
_VERSION_REQUEST = struct.pack(">HBH", 5, ord("V"), 2)


def refusal(host: str, port: int = RTDE_PORT, timeout: float = PROBE_TIMEOUT) -> str:
    """"" when ``host:port`` accepts a TCP connection and answers RTDE's protocol version
    request within ``timeout`` s, else why not (for a log line). A stopped controller
    (process frozen, socket open) accepts the connection in the kernel but never answers:
    ur_rtde's reconnect to it blocked the control loop inside the library, and the
    process that then stopped crashed on exit."""
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            sock.settimeout(timeout)
            sock.sendall(_VERSION_REQUEST)
            if not sock.recv(3):
                return f"robot controller {host}:{port} closed the connection"
            return ""
    except TimeoutError:
        return f"robot controller {host}:{port} does not answer (within {timeout:g} s)"
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        return f"robot controller {host}:{port} not reachable ({reason})"


class _Probed:
    """An RTDE interface whose ``reconnect()`` probes first; everything else passes."""

    def __init__(self, inner: Any, probe: Callable[[], None]) -> None:
        self._inner, self._probe = inner, probe

    def reconnect(self) -> bool:
        self._probe()
        return bool(self._inner.reconnect())

    def __getattr__(self, name: str) -> Any:
        return getattr(self._inner, name)


def probed_factories(factories: tuple[Callable[[], Any], Callable[[], Any]], host: str,
                     report: Callable[[str], None], port: int = RTDE_PORT
                     ) -> tuple[Callable[[], Any], Callable[[], Any]]:
    """``(make_receive, make_io)`` that probe ``host:port`` before ur_rtde connects.

    On a refusal ``report(message)`` is called and ``ConnectionRefusedError`` (an
    ``OSError``, which the controller treats as a failed attempt) is raised.
    """
    def probe() -> None:
        message = refusal(host, port)
        if message:
            report(message)
            raise ConnectionRefusedError(message)

    def wrap(factory: Callable[[], Any]) -> Callable[[], Any]:
        def make() -> Any:
            probe()
            return _Probed(factory(), probe)
        return make

    make_receive, make_io = factories
    return wrap(make_receive), wrap(make_io)
