"""Ctrl-C that no library can swallow.

trimesh imports its optional parts under ``except BaseException``, and other imports may
do the same, so a KeyboardInterrupt raised while they run is lost and the command runs
on (seen: ``ltl-human-motion bringup`` ignoring a Ctrl-C that came during start-up). The
CLI's handler counts the Ctrl-C before it raises, and the CLI checks the count after its
long steps (:func:`check`).
"""

from __future__ import annotations

import signal
from typing import Any

_COUNT = [0]


def _on_sigint(signum: int, frame: Any) -> None:
    _COUNT[0] += 1
    raise KeyboardInterrupt


def install() -> None:
    """Count Ctrl-C from now on (only where SIGINT has Python's default handler: a
    process started with SIGINT ignored, or with a handler of its own, keeps it)."""
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _on_sigint)


def interrupted() -> bool:
    """True once a Ctrl-C came (whether or not its KeyboardInterrupt got through)."""
    return _COUNT[0] > 0


def check() -> None:
    """Raise KeyboardInterrupt if a Ctrl-C came."""
    if interrupted():
        raise KeyboardInterrupt
