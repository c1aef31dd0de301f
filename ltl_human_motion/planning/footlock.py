"""Foot locking of a whole blended motion: planted feet stay where they landed.

Blending primitives that come from different clips and placements, and the start and
stop primitives' time warp, leave small slides of the planted foot (foot skate). As in
the footskate clean-up of Kovar, Schreiner & Gleicher (SCA 2002), every stance of every
foot is detected on the final motion and its contact point is pinned; the leg is then
re-solved by two-bone IK from the unchanged hip, so bone lengths stay exact.

Per foot and frame the contact point is the foot joint nearer its rest height (heel =
ankle, ball = toe), with a hysteresis of ``CONTACT_SWITCH``. A stance is a run of frames
where that joint is within ``CONTACT_HEIGHT`` of its rest height above the floor and moves
horizontally slower than ``STANCE_SPEED``. Within a stance a flat foot keeps its heading
(it pivots about its lower joint), and the foot is translated (horizontally) so that its
pinned point does not move: the lower joint, or while heel and ball are within
``CONTACT_SWITCH`` of each other (the foot rolls) a blend of the two, so the pin passes
from heel to ball without a jump. After a stance the correction returns to zero over
``RELEASE`` seconds with the minimum-jerk profile, while the foot is in the air. Where the
leg cannot hold a grounded pin, the foot is lifted clear of the floor instead.
"""

from __future__ import annotations

import itertools
import math
from types import ModuleType

import numpy as np
from scipy.ndimage import maximum_filter1d, uniform_filter1d

from ltl_human_motion.kernel.segments import compiled_module
from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii
from ltl_human_motion.motion.ik import min_jerk, two_bone_ik
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton

__all__ = ["lock_feet"]

_J = JOINT_INDEX
#: Height above its rest height under which a foot joint can be in contact, m (as the
#: MOJO skate measure of :mod:`~ltl_human_motion.motion.quality`).
CONTACT_HEIGHT = 0.02
#: Horizontal speed under which a low foot joint is taken as planted, m/s (the swing foot
#: of the gait clips moves at 1-4 m/s; a planted one slides under 0.5 m/s).
STANCE_SPEED = 0.4
#: Fastest change of the applied correction, m/s (where the leg's reach shortens it).
MAX_CORRECTION_RATE = 1.0
#: Heading change (rad) of a flat planted foot the lock undoes in full; from there to
#: twice that it lets the foot pivot (a turn in place turns the feet).
MAX_TWIST = np.radians(25.0)
#: Largest correction of a stance, m: a foot that would have to be held back further is
#: stepping, not planted (a slow, low final step of a stop), so its stance ends there.
MAX_LOCK = 0.05
#: The same while the ball is the contact point and the heel is up (push-off), m: a ball
#: the motion slides forward as the foot leaves is held back this far at most, then
#: the foot leaves the floor (lifted clear). Holding it the full ``MAX_LOCK`` grew the
#: leg's correction at the slide's 0.3-0.5 m/s just as the knee flexes fastest in the
#: swing's start: the knee 5-10 % over its speed limit (issue 13).
MAX_LOCK_BALL = 0.02
#: Speed (m/s) under which a planted foot's contact point stands still, and the least
#: time (s) it must do so to anchor its stance there (:func:`_anchor`): the stand
#: primitives hold the feet exactly still (under 1 mm/s); a stance of a step is shorter
#: or slides throughout.
STILL_SPEED = 0.005
STILL_TIME = 0.25
#: Least time (s) a foot that shuffled on after its stance's pin reached ``MAX_LOCK``
#: must then stand still (``STILL_SPEED``) for that to be pinned as a stance of its own
#: (:func:`_next_stance`): the 0.07-0.1 s a stop's last flat shuffle stands before the
#: next step (S1 at 1.95 m, seed 4), not a slow moment of a walk (0.12 s let a
#: 0.5 m/s shuffle of a 1.95 m worker slide; a walk's extra stance took a 1.55 m
#: worker's knee 0.3 % over its limit).
SHUFFLE_STILL_TIME = 0.05
#: Time the foot takes to return to its own path after a stance, s.
RELEASE = 0.15
#: Height above its rest height a moving, unplanted foot is lifted to, m: just above the
#: contact height, so it neither slides over the floor nor counts as skating.
SWING_CLEARANCE = 1.2 * CONTACT_HEIGHT
#: Half-width (s) of the smoothing of that lift (it starts and ends this gradually).
LIFT_RAMP = 0.1
#: Horizontal miss (m) of a grounded contact point from its pin over which the leg is
#: taken as unable to hold it (the foot is then lifted clear there instead).
LOCK_MISS = 0.003
#: How much lower (m) the other foot joint must be for the contact to pass to it.
CONTACT_SWITCH = 0.003
#: Time (s) over which the heading lock of a flat planted foot fades fully in or out.
YAW_RAMP = 0.1
#: Half-width (s) of the smoothing of the knee's bend direction (the IK pole) of a locked
#: leg: without it a straight leg's knee jumped sideways at 3-4 m/s.
POLE_SMOOTH = 0.05
#: Least forward lean (m) of the knee's bend direction (the IK pole) of a locked leg in
#: front of the hip-ankle line, along the pelvis's facing (a knee bends forward; the
#: foot's own heading turns with a swinging foot). The gait clips
#: straighten the stance leg to a few degrees of hyperextension (the knee 1-2 cm behind
#: that line), where the smoothed pole lay near the line and flipped between frames:
#: the re-solved knee then bent backwards (-12 deg) and back at 3-4 m/s.
POLE_FORWARD = 0.03

