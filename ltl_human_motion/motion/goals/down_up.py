"""Posture task primitives: bend, stoop, kneel (one knee), sit, standUp and wait.

``bend`` flexes the trunk with nearly straight knees so that the head comes within chest
height of the floor while the buttocks stay above knee height; ``stoop`` bends the knees
until the buttocks are below knee height and flexes the trunk (Table I). ``sit`` ends
seated, ``standUp`` is sitting down played backwards, ``wait`` stands with a small sway.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.goals.body import (
    _KNEE_ON_FLOOR,
    _balance_shift,
    _frames,
    _kneel_legs,
    _Start,
    _trunk,
)
from ltl_human_motion.motion.goals.placement import reach_placement
from ltl_human_motion.motion.goals.tasks import (
    _J,
    _REACH_FRACTION,
    _SIDES,
    _arm_length,
    _bones,
    _fmt,
    _hand_targets,
    _posture_name,
    seat_height_range,
)
from ltl_human_motion.motion.goals.timelines import _arc_keys, _finish, _n_frames, _profile
from ltl_human_motion.motion.ik import min_jerk
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.motion.types import MotionPrimitive


def _bend_path(skeleton: Skeleton, st: _Start, rng: np.random.Generator, s: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """Pelvis (T, 3) and trunk pitch (T,) of bend at progress ``s`` (T,): head to 0.60 H
    (below chest height 0.72 H), knees nearly straight."""
    H = skeleton.stature
    pelvis = np.tile(st.pelvis, (s.shape[0], 1))
    head_off = skeleton.rest_positions()[_J["head"]] - skeleton.rest_positions()[0]
    want = 0.60 * H + rng.uniform(-0.02, 0.02) * H
    drop = 0.01 * H
    c = np.clip((want - (st.pelvis[2] - drop)) / np.linalg.norm(head_off), -1, 1)
    pitch1 = float(np.arccos(c))
    pitch = pitch1 * s
    pelvis[:, 2] -= drop * s
    p1 = np.array([[st.pelvis[0], st.pelvis[1], st.pelvis[2] - drop]])
    shift = _balance_shift(skeleton, p1, np.array([pitch1]), st)[0]
    pelvis[:, 0] += shift * s
    return pelvis, pitch


def _stoop_path(skeleton: Skeleton, st: _Start, rng: np.random.Generator, s: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """Pelvis (T, 3) and trunk pitch (T,) of stoop at progress ``s`` (T,): buttocks (hips)
    below knee height, trunk flexed forward."""
    H = skeleton.stature
    pelvis = np.tile(st.pelvis, (s.shape[0], 1))
    hip_h = 0.20 * H + rng.uniform(-0.01, 0.01) * H
    rest = skeleton.rest_positions()
    drop = st.pelvis[2] - (hip_h + (rest[0, 2] - rest[_J["l_hip"], 2]))
    pitch1 = float(0.85 + rng.uniform(-0.05, 0.05))
    p1 = np.array([[st.pelvis[0], st.pelvis[1], st.pelvis[2] - drop]])
    shift = _balance_shift(skeleton, p1, np.array([pitch1]), st)[0]
    pelvis[:, 2] -= drop * s
    pelvis[:, 0] += shift * s
    pitch = pitch1 * s
    return pelvis, pitch


def _kneel_path(skeleton: Skeleton, st: _Start, hand: str, t: np.ndarray, s: np.ndarray,
                times: tuple[float, float, float, float], ankles: np.ndarray,
                toes: np.ndarray, knee_pole: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pelvis (T, 3) and trunk pitch (T,) of kneeling on one knee (right by default,
    ``hand="l_hand"`` kneels on the left) at times ``t`` and progress ``s`` (T,);
    ``times`` = (t1, t2, t_up, total). Moves the kneeling leg's ankle, toe and knee pole
    (each (T, 2, 3)) in place."""
    H = skeleton.stature
    thigh = _bones(skeleton)[_J["l_knee"]]
    t1, t2, t_up, total = times
    k = 0 if hand in ("l_hand", "left", "l") else 1
    rest = skeleton.rest_positions()
    # the knee 0.36 thigh behind the start, the hip 0.97 thigh above it
    hip = np.array([-0.36 * thigh - np.sqrt(thigh ** 2 - (0.97 * thigh) ** 2), st.ankles[k, 1],
                    _KNEE_ON_FLOOR * H + 0.97 * thigh])
    ankle, toe, pole = (v[0, 0] for v in _kneel_legs(skeleton, hip[None, None])[:3])
    pel1 = hip - (rest[_J[f"{_SIDES[k]}_hip"]] - rest[0])
    # the moving foot lifts while it steps back
    # it moves only once lifted and lands before it stops, so it never slides over
    # the floor (the first and last 15 % of each step are rise and set-down)
    w0, w1 = 0.55 * t1, total - (t2 + 0.45 * t_up)
    s_foot = _profile(t, [(0.15 * w0, 0.0), (0.85 * w0, 1.0),
                          (t2 + 0.45 * t_up + 0.15 * w1, 1.0), (total - 0.15 * w1, 0.0)])
    tau = np.where(t < w0, t / w0, np.where(t > total - w1, (t - (total - w1)) / w1, 0.0))
    lift = 0.05 * H * np.sin(np.pi * tau) ** 2
    ankles[:, k] = st.ankles[k] + s_foot[:, None] * (ankle - st.ankles[k])
    ankles[:, k, 2] += lift
    toes[:, k] = st.toes[k] + s_foot[:, None] * (toe - st.toes[k])
    toes[:, k, 2] += lift
    knee_pole[:, k] = pole
    pelvis = st.pelvis + s[:, None] * (pel1 - st.pelvis)
    pitch = 0.15 * s
    return pelvis, pitch


