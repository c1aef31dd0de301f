"""On-disk layout of a motion dataset, written crash-safely by one process (the driver).

Layout of ``out/`` (docs/datasets.md describes every file and field)::

    dataset.json                    header: format, job fingerprint, specs, seed, count,
                                    shard size, joint and object names; at the end also
                                    ``complete``, counts and the shard checksums
    staging/item-0000000123.npz     one finished item, waiting for its shard
    shards/shard-000001.npz         columnar arrays of items [100, 200)
    shards/shard-000001.json        the shard's records and SHA-256 (commit marker)
    manifest.jsonl                  every record sorted by index (rebuilt at the end)
    .lock                           held by the run writing the folder

Every file is written atomically (temporary file, fsync, rename). An item counts as done
when its staged file or its shard's ``.json`` exists, so a run killed at any point and
started again recomputes only unfinished items. A shard is packed when all its items are
staged: its ``.npz`` is written, then its ``.json`` (the commit), then the staged files are
removed; a crash in between leaves the staged files, from which the shard is rebuilt
(byte-identical: shard files hold no timing data). A complete run removes ``staging/``
and ``.lock``.

Shard arrays (F = total frames of the shard's stored items, n = their number):
``item_index`` (n,) int64, ``frame_offsets`` (n + 1,) int64, ``positions`` (F, J, 3),
``root_yaw`` (F,), ``task_index`` (F,) int16, ``objects`` (F, N, 3), ``task_label``
(F,) int16 and ``phase`` (F,) int8 (version 2). Item ``k`` is rows
``frame_offsets[k]:frame_offsets[k + 1]``. Failed items have records but no rows.

A record holds ``index``, ``status`` (ok | unverified | failed), ``spec_name``, ``spec``,
``ltl``, ``seed``, ``params`` (cycles, stature, object/region offsets), ``sequence``,
``lasso``, ``duration``, ``n_frames``, ``fps``, ``start_pose`` (x, y, yaw),
``nodes_expanded``, ``verified``, ``verification`` (every check), ``realism``,
``motion_sha256``, ``captions``, ``steps``, ``labels_sha256``, ``error`` (type, message,
check, task), ``shard``, ``row``, ``shard_sha256`` and ``timing`` (compute and CPU times,
worker: the only part that differs between runs).
"""

from __future__ import annotations

import contextlib
import errno
import functools
import hashlib
import io
import json
import os
import re
import zipfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from ltl_human_motion.atomic import atomic_write_bytes, atomic_write_text
from ltl_human_motion.batch.specs import BatchConfigError
from ltl_human_motion.batch.worker import STORED_NAMES, ItemResult
from ltl_human_motion.errors import LtlHumanMotionError

__all__ = ["DATASET_FORMAT", "DATASET_VERSION", "BatchOutputError", "DatasetStore",
           "npz_bytes_of", "shard_name"]

DATASET_FORMAT = "ltl_human_motion.motion_dataset"
DATASET_VERSION = 2
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)
_ITEM_FILE = re.compile(r"^item-(\d{10})\.npz$")
_SHARD_JSON = re.compile(r"^shard-(\d{6})\.json$")


class BatchOutputError(LtlHumanMotionError):
    """The dataset folder cannot be written (missing, read-only, disk full); the message
    names the folder and the cause. What was written before stays: a rerun finishes."""


_FULL = (errno.ENOSPC, errno.EDQUOT)
_NOT_WRITABLE = (errno.EROFS, errno.EACCES, errno.EPERM)
_T = TypeVar("_T")


def _output_errors(method: Callable[..., _T]) -> Callable[..., _T]:
    """Turn an OSError of a :class:`DatasetStore` method into a BatchOutputError."""
    @functools.wraps(method)
    def wrapper(self: DatasetStore, *args: Any, **kwargs: Any) -> _T:
        try:
            return method(self, *args, **kwargs)
        except OSError as exc:
            cause = exc.strerror or type(exc).__name__
            if exc.errno in _FULL:
                hint = "; free some space and run the same command again to finish"
            elif exc.errno in _NOT_WRITABLE:
                hint = "; choose a folder you can write to"
            else:
                hint = ""
            raise BatchOutputError(f"cannot write the dataset to {self.root} ({cause}){hint}"
                                   ) from None
    return wrapper