#: Room (m) a swinging foot's bone axis keeps beyond the other leg's shank capsule as it
#: passes it (the self-penetration check of motion.biomechanics wants the axis outside
#: the capsule; blending and foot locking move the feet by millimetres afterwards).
FOOT_PASS_MARGIN = 0.005
#: Order of the feet moved clear of the other leg's shank (:func:`_pass_clear`), twice
#: round: a sideways shift gains less than its length where the gap is partly vertical,
#: and moving one leg can bring its shank nearer the other foot.
PASS_ORDER = (("l", "r"), ("r", "l")) * 2


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) of every run of True in ``mask`` (1-D), end exclusive."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _contact_joint(h: np.ndarray) -> np.ndarray:
    """Contact joint of every frame (T,) (0 = ankle, 1 = toe) from their heights over their
    rest heights (T, 2): the lower one, kept until the other is ``CONTACT_SWITCH`` lower
    (a flat foot's pin and pivot do not flicker between heel and ball)."""
    if not len(h):
        return np.zeros(0, dtype=np.int64)
    # the ball takes over where it is CONTACT_SWITCH lower, the heel where it is; in
    # between the contact stays (the last decided one, at first the lower joint)
    d = h[:, 0] - h[:, 1]
    decided = np.where(d > CONTACT_SWITCH, 1, np.where(-d > CONTACT_SWITCH, 0, -1))
    last = np.maximum.accumulate(np.where(decided >= 0, np.arange(len(h)), -1))
    first = int(np.argmin(h[0]))
    return np.where(last >= 0, decided[np.maximum(last, 0)], first).astype(np.int64)


def _stance(hc: np.ndarray, vc: np.ndarray) -> np.ndarray:
    """Stance frames (T,) of bool from the contact point's height over its rest height and
    horizontal speed (T,): low and slower than ``STANCE_SPEED`` to enter, slower than twice
    that to stay (no flicker)."""
    low = hc <= CONTACT_HEIGHT
    enter = low & (vc <= STANCE_SPEED)
    keep = low & (vc <= 2.0 * STANCE_SPEED)          # holds every entering frame
    # the runs of keep frames that hold an entering frame
    run = np.cumsum(np.diff(np.concatenate([[False], keep]).astype(np.int8)) > 0)
    entered = np.zeros(int(run[-1]) + 1 if len(run) else 1, dtype=bool)
    entered[run[enter]] = True
    return keep & entered[run]


def _keep_heading(joints: np.ndarray, h: np.ndarray, stance: np.ndarray, fps: float
                  ) -> np.ndarray:
    """The foot's joints (T, 2, 3) with a flat planted foot keeping the heading it landed
    with, pivoting about its lower joint (a blend of heel and ball while they are within
    ``CONTACT_SWITCH`` of each other).

    The lock fades out where the motion turns the foot further than ``MAX_TWIST`` (to
    nothing at twice that: a turn in place turns the feet), and its weight changes by at
    most 1 over ``YAW_RAMP``, reaching full weight when the foot becomes flat (the ball
    does not swing round as it comes down).
    """
    T = len(joints)
    w = np.zeros(T)
    ref = np.zeros((T, 2))
    for a, b in _runs(stance):
        flat = np.flatnonzero(np.all(h[a:b] <= CONTACT_HEIGHT, axis=1)) + a
        if not flat.size:
            continue
        kf = flat[0]
        r = joints[kf, 1, :2] - joints[kf, 0, :2]
        ref[a:b] = r
        cur = joints[flat, 1, :2] - joints[flat, 0, :2]
        twist = np.abs(np.arctan2(cur[:, 0] * r[1] - cur[:, 1] * r[0], cur @ r))
        w[flat] = np.clip(2.0 - twist / MAX_TWIST, 0.0, 1.0)
    # the lock is in full by the time the foot is flat: it fades in over YAW_RAMP before
    # (while the heel is down and the ball comes down) and out over YAW_RAMP after
    w = np.minimum(_decay_envelope(w, 1.0 / max(1.0, YAW_RAMP * fps)), stance.astype(float))
    out = joints.copy()
    idx = np.flatnonzero((w > 0) & stance)
    if not idx.size:
        return out
    fv = joints[idx, 1, :2] - joints[idx, 0, :2]
    hl = np.linalg.norm(fv, axis=-1, keepdims=True)
    cur = fv / np.maximum(hl, 1e-9)
    want = ref[idx] / np.maximum(np.linalg.norm(ref[idx], axis=-1, keepdims=True), 1e-9)
    d = (1.0 - w[idx, None]) * cur + w[idx, None] * want
    phi = np.arctan2(cur[:, 0] * d[:, 1] - cur[:, 1] * d[:, 0], np.sum(cur * d, -1))
    # the pivot slides from heel to ball as the ball becomes the lower joint, so the turned
    # foot never jumps (the pin then holds the contact joint where it is)
    beta = _roll_weight(h[idx])
    pivot = (1.0 - beta[:, None]) * joints[idx, 0, :2] + beta[:, None] * joints[idx, 1, :2]
    c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
    for j in range(2):
        r = joints[idx, j, :2] - pivot
        out[idx, j, 0] = pivot[:, 0] + c[:, 0] * r[:, 0] - s[:, 0] * r[:, 1]
        out[idx, j, 1] = pivot[:, 1] + s[:, 0] * r[:, 0] + c[:, 0] * r[:, 1]
    return out