def _low_reach(task: str, skeleton: Skeleton, st: _Start, t: np.ndarray,
               shoulders: np.ndarray, target: np.ndarray | None, hand: str,
               times: tuple[float, float, float], fps: float
               ) -> tuple[np.ndarray, np.ndarray | None, str]:
    """Hands (T, 2, 3) of a down-up task: resting relative to the shoulders (T, 2, 3),
    or reaching ``target`` (3,) in the low posture; also the checked target and the
    acting hand's name. ``times`` = (t1, t2, total)."""
    hands = shoulders + st.hand_rel
    if target is None:
        return hands, None, "none"
    t1, t2, total = times
    T = t.shape[0]
    target = np.asarray(target, dtype=np.float64)
    if target.shape != (3,):
        raise ValueError(f"target must have shape (3,), got {target.shape}")
    targets, active, hand_name = _hand_targets("grasp", target, hand if hand != "auto"
                                               else "auto")
    f1 = min(round(t1 * fps), T - 1)
    arm = _arm_length(skeleton)
    rel = np.broadcast_to(st.hand_rel, (T, 2, 3)).copy()
    for k in active:
        goal = targets[k] - shoulders[f1, k]
        if np.linalg.norm(goal) > _REACH_FRACTION * arm:
            raise ValueError(f"{task}: target {np.round(target, 3).tolist()} is out of reach "
                             f"from the {task} posture")
        rel[:, k] = _arc_keys(t, [(0.0, st.hand_rel[k]), (t1, goal), (t2, goal),
                                  (total, st.hand_rel[k])])
    return shoulders + rel, target, hand_name


def _down_up(task: str, skeleton: Skeleton, st: _Start, rng: np.random.Generator,
             duration: float | None, fps: float, target: np.ndarray | None,
             hand: str) -> MotionPrimitive:
    """bend, stoop and kneel: go down, stay, come back up."""
    jitter = rng.uniform(0.9, 1.1)
    t_down = {"bend": 1.1, "stoop": 1.3, "kneel": 1.7}[task] * jitter
    t_up = t_down * rng.uniform(1.0, 1.15)
    hold = 1.0 if duration is None else float(duration) - t_down - t_up
    if hold < 0.1:
        raise ValueError(f"{task}: duration {duration:.2f} s is too short; this motion needs "
                         f"at least {t_down + t_up + 0.1:.2f} s")
    total = t_down + hold + t_up
    T = _n_frames(total, fps)
    t = np.arange(T) / fps
    t1, t2 = t_down, t_down + hold
    s = _profile(t, [(0.0, 0.0), (t1, 1.0), (t2, 1.0), (total, 0.0)])
    ankles = np.broadcast_to(st.ankles, (T, 2, 3)).copy()
    toes = np.broadcast_to(st.toes, (T, 2, 3)).copy()
    knee_pole = np.broadcast_to(st.knee_pole, (T, 2, 3)).copy()
    if task == "bend":
        pelvis, pitch = _bend_path(skeleton, st, rng, s)
    elif task == "stoop":
        pelvis, pitch = _stoop_path(skeleton, st, rng, s)
    else:
        pelvis, pitch = _kneel_path(skeleton, st, hand, t, s, (t1, t2, t_up, total),
                                    ankles, toes, knee_pole)
    tr = _trunk(skeleton, pelvis, pitch)
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    hand_dir = np.broadcast_to(st.hand_dir, (T, 2, 3)).copy()
    elbow_pole = np.broadcast_to(st.elbow_pole, (T, 2, 3)).copy()
    hands, target, hand_name = _low_reach(task, skeleton, st, t, shoulders, target, hand,
                                          (t1, t2, total), fps)
    world = _frames(skeleton, st, t, pelvis, pitch, hands, hand_dir, elbow_pole, ankles, toes,
                    knee_pole)
    f1 = min(round(t1 * fps), T - 1)
    meta = {"contact_frame": f1, "hand": hand_name,
            "target": None if target is None else np.asarray(target).tolist(),
            "hold_frames": [f1, min(round(t2 * fps), T - 1)],
            "posture": "kneel" if task == "kneel" else _posture_name(world[f1], skeleton)}
    return _finish(f"{task}_{_fmt(target)}", task, world, st, fps,
                   f"goals.make_goal_primitive({task!r})", meta)


