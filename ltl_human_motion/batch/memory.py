"""Heap settings of a batch worker process.

A study item allocates and frees tens of arrays of a few megabytes (the positions and
capsules of thousands of frames). With glibc's defaults the freed memory is handed back
to the system and each new array is faulted in (and zeroed) page by page: measured on
the paper cell's study, ~6 % of an item's CPU time. A worker keeps it instead.
"""

from __future__ import annotations

import ctypes
import functools
import sys

__all__ = ["KEEP_FREED_BYTES", "MMAP_THRESHOLD_BYTES", "keep_freed_memory"]

#: Freed heap at the top a worker keeps for reuse (glibc ``M_TRIM_THRESHOLD``), bytes.
KEEP_FREED_BYTES = 256 * 2**20
#: Allocations from this size on are mapped on their own (glibc ``M_MMAP_THRESHOLD``; the
#: largest value it accepts on 64-bit systems). Smaller arrays come from the kept heap.
MMAP_THRESHOLD_BYTES = 32 * 2**20
_M_TRIM_THRESHOLD = -1         # glibc <malloc.h>
_M_MMAP_THRESHOLD = -3


@functools.cache
def keep_freed_memory() -> bool:
    """Keep freed heap memory in this process for reuse (glibc on Linux; elsewhere, e.g.
    musl or macOS, nothing happens). Returns whether the settings took effect."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)) and \
        bool(mallopt(_M_TRIM_THRESHOLD, KEEP_FREED_BYTES))
