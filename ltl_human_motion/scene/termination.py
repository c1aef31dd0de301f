"""Termination conditions of Table I, evaluated on joint positions.

==========  =============================================================================
task        condition (eps = ``eps``, default 0.05 m)
==========  =============================================================================
wait(t)     every joint stays within eps of its position at the task start for t seconds
move(O,R)   enclose(O, R)
leftHand(R) enclose(x, lh, R)
rightHand   enclose(x, rh, R)
insert(O1,  enclose(O1, O2)
 O2)
extract     not enter(O1, O2)
grasp(O)    enter(x, rh, occ(O) ⊕ B(eps)) or enter(x, lh, occ(O) ⊕ B(eps))
release(O)  not grasp(O)
sit(O)      enter(x, buttocks, occ(sittingSurface(O)) ⊕ B(eps))
standUp     not enter(x, head, occ(ground) ⊕ B(chestHeight))
bend        enter(x, head, ground ⊕ B(chestHeight)) and
            not enter(x, buttocks, ground ⊕ B(kneeHeight))
stoop       enter(x, head, ground ⊕ B(chestHeight)) and
            enter(x, buttocks, ground ⊕ B(kneeHeight))
kneel       enter(x, lk, ground ⊕ B(eps)) or enter(x, rk, ground ⊕ B(eps))
walk(R)     enter(x, R)
carry(O,R)  enter(x, R) and enclose(O, R)
==========  =============================================================================

chestHeight and kneeHeight are the heights of the ``chest`` and knee joints of the
standing rest pose of a worker of the given stature (1.26 m and 0.50 m at 1.75 m).
Shorthands of the cell (``assemble(R) = leftHand(R) & rightHand(R)``) are expanded;
their body must be a conjunction of tasks.

Objects are where ``objects_state`` says (name -> position (3,) or trajectory (T, 3));
objects it does not name stay at their initial positions.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, N_JOINTS, Skeleton
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.scene.predicates import (
    enclose,
    enclose_object,
    enter,
    enter_object,
    ground_enter,
)
from ltl_human_motion.scene.shapes import Box, Shape
from ltl_human_motion.vocabulary import TASK_ARGUMENTS, shorthand_conjuncts

__all__ = [
    "DEFAULT_EPS",
    "chest_height",
    "expand_task",
    "knee_height",
    "parse_task",
    "termination_holds",
    "termination_series",
]

DEFAULT_EPS = 0.05
_TASK = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\(([^()]*)\))?\s*$")


def chest_height(stature: float = DEFAULT_STATURE) -> float:
    """Height of the chest joint of the standing rest pose, metres."""
    return float(Skeleton(stature=stature).rest_positions()[JOINT_INDEX["chest"], 2])


def knee_height(stature: float = DEFAULT_STATURE) -> float:
    """Height of the knee joints of the standing rest pose, metres."""
    return float(Skeleton(stature=stature).rest_positions()[JOINT_INDEX["l_knee"], 2])


def parse_task(text: str) -> tuple[str, tuple[str, ...]]:
    """Split ``"carry(O1, R1)"`` into ``("carry", ("O1", "R1"))``."""
    m = _TASK.match(text)
    if not m:
        raise ValueError(f"expected a task such as 'grasp(O1)', got {text!r}")
    args = tuple(a.strip() for a in (m.group(2) or "").split(",") if a.strip())
    return m.group(1), args


def expand_task(task: str, args: Sequence[object], cell: Cell | None
                ) -> list[tuple[str, tuple[str, ...]]]:
    """Expand shorthands into Table I tasks: a list of ``(task, args)`` conjuncts."""
    args = tuple(str(a) for a in args)
    if task in TASK_ARGUMENTS:
        kinds = TASK_ARGUMENTS[task]
        if len(args) != len(kinds):
            raise ValueError(f"task {task} takes {len(kinds)} argument(s) "
                             f"({', '.join(kinds) or 'none'}), got {len(args)}: {args}")
        return [(task, args)]
    if cell is None or task not in cell.shorthands:
        known = sorted(TASK_ARGUMENTS) + sorted(cell.shorthands if cell else ())
        raise ValueError(f"unknown task {task!r}; expected one of {', '.join(known)}")
    params, body = cell.shorthands[task]
    if len(params) != len(args):
        raise ValueError(f"shorthand {task} takes {len(params)} argument(s), got {len(args)}")
    binding = dict(zip(params, args))
    out: list[tuple[str, tuple[str, ...]]] = []
    try:
        conjuncts = shorthand_conjuncts(body)
    except ValueError as exc:
        raise ValueError(f"shorthand {task}: {exc}") from None
    for name, sub in conjuncts:
        out.extend(expand_task(name, [binding.get(a, a) for a in sub], cell))
    return out


def _object_position(cell: Cell, name: str, objects_state: Mapping[str, np.ndarray] | None,
                     n_frames: int) -> np.ndarray:
    """Positions of object ``name`` per frame, shape (T, 3)."""
    obj = cell.object(name)
    if objects_state is not None and name in objects_state:
        p = np.asarray(objects_state[name], dtype=np.float64)
        if p.shape == (3,):
            return np.broadcast_to(p, (n_frames, 3))
        if p.shape == (n_frames, 3):
            return p
        raise ValueError(f"objects_state[{name!r}] must have shape (3,) or ({n_frames}, 3), "
                         f"got {p.shape}")
    return np.broadcast_to(obj.position, (n_frames, 3))


def _per_frame_objects(fn, *trajs: np.ndarray) -> np.ndarray:
    """Evaluate ``fn(*positions)`` once per distinct row tuple, shape (T,)."""
    stacked = np.concatenate(trajs, axis=-1)
    uniq, inverse = np.unique(stacked, axis=0, return_inverse=True)
    vals = np.array([fn(*np.split(row, len(trajs))) for row in uniq], dtype=bool)
    return vals[np.asarray(inverse).reshape(-1)]


def _boxes_enclosed(inner: Shape, inner_at: np.ndarray, outer: Shape,
                    outer_at: np.ndarray | None, *trajs: np.ndarray) -> np.ndarray | None:
    """enclose(inner, outer) per frame (T,) for two boxes that translate with their
    objects (``trajs``: the inner's positions (T, 3), then the outer's if it moves;
    ``*_at``: the positions their shapes are given at), as :func:`shape_enclosed_in`
    computes it for each distinct row, in one vectorized pass; None unless both are
    boxes."""
    if not (isinstance(inner, Box) and isinstance(outer, Box)):
        return None
    uniq, inverse = np.unique(np.concatenate(trajs, axis=-1), axis=0, return_inverse=True)
    centres = inner.center + (uniq[:, :3] - inner_at)
    origin = outer.center if outer_at is None else outer.center + (uniq[:, 3:] - outer_at)
    corners = inner.moved_to(np.zeros(3)).vertices()     # corner offsets, as vertices() adds
    local = (centres[:, None, :] + corners - np.asarray(origin)[..., None, :]) \
        @ matrix_from_yaw(outer.yaw)
    lo, hi = local.min(axis=1), local.max(axis=1)
    tol = 1e-9                                           # shape_enclosed_in's
    vals = np.all(lo >= -outer.half - tol, axis=-1) & np.all(hi <= outer.half + tol, axis=-1)
    return vals[np.asarray(inverse).reshape(-1)]


def _single(task: str, args: tuple[str, ...], window: np.ndarray, cell: Cell,
            objects_state: Mapping[str, np.ndarray] | None, eps: float, stature: float,
            fps: float | None) -> np.ndarray:
    T = window.shape[0]

    def obj_traj(name: str) -> np.ndarray:
        return _object_position(cell, name, objects_state, T)

    if task == "wait":
        try:
            duration = float(args[0].rstrip("s"))
        except ValueError:
            raise ValueError(f"wait takes a duration in seconds, got {args[0]!r}") from None
        if duration < 0:
            raise ValueError(f"wait duration must be non-negative, got {duration}")
        if fps is None:
            raise ValueError("wait needs fps to measure its duration")
        dev = np.max(np.linalg.norm(window - window[0], axis=-1), axis=-1)       # (T,)
        still = np.logical_and.accumulate(dev <= eps)
        elapsed = np.arange(T) / fps
        return still & (elapsed >= duration - 1e-9)
    if task in ("leftHand", "rightHand"):
        part = "l_palm" if task == "leftHand" else "r_palm"
        return enclose(window, cell.region(args[0]), part, stature=stature)
    if task == "walk":
        return enter(window, cell.region(args[0]), stature=stature)
    if task in ("move", "carry"):
        obj, region = cell.object(args[0]), cell.region(args[1])
        inside = _boxes_enclosed(obj.shape, obj.position, region.shape, None,
                                 obj_traj(args[0]))
        if inside is None:
            inside = _per_frame_objects(lambda p: enclose_object(obj.occupancy_at(p), region),
                                        obj_traj(args[0]))
        return inside if task == "move" else inside & enter(window, region, stature=stature)
    if task in ("insert", "extract"):
        o1, o2 = cell.object(args[0]), cell.object(args[1])
        fast = None if task != "insert" else _boxes_enclosed(
            o1.shape, o1.position, o2.shape, o2.position, obj_traj(args[0]), obj_traj(args[1]))
        if fast is not None:
            return fast
        if task == "insert":
            def fn(p1, p2):
                return enclose_object(o1.occupancy_at(p1), o2.occupancy_at(p2))
        else:
            def fn(p1, p2):
                return not enter_object(o1.occupancy_at(p1), o2.occupancy_at(p2))
        return _per_frame_objects(fn, obj_traj(args[0]), obj_traj(args[1]))
    if task in ("grasp", "release"):
        obj = cell.object(args[0])
        traj = obj_traj(args[0])
        # The object only translates: move the palms into its frame instead of moving the
        # object, so one vectorized query covers every frame.
        shift = traj - traj[0]                                           # (T, 3)
        held = enter(window - shift[:, None, :], obj.occupancy_at(traj[0]),
                     ("l_palm", "r_palm"), margin=eps, stature=stature)
        return held if task == "grasp" else ~held
    if task == "sit":
        obj = cell.object(args[0])
        traj = obj_traj(args[0])
        out = np.zeros(T, dtype=bool)
        uniq, inverse = np.unique(traj, axis=0, return_inverse=True)
        inverse = np.asarray(inverse).reshape(-1)
        for k, p in enumerate(uniq):
            rows = inverse == k
            out[rows] = enter(window[rows], obj.sitting_surface_at(p), "buttocks",
                              margin=eps, stature=stature)
        return out
    chest, knee = chest_height(stature), knee_height(stature)
    floor = cell.floor_z
    if task in ("standUp", "bend", "stoop"):
        head_low = ground_enter(window, "head", chest, floor_z=floor, stature=stature)
        if task == "standUp":
            return ~head_low
        seat_low = ground_enter(window, "buttocks", knee, floor_z=floor, stature=stature)
        return head_low & (~seat_low if task == "bend" else seat_low)
    if task == "kneel":
        return ground_enter(window, ("l_knee", "r_knee"), eps, floor_z=floor, stature=stature)
    raise ValueError(f"unknown task {task!r}")  # pragma: no cover - checked by expand_task


def termination_series(task: str, args: Sequence[object] | None, window: np.ndarray, cell: Cell,
                       objects_state: Mapping[str, np.ndarray] | None = None, *,
                       eps: float = DEFAULT_EPS, stature: float = DEFAULT_STATURE,
                       fps: float | None = None) -> np.ndarray:
    """The termination condition of ``task`` at every frame of a window.

    Parameters
    ----------
    task : str
        A Table I task or a shorthand of the cell; ``"grasp(O1)"`` with ``args=None``
        is accepted too.
    args : sequence or None
        Task arguments (object/region names; seconds for ``wait``).
    window : array-like, shape (T, J, 3)
        Joint positions from the task start (frame 0 = t* for ``wait``).
    cell : Cell
    objects_state : mapping of str to array (3,) or (T, 3), optional
        Object positions (default: their initial positions).
    eps : float
        Radius of B(eps) in metres.
    stature : float
    fps : float, optional
        Frame rate of the window (needed by ``wait``).

    Returns
    -------
    holds : ndarray of bool, shape (T,)
    """
    w = np.asarray(window, dtype=np.float64)
    if w.ndim != 3 or w.shape[1:] != (N_JOINTS, 3):
        raise ValueError(f"window must have shape (T, {N_JOINTS}, 3), got {w.shape}")
    if not eps >= 0:
        raise ValueError(f"eps must be non-negative, got {eps!r}")
    if args is None:
        task, args = parse_task(task)
    holds = np.ones(w.shape[0], dtype=bool)
    for name, sub in expand_task(task, args, cell):
        holds &= _single(name, sub, w, cell, objects_state, eps, stature, fps)
    return holds


def termination_holds(task: str, args: Sequence[object] | None, positions: np.ndarray,
                      cell: Cell, objects_state: Mapping[str, np.ndarray] | None = None, *,
                      eps: float = DEFAULT_EPS, stature: float = DEFAULT_STATURE,
                      fps: float | None = None) -> bool:
    """Whether the termination condition of ``task`` holds.

    Parameters
    ----------
    task, args, cell, objects_state, eps, stature, fps
        As for :func:`termination_series`.
    positions : array-like, shape (J, 3) or (T, J, 3)
        One frame, or a window starting at the task start; the condition is evaluated
        at its last frame (``wait`` looks at the whole window).

    Returns
    -------
    holds : bool
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.ndim == 2:
        p = p[None]
    if args is None:
        task, args = parse_task(task)
    if all(name != "wait" for name, _ in expand_task(task, args, cell)):
        p = p[-1:]                          # only the last frame matters
    if objects_state is not None:
        objects_state = {k: np.asarray(v, dtype=np.float64).reshape(-1, 3)[-1]
                         for k, v in objects_state.items()}
    series = termination_series(task, args, p, cell, objects_state, eps=eps, stature=stature,
                                fps=fps)
    return bool(series[-1])
