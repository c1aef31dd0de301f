"""Reference hand paths of hand tasks: key poses, arcs, level and rise paths, timing.

Between key poses the palm moves with the minimum-jerk profile. The shoulder-to-palm
vector is interpolated relative to the moving shoulder (direction slerped, length
interpolated), so the path swings in an arc rather than through the shoulder, plus a
small seeded outward/upward bow. The level path (:data:`.tasks.HAND_PATHS`) brings the
palm near the body to the height it comes in at, then in horizontally; over furniture
above the shoulders it first rises in front of its edge (:func:`_rise_points`). Reach
times follow Fitts' law and a peak palm speed (:func:`_reach_times`).
"""

from __future__ import annotations

import itertools

import numpy as np

from ltl_human_motion.motion.goals.body import _goal_elbow_pole, _goal_hand_dir, _Start
from ltl_human_motion.motion.goals.tasks import LEVEL_REGION_TASKS
from ltl_human_motion.motion.goals.timelines import _arc_keys, _interp_keys, _profile
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE
from ltl_human_motion.motion.timing import fitts_time, min_move_time

_APPROACH_LIFT = 0.08           # m, grasp/release/move come down onto low targets


#: Peak palm speed of a goal reach, m/s at 1.75 m: under the 2.5 m/s limit of
#: planning.biomechanics with room for the seeded bow and the body's own motion.
HAND_GOAL_PEAK_SPEED = 1.8


#: Length of the arced palm path (slerped about the shoulder, plus the bow and the
#: approach from above) over the straight distance.
_ARC_PATH_FACTOR = 1.35


#: Extra outward bow of the palm path for a target below the hips, fraction of stature
#: (full up to 0.45 H, none from 0.6 H): the hand passes outside the thigh.
_LOW_REACH_WIDE = 0.05


#: Fraction of the reach time at which extract's level path is at the start of its
#: straight way in (the rest goes in straight, as the pull comes out); insert's comes
#: back out straight in the same fraction of its return time.
_PUSH_IN_AT = 0.6


#: Horizontal distance from the shoulder of the level path's turn point, fraction of
#: stature (0.12 m at 1.75 m: in front of the chest, behind the front edge of a shelf the
#: worker stands at, also one overhead).
_LEVEL_NEAR = 0.07


#: Shortest shoulder-to-palm distance on the level path, fraction of the arm's length
#: (a palm nearer the shoulder folds the elbow fully and its two-bone solution flips).
_LEVEL_MIN_EXTENSION = 0.5


#: Horizontal distance (m) a palm rising to a target on furniture above the shoulders
#: keeps in front of that furniture's edge on the level path (:func:`_rise_points`): the
#: hand capsule's radius (4.5 cm at 1.75 m) and a margin. An arc about the shoulder from
#: the hip up to such a target passes under the board at arm's length and up through it
#: (a 1.55 m worker at a wall shelf whose board is at 1.6 m).
_RISE_FRONT = 0.08


#: How far below the top of such furniture (m) the palm rises in front of its edge
#: before it goes straight up: on the way up and down the wrist is up to a hand's length
#: above the palm and the arc about the shoulder to and from the hip swings it forward.
_RISE_BELOW = 0.25


#: Least horizontal distance (m) of such a rise from the shoulder: a board edge nearer
#: than this and ``_RISE_FRONT`` leaves no room to raise the hand in front of it.
_RISE_LEAST = 0.12


#: Least horizontal distance of such a rise from the neck and head joints at the reach's
#: end, m at 1.75 m, scaled by stature: the head capsule's radius (0.105 m) and 5 cm. A rise
#: towards a target in front of the face (a short worker close to a wall shelf) took
#: the hand down past the face, through the head capsule; it moves along the edge to
#: the hand's own side instead, and the palm goes over the board to the target.
_RISE_HEAD_CLEAR = 0.155


#: Height (m) over the top of furniture below the shoulders at which a palm coming up in
#: front of its edge turns in over it (:func:`_rise_points`): the hand capsule's radius
#: and a part's half height in it.
_RISE_OVER = 0.08


#: Least horizontal distance of such a rise from the shoulder, m: the palm comes up
#: close in front of the chest.
_RISE_LEAST_LOW = 0.04


#: Reach time of the level path over the arc's (its path is about this much longer).
_LEVEL_TIME = 1.3


