"""Synthesized motions keyed by motion id: in memory, optionally also in a folder of npz.

Plain Python (no rclpy). The synthesis node adds motions; players fetch them by id. In
one process they share one :class:`MotionStore`; players in other processes open a store
on the same folder (its path is announced on the ``motion_catalog`` topic) and load
``<motion_id>.npz`` on demand with ``ltl_human_motion.planning.exports.load_npz``. Files
are written atomically by ``save_npz`` (temporary file, then rename), so a reader never
sees half a motion.

Memory is bounded by count (``max_in_memory``) and bytes (``max_bytes``): the oldest
motions leave memory first; with a directory every motion is on disk and an evicted one
is loaded again on demand, without one it is gone (``get`` says so).
"""

from __future__ import annotations

import os
import re
import threading
import uuid
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ltl_human_motion.planning.playback import task_sequence_text

if TYPE_CHECKING:
    from ltl_human_motion.planning.result import SynthesizedMotion

#: Ids of evicted motions remembered for a clear KeyError (bounded, 100 bytes each).
_MAX_EVICTED_IDS = 10_000
_ID_PATTERN = re.compile(r"^[A-Za-z0-9_.-]{1,128}$")


@dataclass(frozen=True)
class MotionInfo:
    """What the catalog says about one motion."""

    motion_id: str
    task_sequence: str
    duration: float


def check_motion_id(motion_id: str) -> str:
    """Return ``motion_id`` if it is a safe file stem, else raise ValueError."""
    if not isinstance(motion_id, str) or not _ID_PATTERN.match(motion_id) \
            or motion_id.startswith("."):
        raise ValueError(
            f"motion id must be 1-128 characters of letters, digits, '_', '-', '.' "
            f"(not starting with '.'), got {motion_id!r}")
    return motion_id


def default_store_dir() -> Path:
    """``$ROS_HOME/ltl_human_motion/motions`` (ROS_HOME defaults to ``~/.ros``)."""
    ros_home = os.environ.get("ROS_HOME") or os.path.join(os.path.expanduser("~"), ".ros")
    return Path(ros_home) / "ltl_human_motion" / "motions"


def motion_nbytes(motion: SynthesizedMotion) -> int:
    """Bytes of the arrays of a motion (positions, yaw, labels, object tracks)."""
    arrays = [motion.motion.positions, motion.root_yaw, motion.task_index,
              *motion.objects.values()]
    return sum(int(np.asarray(a).nbytes) for a in arrays)


def new_motion_id() -> str:
    """A fresh, unique motion id such as ``motion_3f2a9c1b7d4e``."""
    return f"motion_{uuid.uuid4().hex[:12]}"


