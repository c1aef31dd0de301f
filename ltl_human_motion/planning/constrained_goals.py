"""Goal motions from the whole-body program where the hand-shaped model's motion meets
an obstacle.

:func:`constrained_primitive` takes a goal primitive whose body, or part in hand,
comes into an obstacle, as the reference the worker's kinematic model tracks under
clearance, range-of-motion, speed and planted-feet constraints
(:func:`ltl_human_motion.motion.goals.optimizer.track_reference`), and returns the tracked
motion where it still reaches the task's target at contact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ltl_human_motion.motion.goals.kinematics import HeldPart
from ltl_human_motion.motion.goals.optimizer import (
    RETURN_SECONDS,
    TrackingResult,
    WholeBodyOptions,
    track_reference,
)
from ltl_human_motion.motion.goals.palm_path import PathRoom, clear_palm_path
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.types import MotionPrimitive, world_positions
from ltl_human_motion.scene.clearance import PartSet

__all__ = ["CONTACT_TOLERANCE", "TAKE_TOLERANCE", "PartSetField", "constrained_primitive",
           "constrained_transition", "contact_tolerance"]

#: How far (m) the tracked palm may be from the reference's at the contact and hold
#: frames for the motion to still do the task: where the part goes (insert, move, an
#: assembly or region reach) about a centimetre; where the hand takes a part (grasp,
#: extract: Table I's palm within ``eps`` = 5 cm of the part, the part then carried at
#: the hand's own offset) :data:`TAKE_TOLERANCE`.
CONTACT_TOLERANCE = 0.008
TAKE_TOLERANCE = 0.03


def contact_tolerance(task: str) -> float:
    """:data:`CONTACT_TOLERANCE` or, for grasp and extract, :data:`TAKE_TOLERANCE`."""
    return TAKE_TOLERANCE if task in ("grasp", "extract") else CONTACT_TOLERANCE


#: How far (m) any joint of the program's last frame may be from the reference's before
#: it is faded out (:func:`~ltl_human_motion.motion.goals.optimizer.track_reference`; the
#: bones stretch by as much, as in the goal models' own end blends).
END_TOLERANCE = 0.01
#: Seconds the program may take beyond the reference's end to come back to its last pose
#: (the reference holding it): kept clear of a low board on the way up, a tall worker's
#: thigh lags behind the reference's return and ended 14 cm from the standing pose the
#: next primitive starts in. Only a program still closing on that pose gets them: in the
#: scenario bench every one that had stopped (or moved away) still missed it after the
#: extra second (114 programs given it, 62 made it; 11 of the rest had stopped).
END_HOLD_SECONDS = 1.0
#: m/s below which a program has stopped closing on the pose it must end in.
STOPPED = 1e-3


@dataclass(frozen=True)
class PartSetField:
    """A cell's obstacle parts seen from a worker's start frame: floor pose (x, y, yaw)
    ``pose``; implements :class:`~ltl_human_motion.motion.goals.optimizer.ObstacleField`."""

    parts: PartSet
    pose: tuple[float, float, float]

    def _world(self, p: np.ndarray) -> np.ndarray:
        x, y, yaw = self.pose
        c, s = math.cos(yaw), math.sin(yaw)
        out = np.empty_like(p)
        out[:, 0] = c * p[:, 0] - s * p[:, 1] + x
        out[:, 1] = s * p[:, 0] + c * p[:, 1] + y
        out[:, 2] = p[:, 2]
        return out

    def near(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray, within: float
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(capsule, part, clearance) of every pair nearer than ``within``, (M,) each."""
        seg = np.stack([self._world(a), self._world(b)], axis=1)
        clear = self.parts.pair_clearance(seg, radii, exact_below=within)
        cap, part = np.nonzero(clear < within)
        return cap, part, clear[cap, part]

    def exact(self, a: np.ndarray, b: np.ndarray, radii: np.ndarray, part: np.ndarray
              ) -> np.ndarray:
        """Exact clearance (M,) of capsules (M, 3), (M, 3) to one part each (M,)."""
        return self.parts.exact_pairs(self._world(a), self._world(b), radii, part)