#: Horizontal distance of the under path's drop point in front of the board's edge, m
#: (the hand capsule's radius and a margin).
_BOARD_FRONT = 0.10


def _level_keys(targets: np.ndarray, active: tuple, sh1: np.ndarray, rel_home: np.ndarray,
                rel_goal: np.ndarray, lift: float, t1: float, t2: float, total: float,
                H: float, arm: float, board: tuple[float, float, float] | None = None,
                rise: np.ndarray | None = None
                ) -> tuple[list[tuple[float, np.ndarray]], frozenset[int]]:
    """Shoulder-to-palm keys of the level path (see :data:`HAND_PATHS`): home, the turn
    point near the body at the approach height, above the target, the target (held), and
    back the same way. Arrays (2, 3); ``sh1`` (2, 3): the shoulders in the reach posture;
    ``arm``: the arm's length (the turn point keeps the elbow clearly bent, not folded);
    ``board`` (edge, bottom, top): a low board over the targets (start frame): the turn
    point is ``_BOARD_FRONT`` before its edge (down in front of the edge, then in under
    the board, and out and up the same way; the posture keeps the shoulder behind it,
    :func:`_turns_before_edge`); ``rise`` (2, 3) (:func:`_rise_points`): the palms first
    rise at it in front of the furniture under the targets, then straight up to the
    turn point above it, and go back down the same way. Returns the keys and the legs
    (index of a leg's first key) the path takes straight."""
    front = None if board is None else board[0] - _BOARD_FRONT
    rel_above, rel_near = rel_goal.copy(), rel_goal.copy()
    for k in active:
        above = targets[k] + np.array([0.0, 0.0, lift])
        rel_above[k] = above - sh1[k]
        flat = rel_above[k, :2]
        dh = float(np.linalg.norm(flat))
        unfolded = np.sqrt(max((_LEVEL_MIN_EXTENSION * arm) ** 2 - rel_above[k, 2] ** 2, 0.0))
        near = min(dh, max(_LEVEL_NEAR * H, unfolded))
        if front is not None and flat[0] > 1e-9:
            near = min(dh, max(dh * (front - sh1[k, 0]) / flat[0], 0.0))
        if rise is not None:
            near = float(np.linalg.norm(rise[k, :2]))
        rel_near[k, :2] = flat * (near / dh) if dh > 1e-9 else flat
        rel_near[k, 2] = rel_above[k, 2]
    r = total - t2
    if rise is not None:
        rel_rise = rel_home.copy()
        rel_rise[list(active)] = rise[list(active)]
        return ([(0.0, rel_home), (0.3 * t1, rel_rise), (0.55 * t1, rel_near),
                 (0.8 * t1, rel_above), (t1, rel_goal), (t2, rel_goal),
                 (t2 + 0.2 * r, rel_above), (t2 + 0.45 * r, rel_near),
                 (t2 + 0.7 * r, rel_rise), (total, rel_home)], frozenset(range(1, 8)))
    return [(0.0, rel_home), (0.5 * t1, rel_near), (0.8 * t1, rel_above), (t1, rel_goal),
            (t2, rel_goal), (t2 + 0.2 * r, rel_above), (t2 + 0.5 * r, rel_near),
            (total, rel_home)], frozenset()


def _head_clear_shift(sh1: np.ndarray, k: int, rise: np.ndarray, normal: tuple[float, float],
                      head: np.ndarray, clear: float) -> np.ndarray:
    """Horizontal shift (2,) along a furniture edge (inward normal ``normal``) that takes
    hand ``k``'s rise point ``rise`` (shoulder-relative, (2,)) ``clear`` metres from the
    neck and the head (``head`` (2, 3), their positions at the reach's end; the
    shoulders there ``sh1`` (2, 3)), towards that hand's side; zero where it is that far
    already."""
    e = np.array([-normal[1], normal[0]])
    if float(e @ (sh1[k, :2] - sh1.mean(axis=0)[:2])) < 0.0:
        e = -e
    shift = 0.0
    for point in head[:, :2]:
        v = sh1[k, :2] + rise - point
        ve = float(v @ e)
        shift = max(shift, -ve + np.sqrt(max(ve * ve - float(v @ v) + clear * clear, 0.0)))
    return shift * e


