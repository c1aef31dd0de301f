"""Foot locking of a whole blended motion: planted feet stay where they landed.

Blending primitives that come from different clips and placements, and the start and
stop primitives' time warp, leave small slides of the planted foot (foot skate). As in
the footskate clean-up of Kovar, Schreiner & Gleicher (SCA 2002), every stance of every
foot is detected on the final motion and its contact point is pinned; the leg is then
re-solved by two-bone IK from the unchanged hip, so bone lengths stay exact.

Per foot and frame the contact point is the foot joint nearer its rest height (heel =
ankle, ball = toe). A stance is a run of frames where that joint is within
``contact_height`` of its rest height above the floor and moves horizontally slower than
``stance_speed``. Within a stance the foot is translated (horizontally) so that the
contact point keeps the position it had when it became the contact point; when the
contact passes from heel to ball the new anchor continues the old offset, so nothing
jumps. After a stance the offset returns to zero over ``release`` seconds with the
minimum-jerk profile, while the foot is in the air.
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import maximum_filter1d, uniform_filter1d

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
MAX_TWIST = np.radians(10.0)
#: Largest correction of a stance, m: a foot that would have to be held back further is
#: stepping, not planted (a slow, low final step of a stop), so its stance ends there.
MAX_LOCK = 0.05
#: Time the foot takes to return to its own path after a stance, s.
RELEASE = 0.15
#: Height above its rest height a moving, unplanted foot is lifted to, m: just above the
#: contact height, so it neither slides over the floor nor counts as skating.
SWING_CLEARANCE = 1.2 * CONTACT_HEIGHT
#: Half-width (s) of the smoothing of that lift (it starts and ends this gradually).
LIFT_RAMP = 0.1


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, end) of every run of True in ``mask`` (1-D), end exclusive."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(np.int8), [0]])))
    return list(zip(edges[::2].tolist(), edges[1::2].tolist()))


def _foot_offsets(ankle: np.ndarray, toe: np.ndarray, rest_h: tuple[float, float],
                  fps: float, floor_z: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Offsets (T, 3) of one foot: horizontal ones pin its contact point during its
    stances, vertical ones lift a foot that moves fast while low (a swing foot that would
    slide over the floor) to ``SWING_CLEARANCE`` above its rest height.

    Each stance is anchored where its contact point is nearest its median position (the
    mid-stance of a step, the standing part of a stop or a start); the correction ramps
    in before the stance and out after it over ``RELEASE`` while the foot is in the air.

    Returns
    -------
    offset : ndarray, shape (T, 3)
    heading : ndarray, shape (T, 2)
        Horizontal ankle-to-toe direction a flat planted foot keeps (not normalized).
    heading_weight : ndarray, shape (T,)
        How much of it to apply (0 where the foot is free to turn).
    contact : ndarray of int, shape (T,)
        The contact joint of every frame (0 = ankle, 1 = toe).
    """
    T = len(ankle)
    joints = np.stack([ankle, toe], 1)                                   # (T, 2, 3)
    h = joints[:, :, 2] - floor_z - np.asarray(rest_h)                  # (T, 2)
    v = np.zeros((T, 2))
    if T > 1:
        v[1:] = np.linalg.norm(np.diff(joints[:, :, :2], axis=0), axis=-1) * fps
        v[0] = v[1]
    contact = np.argmin(h, axis=1)                                       # (T,)
    # a flat foot (both joints low) is held by the ball, so the pin never flickers and the
    # heel can rise about it (toe-off)
    contact[np.all(h <= CONTACT_HEIGHT, axis=1)] = 1
    hc = h[np.arange(T), contact]
    vc = v[np.arange(T), contact]
    low = hc <= CONTACT_HEIGHT
    # enter a stance under STANCE_SPEED, stay in it under twice that (no flicker)
    stance = low & (vc <= STANCE_SPEED)
    keep = low & (vc <= 2.0 * STANCE_SPEED)
    for t in range(1, T):
        stance[t] |= stance[t - 1] & keep[t]
    for t in range(T - 2, -1, -1):
        stance[t] |= stance[t + 1] & keep[t]
    offset = np.zeros((T, 2))
    weight = np.zeros(T)
    heading = np.zeros((T, 2))
    yaw_w = np.zeros(T)
    n_rel = max(1, round(RELEASE * fps))
    ramp = min_jerk(np.arange(1, n_rel + 1) / (n_rel + 1))
    for a, b in _runs(stance):
        # the anchor frame: where the contact point is nearest its median position over
        # the stance (a slide within the stance is split, not all undone one way)
        cp = joints[np.arange(a, b), contact[a:b], :2]
        k = a + int(np.argmin(np.linalg.norm(cp - np.median(cp, axis=0), axis=-1)))
        # per frame the lower joint is held at its position at the anchor frame
        off = joints[k, :, :2][None] - joints[a:b, :, :2]                # (n, 2, 2)
        run_off = off[np.arange(b - a), contact[a:b]]
        big = np.linalg.norm(run_off, axis=-1) > MAX_LOCK
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
        offset[a:b] = uniform_filter1d(run_off, size=9, axis=0, mode="nearest")
        weight[a:b] = 1.0
        # a flat planted foot keeps its heading (it pivots only with the heel up)
        flat = np.flatnonzero(np.all(h[a:b] <= CONTACT_HEIGHT, axis=1)) + a
        if flat.size:
            kf = flat[np.argmin(np.abs(flat - k))]
            ref = joints[kf, 1, :2] - joints[kf, 0, :2]
            heading[a:b] = ref
            cur = joints[flat, 1, :2] - joints[flat, 0, :2]
            twist = np.abs(np.arctan2(cur[:, 0] * ref[1] - cur[:, 1] * ref[0],
                                      cur @ ref))
            # a foot turned further than MAX_TWIST by the motion pivots (turns in place)
            yaw_w[flat] = np.clip(2.0 - twist / MAX_TWIST, 0.0, 1.0)
        for i, w in enumerate(ramp[::-1]):          # ramp in before, out after
            if a - 1 - i >= 0 and weight[a - 1 - i] < w:
                offset[a - 1 - i] = offset[a] * w
                weight[a - 1 - i] = w
            if b + i < T and weight[b + i] < w:
                offset[b + i] = offset[b - 1] * w
                weight[b + i] = w
    sliding = (hc < SWING_CLEARANCE) & ~stance
    lift = np.where(sliding, SWING_CLEARANCE - hc, 0.0)
    if np.any(lift > 0):
        width = max(1, round(LIFT_RAMP * fps))
        smooth = uniform_filter1d(maximum_filter1d(lift, 2 * width + 1), 2 * width + 1)
        lift = np.maximum(smooth, lift)
    yaw_w = uniform_filter1d(yaw_w, size=9, mode="nearest")
    return np.concatenate([offset, lift[:, None]], axis=1), heading, yaw_w, contact