#: Nominal length of sitting down and of standing up from a seat, s (each varied by
#: +-8 %): a self-paced sit-to-stand of a healthy adult takes about 1.5-2.5 s (the
#: studies reviewed in Janssen et al. 2002, Phys Ther 82(9):866), the lowering to the
#: seat about as long; the earlier 1.5 s (1.38-1.62 s) was at the fast end.
SIT_DOWN_SECONDS = 1.8


STAND_UP_SECONDS = 1.9


def _sit(skeleton: Skeleton, st: _Start, rng: np.random.Generator, duration: float | None,
         fps: float, target: np.ndarray | None, nominal: float = SIT_DOWN_SECONDS
         ) -> tuple[np.ndarray, dict, np.ndarray]:
    """World frames (T, J, 3) of sitting down onto the seat point ``target`` (start
    frame), over ``duration`` or, if None, ``nominal`` seconds varied by +-8 %."""
    H = skeleton.stature
    lo, hi = seat_height_range(skeleton)
    if target is None:
        target = np.array([reach_placement("sit", 0.26 * H, skeleton)[0], 0.0, 0.26 * H])
    target = np.asarray(target, dtype=np.float64)
    if target.shape != (3,) or not np.all(np.isfinite(target)):
        raise ValueError(f"target must be a finite array of shape (3,), got {target.shape}")
    if not lo - 1e-9 <= target[2] <= hi + 1e-9:
        raise ValueError(f"sit: seat height {target[2]:.3f} m is outside [{lo:.3f}, {hi:.3f}] m "
                         f"for a {H:.2f} m worker")
    rest = skeleton.rest_positions()
    b = _bones(skeleton)
    leg = b[_J["l_knee"]] + b[_J["l_ankle"]]
    hip_z = target[2] + 0.055 * H
    pel1 = np.array([target[0], target[1], hip_z + (rest[0, 2] - rest[_J["l_hip"], 2])])
    for k in range(2):
        hip = pel1 + (rest[_J[f"{_SIDES[k]}_hip"]] - rest[0])
        if np.linalg.norm(hip - st.ankles[k]) > 0.999 * leg or target[0] > -0.02 * H:
            raise ValueError(f"sit: seat point {np.round(target, 3).tolist()} cannot be reached "
                             f"from the start position; it must be behind the worker within "
                             f"reach (see reach_placement)")
    t_down = (nominal if duration is None else float(duration)) * (
        rng.uniform(0.92, 1.08) if duration is None else 1.0)
    if t_down < 0.6:
        raise ValueError(f"sit: duration {t_down:.2f} s is too short (at least 0.6 s)")
    T = _n_frames(t_down, fps)
    t = np.arange(T) / fps
    s = min_jerk(t / t_down)
    # the hips move back early and down later; the trunk leans forward while descending
    s_back = min_jerk(np.clip(t / (0.75 * t_down), 0, 1))
    pelvis = np.empty((T, 3))
    pelvis[:, 0] = st.pelvis[0] + s_back * (pel1[0] - st.pelvis[0])
    pelvis[:, 1] = st.pelvis[1] + s * (pel1[1] - st.pelvis[1])
    pelvis[:, 2] = st.pelvis[2] + s * (pel1[2] - st.pelvis[2])
    lean = rng.uniform(0.45, 0.6)
    pitch = 0.12 * s + lean * np.sin(np.pi * s)
    tr = _trunk(skeleton, pelvis, pitch)
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    hands = shoulders + st.hand_rel
    hands[..., 0] += 0.08 * H * np.sin(np.pi * s)[:, None]     # arms swing forward a little
    world = _frames(skeleton, st, t, pelvis, pitch, hands,
                    np.broadcast_to(st.hand_dir, (T, 2, 3)).copy(),
                    np.broadcast_to(st.elbow_pole, (T, 2, 3)).copy())
    return world, {"target": target.tolist()}, target


