"""Checks of candidate postures against boards, furniture and obstacles.

How deep body capsules of posture candidates go into a low board over a target, a slab
(the furniture under a target or a board over it), or come near the obstacles around the
worker, at the contact pose and on the way into it (:data:`_POSTURE_WAY`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ltl_human_motion.motion.goals.body import _body, _posture_legs, _Start, _trunk
from ltl_human_motion.motion.goals.hand_paths import _BOARD_FRONT
from ltl_human_motion.motion.goals.tasks import _J, _SIDES
from ltl_human_motion.motion.skeleton import Skeleton

#: Clearance (m) the contact posture of a reach under a low board keeps from the board
#: beyond the body's capsules (the seeded timing and the start pose's blend move the
#: body by a few cm).
_BOARD_CLEARANCE = 0.02


#: Points sampled along every body capsule for the board check of a posture.
_CAPSULE_SAMPLES = 5


#: Body capsules the posture search keeps out of the furniture under a hand target
#: (:func:`make_goal_primitive`'s ``support``): all but the arms, which reach onto it,
#: and the feet, which stay where they stand.
#: A 1.95 m worker's contact posture for a part on a 0.75 m table put its thigh 1-3 cm
#: into the table's edge (the knees bend forward at table-top height).
_SUPPORT_FREE_PARTS: tuple[str, ...] = (
    "head", "abdomen", "torso", "pelvis", "buttocks", "l_thigh", "r_thigh", "l_knee",
    "r_knee", "l_shank", "r_shank")


#: The obstacles around a worker as the posture search sees them
#: (:func:`make_goal_primitive`'s ``obstacles``): ``clearance(poses, parts)`` is the
#: smallest clearance (m) of the capsules ``parts`` (names of
#: ``scene.occupancy.BODY_PARTS``) of start-frame poses (C, J, 3) to any obstacle, (C,);
#: only compared with ``_OBSTACLE_CLEARANCE``, so above it a lower bound will do.
ObstacleClearance = Callable[[np.ndarray, tuple[str, ...]], np.ndarray]


#: Clearance (m) a reaching posture keeps from the obstacles around the worker, at
#: contact and on the trunk's and legs' way there: over the planner's 3 mm
#: (planning.steps.PLACED_MARGIN) by the few mm the blends at the primitive's ends and
#: the start pose's residual move the body.
_OBSTACLE_CLEARANCE = 0.01


#: Fractions of the way into the reaching posture at which the trunk and legs are
#: checked against the obstacles (they move along pitch, drop and shift scaled by one
#: profile, so these are poses of the primitive; a tall worker's head sweeps forward
#: through the board above a low shelf before it is under it).
_POSTURE_WAY = (0.2, 0.35, 0.5, 0.65, 0.8, 0.9)


#: Capsules checked on the way into the posture (the arms follow the hand path, which
#: the planner checks on every frame).
_WAY_PARTS: tuple[str, ...] = ("head", "abdomen", "torso", "pelvis", "buttocks", "l_thigh",
                               "r_thigh", "l_knee", "r_knee", "l_shank", "r_shank")


def _board_depth(poses: np.ndarray, board: tuple[float, float, float],
                 stature: float, parts: np.ndarray | None = None) -> np.ndarray:
    """How deep the body's capsules (or the capsules ``parts``, indices) of poses
    (C, J, 3) go into a board beyond x = edge between heights bottom and top
    (``board = (edge, bottom, top)``, start frame), plus ``_BOARD_CLEARANCE``, metres
    (C,); negative: clear."""
    from ltl_human_motion.motion.capsules import capsule_ends, capsule_radii
    edge, bottom, top = board
    ia, ib = capsule_ends()
    radii = capsule_radii(stature)
    if parts is not None:
        ia, ib, radii = ia[parts], ib[parts], radii[parts]
    s = np.linspace(0.0, 1.0, _CAPSULE_SAMPLES)[:, None, None, None]
    pts = poses[:, ia] + s * (poses[:, ib] - poses[:, ia])          # (S, C, K, 3)
    x, z = pts[..., 0], pts[..., 2]
    dz = np.maximum(bottom - z, z - top)
    out_x, out_z = np.maximum(edge - x, 0.0), np.maximum(dz, 0.0)
    dist = np.where((x >= edge) & (dz <= 0.0), -np.minimum(x - edge, -dz),
                    np.hypot(out_x, out_z))
    depth = radii + _BOARD_CLEARANCE - dist
    return depth.max(axis=(0, 2))


def _way_poses(skeleton: Skeleton, st: _Start,
               posture: tuple[np.ndarray, np.ndarray, np.ndarray], cap: np.ndarray,
               by_hip: tuple[int, ...] = (), kneel: np.ndarray | None = None) -> np.ndarray:
    """Poses (S C, J, 3) on the way into posture candidates (pitch, drop, shift), each
    (C,), at the fractions :data:`_POSTURE_WAY` (S), fraction-major: the hands held as in
    the start pose relative to the shoulders, those in ``by_hip`` (0 left, 1 right) by the
    hip as :func:`_hand_task` holds a free hand; ``cap`` (C,) as :func:`_trunk`'s; a
    kneeling candidate (``kneel``, (C,) of bool) on its knees, leaning forward (it kneels
    down upright first, :func:`_kneel_progress`)."""
    pitch, drop, shift = posture
    C, S = pitch.size, len(_POSTURE_WAY)
    frac = np.repeat(np.asarray(_POSTURE_WAY), C)                    # (S C,)
    knelt = np.zeros(S * C, bool) if kneel is None else np.tile(kneel, S)
    down = np.where(knelt, 1.0, frac)
    pelvis = np.tile(st.pelvis, (S * C, 1))
    pelvis[:, 2] -= down * np.tile(drop, S)
    pelvis[:, 0] += down * np.tile(shift, S)
    pit = frac * np.tile(pitch, S)
    tr = _trunk(skeleton, pelvis, pit, np.tile(cap, S), st.hips(), knelt)
    hands = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1) + st.hand_rel
    for k in by_hip:
        hands[:, k] = pelvis + (st.hands[k] - st.pelvis) + np.outer(frac, [0.0, 0.0, 0.04])
    n = S * C
    return _body(skeleton, pelvis, pit, *_posture_legs(skeleton, st, tr, knelt),
                 hands, np.broadcast_to(st.hand_dir, (n, 2, 3)),
                 np.broadcast_to(st.elbow_pole, (n, 2, 3)), tr)


def _board_way_blocked(skeleton: Skeleton, st: _Start,
                       posture: tuple[np.ndarray, np.ndarray, np.ndarray],
                       active: tuple[int, ...], board: tuple[float, float, float],
                       cap: np.ndarray, kneel: np.ndarray | None = None) -> np.ndarray:
    """Whether posture candidates (pitch, drop, shift), each (C,), bring the body or a free
    arm (hanging by the hip, as :func:`_hand_task` holds it) nearer the low board than
    ``_BOARD_CLEARANCE`` on the way into the posture (:data:`_POSTURE_WAY`), shape (C,)
    of bool. The acting arm follows the level path, which turns before the board's edge
    (:func:`_level_keys`)."""
    from ltl_human_motion.motion.capsules import part_indices
    free = tuple(k for k in range(2) if k not in active)
    way = _way_poses(skeleton, st, posture, cap, free, kneel)
    S, C = len(_POSTURE_WAY), posture[0].size
    parts = part_indices(_WAY_PARTS + tuple(f"{_SIDES[k]}_{p}" for k in free
                                            for p in ("upper_arm", "lower_arm", "hand")))
    return (_board_depth(way, board, skeleton.stature, parts).reshape(S, C) > 0.0).any(axis=0)


def _support_depth(poses: np.ndarray, support: tuple[float, float, float, float],
                   stature: float) -> np.ndarray:
    """How deep the trunk and legs (``_SUPPORT_FREE_PARTS``) of poses (C, J, 3) go into
    the furniture under a target, plus ``_BOARD_CLEARANCE``, metres (C,); negative:
    clear. ``support = (nx, ny, offset, top)`` (start frame): the furniture is where
    ``nx * x + ny * y >= offset`` ((nx, ny) the unit normal into it from its edge), from
    the floor up to height ``top``."""
    from ltl_human_motion.motion.capsules import BODY_PARTS
    keep = np.array([BODY_PARTS.index(name) for name in _SUPPORT_FREE_PARTS])
    return _slab_depth(poses, (*support[:3], -1.0, support[3]), stature, keep)


def _slab_depth(poses: np.ndarray, slab: tuple[float, float, float, float, float],
                stature: float, parts: np.ndarray | None = None) -> np.ndarray:
    """How deep the body's capsules (``parts``: indices (K,), default all) of poses
    (C, J, 3) go into ``slab = (nx, ny, offset, bottom, top)`` (start frame: where
    ``nx * x + ny * y >= offset`` between heights bottom and top), plus
    ``_BOARD_CLEARANCE``, metres (C,); negative: clear."""
    from ltl_human_motion.motion.capsules import capsule_ends, capsule_radii
    nx, ny, offset, bottom, top = slab
    ia, ib = capsule_ends()
    radii = capsule_radii(stature)
    if parts is not None:
        ia, ib, radii = ia[parts], ib[parts], radii[parts]
    s = np.linspace(0.0, 1.0, _CAPSULE_SAMPLES)[:, None, None, None]
    pts = poses[:, ia] + s * (poses[:, ib] - poses[:, ia])          # (S, C, K, 3)
    into = nx * pts[..., 0] + ny * pts[..., 1] - offset              # beyond the edge
    out_z = np.maximum(bottom - pts[..., 2], pts[..., 2] - top)      # above or below
    dist = np.where((into >= 0.0) & (out_z <= 0.0), -np.minimum(into, -out_z),
                    np.hypot(np.maximum(-into, 0.0), np.maximum(out_z, 0.0)))
    return (radii + _BOARD_CLEARANCE - dist).max(axis=(0, 2))


def _turns_before_edge(shoulders: np.ndarray, active: tuple[int, ...],
                       board: tuple[float, float, float]) -> np.ndarray:
    """Whether the acting shoulders of postures (C, 2, 3) stay behind the level path's
    turn point, ``_BOARD_FRONT`` before the edge of the low board (edge, bottom, top) over
    the targets, shape (C,) of bool: the hand goes down there, in under the board and
    out and up the same way (:func:`_level_keys`); from a shoulder past it the hand would
    go down under the board's edge."""
    front = board[0] - _BOARD_FRONT
    return np.all(shoulders[:, list(active), 0] <= front, axis=1)


