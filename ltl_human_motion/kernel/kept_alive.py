"""Native objects that must never be destroyed, and how a process ends while they live.

A ur_rtde interface whose controller died or froze aborts the process when it is
destroyed (its destructor writes to the closed socket: std::terminate) or hangs in its
disconnect, so :mod:`ltl_human_motion.robot.coexistence` keeps such an interface alive
(:func:`keep_alive_forever`). Its receive thread still runs then, and the C++ teardown of
the interpreter under it aborted a bringup stopped after its controller froze ("pure
virtual method called", exit -6). Entry points end through :func:`end_if_kept`.
"""

from __future__ import annotations

import ctypes
import logging
import os
import sys

__all__ = ["end_if_kept", "keep_alive_forever"]

_KEPT: list[object] = []


def keep_alive_forever(obj: object) -> None:
    """Never destroy ``obj`` (a reference is held and one more counted)."""
    _KEPT.append(obj)
    ctypes.pythonapi.Py_IncRef(ctypes.py_object(obj))


def end_if_kept(code: int) -> None:
    """End the process now with exit status ``code`` (logs and Python's streams flushed,
    no interpreter teardown) where an object is kept alive; return otherwise."""
    if not _KEPT:
        return
    logging.shutdown()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):
            pass
    os._exit(code)