def _sit_primitive(skeleton: Skeleton, st: _Start, rng: np.random.Generator,
                   duration: float | None, fps: float, target: np.ndarray | None
                   ) -> MotionPrimitive:
    """sit onto the seat point ``target`` (3,) (see :func:`_sit`)."""
    world, meta, tgt = _sit(skeleton, st, rng, duration, fps, target)
    meta.update({"contact_frame": world.shape[0] - 1, "hand": "none",
                 "posture": "seated", "hold_frames": [world.shape[0] - 1] * 2})
    return _finish(f"sit_{_fmt(tgt)}", "sit", world, st, fps,
                   f"goals.make_goal_primitive('sit', target={_fmt(tgt)})", meta,
                   start_exact=True, end_exact=False)


def _stand_up(skeleton: Skeleton, st: _Start, rng: np.random.Generator,
              duration: float | None, fps: float, target: np.ndarray | None
              ) -> MotionPrimitive:
    """standUp from the seat height of ``target`` (default 0.26 H): sitting down on a seat
    behind the standing pose, played backwards and re-rooted at the seated pelvis."""
    H = skeleton.stature
    seat_z = 0.26 * H if target is None else float(np.asarray(target, dtype=np.float64)[2])
    dist, _ = reach_placement("sit", seat_z, skeleton)
    world, _, _ = _sit(skeleton, st, rng, duration, fps, np.array([dist, 0.0, seat_z]),
                        nominal=STAND_UP_SECONDS)
    world = world[::-1].copy()
    world[..., :2] -= world[0, 0, :2]
    # Table I's condition (head above chest height) already holds for an upright seated
    # worker; the contact frame marks the end of rising: the pelvis at 95 % of its
    # standing height
    risen = np.nonzero(world[:, 0, 2] >= 0.95 * st.pelvis[2])[0]
    contact = int(risen[0]) if risen.size else world.shape[0] - 1
    meta = {"contact_frame": contact, "hand": "none", "target": [0.0, 0.0, seat_z],
            "posture": "upright", "hold_frames": [0, 0]}
    return _finish(f"standUp_{_fmt(np.array([0.0, 0.0, seat_z]))}", "standUp", world, st, fps,
                   f"goals.make_goal_primitive('standUp', seat height {seat_z:.3f})", meta,
                   start_exact=False, end_exact=True)


def _wait(skeleton: Skeleton, st: _Start, rng: np.random.Generator, duration: float | None,
          fps: float) -> MotionPrimitive:
    """Stand still with a small postural sway (under 1 cm) and a breathing-like arm drift."""
    total = 2.0 if duration is None else float(duration)
    T = _n_frames(total, fps)
    t = np.arange(T) / fps
    env = np.minimum(min_jerk(t / 0.4), min_jerk((total - t) / 0.4)) if total > 0.8 else \
        np.sin(np.pi * t / max(total, 1e-9)) ** 2
    f = rng.uniform(0.2, 0.35, size=2)
    ph = rng.uniform(0.0, 2 * np.pi, size=2)
    pelvis = np.tile(st.pelvis, (T, 1))
    pelvis[:, 0] += env * 0.004 * np.sin(2 * np.pi * f[0] * t + ph[0])
    pelvis[:, 1] += env * 0.006 * np.sin(2 * np.pi * f[1] * t + ph[1])
    pitch = env * 0.01 * np.sin(2 * np.pi * f[0] * t + ph[1])
    tr = _trunk(skeleton, pelvis, pitch)
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    world = _frames(skeleton, st, t, pelvis, pitch, shoulders + st.hand_rel,
                    np.broadcast_to(st.hand_dir, (T, 2, 3)).copy(),
                    np.broadcast_to(st.elbow_pole, (T, 2, 3)).copy())
    meta = {"contact_frame": T - 1, "hand": "none", "target": None, "hold_frames": [0, T - 1],
            "posture": "upright", "duration": total}
    return _finish(f"wait_{total:.2f}s", "wait", world, st, fps,
                   f"goals.make_goal_primitive('wait', duration={total:.2f})", meta)