#: Fraction of the verifier's joint speed limits the program keeps to (its per-axis
#: bound lets a speed reach 1.22 times the value given).
SPEED_ROOM = 0.75
#: How far (m) beyond the verifier's self-penetration threshold the program keeps the
#: body's own capsule pairs.
SELF_MARGIN = 0.01


@dataclass(frozen=True)
class BodyPairs:
    """The verifier's self-penetration pairs (:mod:`.biomechanics`) as the program keeps
    them apart (:class:`~ltl_human_motion.motion.goals.constraints.SelfPairs`)."""

    ends_a: np.ndarray
    ends_b: np.ndarray
    least: np.ndarray


def program_options(kind: str, stature: float) -> WholeBodyOptions:
    """The whole-body program's options for goal task ``kind``: the verifier's joint speed
    limits (with :data:`SPEED_ROOM`), self-penetration pairs (with :data:`SELF_MARGIN`)
    and ranges of motion for a worker of ``stature``."""
    from ltl_human_motion.motion.biomechanics import (
        _PAIR_CAPSULES,
        _PAIR_ENDS,
        BiomechanicsLimits,
        _speed_limits,
    )
    from ltl_human_motion.motion.capsules import capsule_radii
    limits = BiomechanicsLimits()
    speeds = _speed_limits(1, [kind], limits, stature / limits.reference_stature)[0]
    r = capsule_radii(stature)
    a, b = _PAIR_CAPSULES
    pairs = BodyPairs(_PAIR_ENDS[0], _PAIR_ENDS[1], np.maximum(r[a], r[b]) + SELF_MARGIN)
    return WholeBodyOptions(speed_limits=tuple(float(v) * SPEED_ROOM for v in speeds),
                            self_pairs=pairs,
                            ranges=tuple((k, float(lo), float(hi))
                                         for k, (lo, hi) in sorted(limits.rom.items())))


def _primitive(mp: MotionPrimitive, world: np.ndarray) -> MotionPrimitive:
    """``mp`` with start-frame joint positions ``world`` (T, J, 3) (goal primitives keep
    their heading: yaw 0 throughout)."""
    root = np.zeros((len(world), 4))
    root[:, :3] = world[:, 0]
    root[:, :2] -= world[0, 0, :2]
    meta = dict(mp.meta)
    meta["whole_body"] = True
    return MotionPrimitive(name=mp.name + "_wb", task=mp.task, poses=world - world[:, :1],
                           root=root, fps=mp.fps, source=mp.source + " + whole-body program",
                           meta=meta)


def _palm_room(stature: float, options: WholeBodyOptions) -> float:
    """The clearance a palm path keeps: the hand's and forearm's capsule radius and the
    program's hand margin, m."""
    from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii
    radii = capsule_radii(stature)
    return float(max(r for c, r in zip(BODY_CAPSULES, radii, strict=True)
                     if c[0][2:] in ("hand", "palm", "lower_arm"))) + options.hand_margin


def clear_palms(ref: np.ndarray, tracked: tuple[str, ...], field_: PartSetField,
                contact: int, last_hold: int, room: PathRoom) -> np.ndarray | None:
    """The tracked palms' paths (T, len(tracked), 3) of reference ``ref`` (T, J, 3) with
    the way to the ``contact`` frame and the way back from the ``last_hold`` frame each
    remade clear of the obstacles (:func:`.motion.goals.palm_path.clear_palm_path`; the
    hold itself stays); None where they are clear already or no clear way was found
    (the program tracks the reference's palms)."""
    palms = ref[:, [JOINT_INDEX[j] for j in tracked]].copy()
    changed = False
    for k in range(len(tracked)):
        for lo, hi in ((0, contact), (last_hold, len(ref) - 1)):
            if hi - lo < 2:
                continue
            way = clear_palm_path(field_, palms[lo:hi + 1, k], room)
            if way is not None and not np.array_equal(way, palms[lo:hi + 1, k]):
                palms[lo:hi + 1, k] = way
                changed = True
    return palms if changed else None


