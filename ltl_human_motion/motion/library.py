"""The motion library: gait primitives, their motion automaton, goal primitives, cache.

``load_library()`` builds (or loads from the on-disk cache) everything the planner needs
about gait primitives as flat arrays:

* ``successors(i)`` / ``gait_successors(i)``: CSR successor indices (Delta);
* ``displacement`` (N, 3): floor pose (dx, dy, dyaw) where the *successor* starts, i.e.
  the root at frame ``n_frames - overlap`` (the last ``overlap`` frames of a primitive are
  blended with the first ``overlap`` frames of its successor, paper Eq. 2 with
  ``nf = overlap``); ``end_displacement`` (N, 3) is the root at the last frame;
* ``durations`` (N,): time advanced by a primitive, ``(n_frames - overlap) / fps``
  (166.6 ms for every loop primitive);
* ``root_paths`` (N, S, 2): root x, y at S evenly spaced times over that advance;
* ``is_carry`` (N,), ``kinds`` (N,) in {"loop", "start", "stop"}, ``starts`` (= MP0, from
  standing) and ``stops`` (end standing), ``standing_pose`` / ``standing_height``.

Goal primitives are made on demand for the exact target by
:func:`~ltl_human_motion.motion.goals.make_goal_primitive` (``library.goal(...)``).

Cache: ``$LTL_HUMAN_MOTION_CACHE`` or ``~/.cache/ltl_human_motion``; one ``.npz`` per key,
where the key hashes the library format, the build parameters, the source files' bytes and
the source code of this package's ``motion`` modules. Written atomically; an unreadable
cache file is rebuilt.
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import zipfile
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.sparse import csr_matrix

from ltl_human_motion.atomic import atomic_write_with
from ltl_human_motion.deadline import checkpoint
from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.motion import gait as _gait
from ltl_human_motion.motion.automaton import (
    DEFAULT_K_COMP,
    MotionAutomaton,
    build_transitions,
    largest_scc,
    window_positions,
)
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, Skeleton
from ltl_human_motion.motion.types import Motion, MotionPrimitive

__all__ = [
    "DEFAULT_LIBRARY_DELTA",
    "LOADERS",
    "MAX_LIBRARY_STATURE",
    "MIN_LIBRARY_STATURE",
    "ROOT_PATH_SAMPLES",
    "MotionLibrary",
    "build_library",
    "cache_dir",
    "library_cached",
    "library_key",
    "load_library",
    "load_motion",
]

LIBRARY_FORMAT = 1
# With our normalisation (see automaton.py) delta = 0.135 keeps the walk graph's largest
# strongly connected component to a third of the primitives (straight walking and left
# turns drop out); 0.20 (4.2 cm RMS per joint) connects every clip.
DEFAULT_LIBRARY_DELTA = 0.20
MIN_LIBRARY_STATURE = 1.55
MAX_LIBRARY_STATURE = 1.95
ROOT_PATH_SAMPLES = 9
_MOTION_DIR = Path(__file__).resolve().parent


def cache_dir() -> Path:
    """``$LTL_HUMAN_MOTION_CACHE`` or ``~/.cache/ltl_human_motion``."""
    env = os.environ.get("LTL_HUMAN_MOTION_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "ltl_human_motion"


# ---------------------------------------------------------------------------- loaders
def _load_bvh(path: Path, skeleton: Skeleton) -> Motion:
    from ltl_human_motion.motion import bvh
    return bvh.load(path, skeleton=skeleton)


def _load_deepmimic(path: Path, skeleton: Skeleton) -> Motion:
    from ltl_human_motion.motion import deepmimic
    return deepmimic.load(path, skeleton=skeleton)


def _load_npz(path: Path, skeleton: Skeleton) -> Motion:
    from ltl_human_motion.motion import npz
    return npz.load(path, skeleton=skeleton)


LOADERS = {".bvh": _load_bvh, ".txt": _load_deepmimic, ".json": _load_deepmimic,
           ".npz": _load_npz}


def asf_for(amc: Path) -> Path:
    """The ASF skeleton of an AMC motion, paired by name: ``07_01.amc`` -> ``07_01.asf``,
    else ``07.asf`` (the CMU layout: one subject's skeleton for all its trials), else the
    folder's only ASF. MotionFormatError naming what was looked for otherwise."""
    folder = amc.parent
    candidates = [folder / f"{amc.stem}.asf", folder / f"{amc.stem.split('_')[0]}.asf"]
    for c in candidates + [c.with_suffix(".ASF") for c in candidates]:
        if c.is_file():
            return c
    asfs = sorted(folder.glob("*.asf")) + sorted(folder.glob("*.ASF"))
    if len(asfs) == 1:
        return asfs[0]
    raise MotionFormatError(f"{amc}: no ASF skeleton found for it (looked for "
                            f"{candidates[0].name}, {candidates[1].name}, or a folder with "
                            f"one .asf; found {len(asfs)})")


def _load_amc(path: Path, skeleton: Skeleton) -> Motion:
    from ltl_human_motion.motion import asfamc
    return asfamc.load(asf_for(path), path, skeleton=skeleton)


def load_motion(path: str | os.PathLike[str], skeleton: Skeleton | None = None) -> Motion:
    """Load any supported motion file (by suffix) retargeted onto the canonical skeleton;
    an ``.amc`` motion is paired with its ``.asf`` by name (:func:`asf_for`)."""
    path = Path(path)
    if path.suffix.lower() == ".amc":
        return _load_amc(path, skeleton or Skeleton())
    loader = LOADERS.get(path.suffix.lower())
    if loader is None:
        raise MotionFormatError(
            f"{path}: unsupported motion format {path.suffix!r}; expected one of "
            f"{', '.join(sorted(LOADERS))} (ASF/AMC: motion.asfamc.load(asf, amc))")
    return loader(path, skeleton or Skeleton())


def _source_files(source: str | os.PathLike[str] | Iterable | None) -> list[Path]:
    if source is None:
        return []
    if isinstance(source, (str, os.PathLike)):
        items = [Path(source)]
    else:
        items = [Path(s) for s in source]
    files: list[Path] = []
    for item in items:
        if item.is_dir():
            found = sorted(p for p in item.rglob("*") if p.suffix.lower() in LOADERS
                           and p.is_file())
            found += [p for p in sorted(item.rglob("*.amc")) + sorted(item.rglob("*.AMC"))
                      if p.is_file()]
            if not found:
                raise ValueError(f"source folder {item} holds no motion files "
                                 f"({', '.join(sorted(LOADERS))}, or .amc with its .asf)")
            files += found
        elif item.is_file():
            files.append(item)
        else:
            raise ValueError(f"motion source {item} does not exist")
    return files


def _default_files() -> list[Path]:
    from ltl_human_motion.motion import deepmimic
    root = deepmimic.motions_dir()
    return [root / c for c in deepmimic.DEFAULT_GAIT_CLIPS]


# ---------------------------------------------------------------------------- library
@dataclass(eq=False)
class MotionLibrary:
    """Gait primitives, their motion automaton and planner-ready arrays (module docstring).

    Attributes
    ----------
    skeleton : Skeleton
    automaton : MotionAutomaton
        Gait primitives only (goal primitives are made per target).
    fps : float
    overlap : int
        Frames blended between consecutive primitives (= ``k_comp``).
    displacement, end_displacement : ndarray, shape (N, 3)
    durations : ndarray, shape (N,)
    root_paths : ndarray, shape (N, S, 2)
    is_carry : ndarray of bool, shape (N,)
    kinds : ndarray of str, shape (N,)
    starts, stops : ndarray of int
    standing_pose, carry_standing_pose : ndarray, shape (J, 3)
    standing_height : float
    key : str
        Cache key.
    stats : dict
        Build statistics (counts before/after SCC pruning, timings).
    quality : dict
        Quality report of the gait primitives (see :mod:`.quality`).
    """

    skeleton: Skeleton
    automaton: MotionAutomaton
    fps: float
    overlap: int
    displacement: np.ndarray
    end_displacement: np.ndarray
    durations: np.ndarray
    root_paths: np.ndarray
    is_carry: np.ndarray
    kinds: np.ndarray
    starts: np.ndarray
    stops: np.ndarray
    standing_pose: np.ndarray
    carry_standing_pose: np.ndarray
    standing_height: float
    key: str = ""
    stats: dict = field(default_factory=dict)
    quality: dict = field(default_factory=dict)

    @property
    def primitives(self) -> list[MotionPrimitive]:
        return self.automaton.primitives

    @property
    def n_primitives(self) -> int:
        return self.automaton.n_states

    @property
    def delta(self) -> float:
        return self.automaton.delta

    @property
    def stature(self) -> float:
        return self.skeleton.stature

    @property
    def indptr(self) -> np.ndarray:
        return self.automaton.indptr

    @property
    def indices(self) -> np.ndarray:
        return self.automaton.indices

    def gait_successors(self, i: int) -> np.ndarray:
        """Indices of the gait primitives that may follow primitive ``i``."""
        return self.automaton.successors(i)

    successors = gait_successors

    def primitive(self, i: int) -> MotionPrimitive:
        return self.automaton.primitives[i]


    def start_indices(self, carry: bool = False) -> np.ndarray:
        """Start primitives (from standing) of walk or carry."""
        return self.starts[self.is_carry[self.starts] == bool(carry)]


    def goal(self, task: str, target: np.ndarray | None, **kwargs) -> MotionPrimitive:
        """A goal primitive for ``task`` at ``target`` (start frame) on this body.

        Keyword arguments go to :func:`~ltl_human_motion.motion.goals.make_goal_primitive`.
        """
        from ltl_human_motion.motion.goals import make_goal_primitive
        kwargs.setdefault("fps", self.fps)
        return make_goal_primitive(task, target, self.skeleton, **kwargs)

    def summary(self) -> dict:
        """Counts for reports: primitives per kind/task, edges, initial set size."""
        return {
            "stature": self.stature, "delta": self.delta, "k_comp": self.automaton.k_comp,
            "fps": self.fps, "primitives": self.n_primitives,
            "walk": int(np.sum(~self.is_carry)), "carry": int(np.sum(self.is_carry)),
            "loop": int(np.sum(self.kinds == "loop")), "start": int(self.starts.size),
            "stop": int(self.stops.size), "edges": self.automaton.n_transitions,
            "key": self.key, **{k: v for k, v in self.stats.items() if k not in ("key",)},
        }


def _planner_arrays(prims: list[MotionPrimitive], overlap: int, fps: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    n = len(prims)
    disp = np.zeros((n, 3))
    end = np.zeros((n, 3))
    dur = np.zeros(n)
    paths = np.zeros((n, ROOT_PATH_SAMPLES, 2))
    for i, mp in enumerate(prims):
        k = mp.n_frames - overlap
        disp[i] = mp.root[k, [0, 1, 3]]
        end[i] = mp.root[-1, [0, 1, 3]]
        dur[i] = k / fps
        t = np.linspace(0.0, k, ROOT_PATH_SAMPLES)
        frames = np.arange(mp.n_frames)
        paths[i, :, 0] = np.interp(t, frames, mp.root[:, 0])
        paths[i, :, 1] = np.interp(t, frames, mp.root[:, 1])
    return disp, end, dur, paths


def library_key(stature: float, files: list[Path], delta: float, k_comp: int,
                phase_step: int, include_default: bool) -> str:
    """Content hash of everything the library is built from."""
    h = hashlib.sha256()
    h.update(json.dumps({"format": LIBRARY_FORMAT, "stature": round(float(stature), 6),
                         "delta": float(delta), "k_comp": int(k_comp),
                         "phase_step": int(phase_step), "fps": _gait.LIBRARY_FPS,
                         "default": bool(include_default)}, sort_keys=True).encode())
    for code in sorted(_MOTION_DIR.rglob("*.py")):
        h.update(code.relative_to(_MOTION_DIR).as_posix().encode())
        h.update(code.read_bytes())
    for f in files:
        h.update(str(f.name).encode())
        h.update(hashlib.sha256(f.read_bytes()).digest())
    return h.hexdigest()[:24]


def _progress(total: int, desc: str, enabled: bool | None):
    show = sys.stderr.isatty() if enabled is None else enabled
    if not show:
        return None
    from tqdm import tqdm
    return tqdm(total=total, desc=desc, unit="prim", file=sys.stderr, leave=False)


def build_library(stature: float = DEFAULT_STATURE, source=None,
                  delta: float = DEFAULT_LIBRARY_DELTA, k_comp: int = DEFAULT_K_COMP,
                  phase_step: int = 4,
                  include_default: bool = True, mirror: bool = True,
                  progress: bool | None = None, quality: bool = True,
                  _files: list[Path] | None = None, key: str = "",
                  user_step: int = _gait.PRIMITIVE_FRAMES) -> MotionLibrary:
    """Build the library without touching the cache (see :func:`load_library`).

    ``user_step``: frames between primitive starts in non-looping (user) clips; the default
    20 splits them like the paper. The graph build is quadratic in the number of primitives
    (about 15 to 40 s for 20 000 on two cores, see ``bench/motion_graph.py``), so point
    ``source`` at walking clips rather than at a whole database.
    """
    import time

    t0 = time.perf_counter()
    skeleton = Skeleton(stature)
    files = _files if _files is not None else (
        (_default_files() if include_default else []) + _source_files(source))
    if not files:
        raise ValueError("no motion sources: include_default=False and no source given")
    loop_names = set(_default_files()) if include_default else set()
    prims: list[MotionPrimitive] = []
    bar = _progress(len(files), "loading clips", progress)
    for f in files:
        checkpoint("library")
        motion = load_motion(f, skeleton)
        looping = f in loop_names
        if not looping and f.suffix.lower() in (".txt", ".json"):
            from ltl_human_motion.motion import deepmimic
            looping = deepmimic.load_raw(f)[2]
        for m in ((False, True) if mirror else (False,)):
            name = f.stem
            if looping:
                clip = _gait.prepare_loop(motion, name, str(f), mirror=m)
                prims += _gait.start_stop_primitives(clip, skeleton, overlap=k_comp)
                prims += _gait.gait_primitives(clip, skeleton, phase_step=phase_step,
                                               overlap=k_comp)
            else:
                # user clips are cut every 20 frames as in the paper (they are long)
                clip = _gait.prepare_clip(motion, name, str(f), mirror=m)
                prims += _gait.gait_primitives(clip, skeleton,
                                               phase_step=max(phase_step, user_step),
                                               overlap=k_comp)
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    t_prims = time.perf_counter() - t0
    dropped: list[str] = []
    generated = len(prims)
    checkpoint("library")
    if quality:
        from ltl_human_motion.motion.quality import check_primitives
        pre = check_primitives(prims, skeleton, kind="gait candidates")
        checkpoint("library")
        bad = set(pre["failed"])
        dropped = sorted(bad)
        prims = [mp for mp in prims if mp.name not in bad]
    auto, stats = _automaton(prims, skeleton, delta, k_comp, progress)
    stats["generated"] = generated
    stats["dropped_quality"] = dropped
    stats["time_primitives_s"] = round(t_prims, 3)
    stats["time_total_s"] = round(time.perf_counter() - t0, 3)
    stats["sources"] = [str(f) for f in files]
    lib = _assemble(auto, skeleton, k_comp, key, stats)
    if quality:
        from ltl_human_motion.motion.quality import check_primitives, goal_sample
        lib.quality = {
            "gait": check_primitives(lib.primitives, skeleton, kind="gait"),
            "goal": check_primitives(goal_sample(skeleton), skeleton, kind="goal"),
        }
        lib.quality["ok"] = bool(lib.quality["gait"]["ok"] and lib.quality["goal"]["ok"])
    return lib


def _automaton(prims: list[MotionPrimitive], skeleton: Skeleton, delta: float, k_comp: int,
               progress: bool | None) -> tuple[MotionAutomaton, dict]:
    import time

    t0 = time.perf_counter()
    if any(mp.n_frames < k_comp + 1 for mp in prims):
        raise ValueError(f"every primitive needs more than k_comp={k_comp} frames")
    ends = window_positions(prims, k_comp, end=True)
    begins = window_positions(prims, k_comp, end=False)
    bar = _progress(len(prims), "transitions", progress)
    D = build_transitions(ends, begins, delta, skeleton.stature,
                          progress=None if bar is None else bar.update)
    if bar is not None:
        bar.close()
    kinds = np.array([mp.meta.get("kind", "loop") for mp in prims])
    carry = np.array([mp.task == "carry" for mp in prims])
    # transitions never switch between walk and carry, never lead into a start primitive
    # and never leave a stop primitive
    coo = D.tocoo()
    keep = ((carry[coo.row] == carry[coo.col]) & (kinds[coo.col] != "start")
            & (kinds[coo.row] != "stop") & (coo.row != coo.col))
    D = csr_matrix((coo.data[keep], (coo.row[keep], coo.col[keep])), shape=D.shape)
    t_edges = time.perf_counter() - t0
    # largest SCC of the loop primitives, separately for walk and carry
    kept: list[np.ndarray] = []
    scc_sizes = {}
    for flag, task in ((False, "walk"), (True, "carry")):
        loop_idx = np.nonzero((kinds == "loop") & (carry == flag))[0]
        if loop_idx.size == 0:
            continue
        scc = largest_scc(D, loop_idx)
        scc_sizes[task] = int(scc.size)
        in_scc = np.zeros(len(prims), bool)
        in_scc[scc] = True
        # start primitives that lead into the SCC, stop primitives reached from it
        starts = np.nonzero((kinds == "start") & (carry == flag))[0]
        starts = starts[[bool(in_scc[D.indices[D.indptr[s]:D.indptr[s + 1]]].any())
                         for s in starts]] if starts.size else starts
        Dt = D.T.tocsr()
        stops = np.nonzero((kinds == "stop") & (carry == flag))[0]
        stops = stops[[bool(in_scc[Dt.indices[Dt.indptr[s]:Dt.indptr[s + 1]]].any())
                       for s in stops]] if stops.size else stops
        kept += [scc, starts, stops]
    keep_idx = np.sort(np.concatenate(kept)) if kept else np.zeros(0, int)
    sub = D[keep_idx][:, keep_idx].tocsr()
    new_prims = [prims[i] for i in keep_idx]
    new_kinds = kinds[keep_idx]
    auto = MotionAutomaton(new_prims, sub, np.nonzero(new_kinds == "start")[0], delta, k_comp)
    stats = {"candidates": len(prims), "candidate_edges": int(D.nnz),
             "scc": scc_sizes, "time_edges_s": round(t_edges, 3),
             "time_automaton_s": round(time.perf_counter() - t0, 3)}
    return auto, stats


def _assemble(auto: MotionAutomaton, skeleton: Skeleton, k_comp: int, key: str,
              stats: dict) -> MotionLibrary:
    prims = auto.primitives
    disp, end, dur, paths = _planner_arrays(prims, k_comp, _gait.LIBRARY_FPS)
    kinds = np.array([mp.meta.get("kind", "loop") for mp in prims], dtype="<U8")
    stand, h = _gait.standing_pose(skeleton)
    carry_stand, _ = _gait.standing_pose(skeleton, carry=True)
    return MotionLibrary(
        skeleton=skeleton, automaton=auto, fps=_gait.LIBRARY_FPS, overlap=k_comp,
        displacement=disp, end_displacement=end, durations=dur, root_paths=paths,
        is_carry=np.array([mp.task == "carry" for mp in prims], dtype=bool), kinds=kinds,
        starts=np.nonzero(kinds == "start")[0], stops=np.nonzero(kinds == "stop")[0],
        standing_pose=stand, carry_standing_pose=carry_stand, standing_height=h, key=key,
        stats=stats)


# ---------------------------------------------------------------------------- cache
def _save(lib: MotionLibrary, path: Path) -> None:
    prims = lib.primitives
    lengths = np.array([mp.n_frames for mp in prims], dtype=np.int64)
    header = {
        "format": LIBRARY_FORMAT, "stature": lib.stature, "delta": lib.delta,
        "k_comp": lib.automaton.k_comp, "fps": lib.fps, "key": lib.key, "stats": lib.stats,
        "quality": lib.quality,
        "primitives": [{"name": mp.name, "task": mp.task, "source": mp.source,
                        "meta": mp.meta} for mp in prims],
    }
    t = lib.automaton.transitions

    def writer(fh) -> None:
        np.savez(fh, header=np.array(json.dumps(header)), lengths=lengths,
                 poses=np.concatenate([mp.poses for mp in prims]),
                 root=np.concatenate([mp.root for mp in prims]),
                 indptr=t.indptr, indices=t.indices, data=t.data,
                 initial=lib.automaton.initial)

    atomic_write_with(path, writer)


def _check_cache_arrays(n: int, poses: np.ndarray, root: np.ndarray, indptr: np.ndarray,
                        indices: np.ndarray, data: np.ndarray, initial: np.ndarray) -> None:
    """ValueError unless the cached arrays are finite and the transition matrix (CSR of
    ``n`` primitives) and initial states index real primitives (a damaged cache is then
    rebuilt instead of crashing synthesis later)."""
    if not (np.all(np.isfinite(poses)) and np.all(np.isfinite(root))
            and np.all(np.isfinite(data))):
        raise ValueError("cache entry holds NaN or infinite values")
    if indptr.shape != (n + 1,) or indptr[0] != 0 or np.any(np.diff(indptr) < 0) \
            or indptr[-1] != indices.size or indices.size != data.size:
        raise ValueError("cache entry has a malformed transition matrix")
    for name, ids in (("transition", indices), ("initial", initial)):
        ids = np.asarray(ids)
        if ids.size and (not np.issubdtype(ids.dtype, np.integer) or ids.min() < 0
                         or ids.max() >= n):
            raise ValueError(f"cache entry has {name} indices outside 0..{n - 1}")


def _load(path: Path, key: str) -> MotionLibrary:
    with np.load(path, allow_pickle=False) as z:
        header = json.loads(str(z["header"]))
        if header.get("format") != LIBRARY_FORMAT or header.get("key") != key:
            raise ValueError("cache entry does not match")
        lengths = z["lengths"]
        poses, root = z["poses"], z["root"]
        indptr, indices, data, initial = z["indptr"], z["indices"], z["data"], z["initial"]
    bounds = np.concatenate([[0], np.cumsum(lengths)])
    if bounds[-1] != poses.shape[0] or len(header["primitives"]) != lengths.size:
        raise ValueError("cache entry is inconsistent")
    _check_cache_arrays(lengths.size, poses, root, indptr, indices, data, initial)
    fps = float(header["fps"])
    prims = [MotionPrimitive(name=h["name"], task=h["task"], poses=poses[a:b], root=root[a:b],
                             fps=fps, source=h["source"], meta=h["meta"])
             for h, a, b in zip(header["primitives"], bounds[:-1], bounds[1:])]
    n = len(prims)
    trans = csr_matrix((data, indices, indptr), shape=(n, n))
    auto = MotionAutomaton(prims, trans, initial, float(header["delta"]), int(header["k_comp"]))
    lib = _assemble(auto, Skeleton(float(header["stature"])), int(header["k_comp"]), key,
                    header["stats"])
    lib.quality = header.get("quality", {})
    return lib


def _library_path(key: str, folder: str | os.PathLike | None) -> Path:
    return (Path(folder) if folder is not None else cache_dir()) / f"library-{key}.npz"


def library_cached(stature: float = DEFAULT_STATURE, source=None,
                   delta: float = DEFAULT_LIBRARY_DELTA,
                   cache_dir: str | os.PathLike | None = None, *,
                   k_comp: int = DEFAULT_K_COMP, phase_step: int = 4,
                   include_default: bool = True) -> bool:
    """Whether :func:`load_library` with these arguments finds its cache file (and so
    loads instead of building)."""
    files = (_default_files() if include_default else []) + _source_files(source)
    return _library_path(library_key(stature, files, delta, k_comp, phase_step,
                                     include_default), cache_dir).is_file()


def load_library(stature: float = DEFAULT_STATURE, source=None,
                 delta: float = DEFAULT_LIBRARY_DELTA, cache_dir: str | os.PathLike | None = None,
                 *, k_comp: int = DEFAULT_K_COMP, phase_step: int = 4,
                 include_default: bool = True, use_cache: bool = True,
                 progress: bool | None = None) -> MotionLibrary:
    """The gait library for one body size, from the cache when its inputs are unchanged.

    Parameters
    ----------
    stature : float
        Body height in metres, 1.55 to 1.95.
    source : path-like or list of path-like, optional
        Extra motion files or folders (BVH, DeepMimic, npz) of walking, e.g. a user's CMU
        BVH database; added to the default DeepMimic loops. Non-looping clips are cut
        every 20 frames along their whole length (as in the paper); primitives that do
        not connect to the largest strongly connected component are pruned.
    delta : float
        Transition threshold on d_ij (see :mod:`.automaton` for its meaning).
    cache_dir : path-like, optional
        Default ``$LTL_HUMAN_MOTION_CACHE`` or ``~/.cache/ltl_human_motion``.
    k_comp : int
        Transition window and blend overlap in frames.
    phase_step : int
        Frames between the starts of primitives cut from the same clip (divides 20).
    include_default : bool
        Use the DeepMimic walk loops shipped with pybullet.
    use_cache : bool
    progress : bool, optional
        Show progress bars (default: when stderr is a terminal).

    Returns
    -------
    MotionLibrary
    """
    if not (MIN_LIBRARY_STATURE <= float(stature) <= MAX_LIBRARY_STATURE):
        raise ValueError(f"stature must be between {MIN_LIBRARY_STATURE} and "
                         f"{MAX_LIBRARY_STATURE} m, got {stature!r}")
    if not delta > 0:
        raise ValueError(f"delta must be positive, got {delta!r}")
    if not (isinstance(k_comp, (int, np.integer)) and 1 <= k_comp <= 20):
        raise ValueError(f"k_comp must be an integer in [1, 20], got {k_comp!r}")
    files = (_default_files() if include_default else []) + _source_files(source)
    key = library_key(stature, files, delta, k_comp, phase_step, include_default)
    path = _library_path(key, cache_dir)
    if use_cache and path.is_file():
        try:
            return _load(path, key)
        except (OSError, ValueError, KeyError, TypeError, zipfile.BadZipFile, EOFError):
            pass  # corrupt or stale: rebuild below
    lib = build_library(stature, delta=delta, k_comp=k_comp, phase_step=phase_step,
                        include_default=include_default, progress=progress, _files=files,
                        key=key)
    if use_cache:
        try:
            _save(lib, path)
        except OSError:
            pass  # a read-only cache folder must not stop synthesis
    return lib