def _unit3(v: np.ndarray) -> np.ndarray:
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)


def _rate_limited(x: np.ndarray, step: float) -> np.ndarray:
    """``x`` (T, D) with every frame-to-frame change at most ``step`` (forward and backward
    passes, so the result stays within ``x``'s envelope towards zero)."""
    out = x.copy()
    for order in (range(1, len(x)), range(len(x) - 2, -1, -1)):
        for t in order:
            prev = out[t - 1] if order.step == 1 else out[t + 1]
            d = out[t] - prev
            n = float(np.linalg.norm(d))
            if n > step:
                out[t] = prev + d * (step / n)
    return out


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
        hip, knee, ank, toe = (_J[f"{s}_{n}"] for n in ("hip", "knee", "ankle", "toe"))
        off, heading, yaw_w, contact = _foot_offsets(
            p[:, ank], p[:, toe], (rest[ank, 2], rest[toe, 2]), fps, floor_z)
        moved = np.any(np.abs(off) > 1e-9, axis=1) | (yaw_w > 0)
        if not np.any(moved):
            continue
        foot = p[moved, toe] - p[moved, ank]
        d = off[moved]
        d = d.copy()
        hip_p = p[moved, hip]
        leg = 0.995 * (bones[knee] + bones[ank])
        ank_t = p[moved, ank] + d
        toe_t = p[moved, toe] + d
        w = yaw_w[moved]
        turn = w > 0
        if np.any(turn):
            fv = toe_t[turn] - ank_t[turn]
            hl = np.linalg.norm(fv[:, :2], axis=-1, keepdims=True)
            cur = fv[:, :2] / np.maximum(hl, 1e-9)
            want = heading[moved][turn]
            want = want / np.maximum(np.linalg.norm(want, axis=-1, keepdims=True), 1e-9)
            dirn = (1 - w[turn, None]) * cur + w[turn, None] * want
            dirn /= np.maximum(np.linalg.norm(dirn, axis=-1, keepdims=True), 1e-9)
            on_toe = contact[moved][turn] == 1
            new_ank = ank_t[turn].copy()
            new_toe = toe_t[turn].copy()
            new_toe[:, :2] = np.where(on_toe[:, None], new_toe[:, :2],
                                      new_ank[:, :2] + dirn * hl)
            new_ank[:, :2] = np.where(on_toe[:, None], new_toe[:, :2] - dirn * hl,
                                      new_ank[:, :2])
            ank_t[turn], toe_t[turn] = new_ank, new_toe
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
        pole = p[moved, knee] - 0.5 * (p[moved, hip] + p[moved, ank]) + 0.01 * fwd
        kn, an = two_bone_ik(p[moved, hip], target, bones[knee], bones[ank], pole,
                             max_stretch=1.0)
        p[moved, knee] = kn
        p[moved, ank] = an
        p[moved, toe] = an + float(bones[toe]) * _unit3(toe_target - an)
    return p
