"""Read a motion dataset written by :func:`~ltl_human_motion.batch.runner.run_batch`.

>>> ds = open_dataset("dataset/")                              # doctest: +SKIP
>>> for item in ds.items(verified_only=True):                  # doctest: +SKIP
...     x = item.positions          # (T, J, 3)
...     tasks = item.record["sequence"]

Every shard's SHA-256 (from the manifest) is checked the first time the shard is read, and
every item's ``motion_sha256`` when the item is read; a mismatch raises
:class:`CorruptDatasetError` naming the file. Shards are read one at a time (the most
recent one is kept), so iterating in index order reads each shard once.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import zipfile
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.batch.store import DATASET_FORMAT, DATASET_VERSION
from ltl_human_motion.batch.worker import (
    ARRAY_NAMES,
    LABEL_NAMES,
    labels_sha256,
    motion_sha256,
)
from ltl_human_motion.errors import MotionFormatError

__all__ = ["CorruptDatasetError", "MotionDataset", "MotionItem", "deterministic_record",
           "open_dataset"]


class CorruptDatasetError(MotionFormatError):
    """A dataset file is missing, unreadable or does not match its checksum."""


def deterministic_record(record: dict[str, Any]) -> dict[str, Any]:
    """``record`` without ``timing`` (the only part that differs between runs)."""
    return {k: v for k, v in record.items() if k != "timing"}


@dataclass
class MotionItem:
    """One stored motion.

    Attributes
    ----------
    record : dict
        Its manifest record (spec, seed, params, sequence, verification, ...).
    positions : ndarray, shape (T, J, 3)
        Joint positions, world frame, z up, metres.
    root_yaw : ndarray, shape (T,)
    task_index : ndarray of int16, shape (T,)
        Task step per frame, -1 while walking between tasks.
    objects : dict of str to ndarray, shape (T, 3)
    task_label : ndarray of int16, shape (T,), or None
        Step of the task sequence each frame works towards (its walk included), -1 after
        the last; None in datasets of version 1.
    phase : ndarray of int8, shape (T,), or None
        Index into the header's ``phases`` (walk, reach, manipulate, transition).
    """

    record: dict[str, Any]
    positions: np.ndarray
    root_yaw: np.ndarray
    task_index: np.ndarray
    objects: dict[str, np.ndarray]
    task_label: np.ndarray | None = None
    phase: np.ndarray | None = None

    @property
    def captions(self) -> list[str]:
        """The canonical caption first, then paraphrases ([] in version 1 datasets)."""
        return list(self.record.get("captions") or [])

    @property
    def ltl(self) -> str:
        """The LTL specification the motion satisfies."""
        return str(self.record.get("ltl") or self.record["spec"])

    @property
    def index(self) -> int:
        return int(self.record["index"])

    @property
    def verified(self) -> bool:
        return bool(self.record["verified"])

    @property
    def fps(self) -> float:
        return float(self.record["fps"])


class MotionDataset:
    """A finished dataset folder (use :func:`open_dataset`).

    Attributes
    ----------
    root : Path
    header : dict
        ``dataset.json``: specs, seed, count, joint and object names, shard checksums.
    records : list of dict
        Every manifest record, sorted by index (failed items included).
    """

    def __init__(self, root: Path, header: dict[str, Any], records: list[dict[str, Any]],
                 verify_checksums: bool = True) -> None:
        self.root = root
        self.header = header
        self.records = records
        self.verify_checksums = verify_checksums
        self.joint_names: list[str] = list(header["joint_names"])
        self.object_names: list[str] = list(header["object_names"])
        self._shard_path: str | None = None
        self._shard: dict[str, np.ndarray] = {}

    def __len__(self) -> int:
        """Number of stored motions (items with arrays)."""
        return sum(1 for r in self.records if r["row"] is not None)

    def __iter__(self) -> Iterator[MotionItem]:
        return self.items(verified_only=False)

    def __repr__(self) -> str:
        counts = self.counts()
        return (f"MotionDataset({str(self.root)!r}, {len(self.records)} items: "
                f"{counts['ok']} verified, {counts['unverified']} unverified, "
                f"{counts['failed']} failed; {len(self)} stored)")

    def counts(self) -> dict[str, int]:
        """Items per status (``ok``, ``unverified``, ``failed``); ``len(self)`` is the
        number stored (ok and unverified), ``len(self.failed())`` the failed ones."""
        out = {"ok": 0, "unverified": 0, "failed": 0}
        for r in self.records:
            out[r["status"]] = out.get(r["status"], 0) + 1
        return out

    def failed(self) -> list[dict[str, Any]]:
        """Records of failed items (with ``error``: type, message, check)."""
        return [r for r in self.records if r["status"] == "failed"]

    def stored_records(self, verified_only: bool = True) -> list[dict[str, Any]]:
        """Records of stored motions, optionally only the verified ones."""
        return [r for r in self.records if r["row"] is not None
                and (r["verified"] or not verified_only)]

    def items(self, verified_only: bool = True) -> Iterator[MotionItem]:
        """Iterate stored motions in index order.

        Parameters
        ----------
        verified_only : bool
            Skip motions with status ``unverified`` (default).
        """
        for record in self.stored_records(verified_only):
            yield self.item(record)

    def item(self, record: dict[str, Any]) -> MotionItem:
        """The arrays of the motion described by ``record``."""
        if record.get("row") is None:
            raise ValueError(f"item {record.get('index')} has no stored motion (status "
                             f"{record.get('status')!r})")
        arrays = self._load_shard(record["shard"], record["shard_sha256"])
        row = int(record["row"])
        a, b = (int(x) for x in arrays["frame_offsets"][row:row + 2])
        if int(arrays["item_index"][row]) != int(record["index"]):
            raise CorruptDatasetError(f"{self.root / record['shard']}: row {row} holds item "
                                      f"{int(arrays['item_index'][row])}, manifest says "
                                      f"{record['index']}")
        part = {name: arrays[name][a:b] for name in ARRAY_NAMES}
        if self.verify_checksums and motion_sha256(part) != record["motion_sha256"]:
            raise CorruptDatasetError(f"{self.root / record['shard']}: item "
                                      f"{record['index']} does not match its motion_sha256")
        labels: dict[str, np.ndarray | None] = dict.fromkeys(LABEL_NAMES)
        if all(name in arrays for name in LABEL_NAMES):
            labels = {name: arrays[name][a:b] for name in LABEL_NAMES}
            expected = record.get("labels_sha256")
            if self.verify_checksums and expected is not None \
                    and labels_sha256(labels) != expected:
                raise CorruptDatasetError(f"{self.root / record['shard']}: item "
                                          f"{record['index']} does not match its "
                                          "labels_sha256")
        objects = {n: part["objects"][:, k] for k, n in enumerate(self.object_names)}
        return MotionItem(record, part["positions"], part["root_yaw"], part["task_index"],
                          objects, labels["task_label"], labels["phase"])

    def verify(self) -> None:
        """Check every shard against its SHA-256 (raises CorruptDatasetError)."""
        for shard in self.header.get("shards", []):
            self._check_file(self.root / shard["file"], shard["sha256"])

    def _check_file(self, path: Path, expected: str) -> bytes:
        try:
            data = path.read_bytes()
        except OSError as exc:
            raise CorruptDatasetError(f"{path}: cannot read shard: {exc.strerror or exc}") \
                from exc
        digest = hashlib.sha256(data).hexdigest()
        if digest != expected:
            raise CorruptDatasetError(f"{path}: corrupt shard: SHA-256 {digest[:16]}... does "
                                      f"not match the manifest's {expected[:16]}...")
        return data

    def _load_shard(self, rel: str, sha256: str) -> dict[str, np.ndarray]:
        if rel == self._shard_path:
            return self._shard
        path = self.root / rel
        if self.verify_checksums:
            source: Any = io.BytesIO(self._check_file(path, sha256))
        else:
            source = path
        try:
            with np.load(source, allow_pickle=False) as z:
                arrays = {name: z[name] for name in z.files}
        except (OSError, ValueError, KeyError, zipfile.BadZipFile) as exc:
            raise CorruptDatasetError(f"{path}: cannot read shard: {exc}") from exc
        names = ("item_index", "frame_offsets", *ARRAY_NAMES,
                 *(LABEL_NAMES if int(self.header.get("version", 1)) >= 2 else ()))
        missing = [n for n in names if n not in arrays]
        if missing:
            raise CorruptDatasetError(f"{path}: shard lacks arrays {missing}")
        self._shard_path, self._shard = rel, arrays
        return arrays


def open_dataset(path: str | os.PathLike[str], verify_checksums: bool = True
                 ) -> MotionDataset:
    """Open a finished dataset folder.

    Parameters
    ----------
    path : path-like
        The ``--out`` folder of ``ltl-human-motion batch``.
    verify_checksums : bool
        Check shard and item checksums while reading (default).

    Raises
    ------
    CorruptDatasetError
        Missing or malformed ``dataset.json`` / ``manifest.jsonl`` (names the file), or
        an unfinished dataset.
    """
    root = Path(path)
    header_path = root / "dataset.json"
    try:
        header = json.loads(header_path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise CorruptDatasetError(f"{header_path}: not found; {root} is not a motion "
                                  "dataset") from None
    except (OSError, ValueError) as exc:
        raise CorruptDatasetError(f"{header_path}: unreadable: {exc}") from exc
    if header.get("format") != DATASET_FORMAT or int(header.get("version", 0)) > \
            DATASET_VERSION:
        raise CorruptDatasetError(f"{header_path}: not a motion dataset of version <= "
                                  f"{DATASET_VERSION} (format {header.get('format')!r})")
    if not header.get("complete"):
        raise CorruptDatasetError(f"{root}: the dataset is unfinished; run the same batch "
                                  "command again to finish it")
    manifest = root / "manifest.jsonl"
    records = []
    try:
        with open(manifest, encoding="utf-8") as fh:
            for n, line in enumerate(fh, 1):
                if line.strip():
                    try:
                        records.append(json.loads(line))
                    except ValueError as exc:
                        raise CorruptDatasetError(f"{manifest}: line {n}: {exc}") from exc
    except OSError as exc:
        raise CorruptDatasetError(f"{manifest}: cannot read: {exc.strerror or exc}") from exc
    if len(records) != int(header["count"]):
        raise CorruptDatasetError(f"{manifest}: {len(records)} records, dataset.json says "
                                  f"{header['count']}")
    return MotionDataset(root, header, records, verify_checksums)