def _obstacle_blocked(skeleton: Skeleton, st: _Start,
                      posture: tuple[np.ndarray, np.ndarray, np.ndarray], contact: np.ndarray,
                      active: tuple[int, ...], obstacles: ObstacleClearance,
                      cap: np.ndarray, kneel: np.ndarray | None = None) -> np.ndarray:
    """Whether posture candidates come nearer the obstacles than ``_OBSTACLE_CLEARANCE``.

    Parameters
    ----------
    posture : (pitch, drop, shift), each ndarray (C,)
    contact : ndarray, shape (C, J, 3)
        The candidates' contact poses (:func:`_contact_poses`): checked whole but for the
        acting hands, which are on their targets, and the feet, which stand where the
        worker stands, whatever the posture.
    active : tuple of int
        The acting hands (0 left, 1 right).
    obstacles : ObstacleClearance
    cap, kneel : ndarray of bool, shape (C,)
        As :func:`_trunk`'s.

    Returns
    -------
    ndarray of bool, shape (C,)
    """
    from ltl_human_motion.motion.capsules import BODY_PARTS
    fixed = {f"{_SIDES[k]}_{n}" for k in active for n in ("hand", "palm")} | {"l_foot",
                                                                               "r_foot"}
    whole = tuple(p for p in BODY_PARTS if p not in fixed)
    hit = obstacles(contact, whole) <= _OBSTACLE_CLEARANCE
    # the way into the postures not already hit
    todo = np.flatnonzero(~hit)
    if todo.size:
        way = _way_poses(skeleton, st, tuple(a[todo] for a in posture), cap[todo], (),
                         None if kneel is None else kneel[todo])
        near = obstacles(way, _WAY_PARTS).reshape(len(_POSTURE_WAY), todo.size)
        hit[todo] = (near <= _OBSTACLE_CLEARANCE).any(axis=0)
    return hit
