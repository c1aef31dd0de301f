"""Arrays over the gait primitives that the A* search reads on its hot path."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.kernel.cache import BoundedCache
from ltl_human_motion.motion.types import MotionPrimitive, place_poses, world_positions
from ltl_human_motion.planning.turns import turn_primitives

#: Frames of each gait primitive the search checks the body on (evenly spaced, ends
#: included; the path it returns is then checked on every frame). The even ones (every
#: ~31st frame of a 125-frame step, the search's 5 samples until now) keep 1 cm, the odd
#: ones between them (``steps.SWEEP_MARGIN``) must not enter an obstacle: with only the
#: 5, a swinging hand passed 1-7 cm into a crate or barrier between samples and every
#: path found near them collided (29 corpus runs, cluttered). Odd, so that the samples
#: alternate.
BODY_SAMPLES = 9


def sample_body(mp: MotionPrimitive, samples: int = BODY_SAMPLES) -> np.ndarray:
    """Poses of ``mp`` placed at the origin at evenly spaced frames, shape (S, J, 3)."""
    frames = np.linspace(0, mp.n_frames - 1, samples).round().astype(int)
    return world_positions(mp, frames=frames)


def sample_bodies(primitives: Sequence[MotionPrimitive], samples: int = BODY_SAMPLES
                  ) -> np.ndarray:
    """:func:`sample_body` of every primitive, shape (N, S, J, 3), in one vectorized pass."""
    if not primitives:
        return np.zeros((0, samples, 0, 3))
    picks: dict[int, np.ndarray] = {}
    roots, poses = [], []
    for mp in primitives:
        frames = picks.get(mp.n_frames)
        if frames is None:
            frames = picks[mp.n_frames] = np.linspace(0, mp.n_frames - 1,
                                                      samples).round().astype(int)
        roots.append(mp.root[frames])
        poses.append(mp.poses[frames])
    body = place_poses(np.concatenate(roots), np.concatenate(poses))
    return body.reshape(len(primitives), samples, *body.shape[1:])


@dataclass(frozen=True, eq=False)
class GaitIndex:
    """Precomputed placement data of the gait primitives.

    Primitive ``j`` placed at floor pose ``(x, y, yaw)`` hands over to its successor at
    frame ``T_j - nf`` (the start of the blend overlap), so its displacement and cost
    are measured to that frame.

    Attributes
    ----------
    primitives : list of MotionPrimitive, length N
    disp : ndarray, shape (N, 3)
        Root (dx, dy, dyaw) at the hand-over frame, in the primitive's start frame.
    cost : ndarray, shape (N,)
        Seconds of motion the primitive adds, (T - nf) / fps.
    path : ndarray, shape (N, S, 2)
        Root floor positions sampled along the primitive, start frame.
    indptr, indices : ndarray of int
        Successors of ``j`` are ``indices[indptr[j]:indptr[j + 1]]`` (CSR).
    starts : ndarray of int
        Primitives that may follow the standing pose.
    stops : ndarray of bool, shape (N,)
        True for primitives that end standing (a walk may only end with one).
    carry : ndarray of bool, shape (N,)
        True for carry primitives (arms holding an object).
    nf : int
        Blend overlap between gait primitives, frames.
    body : ndarray, shape (N, B, J, 3)
        Sampled poses of each primitive placed at the origin, for whole-body obstacle
        checks during the search (empty when not built).
    standing : ndarray of bool, shape (N,)
        Standing-to-standing primitives (turns and steps on the spot): their root path
        says nothing about the sweeping arms, so their whole body is always checked.
        Blend overlap between gait primitives, frames.
    """

    primitives: list[MotionPrimitive]
    disp: np.ndarray
    cost: np.ndarray
    path: np.ndarray
    indptr: np.ndarray
    indices: np.ndarray
    starts: np.ndarray
    stops: np.ndarray
    carry: np.ndarray
    nf: int
    body: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 0, 3)))
    standing: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    @classmethod
    def from_library(cls, library) -> GaitIndex:
        """The index over a :class:`~ltl_human_motion.motion.library.MotionLibrary`."""
        n = library.n_primitives
        stops = np.zeros(n, dtype=bool)
        stops[np.asarray(library.stops, dtype=np.int64)] = True
        body = sample_bodies(library.primitives)
        return cls(list(library.primitives), np.asarray(library.displacement),
                   np.asarray(library.durations), np.asarray(library.root_paths),
                   np.asarray(library.indptr, dtype=np.int64),
                   np.asarray(library.indices, dtype=np.int64),
                   np.asarray(library.starts, dtype=np.int64), stops,
                   np.asarray(library.is_carry, dtype=bool), int(library.overlap), body,
                   np.zeros(n, dtype=bool))

    @classmethod
    def build(cls, primitives: Sequence[MotionPrimitive], successors: Sequence[Sequence[int]],
              starts: Sequence[int] | None = None, stops: Sequence[int] | None = None,
              nf: int = 4, samples: int = 5) -> GaitIndex:
        """Build the index from gait primitives and their successor lists.

        ``starts``/``stops`` default to every primitive.
        """
        if len(primitives) != len(successors):
            raise ValueError(f"{len(primitives)} primitives but {len(successors)} successor lists")
        if not primitives:
            raise ValueError("the gait library is empty")
        n = len(primitives)
        disp = np.zeros((n, 3))
        cost = np.zeros(n)
        path = np.zeros((n, samples, 2))
        for j, mp in enumerate(primitives):
            k = min(max(mp.n_frames - nf, 1), mp.n_frames - 1)
            disp[j] = (mp.root[k, 0], mp.root[k, 1], mp.root[k, 3])
            cost[j] = k / mp.fps
            idx = np.linspace(0, k, samples).round().astype(int)
            path[j] = mp.root[idx, :2]
        lengths = np.array([len(s) for s in successors])
        indptr = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        indices = (np.concatenate([np.asarray(s, dtype=np.int64) for s in successors])
                   if lengths.sum() else np.zeros(0, dtype=np.int64))
        start_ids = np.arange(n) if starts is None else np.asarray(starts, dtype=np.int64)
        body = sample_bodies(primitives)
        stop_mask = np.ones(n, dtype=bool)
        if stops is not None:
            stop_mask[:] = False
            stop_mask[np.asarray(stops, dtype=np.int64)] = True
        carry = np.array([mp.task == "carry" for mp in primitives])
        return cls(list(primitives), disp, cost, path, indptr, indices, start_ids, stop_mask,
                   carry, nf, body, np.zeros(n, dtype=bool))

    def with_standing_primitives(self, extra: Sequence[MotionPrimitive],
                                 samples: int | None = None) -> GaitIndex:
        """A new index with standing-to-standing primitives (e.g. turns on the spot).

        They may follow standing and every stop primitive of the same task (walk or
        carry), end standing themselves, and are followed by the start primitives.
        """
        if not extra:
            return self
        samples = samples or self.path.shape[1]
        add = GaitIndex.build(extra, [[] for _ in extra], nf=self.nf, samples=samples)
        n0, n1 = len(self.primitives), len(extra)
        new_ids = np.arange(n0, n0 + n1)
        start_set = self.starts
        succ: list[np.ndarray] = []
        for j in range(n0):
            own = self.successors(j)
            if self.stops[j]:
                own = np.concatenate([own, new_ids[add.carry == self.carry[j]]])
            succ.append(own)
        for k in range(n1):
            succ.append(start_set[self.carry[start_set] == add.carry[k]])
        lengths = np.array([len(x) for x in succ])
        indptr = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        body = np.concatenate([self.body, add.body]) if self.body.size else add.body
        return GaitIndex(
            self.primitives + list(extra), np.concatenate([self.disp, add.disp]),
            np.concatenate([self.cost, add.cost]), np.concatenate([self.path, add.path]),
            indptr, np.concatenate(succ).astype(np.int64),
            np.concatenate([self.starts, new_ids]), np.concatenate([self.stops, add.stops]),
            np.concatenate([self.carry, add.carry]), self.nf, body,
            np.concatenate([self.standing, np.ones(n1, dtype=bool)]))

    def successors(self, j: int) -> np.ndarray:
        """Indices of the primitives that may follow primitive ``j``."""
        return self.indices[self.indptr[j]:self.indptr[j + 1]]


_INDEX_CACHE: BoundedCache[GaitIndex] = BoundedCache(8)


def gait_index(library) -> GaitIndex:
    """The library's gait index extended with turns on the spot, built once per library."""
    return _INDEX_CACHE.get_or_build(
        "gait", lambda: GaitIndex.from_library(library).with_standing_primitives(
            turn_primitives(library)), owner=library)