def constrained_primitive(mp: MotionPrimitive, parts: PartSet,
                          pose: tuple[float, float, float], stature: float,
                          held: HeldPart | None = None, held_from: int = 0
                          ) -> tuple[MotionPrimitive | None, float, TrackingResult]:
    """The goal primitive ``mp`` (started at floor pose ``pose``) remade by the whole-body
    program among the obstacle ``parts``: the primitive, or None where the tracked palm
    misses the reference's by more than :func:`contact_tolerance` at the contact or hold
    frames, an obstacle is still within 0 or the end cannot be faded in; that miss (m);
    the program's result."""
    if mp.meta.get("hand") in (None, "none") or float(mp.meta.get("yaw_span", 0.0)) != 0.0 \
            or np.any(mp.root[:, 3] != 0.0):
        raise ValueError(f"{mp.name}: the whole-body program remakes hand goal primitives")
    ref = world_positions(mp)
    tracked = ("l_hand", "r_hand") if mp.meta["hand"] == "both" else (mp.meta["hand"],)
    hold = [int(f) for f in mp.meta.get("hold_frames", [])] \
        + [int(mp.meta.get("contact_frame", len(ref) - 1))]
    field_ = PartSetField(parts, tuple(map(float, pose)))
    options = program_options(mp.task, stature)
    palms = clear_palms(ref, tracked, field_, min(hold), max(hold),
                        PathRoom(_palm_room(stature, options)))

    def track(reference: np.ndarray, palms: np.ndarray | None) -> TrackingResult:
        return track_reference(reference, stature, field_, tracked=tracked, fps=mp.fps,
                               held=held, held_from=held_from, release_from=max(hold),
                               options=options, palms=palms,
                               give_up=(tuple(hold), contact_tolerance(mp.task)))

    result = track(ref, palms)
    miss = max(float(np.linalg.norm(result.positions[f, JOINT_INDEX[j]]
                                     - ref[f, JOINT_INDEX[j]]))
               for f in hold for j in tracked)
    if miss > contact_tolerance(mp.task) or result.least_clearance < 0.0:
        return None, miss, result
    if result.end_miss > END_TOLERANCE:
        if result.closing < STOPPED:
            return None, miss, result
        result = _with_more_time(track, ref, palms, round(END_HOLD_SECONDS * mp.fps), mp.fps)
        if result.end_miss > END_TOLERANCE or result.least_clearance < 0.0:
            return None, miss, result
    return _primitive(mp, result.positions), miss, result


def constrained_transition(mp: MotionPrimitive, parts: PartSet,
                           pose: tuple[float, float, float], stature: float
                           ) -> MotionPrimitive | None:
    """The empty-handed arm transition ``mp`` (both palms from one stance to the other,
    started at floor pose ``pose``) remade by the whole-body program among the obstacle
    ``parts``: the palms' way made clear of them (:func:`clear_palms`), the body kept
    clear, and the motion ending in the reference's last pose (where the next primitive
    starts); None where the program does not make it so. A worker who let go of a part
    over a desk brings the hands back over its edge, not through it."""
    meta = dict(mp.meta, hand="both", contact_frame=mp.n_frames - 1, hold_frames=[])
    made, _, _ = constrained_primitive(replace(mp, meta=meta), parts, pose, stature)
    if made is None:
        return None
    return replace(made, meta=dict(mp.meta, whole_body=True))


def _with_more_time(track, ref: np.ndarray, palms: np.ndarray | None, frames: int,
                    fps: float) -> TrackingResult:
    """``track`` (the program) of ``ref`` (T, J, 3) followed by ``frames`` frames holding
    its last pose (``palms`` (T, K, 3) likewise), cut at the first frame from T - 1 on
    within ``END_TOLERANCE`` of that pose: the motion takes the time it needs to end
    where the next primitive starts (``fps``: its frame rate). Its ``end_miss`` is the
    cut frame's distance."""
    def held(a: np.ndarray) -> np.ndarray:
        return np.concatenate([a, np.repeat(a[-1:], frames, axis=0)])

    longer = track(held(ref), None if palms is None else held(palms))
    # (the last RETURN_SECONDS are faded onto the pose: only the frames before count)
    solved = longer.positions[len(ref) - 1:len(ref) + frames - int(RETURN_SECONDS * fps)]
    off = np.abs(solved - ref[-1]).max(axis=(1, 2))
    within = np.flatnonzero(off <= END_TOLERANCE)
    if not within.size:
        return longer
    end = len(ref) - 1 + int(within[0])
    return replace(longer, positions=longer.positions[:end + 1], end_miss=float(off[within[0]]))
