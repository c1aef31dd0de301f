"""Kneeling on both knees in a hand task: the feet's steps and the free hand's prop.

A reach under a low board that no crouch makes within the hips' range of motion is done
kneeling (:func:`.postures._kneel_set`): one foot steps back, then the other, both knees
go down and the trunk leans forward, a free palm propping it on the floor.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.goals.body import _kneel_legs, _Start
from ltl_human_motion.motion.goals.tasks import _J
from ltl_human_motion.motion.goals.timelines import _profile
from ltl_human_motion.motion.skeleton import Skeleton

#: Seconds to go down onto both knees (one foot steps back, that knee goes down, then the
#: other), as long again to get up: kneeling down and getting up take about as long as
#: a sit-to-stand, 1.5-3 s (issue 13's timing; Janssen et al. 2002 for sit-to-stand).
KNEEL_DOWN_SECONDS = 2.0


#: Phases of kneeling down (fractions of the time to the posture; getting up runs them
#: backwards): the first foot steps back as the pelvis goes half way down, the second
#: foot steps back, both knees go down, and the trunk leans forward. (With the pelvis
#: lower, the second foot passing under the hip folded the knee past 150 degrees.)
_KNEEL_FIRST_STEP = (0.03, 0.28)


_KNEEL_SECOND_STEP = (0.32, 0.62)


_KNEEL_PELVIS = ((0.0, 0.0), (0.30, 0.55), (0.62, 0.6), (0.90, 1.0))


_KNEEL_LEAN = ((0.62, 0.0), (1.0, 1.0))


#: Where a kneeling worker's free palm props the leaning trunk (fractions of stature):
#: this far in front of its shoulder, this high (on the floor, the palm's capsule above
#: it), or as low as the arm reaches; and this fraction of the way in from the shoulder
#: to the body's midline (under the chest: the palm outside the shoulder met the leg of
#: the shelf the other hand reached under).
_PROP_AHEAD = 0.0


_PROP_IN = 0.4


_PROP_HEIGHT = 0.03


#: Direction (wrist to palm) of the propping hand: forward, nearly flat on the floor.
_PROP_PALM = np.array([1.0, 0.0, -0.2]) / np.hypot(1.0, 0.2)


def _hangs(st: _Start, k: int) -> bool:
    """Whether hand ``k`` of the start pose hangs by the body (below the pelvis), free to
    prop a kneeling worker; not in the carry stance, where it may hold a part."""
    return bool(st.hands[k, 2] < st.pelvis[2])


def _prop_point(shoulder: np.ndarray, stature: float, arm: float) -> np.ndarray:
    """Where the free palm of a kneeling worker props the trunk, below ``shoulder``
    (..., 3, start frame) and in from it (:data:`_PROP_AHEAD`, :data:`_PROP_IN`,
    :data:`_PROP_HEIGHT`), shape (..., 3)."""
    prop = np.array(shoulder, dtype=np.float64)
    prop[..., 0] += _PROP_AHEAD * stature
    prop[..., 1] *= 1.0 - _PROP_IN
    prop[..., 2] = np.maximum(_PROP_HEIGHT * stature, prop[..., 2] - 0.95 * arm)
    return prop


def _prop_orientation(hand_dir: np.ndarray, elbow_pole: np.ndarray, lean: np.ndarray,
                      keep: tuple[int, ...]) -> None:
    """Turn the palm direction and elbow pole (each (T, 2, 3), in place) of the hands
    not in ``keep`` to a palm flat on the floor, pointing forward, and the elbow out and
    back, with the trunk's lean (T,) (:func:`_prop_point`)."""
    w = lean[:, None]
    for k in range(2):
        if k in keep:
            continue
        hd = (1.0 - w) * hand_dir[:, k] + w * _PROP_PALM
        hand_dir[:, k] = hd / np.linalg.norm(hd, axis=-1, keepdims=True)
        out = np.array([-1.0, 0.5 if k == 0 else -0.5, 0.0])
        elbow_pole[:, k] = (1.0 - w) * elbow_pole[:, k] + w * out


def _kneel_progress(skeleton: Skeleton, st: _Start, t: np.ndarray,
                    times: tuple[float, float, float], posture: tuple[float, float],
                    first: int) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, ...]]:
    """Kneeling down onto both knees and getting up at times ``t`` (T,): the pelvis's
    progress (T,) to the kneeling place (``posture`` = its drop and shift), the trunk
    lean's (T,), and the ankles, toes and knee poles (each (T, 2, 3)), the foot ``first``
    (0 left, 1 right) stepping back first and forward last. ``times`` = (down, rise,
    total): the body is down at ``down`` and starts getting up at ``rise``. A foot moves
    only while lifted (the first and last 15 % of its step are rise and set-down), so it
    never slides over the floor; at most one foot is off the floor at a time."""
    H = skeleton.stature
    down, rise, total = times
    tau = np.where(t <= down, t / down, np.where(t >= rise, (total - t) / (total - rise), 1.0))
    tau = np.clip(tau, 0.0, 1.0)
    drop, shift = posture
    pelvis1 = st.pelvis + np.array([shift, 0.0, -drop])
    hips1 = pelvis1 + skeleton.rest_positions()[[_J["l_hip"], _J["r_hip"]]] \
        - skeleton.rest_positions()[0]
    end = _kneel_legs(skeleton, hips1[None])[:3]
    T = t.size
    ankles = np.broadcast_to(st.ankles, (T, 2, 3)).copy()
    toes = np.broadcast_to(st.toes, (T, 2, 3)).copy()
    pole = np.broadcast_to(st.knee_pole, (T, 2, 3)).copy()
    for k, (a, b) in ((first, _KNEEL_FIRST_STEP), (1 - first, _KNEEL_SECOND_STEP)):
        w = b - a
        s_foot = _profile(tau, [(a + 0.15 * w, 0.0), (b - 0.15 * w, 1.0)])[:, None]
        lift = 0.05 * H * np.sin(np.pi * np.clip((tau - a) / w, 0.0, 1.0)) ** 2
        for arr, start, goal in ((ankles, st.ankles, end[0]), (toes, st.toes, end[1]),
                                 (pole, st.knee_pole, end[2])):
            arr[:, k] = start[k] + s_foot * (goal[0, k] - start[k])
        ankles[:, k, 2] += lift
        toes[:, k, 2] += lift
    return (_profile(tau, list(_KNEEL_PELVIS)), _profile(tau, list(_KNEEL_LEAN)),
            (ankles, toes, pole))
