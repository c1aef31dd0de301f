"""One simulated UR controller at a time: ur_rtde always connects to TCP 30004.

A second simulated controller on the machine (another test session, demo or benchmark)
would serve, or steal, the first one's clients, so everything that starts one takes a
machine-wide lock and waits for the port to be free.
"""

from __future__ import annotations

import contextlib
import fcntl
import os
import socket
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

__all__ = ["RTDE_PORT", "rtde_port_lock", "wait_port_free"]

RTDE_PORT = 30004


@contextlib.contextmanager
def rtde_port_lock(timeout: float = 120.0) -> Iterator[None]:
    """Hold the machine-wide lock of the simulated controller's port 30004.

    ur_rtde always connects to 30004, so a second simulated controller (another test
    session, demo or benchmark on the machine) would serve, or steal, the first one's
    clients. Everything here that starts one takes this lock (an ``flock`` on a file in
    the temporary folder) for as long as its controller runs. TimeoutError after
    ``timeout`` s.
    """
    path = Path(tempfile.gettempdir()) / f"ltl_human_motion-rtde-{RTDE_PORT}.lock"
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
    try:
        end = time.monotonic() + timeout
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                break
            except BlockingIOError:
                if time.monotonic() > end:
                    raise TimeoutError(f"another simulated UR run holds {path} for over "
                                       f"{timeout:g} s") from None
                time.sleep(0.2)
        yield
    finally:
        os.close(fd)                              # releases the lock


def wait_port_free(host: str = "127.0.0.1", port: int = RTDE_PORT,
                   timeout: float = 60.0) -> None:
    """Wait until nothing listens on ``host:port`` (e.g. another test's simulated UR).

    Raises
    ------
    TimeoutError
        Naming the port, if it stays taken for ``timeout`` s.
    """
    end = time.monotonic() + timeout
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                sock.bind((host, port))
                return
            except OSError:
                pass
        if time.monotonic() > end:
            raise TimeoutError(f"{host}:{port} is still in use after {timeout:g} s (another "
                               f"simulated UR controller?); only one can run at a time")
        time.sleep(0.2)
