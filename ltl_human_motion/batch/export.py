"""Optional exports of a finished dataset for training: BVH per item, one npz of windows.

``export_bvh`` writes ``item-0000000012.bvh`` per stored motion (the canonical skeleton
at the item's stature, y up by default: :func:`ltl_human_motion.planning.exports.save_bvh`)
and ``items.jsonl`` beside them (file, index, fps, stature, LTL, sequence, captions).

``export_windows`` cuts every stored motion into fixed-length windows and writes one
uncompressed ``.npz`` (N windows of W frames, J joints, K captions per item):

============== ============== ======== ==================================================
array          shape          dtype    meaning
============== ============== ======== ==================================================
positions      (N, W, J, 3)   float32  joint positions, world frame, z up, metres
task_label     (N, W)         int16    task of the sequence per frame (-1 after the last)
phase          (N, W)         int8     index into ``phases``
item_index     (N,)           int64    the window's item
start_frame    (N,)           int64    first frame of the window in the item (item fps)
captions       (N, K)         str      the item's captions (canonical first)
ltl            (N,)           str      the item's LTL specification
fps            ()             float64  frame rate of the windows (item fps / step)
joint_names    (J,)           str
joint_parents  (J,)           int64    parent index, -1 for the root
phases         (4,)           str      walk, reach, manipulate, transition
============== ============== ======== ==================================================

Strings are fixed-width unicode arrays, so ``np.load(path)`` reads it without pickles.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ltl_human_motion.atomic import atomic_write_bytes, atomic_write_text
from ltl_human_motion.batch.reader import MotionDataset, open_dataset
from ltl_human_motion.batch.store import npz_bytes_of

__all__ = ["WindowSpec", "export_bvh", "export_windows"]


@dataclass(frozen=True)
class WindowSpec:
    """How motions are cut into windows.

    Attributes
    ----------
    length : int
        Frames per window (after subsampling), >= 1.
    stride : int
        Frames (after subsampling) between the starts of consecutive windows, >= 1.
    step : int
        Keep every ``step``-th frame of the item (120 fps / 4 = 30 fps), >= 1.
    """

    length: int = 64
    stride: int = 32
    step: int = 4

    def __post_init__(self) -> None:
        for name in ("length", "stride", "step"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                raise ValueError(f"window {name} must be an integer >= 1, got {v!r}")


def _dataset(dataset: MotionDataset | str | os.PathLike[str]) -> MotionDataset:
    return dataset if isinstance(dataset, MotionDataset) else open_dataset(dataset)


def export_bvh(dataset: MotionDataset | str | os.PathLike[str],
               out: str | os.PathLike[str], verified_only: bool = True, up: str = "y"
               ) -> list[Path]:
    """One BVH file per stored motion in folder ``out`` and ``out/items.jsonl``.

    Returns
    -------
    list of Path
        The BVH files, in item order.
    """
    from ltl_human_motion.motion.skeleton import Skeleton
    from ltl_human_motion.motion.types import Motion
    from ltl_human_motion.planning.exports import save_bvh

    ds = _dataset(dataset)
    folder = Path(out)
    folder.mkdir(parents=True, exist_ok=True)
    files, lines = [], []
    for item in ds.items(verified_only=verified_only):
        stature = float(item.record["params"]["stature"])
        motion = Motion(np.asarray(item.positions, dtype=np.float64), item.fps,
                        Skeleton(stature), name=f"item-{item.index:010d}")
        path = folder / f"item-{item.index:010d}.bvh"
        save_bvh(motion, path, up=up)
        files.append(path)
        lines.append(json.dumps({"file": path.name, "index": item.index, "fps": item.fps,
                                 "stature": stature, "ltl": item.ltl,
                                 "sequence": item.record["sequence"],
                                 "captions": item.captions}, sort_keys=True))
    atomic_write_text(folder / "items.jsonl", "".join(f"{ln}\n" for ln in lines))
    return files


def export_windows(dataset: MotionDataset | str | os.PathLike[str],
                   path: str | os.PathLike[str], spec: WindowSpec = WindowSpec(),
                   verified_only: bool = True) -> int:
    """Write the fixed-length windows of every stored motion to one ``.npz`` (see the
    module docstring); a motion shorter than one window gives none.

    Returns
    -------
    int
        Number of windows N.

    Raises
    ------
    ValueError
        The dataset has no per-frame labels (version 1), or its items differ in fps.
    """
    ds = _dataset(dataset)
    pos, task, phase, index, start, caps, ltl = [], [], [], [], [], [], []
    fps = None
    n_caps = max((len(r.get("captions") or []) for r in ds.stored_records(verified_only)),
                 default=1)
    for item in ds.items(verified_only=verified_only):
        if item.phase is None or item.task_label is None:
            raise ValueError(f"{ds.root}: dataset version {ds.header.get('version')} has "
                             "no per-frame labels; make it again with this version")
        if fps is None:
            fps = item.fps
        elif abs(item.fps - fps) > 1e-9:
            raise ValueError(f"{ds.root}: item {item.index} has {item.fps} fps, others "
                             f"{fps}")
        sub = slice(None, None, spec.step)
        p, t, f = item.positions[sub], item.task_label[sub], item.phase[sub]
        item_caps = (item.captions + [""] * n_caps)[:n_caps]
        for a in range(0, len(p) - spec.length + 1, spec.stride):
            pos.append(p[a:a + spec.length])
            task.append(t[a:a + spec.length])
            phase.append(f[a:a + spec.length])
            index.append(item.index)
            start.append(a * spec.step)
            caps.append(item_caps)
            ltl.append(item.ltl)
    J = len(ds.joint_names)
    n = len(pos)
    entries = [
        ("positions", np.asarray(pos, dtype=np.float32).reshape(n, spec.length, J, 3)),
        ("task_label", np.asarray(task, dtype=np.int16).reshape(n, spec.length)),
        ("phase", np.asarray(phase, dtype=np.int8).reshape(n, spec.length)),
        ("item_index", np.asarray(index, dtype=np.int64)),
        ("start_frame", np.asarray(start, dtype=np.int64)),
        ("captions", np.asarray(caps, dtype=np.str_).reshape(n, n_caps)),
        ("ltl", np.asarray(ltl, dtype=np.str_).reshape(n)),
        ("fps", np.float64((fps or 0.0) / spec.step)),
        ("joint_names", np.asarray(ds.joint_names, dtype=np.str_)),
        ("joint_parents", np.asarray(ds.header.get("joint_parents", []), dtype=np.int64)),
        ("phases", np.asarray(ds.header.get("phases", []), dtype=np.str_)),
    ]
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(target, npz_bytes_of(entries))
    return n
