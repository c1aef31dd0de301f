"""Re-blending the junctions whose offset ramps broke a check of the final motion.

Offset blending (:mod:`~ltl_human_motion.planning.blend`) spreads each junction's pose
mismatch over the poses around it, and foot locking (:mod:`.footlock`) moves the legs,
both after the planner checked the poses. Where that moves a pose into an obstacle or
one body part into another, the junctions near those frames put their whole mismatch on
their other side, and where that is not enough foot locking is faded out around them;
where it makes a joint faster than its limit, the junctions near those frames spread it
over twice the time. The motion is then blended and verified again (at most
:data:`JUNCTION_REPAIRS` times).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.motion.biomechanics import (
    BiomechanicsLimits,
    frame_labels,
    self_penetration,
    speed_excess,
)
from ltl_human_motion.motion.ik import min_jerk
from ltl_human_motion.planning.blend import JUNCTION_FOOT_SPREAD_MAX
from ltl_human_motion.planning.verify import colliding_frames

#: Times a motion is blended again with repaired junctions.
JUNCTION_REPAIRS = 3
#: Factor on the windows of a junction near a joint faster than its limit, each repair.
JUNCTION_STRETCH = 2.0
#: The most a junction's windows are stretched, repair after repair.
MAX_STRETCH = JUNCTION_STRETCH ** JUNCTION_REPAIRS
#: Seconds around a frame that foot locking moved into an obstacle or through a body
#: part over which it is faded out, and the length of the fades on either side.
UNLOCK_HOLD = 0.1
UNLOCK_RAMP = 0.3


@dataclass
class JunctionRepairs:
    """Per junction (index ``i``: between segments ``i`` and ``i + 1``), the share of its
    mismatch the outgoing segment takes and the factor on its windows
    (:func:`~ltl_human_motion.planning.blend.concatenate`'s ``shares`` and
    ``stretch``), and the frames around which foot locking is faded out
    (:func:`unlock_weights`)."""

    shares: dict[int, float] = field(default_factory=dict)
    stretch: dict[int, float] = field(default_factory=dict)
    unlock: tuple[int, ...] = ()


def unlock_weights(frames: tuple[int, ...], n_frames: int, fps: float) -> np.ndarray:
    """How much of the unlocked motion to take at each frame, shape (n_frames,): 1 within
    :data:`UNLOCK_HOLD` of one of ``frames``, fading to 0 over :data:`UNLOCK_RAMP`
    (minimum jerk)."""
    w = np.zeros(n_frames)
    if not frames:
        return w
    t = np.arange(n_frames)
    gap = np.min(np.abs(t[:, None] - np.asarray(frames)[None]), axis=1) / fps
    return 1.0 - min_jerk(np.clip((gap - UNLOCK_HOLD) / UNLOCK_RAMP, 0.0, 1.0))


def repaired(report: dict, synth, cell, held: dict[str, np.ndarray] | None, stature: float,
             junctions: list[int], repairs: JunctionRepairs, wide: bool,
             limits: BiomechanicsLimits | None = None) -> JunctionRepairs | None:
    """The repairs after ``repairs`` for a motion ``synth`` whose verification ``report``
    failed: the junctions (centre frames ``junctions``) near colliding or
    self-penetrating frames move their mismatch off that side (:func:`shares_off`;
    ``wide`` as there), or where none is left to move foot locking is faded out around
    those frames; else the junctions near too fast frames are stretched. None when there
    is nothing left to change. ``limits``: the biomechanical limits verified against
    (default :class:`~ltl_human_motion.motion.biomechanics.BiomechanicsLimits`)."""
    pos = synth.motion.positions
    fps = synth.motion.fps
    blocked = np.zeros(len(pos), dtype=bool)
    if not report["collision"]["passed"]:
        blocked |= colliding_frames(synth, cell, held, stature)
    if not report.get("self_penetration", {"passed": True})["passed"]:
        blocked |= self_penetration(pos, stature)[0].max(axis=1) > 0.0
    if blocked.any():
        shares = shares_off(blocked, junctions, repairs.shares, fps, wide)
        if shares is not None:
            return JunctionRepairs(shares, dict(repairs.stretch), repairs.unlock)
        unlock = tuple(sorted(set(repairs.unlock) | {int(f) for f in np.flatnonzero(blocked)}))
        if unlock != repairs.unlock:
            return JunctionRepairs(dict(repairs.shares), dict(repairs.stretch), unlock)
    if report.get("joint_speed", {"passed": True})["passed"]:
        return None
    limits = limits or BiomechanicsLimits()
    fast = speed_excess(pos, fps, frame_labels(len(pos), synth.timeline), stature=stature,
                        limits=limits)
    window = round(JUNCTION_FOOT_SPREAD_MAX * fps)
    frames = np.flatnonzero(fast)
    stretch = dict(repairs.stretch)
    for i, c in enumerate(junctions):
        if frames.size and np.min(np.abs(frames - c)) <= window:
            stretch[i] = min(stretch.get(i, 1.0) * JUNCTION_STRETCH, MAX_STRETCH)
    if stretch == repairs.stretch:
        return None
    return JunctionRepairs(dict(repairs.shares), stretch, repairs.unlock)


def shares_off(hits: np.ndarray, junctions: list[int], shares: dict[int, float],
               fps: float, wide: bool) -> dict[int, float] | None:
    """Junction shares that move the mismatch of junctions near ``hits`` ((T,) of bool)
    onto their other side: the junction nearest each hit, or (``wide``) every junction
    within :data:`~ltl_human_motion.planning.blend.JUNCTION_FOOT_SPREAD_MAX` of one (a
    walk's junctions are a sixth of a second apart, and a foot's ramps reach over
    several). A junction whose outgoing side holds more of its hits than its incoming
    side gives the whole mismatch to the incoming one, and the other way round. None
    when no junction's share is left to change."""
    window = round(JUNCTION_FOOT_SPREAD_MAX * fps)
    frames = np.flatnonzero(hits)
    if not frames.size or not junctions:
        return None
    centres = np.asarray(junctions)
    owner = [np.flatnonzero(np.abs(centres - f) <= window) if wide
             else np.array([np.argmin(np.abs(centres - f))]) for f in frames]
    out = dict(shares)
    for i, c in enumerate(junctions):
        near = np.array([f for f, own in zip(frames, owner) if i in own
                         and abs(int(f) - c) <= window])
        if near.size and shares.get(i, 0.5) == 0.5:
            out[i] = 0.0 if np.sum(near < c) >= np.sum(near >= c) else 1.0
    return out if out != shares else None