def _roll_weight(h: np.ndarray) -> np.ndarray:
    """Share (T,) of the ball in the pinned point of a foot, from the heights of heel and
    ball over their rest heights (T, 2): 0 with the heel the lower joint by
    ``CONTACT_SWITCH`` or more, 1 with the ball, in between while the foot rolls."""
    return np.clip(0.5 + (h[:, 0] - h[:, 1]) / (2.0 * CONTACT_SWITCH), 0.0, 1.0)


def _anchor(cp: np.ndarray, fps: float) -> int:
    """Anchor frame of a stance from its contact point's positions (n, 2): the middle of
    its first still part at least ``STILL_TIME`` long (the standing part of a stop or a
    start, the pose the planner placed and checked: in a region, clear of obstacles; a
    task done standing there afterwards, such as a stoop, may shift the feet by
    millimetres);
    else the frame where the contact point is nearest its median position over the
    stance (the mid-stance of a step: a slide within it is split, not all undone one
    way)."""
    speed = np.zeros(len(cp))
    speed[1:] = np.linalg.norm(np.diff(cp, axis=0), axis=-1) * fps
    speed[0] = speed[min(1, len(cp) - 1)]
    for a, b in _runs(speed <= STILL_SPEED):
        if b - a >= STILL_TIME * fps:
            return (a + b) // 2
    return int(np.argmin(np.linalg.norm(cp - np.median(cp, axis=0), axis=-1)))


def _pin_offsets(joints: np.ndarray, h: np.ndarray, a: int, b: int, k: int) -> np.ndarray:
    """Horizontal offsets (b - a, 2) that hold the foot's pinned point still over frames
    ``a..b-1``, zero at frame ``k``: the lower of heel and ball, a blend of the two while
    their heights are within ``CONTACT_SWITCH`` (:func:`_roll_weight`). Each frame's
    offset cancels the pinned point's step from the frame before, so the pin passes from
    heel to ball without a jump."""
    beta = _roll_weight(h[a + 1:b])[:, None]
    step = np.diff(joints[a:b, :, :2], axis=0)                         # (n-1, 2, 2)
    # the pinned point's step into each frame; the offsets undo their sum from frame k
    pin_step = (1.0 - beta) * step[:, 0] + beta * step[:, 1]            # (n-1, 2)
    travelled = np.zeros((b - a, 2))
    np.cumsum(pin_step, axis=0, out=travelled[1:])
    return travelled[k - a] - travelled


def _trim_to_anchor(run_off: np.ndarray, stance: np.ndarray, a: int, b: int, k: int,
                    limit: np.ndarray | float = MAX_LOCK
                    ) -> tuple[np.ndarray, int, int]:
    """Keep only the frames around the anchor ``k`` of the stance [a, b) whose pin
    offsets ``run_off`` (b - a, 2) stay within ``limit`` (m, per frame (b - a,) or one
    for all); the others leave ``stance`` (T,) of bool, which is changed in place.
    Returns the kept offsets and their [a, b)."""
    big = np.linalg.norm(run_off, axis=-1) > limit
    if np.any(big):                     # keep the frames around the anchor only
        ok = ~big
        lo = k - a
        while lo > 0 and ok[lo - 1]:
            lo -= 1
        hi = k - a
        while hi < b - a - 1 and ok[hi + 1]:
            hi += 1
        stance[a:a + lo] = False
        stance[a + hi + 1:b] = False
        run_off = run_off[lo:hi + 1]
        a, b = a + lo, a + hi + 1
    return run_off, a, b


def _next_stance(hc: np.ndarray, vc: np.ndarray, a: int, b: int, fps: float
                 ) -> tuple[int, int] | None:
    """Where the frames [a, b) left over after a stance's pin reached its limit plant the
    foot again, standing: from the first frame slower than ``STANCE_SPEED`` to ``b``,
    where a still part (``STILL_SPEED``, ``SHUFFLE_STILL_TIME``) follows; else None.
    A flat foot shuffled forward a few centimetres without leaving the contact height
    (a stop's last small step) is one run of low frames: its first standing part is
    pinned, and the second would otherwise slide with nothing holding it. The caller
    starts ``a`` a release time after the first stance, so the correction passes
    between the two pins (:func:`_bridge_stances`) while the foot is lifted clear."""
    if b - a < SHUFFLE_STILL_TIME * fps:
        return None
    still = vc[a:b] <= STILL_SPEED
    if not any(e - s >= SHUFFLE_STILL_TIME * fps for s, e in _runs(still)):
        return None
    enter = np.flatnonzero((hc[a:b] <= CONTACT_HEIGHT) & (vc[a:b] <= STANCE_SPEED))
    return a + int(enter[0]), b