def _rise_points(targets: np.ndarray, active: tuple, sh1: np.ndarray,
                 support: tuple[float, float, float, float] | None, arm: float,
                 stature: float = DEFAULT_STATURE, head: np.ndarray | None = None,
                 home: np.ndarray | None = None) -> np.ndarray | None:
    """Shoulder-to-palm points (2, 3) in front of the edge of the furniture under the
    targets (``support`` (nx, ny, offset, top), start frame, :func:`_slab_depth`),
    towards each active hand's target (along the edge to the hand's own side where that
    passes the face, ``_RISE_HEAD_CLEAR``): where the level path's palms rise before they
    come straight up and in over the furniture.

    Over furniture above the shoulders each is as high above the shoulder as keeps it
    ``_LEVEL_MIN_EXTENSION`` of ``arm`` from it (the elbow not folded on the way up), and
    no higher than ``_RISE_BELOW`` under the furniture's top; each edge must leave
    ``_RISE_LEAST`` in front of the shoulder. Over furniture below the shoulders whose
    top is above a hand's start (``home`` (2, 3), start frame: the arms hang beside a
    machine's sill; given for insert and extract, and for the others where the arms
    hang), each is ``_RISE_OVER`` above
    that top, so the palm comes up in front of the edge and then in over it (an arc from
    the hip to a point in the furniture passes through its face); each edge must leave
    ``_RISE_LEAST_LOW``.
    None where neither applies to every active hand (the palms come down onto the
    furniture, or the arc clears it)."""
    if support is None:
        return None
    nx, ny, offset, top = support
    rise = np.zeros((2, 3))
    for k in active:
        flat = targets[k, :2] - sh1[k, :2]
        dh = float(np.linalg.norm(flat))
        toward = (nx * flat[0] + ny * flat[1]) / dh if dh > 1e-9 else 0.0
        low = top <= sh1[k, 2]
        if toward < 0.3 or (low and (home is None or top <= home[k, 2])):
            return None
        ahead = (offset - (nx * sh1[k, 0] + ny * sh1[k, 1])) / toward - _RISE_FRONT
        if ahead < (_RISE_LEAST_LOW if low else _RISE_LEAST):
            return None
        if low:
            rise[k, :2] = flat / dh * min(ahead, dh)
            rise[k, 2] = top + _RISE_OVER - sh1[k, 2]
            continue
        rise[k, :2] = flat / dh * min(ahead, dh)
        if head is not None:
            rise[k, :2] += _head_clear_shift(sh1, k, rise[k, :2], (nx, ny), head,
                                             _RISE_HEAD_CLEAR * stature / DEFAULT_STATURE)
        least = _LEVEL_MIN_EXTENSION * arm
        rise[k, 2] = min(np.sqrt(max(least ** 2 - float(np.sum(rise[k, :2] ** 2)), 0.0)),
                         top - sh1[k, 2] - _RISE_BELOW)
    return rise


def _with(rel: np.ndarray, active: tuple, points: np.ndarray) -> np.ndarray:
    """``rel`` (2, 3) with the ``active`` hands' rows from ``points`` (2, 3)."""
    out = rel.copy()
    out[list(active)] = points[list(active)]
    return out