def shard_name(shard: int) -> str:
    """File stem of shard number ``shard``, e.g. ``shard-000003``."""
    return f"shard-{shard:06d}"


def npz_bytes_of(entries: Iterable[tuple[str, np.ndarray]]) -> bytes:
    """A deterministic, uncompressed ``.npz``: fixed entry order and timestamps, no pickles."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", compression=zipfile.ZIP_STORED) as zf:
        for name, arr in entries:
            info = zipfile.ZipInfo(f"{name}.npy", date_time=_ZIP_DATE)
            info.external_attr = 0o644 << 16
            body = io.BytesIO()
            np.lib.format.write_array(body, np.asarray(arr), allow_pickle=False)
            zf.writestr(info, body.getvalue())
    return buf.getvalue()


def _json_line(record: dict[str, Any]) -> str:
    return json.dumps(record, sort_keys=True, allow_nan=False, separators=(",", ":"))


class DatasetStore:
    """Reads and writes the files of one dataset folder (see the module docstring).

    Parameters
    ----------
    root : path-like
        The dataset folder.
    header : dict
        The dataset header (``fingerprint``, ``count``, ``shard_size``, ...). If the folder
        already holds a dataset its fingerprint must match (then the run resumes).

    Raises
    ------
    BatchConfigError
        The folder holds a different dataset, or files that are not a dataset.
    """

    def __init__(self, root: str | os.PathLike[str], header: dict[str, Any]) -> None:
        self.root = Path(root)
        self.header = dict(header)
        self.count = int(header["count"])
        self.shard_size = int(header["shard_size"])
        if self.count < 0 or self.shard_size < 1:
            raise ValueError(f"need count >= 0 and shard_size >= 1, got {self.count}, "
                             f"{self.shard_size}")
        self.staging = self.root / "staging"
        self.shards = self.root / "shards"
        # Items staged by this process, kept until their shard is packed, so packing
        # does not read back what was just written (the files stay for crash recovery).
        self._staged_here: dict[int, tuple[dict, dict, dict[str, np.ndarray] | None]] = {}
        self._open()

    # ------------------------------------------------------------------ set-up
    @property
    def header_path(self) -> Path:
        return self.root / "dataset.json"

    @_output_errors
    def _open(self) -> None:
        if self.header_path.is_file():
            try:
                old = json.loads(self.header_path.read_text(encoding="utf-8"))
            except (OSError, ValueError) as exc:
                raise BatchConfigError(f"{self.header_path}: unreadable dataset header: "
                                       f"{exc}") from exc
            if old.get("fingerprint") != self.header["fingerprint"]:
                diff = sorted(k for k in set(old) | set(self.header)
                              if k not in ("complete", "counts", "shards")
                              and old.get(k) != self.header.get(k))
                raise BatchConfigError(
                    f"{self.root}: holds a different dataset (differs in {', '.join(diff)}); "
                    "resuming needs the same cell, specs, seed, count, shard size and dtype. "
                    "Use another --out folder.")
        elif self.root.exists() and not self._half_started():
            raise BatchConfigError(f"{self.root}: exists, is not empty and is not a dataset "
                                   "(no dataset.json); use an empty or new --out folder")
        # The header first: a run killed during start-up leaves a folder that resumes.
        self.root.mkdir(parents=True, exist_ok=True)
        self._lock()
        if not self.header_path.is_file():
            self._write_header(self.header)
        self.staging.mkdir(parents=True, exist_ok=True)
        self.shards.mkdir(parents=True, exist_ok=True)
        for folder in (self.staging, self.shards, self.root):
            for tmp in folder.glob(".*.tmp"):          # left by a killed atomic write
                tmp.unlink(missing_ok=True)

    def _half_started(self) -> bool:
        """True when the folder holds only what an interrupted start-up leaves: the lock,
        and empty staging and shard folders (or temporary files in them)."""
        for p in self.root.iterdir():
            if p.name in (".gitkeep", ".lock") or (p.is_file() and p.name.endswith(".tmp")):
                continue
            if p in (self.staging, self.shards) and p.is_dir() and all(
                    q.name.endswith(".tmp") for q in p.iterdir()):
                continue
            return False
        return True

    def _lock(self) -> None:
        """Hold an exclusive lock on ``out/.lock`` (released when the process ends).

        A finished run removes the file while it holds the lock; a run that locked the
        removed file (opened just before) sees that the path no longer names it and
        locks the new one instead."""
        import fcntl
        path = self.root / ".lock"
        while True:
            # Held (not a context manager) until close() or the end of the process.
            self._lock_fh = open(path, "a+b")
            try:
                fcntl.flock(self._lock_fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                self._lock_fh.close()
                raise BatchConfigError(f"{self.root}: another batch run is writing to this "
                                       "folder") from None
            try:
                same = os.stat(path).st_ino == os.fstat(self._lock_fh.fileno()).st_ino
            except FileNotFoundError:
                same = False
            if same:
                return
            self._lock_fh.close()

    def close(self) -> None:
        """Release the folder lock; after :meth:`finalize` remove ``.lock`` and the empty
        ``staging/`` folder, so a finished dataset holds only its own files."""
        fh = getattr(self, "_lock_fh", None)
        if fh is not None and not fh.closed:
            if getattr(self, "_finished", False):
                with contextlib.suppress(OSError):
                    self.staging.rmdir()
                with contextlib.suppress(OSError):
                    (self.root / ".lock").unlink()
            fh.close()

    def _write_header(self, header: dict[str, Any]) -> None:
        atomic_write_text(self.header_path, json.dumps(header, sort_keys=True, indent=1)
                          + "\n")

    # ------------------------------------------------------------------ bookkeeping
    @property
    def n_shards(self) -> int:
        return (self.count + self.shard_size - 1) // self.shard_size

    def shard_of(self, index: int) -> int:
        return int(index) // self.shard_size

    def shard_range(self, shard: int) -> range:
        return range(shard * self.shard_size, min((shard + 1) * self.shard_size, self.count))

    def _item_path(self, index: int) -> Path:
        return self.staging / f"item-{int(index):010d}.npz"

    def committed_shards(self) -> set[int]:
        """Shards whose ``.json`` (the commit marker) and ``.npz`` exist."""
        out = set()
        for p in self.shards.iterdir():
            m = _SHARD_JSON.match(p.name)
            if m and p.with_suffix(".npz").is_file() and int(m.group(1)) < self.n_shards:
                out.add(int(m.group(1)))
        return out

    def staged_items(self) -> set[int]:
        out = set()
        for p in self.staging.iterdir():
            m = _ITEM_FILE.match(p.name)
            if m and int(m.group(1)) < self.count:
                out.add(int(m.group(1)))
        return out

    @_output_errors
    def recover(self) -> set[int]:
        """Finish what a killed run left half done; return the indices already done."""
        committed = self.committed_shards()
        staged = self.staged_items()
        for index in sorted(staged):
            if self.shard_of(index) in committed:     # packed, but not yet cleaned up
                self._item_path(index).unlink(missing_ok=True)
        staged = {i for i in staged if self.shard_of(i) not in committed}
        for shard in sorted({self.shard_of(i) for i in staged}):
            if all(i in staged for i in self.shard_range(shard)):
                self.pack(shard)
                committed.add(shard)
        done = {i for s in committed for i in self.shard_range(s)}
        return done | {i for i in staged if self.shard_of(i) not in committed}

    # ------------------------------------------------------------------ writing
    @_output_errors
    def stage(self, result: ItemResult) -> None:
        """Write one finished item atomically."""
        text = json.dumps({"record": result.record, "timing": result.timing}, sort_keys=True,
                          allow_nan=False)
        entries: list[tuple[str, np.ndarray]] = [("meta", np.array(text))]
        if result.arrays is not None:
            entries += [(name, result.arrays[name]) for name in STORED_NAMES]
        atomic_write_bytes(self._item_path(result.index), npz_bytes_of(entries))
        meta = json.loads(text)                 # as a read-back would give it
        self._staged_here[result.index] = (meta["record"], meta["timing"], result.arrays)

    def _read_staged(self, index: int) -> tuple[dict, dict, dict[str, np.ndarray] | None]:
        kept = self._staged_here.pop(index, None)
        if kept is not None:
            return kept
        path = self._item_path(index)
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"].reshape(-1)[0]))
            arrays = ({n: z[n] for n in STORED_NAMES} if "positions" in z.files else None)
        return meta["record"], meta["timing"], arrays

    def shard_complete(self, shard: int, staged: set[int]) -> bool:
        return all(i in staged for i in self.shard_range(shard))

    @_output_errors
    def pack(self, shard: int) -> None:
        """Write shard ``shard`` from its staged items, commit it, remove the staged files."""
        stem = shard_name(shard)
        npz_path = self.shards / f"{stem}.npz"
        records, timings, stored = [], [], []
        for index in self.shard_range(shard):
            record, timing, arrays = self._read_staged(index)
            records.append(record)
            timings.append(timing)
            if arrays is not None:
                stored.append((index, arrays))
        lengths = [a["positions"].shape[0] for _, a in stored]
        offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        entries: list[tuple[str, np.ndarray]] = [
            ("item_index", np.array([i for i, _ in stored], dtype=np.int64)),
            ("frame_offsets", offsets)]
        dtype = np.dtype(self.header["dtype"])
        n_joints = len(self.header["joint_names"])
        n_objects = len(self.header["object_names"])
        empty = {"positions": np.zeros((0, n_joints, 3), dtype),
                 "root_yaw": np.zeros((0,), dtype), "task_index": np.zeros((0,), np.int16),
                 "objects": np.zeros((0, n_objects, 3), dtype),
                 "task_label": np.zeros((0,), np.int16), "phase": np.zeros((0,), np.int8)}
        for name in STORED_NAMES:
            parts = [a[name] for _, a in stored]
            entries.append((name, np.concatenate(parts) if parts else empty[name]))
        data = npz_bytes_of(entries)
        digest = hashlib.sha256(data).hexdigest()
        atomic_write_bytes(npz_path, data)
        rows = {index: row for row, (index, _) in enumerate(stored)}
        rel = f"shards/{stem}.npz"
        for record, timing in zip(records, timings):
            row = rows.get(record["index"])
            record.update({"shard": rel if row is not None else None, "row": row,
                           "shard_sha256": digest if row is not None else None,
                           "timing": timing})
        doc = {"shard": rel, "sha256": digest, "bytes": len(data),
               "first": self.shard_range(shard).start, "stop": self.shard_range(shard).stop,
               "records": records}
        atomic_write_text(self.shards / f"{stem}.json",
                          json.dumps(doc, sort_keys=True, allow_nan=False) + "\n")
        for index in self.shard_range(shard):
            self._item_path(index).unlink(missing_ok=True)

    def shard_records(self, shard: int) -> dict[str, Any]:
        path = self.shards / f"{shard_name(shard)}.json"
        return json.loads(path.read_text(encoding="utf-8"))

    @_output_errors
    def finalize(self) -> dict[str, Any]:
        """Write ``manifest.jsonl`` (sorted by index) and the completed header.

        Returns
        -------
        dict
            Counts per status.
        """
        committed = self.committed_shards()
        missing = [s for s in range(self.n_shards) if s not in committed]
        if missing:
            raise RuntimeError(f"cannot finalize {self.root}: shards {missing[:5]} are not "
                               "complete")
        lines, shards = [], []
        counts = {"ok": 0, "unverified": 0, "failed": 0}
        for s in range(self.n_shards):
            doc = self.shard_records(s)
            shards.append({"file": doc["shard"], "sha256": doc["sha256"],
                           "bytes": doc["bytes"], "first": doc["first"],
                           "stop": doc["stop"]})
            for record in sorted(doc["records"], key=lambda r: r["index"]):
                counts[record["status"]] += 1
                lines.append(_json_line(record))
        atomic_write_text(self.root / "manifest.jsonl", "".join(f"{ln}\n" for ln in lines))
        header = dict(self.header, complete=True, counts=counts, shards=shards)
        self._write_header(header)
        self._finished = True
        return counts