def _bridge_stances(disp: np.ndarray, weight: np.ndarray, n_rel: int) -> None:
    """Between two held stances closer than two release times (``n_rel`` frames each),
    pass the displacement ``disp`` (T, 2, 2) from the one to the other along the
    minimum-jerk profile, in place; ``weight`` (T,) is 1 on held frames."""
    held_runs = _runs(weight >= 1.0)
    for (_, b0), (a1, _) in itertools.pairwise(held_runs):
        if a1 - b0 < 2 * n_rel:
            u = min_jerk(np.arange(1, a1 - b0 + 1) / (a1 - b0 + 1))[:, None, None]
            disp[b0:a1] = disp[b0 - 1] + u * (disp[a1] - disp[b0 - 1])


def _swing_lift(h: np.ndarray, stance: np.ndarray, fps: float) -> np.ndarray:
    """Lift (T,) in metres of a foot that is low but not in stance, up to
    ``SWING_CLEARANCE`` above its rest height, ramped over ``LIFT_RAMP``; ``h`` is the
    (T, 2) height of ankle and toe above their rest heights."""
    h_min = h.min(axis=1)
    sliding = (h_min < SWING_CLEARANCE) & ~stance
    lift = np.where(sliding, SWING_CLEARANCE - h_min, 0.0)
    if np.any(lift > 0):
        width = max(1, round(LIFT_RAMP * fps))
        smooth = uniform_filter1d(maximum_filter1d(lift, 2 * width + 1), 2 * width + 1)
        lift = np.maximum(smooth, lift)
    return lift