def _segment_origin_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Distance of the origin from the segment a-b (points (3,))."""
    d = b - a
    s = float(np.clip(-np.dot(a, d) / max(float(np.dot(d, d)), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(a + s * d))


def _reach_times(task: str, dist: float, pitch1: float, drop1: float, H: float, level: bool,
                 duration: float | None, rng: np.random.Generator
                 ) -> tuple[float, float, float]:
    """Reach, hold and return times (s) of a hand task whose palm travels ``dist`` (m) into
    a posture of trunk flexion ``pitch1`` and pelvis drop ``drop1``."""
    jitter = rng.uniform(0.9, 1.1)
    t_reach = float(np.clip(0.5 + 0.55 * dist + 0.35 * pitch1 + 1.2 * drop1 / H, 0.6, 2.2))
    # never faster than people reach (Fitts' law) nor than a peak palm speed of
    # HAND_GOAL_PEAK_SPEED along the arced path (motion.timing)
    t_reach = max(t_reach, fitts_time(dist), min_move_time(
        _ARC_PATH_FACTOR * dist, HAND_GOAL_PEAK_SPEED * H / DEFAULT_STATURE) / 0.9)
    t_reach *= jitter * (_LEVEL_TIME if level else 1.0)
    t_ret = t_reach * rng.uniform(0.95, 1.05)
    holds = {"grasp": 0.3, "release": 0.3, "move": 0.3, "leftHand": 1.0, "rightHand": 1.0,
             "assemble": 3.0, "insert": 0.9, "extract": 0.9}
    hold = holds[task]
    if duration is not None:
        hold = float(duration) - t_reach - t_ret
        if hold < 0.1 + (0.6 if task in ("insert", "extract") else 0.0):
            raise ValueError(f"{task}: duration {duration:.2f} s is too short; this motion "
                             f"needs at least {t_reach + t_ret + 0.1:.2f} s")
    return t_reach, hold, t_ret


def _hand_keys(task: str, targets: np.ndarray, active: tuple, sh1: np.ndarray,
               rel_home: np.ndarray, rel_goal: np.ndarray, rel_pre: np.ndarray,
               times: tuple[float, float, float], level: bool,
               board: tuple[float, float, float] | None, H: float, arm: float,
               rise: np.ndarray | None = None
               ) -> tuple[list[tuple[float, np.ndarray]], float, frozenset[int]]:
    """Shoulder-to-palm keys (arrays (2, 3)) of a hand task, its contact time (s) and the
    legs its path takes straight (:func:`_level_keys`); ``times``: (t1 reach end, t2
    hold end, total), ``rel_pre``: where insert's push starts and extract's pull ends,
    ``rise``: :func:`_rise_points`."""
    t1, t2, total = times
    if task == "insert":
        push = min(0.5, 0.6 * (t2 - t1))
        keys = [(0.0, rel_home), (t1, rel_pre), (t1 + push, rel_goal), (t2, rel_goal),
                (total, rel_home)]
        if level:           # out the straight way it pushed in (PUSH_LEVEL_TASKS)
            keys.insert(-1, (t2 + (1.0 - _PUSH_IN_AT) * (total - t2), rel_pre))
        if level and rise is not None:     # up in front of the furniture's edge first
            rel_rise = _with(rel_home, active, rise)
            keys.insert(1, (0.5 * t1, rel_rise))
            keys.insert(-1, (t2 + (1.0 - 0.5 * _PUSH_IN_AT) * (total - t2), rel_rise))
            return keys, t1 + push, frozenset({1, len(keys) - 3})
        return keys, t1 + push, frozenset()
    if task == "extract":
        pull = min(0.5, 0.6 * (t2 - t1))
        keys = [(0.0, rel_home), (t1, rel_goal), (t2 - pull, rel_goal), (t2, rel_pre),
                (total, rel_home)]
        if level:           # in the straight way it pulls out (PUSH_LEVEL_TASKS)
            keys.insert(1, (_PUSH_IN_AT * t1, rel_pre))
        if level and rise is not None:     # up in front of the furniture's edge first
            rel_rise = _with(rel_home, active, rise)
            keys.insert(1, (0.5 * _PUSH_IN_AT * t1, rel_rise))
            keys.insert(-1, (t2 + 0.5 * (total - t2), rel_rise))
            return keys, t2, frozenset({1, len(keys) - 3})
        return keys, t2, frozenset()
    keys = [(0.0, rel_home), (t1, rel_goal), (t2, rel_goal), (total, rel_home)]
    if level and task in LEVEL_REGION_TASKS:
        keys, straight = _level_keys(targets, active, sh1, rel_home, rel_goal, 0.0, t1, t2,
                                     total, H, arm)
        return keys, t1, straight
    if task in ("grasp", "release", "move"):
        # Parts rest on surfaces: come down onto a target below the shoulder from
        # _APPROACH_LIFT above it, and lift off the same way.
        lift = np.zeros_like(rel_goal)
        for k in active:
            if targets[k][2] < sh1[k][2] - 0.1:
                lift[k, 2] = _APPROACH_LIFT
        if level:
            keys, straight = _level_keys(targets, active, sh1, rel_home, rel_goal,
                                         _APPROACH_LIFT, t1, t2, total, H, arm, board, rise)
            return keys, t1, straight
        if np.any(lift):
            rel_above = rel_goal + lift
            keys = [(0.0, rel_home), (0.7 * t1, rel_above), (t1, rel_goal), (t2, rel_goal),
                    (t2 + 0.3 * (total - t2), rel_above), (total, rel_home)]
    return keys, t1, frozenset()


def _hand_path(t: np.ndarray, keys: list[tuple[float, np.ndarray]],
               times: tuple[float, float, float], active: tuple, targets: np.ndarray,
               shoulders: np.ndarray, sh1: np.ndarray, st: _Start, level: bool,
               board: tuple[float, float, float] | None, dist: float, H: float, arm: float,
               rng: np.random.Generator, wide: float = 1.0,
               straight_legs: frozenset[int] = frozenset()) -> np.ndarray:
    """Shoulder-to-palm vectors (T, 2, 3) through ``keys`` at times ``t`` (T,), with a
    small seeded bow; ``times``: (reach end, hold end, total), ``shoulders`` (T, 2, 3):
    the moving shoulders, ``sh1`` (2, 3): at the reach's end; ``wide`` scales a low
    reach's swing outside the thigh; ``straight_legs``: legs (index of their first key)
    of the level path taken straight whatever their distance from the shoulder."""
    rel = _arc_keys(t, keys)
    if level:
        # Straight legs (an arc about the shoulder bulges forward, into the shelf), except
        # a leg to or from home passing the shoulder nearer than a folded elbow allows
        # (under a low board every leg: the arc would swing the hand into its edge).
        straight = _interp_keys(t, keys)
        least = _LEVEL_MIN_EXTENSION * arm
        for i, ((t0, v0), (t1_, v1)) in enumerate(itertools.pairwise(keys)):
            leg = (t >= t0) & (t <= t1_)
            for k in active:
                if board is not None or i in straight_legs \
                        or _segment_origin_distance(v0[k], v1[k]) >= least:
                    rel[leg, k] = straight[leg, k]
    # a small seeded bow of the hand path (outward and up), zero at every key pose (level
    # path: only between home and the turn point)
    t1, t2, total = times
    out_end, back_start = (keys[1][0], keys[-2][0]) if level else (t1, t2)
    s_out = _profile(t, [(0.0, 0.0), (out_end, 1.0)])
    s_back = _profile(t, [(back_start, 0.0), (total, 1.0)])
    bow = np.sin(np.pi * s_out) * (t <= out_end) + np.sin(np.pi * s_back) * (t >= back_start)
    for k in active:
        out_dir = np.array([0.0, 1.0 if k == 0 else -1.0, 0.6])
        out_dir /= np.linalg.norm(out_dir)
        amp = rng.uniform(0.02, 0.05) * min(1.0, dist / 0.5)
        # a hand going down past the thigh swings wide of it (no hand through the leg)
        amp += wide * _LOW_REACH_WIDE * H * float(np.clip((0.6 * H - targets[k][2]) / (0.15 * H),
                                                   0.0, 1.0))
        rel[:, k] += amp * bow[:, None] * out_dir
        if board is not None:
            # Between home and the turn point the palm goes straight in the world (the
            # body's own motion would swing a shoulder-relative path into the edge).
            away = (t <= out_end) | (t >= back_start)
            near = sh1[k] + keys[1][1][k]
            line = _interp_keys(t, [(0.0, st.hands[k]), (out_end, near), (back_start, near),
                                    (total, st.hands[k])])
            rel[away, k] = line[away] - shoulders[away, k] + amp * bow[away, None] * out_dir
    return rel


def _hand_orientation(task: str, active: tuple, st: _Start, t: np.ndarray,
                      times: tuple[float, float, float], rel_goal: np.ndarray,
                      level: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Palm directions and elbow poles (T, 2, 3): blended from the start pose's to the
    reaching posture's over the reach and back over the return (``times``: reach end,
    hold end, total; ``level``: see :func:`_goal_hand_dir`)."""
    t1, t2, total = times
    T = t.size
    s_hand = _interp_keys(t, [(0.0, 0.0), (t1, 1.0), (t2, 1.0), (total, 0.0)])
    hand_dir = np.broadcast_to(st.hand_dir, (T, 2, 3)).copy()
    elbow_pole = np.broadcast_to(st.elbow_pole, (T, 2, 3)).copy()
    for k in active:
        goal_dir = _goal_hand_dir(task, k, rel_goal[k], level)
        hd = (1 - s_hand)[:, None] * st.hand_dir[k] + s_hand[:, None] * goal_dir
        hand_dir[:, k] = hd / np.linalg.norm(hd, axis=-1, keepdims=True)
        elbow_pole[:, k] = ((1 - s_hand)[:, None] * st.elbow_pole[k]
                            + s_hand[:, None] * _goal_elbow_pole(k))
    return hand_dir, elbow_pole