class MotionStore:
    """Thread-safe store of synthesized motions.

    Parameters
    ----------
    directory : path, optional
        Folder for ``<motion_id>.npz`` files; None keeps motions in memory only.
    max_in_memory : int
        How many motions to keep in memory (oldest are dropped from memory first; with a
        directory they can be loaded again).
    max_bytes : int
        Bytes of motion arrays to keep in memory (the newest motion always stays).
    """

    def __init__(self, directory: str | Path | None = None, max_in_memory: int = 256,
                 max_bytes: int = 512_000_000) -> None:
        if max_in_memory < 1:
            raise ValueError(f"max_in_memory must be >= 1, got {max_in_memory}")
        if max_bytes < 1:
            raise ValueError(f"max_bytes must be >= 1, got {max_bytes}")
        self._lock = threading.Lock()
        self._motions: OrderedDict[str, Any] = OrderedDict()
        self._sizes: dict[str, int] = {}
        self._infos: OrderedDict[str, MotionInfo] = OrderedDict()
        self._evicted: set[str] = set()
        self._max = int(max_in_memory)
        self.max_bytes = int(max_bytes)
        self.bytes_in_memory = 0
        self.directory = Path(directory).expanduser().resolve() if directory else None
        if self.directory is not None:
            self.directory.mkdir(parents=True, exist_ok=True)

    def path_of(self, motion_id: str) -> Path:
        """The npz path of ``motion_id`` (ValueError without a directory)."""
        if self.directory is None:
            raise ValueError("this motion store keeps motions in memory only")
        return self.directory / f"{check_motion_id(motion_id)}.npz"

    def add(self, motion: Any, motion_id: str | None = None) -> str:
        """Store ``motion`` (a SynthesizedMotion); returns its id."""
        motion_id = check_motion_id(motion_id) if motion_id else new_motion_id()
        info = MotionInfo(motion_id, task_sequence_text(motion), float(motion.motion.duration))
        if self.directory is not None:
            from ltl_human_motion.planning.exports import save_npz

            save_npz(motion, self.path_of(motion_id))
        with self._lock:
            self._keep(motion_id, motion)
            self._infos[motion_id] = info
        return motion_id

    @property
    def max_in_memory(self) -> int:
        """How many motions stay in memory."""
        return self._max

    def __len__(self) -> int:
        with self._lock:
            return len(self._motions)

    def _keep(self, motion_id: str, motion: Any) -> None:
        """Hold ``motion`` in memory and evict the oldest beyond the bounds (lock held)."""
        if motion_id in self._motions:
            self.bytes_in_memory -= self._sizes.pop(motion_id, 0)
            del self._motions[motion_id]
        self._motions[motion_id] = motion
        self._sizes[motion_id] = motion_nbytes(motion)
        self.bytes_in_memory += self._sizes[motion_id]
        while len(self._motions) > self._max or (
                self.bytes_in_memory > self.max_bytes and len(self._motions) > 1):
            old, _ = self._motions.popitem(last=False)
            self.bytes_in_memory -= self._sizes.pop(old, 0)
            if self.directory is None:
                self._infos.pop(old, None)
                if len(self._evicted) >= _MAX_EVICTED_IDS:
                    self._evicted.clear()
                self._evicted.add(old)

    def get(self, motion_id: str) -> Any:
        """The motion stored under ``motion_id``; KeyError naming the id if unknown."""
        check_motion_id(motion_id)
        with self._lock:
            motion = self._motions.get(motion_id)
        if motion is not None:
            return motion
        if self.directory is not None and self.path_of(motion_id).is_file():
            from ltl_human_motion.planning.exports import load_npz

            motion = load_npz(self.path_of(motion_id))
            with self._lock:
                self._keep(motion_id, motion)
                self._infos.setdefault(motion_id, MotionInfo(
                    motion_id, task_sequence_text(motion), float(motion.motion.duration)))
            return motion
        if motion_id in self._evicted:
            raise KeyError(f"motion id {motion_id!r} was evicted from memory (this store "
                           f"keeps {self._max} motions and {self.max_bytes / 1e6:g} MB, and "
                           "has no folder to keep older ones in)")
        where = f" or in {self.directory}" if self.directory is not None else ""
        raise KeyError(f"unknown motion id {motion_id!r} (not in memory{where})")

    def __contains__(self, motion_id: object) -> bool:
        if not isinstance(motion_id, str) or not _ID_PATTERN.match(motion_id):
            return False
        with self._lock:
            if motion_id in self._motions:
                return True
        return self.directory is not None and self.path_of(motion_id).is_file()

    def infos(self) -> list[MotionInfo]:
        """Catalog entries of the motions added to (or loaded by) this store, oldest first."""
        with self._lock:
            return list(self._infos.values())

    def ids(self) -> list[str]:
        """Ids known to this store: added or loaded ones, then files in the directory."""
        known = [info.motion_id for info in self.infos()]
        if self.directory is not None:
            seen = set(known)
            files = sorted(self.directory.glob("*.npz"), key=lambda p: p.stat().st_mtime)
            known += [p.stem for p in files if p.stem not in seen and _ID_PATTERN.match(p.stem)]
        return known


class MotionSource:
    """Finds motions by id: the shared store first, then the folder the catalog names."""

    def __init__(self, store: MotionStore | None) -> None:
        self.store = store
        self.remote: MotionStore | None = None
        self.catalog_ids: list[str] = []

    def on_catalog(self, msg: Any) -> list[str]:
        """Take a MotionCatalog message; returns ids not seen before (catalog order)."""
        new = [i for i in msg.motion_ids if i not in self.catalog_ids]
        self.catalog_ids = list(msg.motion_ids)
        folder = msg.store_dir
        if folder and (self.remote is None or str(self.remote.directory) != folder) and (
                self.store is None or str(self.store.directory or "") != folder):
            self.remote = MotionStore(folder)
        return new

    def get(self, motion_id: str) -> Any:
        check_motion_id(motion_id)
        for store in (self.store, self.remote):
            if store is not None and motion_id in store:
                return store.get(motion_id)
        raise KeyError(f"unknown motion id {motion_id!r}; known: "
                       f"{', '.join(self.known()) or 'none yet'}")

    def known(self) -> list[str]:
        ids = list(self.store.ids()) if self.store is not None else []
        return ids + [i for i in self.catalog_ids if i not in ids]