def _foot_targets(ankle: np.ndarray, toe: np.ndarray, rest_h: tuple[float, float],
                  fps: float, floor_z: float, free: np.ndarray | None = None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Ankle and toe targets (T, 3) each of one foot: its contact point (the joint nearer
    its rest height, as the skate measure of :mod:`~ltl_human_motion.planning.
    biomechanics` takes it) pinned during its stances, a flat planted foot keeping its
    heading, and a foot that moves fast while low (a swing foot that would slide over the
    floor) lifted to ``SWING_CLEARANCE`` above its rest height.

    Each stance is anchored where the foot stands (:func:`_anchor`); the correction ramps
    in before the stance and out after it over ``RELEASE`` while the foot is in the air.
    Frames in ``free`` (T,) of bool are never stance frames (the leg cannot hold the pin
    there): a low foot is lifted clear instead.

    Returns
    -------
    ankle_target, toe_target : ndarray, shape (T, 3)
    contact : ndarray of int, shape (T,)
        The contact joint (0 = ankle, 1 = toe).
    stance : ndarray of bool, shape (T,)
    """
    T = len(ankle)
    joints = np.stack([ankle, toe], 1)                                   # (T, 2, 3)
    h = joints[:, :, 2] - floor_z - np.asarray(rest_h)                  # (T, 2)
    v = np.zeros((T, 2))
    if T > 1:
        v[1:] = np.linalg.norm(np.diff(joints[:, :, :2], axis=0), axis=-1) * fps
        v[0] = v[1]
    contact = _contact_joint(h)
    hc = h[np.arange(T), contact]
    stance = _stance(hc, v[np.arange(T), contact])
    if free is not None:
        stance &= ~free
    held = _keep_heading(joints, h, stance, fps)
    n_rel = max(1, round(RELEASE * fps))
    disp, weight = _lock_stances(held, joints, h, hc, v[np.arange(T), contact], contact,
                                 stance, fps, n_rel)
    # between two stances closer than two release times the correction passes from the
    # one to the other along the minimum-jerk profile (their ramps would meet in a step)
    _bridge_stances(disp, weight, n_rel)
    lift = _swing_lift(h, stance, fps)
    out = joints.copy()
    out[:, :, :2] += disp
    out[:, :, 2] += lift[:, None]
    return out[:, 0], out[:, 1], contact, stance


#: The constants :func:`_lock_stances` hands the compiled loop, in its order.
_STANCE_CONSTANTS = np.array([STILL_SPEED, STILL_TIME, MAX_LOCK, MAX_LOCK_BALL, CONTACT_SWITCH,
                              SHUFFLE_STILL_TIME, CONTACT_HEIGHT, STANCE_SPEED])


def _lock_stances(held: np.ndarray, joints: np.ndarray, h: np.ndarray, hc: np.ndarray,
                  vc: np.ndarray, contact: np.ndarray, stance: np.ndarray, fps: float,
                  n_rel: int) -> tuple[np.ndarray, np.ndarray]:
    """The displacement (T, 2, 2) of a foot's ankle and toe that pins every stance of
    ``stance`` (T,) of bool (changed in place: trimmed to the lock limits, a standing
    shuffle added) and ramps in and out over ``n_rel`` frames, and its weight (T,) (1 on
    held frames); ``held`` (T, 2, 3) are the joints with the heading kept, ``joints`` the
    foot's own, ``h`` (T, 2) their heights over their rest heights, ``hc``, ``vc`` (T,)
    the contact point's height and speed, ``contact`` (T,) the contact joint. The
    compiled loop where it is in use (the same numbers), else :func:`_lock_stances_numpy`."""
    T = len(held)
    ramp = min_jerk(np.arange(1, n_rel + 1) / (n_rel + 1))
    runs = _runs(stance)
    nb = _compiled()
    if nb is not None and np.isfinite(held).all() and np.isfinite(joints).all() \
            and np.isfinite(h).all() and np.isfinite(vc).all():
        starts = np.array([a for a, _ in runs], dtype=np.int64)
        ends = np.array([b for _, b in runs], dtype=np.int64)
        out_stance = stance.copy()
        disp, weight = np.zeros((T, 2, 2)), np.zeros(T)
        if nb.lock_stances(np.ascontiguousarray(held), np.ascontiguousarray(joints),
                           np.ascontiguousarray(h), np.ascontiguousarray(hc),
                           np.ascontiguousarray(vc), np.ascontiguousarray(contact,
                                                                          dtype=np.int64),
                           starts, ends, out_stance, ramp, float(fps), _STANCE_CONSTANTS,
                           disp, weight) == 0:
            stance[:] = out_stance
            return disp, weight
    return _lock_stances_numpy(held, joints, h, hc, vc, contact, stance, fps, n_rel, ramp,
                               runs)


def _lock_stances_numpy(held: np.ndarray, joints: np.ndarray, h: np.ndarray,
                        hc: np.ndarray, vc: np.ndarray, contact: np.ndarray,
                        stance: np.ndarray, fps: float, n_rel: int, ramp: np.ndarray,
                        runs: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_lock_stances` in Python and numpy (``ramp`` (n_rel,): the release
    profile; ``runs``: the stances' [a, b))."""
    T = len(held)
    disp = np.zeros((T, 2, 2))
    weight = np.zeros(T)
    runs = list(runs)
    while runs:
        a, b = runs.pop(0)
        k = a + _anchor(held[np.arange(a, b), contact[a:b], :2], fps)
        run_off = _pin_offsets(held, h, a, b, k)
        ball = _roll_weight(h[a:b]) >= 1.0
        end = b
        run_off, a, b = _trim_to_anchor(run_off, stance, a, b, k,
                                        np.where(ball, MAX_LOCK_BALL, MAX_LOCK))
        tail = _next_stance(hc, vc, b + n_rel, end, fps)
        if tail is not None:
            stance[tail[0]:tail[1]] = True
            runs.insert(0, tail)
        # continuous where the contact passes from heel to ball (the pin continues, the
        # heading's pivot slides), and not smoothed: it cancels the motion's slide exactly
        disp[a:b] = held[a:b, :, :2] - joints[a:b, :, :2] + run_off[:, None]
        weight[a:b] = 1.0
        for i, w in enumerate(ramp[::-1]):          # ramp in before, out after
            if a - 1 - i >= 0 and weight[a - 1 - i] < w:
                disp[a - 1 - i] = disp[a] * w
                weight[a - 1 - i] = w
            if b + i < T and weight[b + i] < w:
                disp[b + i] = disp[b - 1] * w
                weight[b + i] = w
    return disp, weight


def _unit3(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _compiled() -> ModuleType | None:
    return compiled_module("ltl_human_motion.planning._motion_numba")


def _decay_envelope(w: np.ndarray, step: float) -> np.ndarray:
    """``w`` (T,) raised so that no value falls by more than ``step`` per frame towards
    either end (a backward pass, then a forward pass)."""
    nb = _compiled()
    if nb is not None:
        return nb.decay_envelope(np.ascontiguousarray(w, dtype=np.float64), float(step))
    wl = w.tolist()                                 # plain floats: sequential loops
    for t in range(len(wl) - 2, -1, -1):
        wl[t] = max(wl[t], wl[t + 1] - step)
    for t in range(1, len(wl)):
        wl[t] = max(wl[t], wl[t - 1] - step)
    return np.array(wl, dtype=np.float64)


def _rate_limited(x: np.ndarray, step: float) -> np.ndarray:
    """``x`` (T, 3) with every frame-to-frame change at most ``step`` (forward and backward
    passes, so the result stays within ``x``'s envelope towards zero)."""
    if not len(x) or np.max(np.linalg.norm(np.diff(x, axis=0), axis=-1), initial=0.0) <= step:
        return x.copy()                 # no change is too fast
    nb = _compiled()
    if nb is not None:
        return nb.rate_limited(np.ascontiguousarray(x, dtype=np.float64), float(step))
    rows = x.tolist()                   # plain floats: this loop is sequential
    for order, back in ((range(1, len(rows)), 1), (range(len(rows) - 2, -1, -1), -1)):
        for t in order:
            px, py, pz = rows[t - back]
            cx, cy, cz = rows[t]
            dx, dy, dz = cx - px, cy - py, cz - pz
            n = math.sqrt(dx * dx + dy * dy + dz * dz)
            if n > step:
                k = step / n
                rows[t] = [px + dx * k, py + dy * k, pz + dz * k]
    return np.array(rows, dtype=np.float64).reshape(x.shape)


def lock_feet(positions: np.ndarray, fps: float, skeleton: Skeleton,
              floor_z: float = 0.0) -> np.ndarray:
    """Pin the planted feet of a whole motion (module docstring).

    Parameters
    ----------
    positions : ndarray, shape (T, J, 3)
        World positions on the canonical skeleton (z up).
    fps : float
    skeleton : Skeleton
    floor_z : float

    Returns
    -------
    ndarray, shape (T, J, 3)
        The same motion with the knees, ankles and toes moved; every bone keeps its length.
    """
    p = np.array(positions, dtype=np.float64, copy=True)
    if len(p) < 2:
        return p
    rest = skeleton.rest_positions()
    bones = skeleton.bone_lengths()
    for s in "lr":
        ank, toe = _J[f"{s}_ankle"], _J[f"{s}_toe"]
        rest_h = (rest[ank, 2], rest[toe, 2])
        ank_all, toe_all, contact, stance = _foot_targets(p[:, ank], p[:, toe], rest_h, fps,
                                                          floor_z)
        leg = _solve_leg(p, s, bones, ank_all, toe_all, fps)
        # where the leg could not hold a grounded contact point on its pin (the hip is too
        # far: a push-off the motion slides), the foot leaves the floor a little earlier
        got = np.stack([leg[1], leg[2]], 1)[np.arange(len(p)), contact]     # (T, 3)
        want = np.stack([ank_all, toe_all], 1)[np.arange(len(p)), contact]
        low = got[:, 2] - floor_z - np.asarray(rest_h)[contact] <= 0.5 * CONTACT_HEIGHT
        miss = stance & low & (np.linalg.norm(got[:, :2] - want[:, :2], axis=-1) > LOCK_MISS)
        if np.any(miss):
            free = maximum_filter1d(miss, 2 * max(1, round(0.025 * fps)) + 1)
            ank_all, toe_all, _, _ = _foot_targets(p[:, ank], p[:, toe], rest_h, fps,
                                                   floor_z, free)
            leg = _solve_leg(p, s, bones, ank_all, toe_all, fps)
        p[:, _J[f"{s}_knee"]], p[:, ank], p[:, toe] = leg
    for s, o in PASS_ORDER:
        rest_h = rest[[_J[f"{s}_ankle"], _J[f"{s}_toe"]], 2] + floor_z
        ank_t, toe_t = _pass_clear(p, s, o, fps, skeleton.stature, rest_h)
        if ank_t is not None:
            p[:, _J[f"{s}_knee"]], p[:, _J[f"{s}_ankle"]], p[:, _J[f"{s}_toe"]] = \
                _solve_leg(p, s, bones, ank_t, toe_t, fps)
    return p


def _segment_gaps(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Closest points of segments [p0, p1] and [q0, q1] (each (T, 3)): the vector (T, 3)
    from the second's closest point to the first's, and its length (T,)."""
    ends = [np.ascontiguousarray(x, dtype=np.float64) for x in (p0, p1, q0, q1)]
    nb = _compiled()
    if nb is not None and all(np.isfinite(x).all() for x in ends):
        gap, dist = np.empty((len(p0), 3)), np.empty(len(p0))
        nb.segment_gaps(*ends, gap, dist)
        return gap, dist
    return _segment_gaps_numpy(p0, p1, q0, q1)


def _segment_gaps_numpy(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_segment_gaps` in numpy (the compiled kernel's reference)."""
    u, v, w = p1 - p0, q1 - q0, p0 - q0
    a, b, c = np.sum(u * u, -1), np.sum(u * v, -1), np.sum(v * v, -1)
    d, e = np.sum(u * w, -1), np.sum(v * w, -1)
    den = a * c - b * b
    sp = np.where(den > 1e-12, np.clip((b * e - c * d) / np.maximum(den, 1e-12), 0, 1), 0.0)
    t = (b * sp + e) / np.maximum(c, 1e-12)
    sp = np.where(t < 0, np.clip(-d / np.maximum(a, 1e-12), 0, 1),
                  np.where(t > 1, np.clip((b - d) / np.maximum(a, 1e-12), 0, 1), sp))
    t = np.clip(t, 0, 1)
    gap = (p0 + sp[:, None] * u) - (q0 + t[:, None] * v)
    return gap, np.linalg.norm(gap, axis=-1)


def _slower_speed(ank: np.ndarray, toe: np.ndarray, fps: float) -> np.ndarray:
    """Horizontal speed (T,) of the slower of ``ank`` and ``toe`` (T, 3) into each frame
    (0 at the first)."""
    nb = _compiled()
    a, t = (np.ascontiguousarray(x, dtype=np.float64) for x in (ank, toe))
    if nb is not None and np.isfinite(a).all() and np.isfinite(t).all():
        speed = np.zeros(len(a))
        nb.slower_foot_speed(a, t, float(fps), speed)
        return speed
    return _slower_speed_numpy(a, t, fps)


def _slower_speed_numpy(a: np.ndarray, t: np.ndarray, fps: float) -> np.ndarray:
    """:func:`_slower_speed` in numpy (the compiled kernel's reference)."""
    speed = np.zeros(len(a))
    speed[1:] = np.min(np.linalg.norm(np.diff(np.stack([a, t], 1)[:, :, :2], axis=0),
                                      axis=-1), axis=1) * fps
    return speed


def _pass_clear(p: np.ndarray, s: str, o: str, fps: float, stature: float,
                rest_h: np.ndarray) -> tuple[np.ndarray | None, np.ndarray | None]:
    """Ankle and toe targets (T, 3) each that keep foot ``s`` ("l"/"r") of ``p`` (T, J, 3)
    clear of the other leg's (``o``) shank and foot while the foot swings past them, or
    (None, None) where it already is.

    The gait clips' narrow steps and turns, and the blends of their junctions, take a
    swinging foot through the standing leg's shank (self-penetration, issue 13): where
    the foot's bone axis comes within the shank's capsule radius plus
    ``FOOT_PASS_MARGIN`` of the shank's axis while heel and ball both move faster than
    ``STANCE_SPEED``, the foot is moved sideways away from the shank by what it lacks,
    the shift grown and smoothed over ``LIFT_RAMP`` (in and out while it swings), and
    applied in full once the foot is ``CONTACT_HEIGHT`` above the floor (none within half
    that: a foot on the floor does not slide). ``rest_h`` (2,) are the heights of the
    foot's ankle and toe standing on the floor.
    """
    names = [c[0] for c in BODY_CAPSULES]
    radii = capsule_radii(stature)
    ank, toe = p[:, _J[f"{s}_ankle"]], p[:, _J[f"{s}_toe"]]
    # the other leg's shank, and its foot (a foot crossing in front of the planted one
    # in a turn): whichever the foot lacks more room from
    lack, gap = np.zeros(len(p)), np.zeros((len(p), 3))
    for part, (a, b) in ((f"{o}_shank", ("knee", "ankle")), (f"{o}_foot", ("ankle", "toe"))):
        need = max(float(radii[names.index(part)]), float(radii[names.index(f"{s}_foot")])) \
            + FOOT_PASS_MARGIN
        g, dist = _segment_gaps(ank, toe, p[:, _J[f"{o}_{a}"]], p[:, _J[f"{o}_{b}"]])
        more = need - dist > lack
        lack = np.where(more, need - dist, lack)
        gap[more] = g[more]
    # swinging: heel and ball both move (a push-off's ankle moves about a planted ball)
    speed = _slower_speed(ank, toe, fps)
    lack = np.where(speed > STANCE_SPEED, lack, 0.0)
    if not np.any(lack > 0):
        return None, None
    # the sideways direction of each pass: away from the shank, horizontally, held over
    # the whole (widened) pass so the shift does not turn
    width = max(1, round(LIFT_RAMP * fps))
    span = maximum_filter1d(lack, 4 * width + 1) > 0
    away = np.zeros((len(p), 3))
    for a, b in _runs(span):
        hit = np.flatnonzero(lack[a:b] > 0) + a
        g = np.sum(gap[hit, :2] * lack[hit, None], axis=0)
        away[a:b, :2] = g / max(float(np.linalg.norm(g)), 1e-9)
    size = uniform_filter1d(maximum_filter1d(lack, 2 * width + 1), 2 * width + 1)
    up = np.min(np.stack([ank[:, 2], toe[:, 2]], 1) - rest_h, axis=1)
    air = np.clip(2.0 * up / CONTACT_HEIGHT - 1.0, 0.0, 1.0)
    shift = away * (np.maximum(size, lack) * air)[:, None]
    return ank + shift, toe + shift


def _solve_leg(p: np.ndarray, s: str, bones: np.ndarray, ank_all: np.ndarray,
               toe_all: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Knee, ankle and toe (T, 3) each of leg ``s`` ("l"/"r") of ``p`` (T, J, 3) moved
    towards the ankle and toe targets (T, 3) by two-bone IK from the unchanged hip."""
    hip, knee, ank, toe = (_J[f"{s}_{n}"] for n in ("hip", "knee", "ankle", "toe"))
    kn_out, an_out, to_out = p[:, knee].copy(), p[:, ank].copy(), p[:, toe].copy()
    nb = _compiled()
    if nb is not None and np.isfinite(p).all() and np.isfinite(ank_all).all() \
            and np.isfinite(toe_all).all():
        return _solve_leg_compiled(nb, p, s, bones, ank_all, toe_all, fps,
                                   (kn_out, an_out, to_out))
    moved = (np.any(np.abs(ank_all - p[:, ank]) > 1e-9, axis=1)
             | np.any(np.abs(toe_all - p[:, toe]) > 1e-9, axis=1))
    if not np.any(moved):
        return kn_out, an_out, to_out
    foot = p[moved, toe] - p[moved, ank]
    hip_p = p[moved, hip]
    leg = 0.995 * (bones[knee] + bones[ank])
    ank_t = ank_all[moved]
    toe_t = toe_all[moved]
    # Where the leg cannot reach the moved ankle (a straight stance leg late in the
    # stance), the heel rises: the ankle goes to the point nearest its target that is
    # within reach and a foot's length from the pinned toe (toe-off).
    reach = np.maximum(leg, np.linalg.norm(p[moved, ank] - hip_p, axis=-1))
    far = np.linalg.norm(ank_t - hip_p, axis=-1) > reach
    if np.any(far):
        leg = reach[far][:, None]
        f_len = float(bones[toe])
        ht = toe_t[far] - hip_p[far]
        D = np.linalg.norm(ht, axis=-1, keepdims=True)
        u = ht / np.maximum(D, 1e-9)
        x = np.clip((D * D + leg * leg - f_len * f_len) / (2.0 * np.maximum(D, 1e-9)),
                    -leg, leg)
        rho = np.sqrt(np.maximum(leg * leg - x * x, 0.0))
        c = hip_p[far] + u * x
        q = ank_t[far] - c
        q = q - np.sum(q * u, -1, keepdims=True) * u
        q /= np.maximum(np.linalg.norm(q, axis=-1, keepdims=True), 1e-9)
        new_ank = c + rho * q
        ok = (D[:, 0] <= leg[:, 0] + f_len) & (new_ank[:, 2] >= ank_t[far, 2])
        idx = np.flatnonzero(far)[ok]
        ank_t[idx] = new_ank[ok]
        toe_t[idx] = ank_t[idx] + f_len * _unit3(toe_t[idx] - ank_t[idx])
    # no correction changes faster than MAX_CORRECTION_RATE
    da = np.zeros((len(p), 3))
    dt = np.zeros((len(p), 3))
    da[moved] = ank_t - p[moved, ank]
    dt[moved] = toe_t - p[moved, toe]
    step = MAX_CORRECTION_RATE / fps
    target = p[moved, ank] + _rate_limited(da, step)[moved]
    toe_target = p[moved, toe] + _rate_limited(dt, step)[moved]
    # the knee bends towards where it was, and forward over the foot when the leg is
    # straight (then the old offset from the hip-ankle line is only noise)
    fwd = np.zeros_like(foot)
    fwd[:, :2] = foot[:, :2] / np.maximum(np.linalg.norm(foot[:, :2], axis=-1,
                                                         keepdims=True), 1e-9)
    # (smoothed over time: a nearly straight leg's offset is a few mm in any direction,
    # and the knee of a pin that shortens the leg swung sideways with it between frames)
    offset = p[:, knee] - 0.5 * (p[:, hip] + p[:, ank])
    offset = uniform_filter1d(offset, 2 * max(1, round(POLE_SMOOTH * fps)) + 1, axis=0,
                              mode="nearest")
    pole = offset[moved] + 0.01 * fwd
    facing = np.zeros_like(foot)
    facing[:, :2] = (p[moved, _J["l_hip"]] - p[moved, _J["r_hip"]])[:, 1::-1] * [1.0, -1.0]
    facing /= np.maximum(np.linalg.norm(facing, axis=-1, keepdims=True), 1e-9)
    lean = np.sum(pole * facing, axis=-1, keepdims=True)
    pole = pole + np.maximum(POLE_FORWARD - lean, 0.0) * facing
    kn, an = two_bone_ik(p[moved, hip], target, bones[knee], bones[ank], pole,
                         max_stretch=1.0)
    kn_out[moved] = kn
    an_out[moved] = an
    to_out[moved] = an + float(bones[toe]) * _unit3(toe_target - an)
    return kn_out, an_out, to_out


def _solve_leg_compiled(nb: ModuleType, p: np.ndarray, s: str, bones: np.ndarray,
                        ank_all: np.ndarray, toe_all: np.ndarray, fps: float,
                        out: tuple[np.ndarray, np.ndarray, np.ndarray]
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_solve_leg` by the compiled loops (the same numbers): ``out`` are the knee,
    ankle and toe (T, 3) each, copies of ``p``'s (finite), changed on the moved frames."""
    hip, knee, ank, toe = (_J[f"{s}_{n}"] for n in ("hip", "knee", "ankle", "toe"))
    T = len(p)
    pc = np.ascontiguousarray(p, dtype=np.float64)
    moved = np.empty(T, dtype=np.bool_)
    da, dt = np.empty((T, 3)), np.empty((T, 3))
    f_len = float(bones[toe])
    nb.leg_corrections(pc, hip, ank, toe, np.ascontiguousarray(ank_all, dtype=np.float64),
                       np.ascontiguousarray(toe_all, dtype=np.float64),
                       float(0.995 * (bones[knee] + bones[ank])), f_len, moved, da, dt)
    if not np.any(moved):
        return out
    # no correction changes faster than MAX_CORRECTION_RATE
    step = MAX_CORRECTION_RATE / fps
    da, dt = _rate_limited(da, step), _rate_limited(dt, step)
    offset = p[:, knee] - 0.5 * (p[:, hip] + p[:, ank])
    offset = uniform_filter1d(offset, 2 * max(1, round(POLE_SMOOTH * fps)) + 1, axis=0,
                              mode="nearest")
    l1, l2 = bones[knee], bones[ank]
    nb.leg_solve(pc, hip, knee, ank, toe, _J["l_hip"], _J["r_hip"], moved,
                 np.ascontiguousarray(da), np.ascontiguousarray(dt),
                 np.ascontiguousarray(offset, dtype=np.float64), float(l1), float(l2),
                 float(abs(l1 - l2) + 1e-6), float(1.0 * (l1 + l2)), f_len, POLE_FORWARD,
                 *out)
    return out
