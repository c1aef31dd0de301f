"""Goal primitives made by a body model: inverse kinematics plus posture rules.

There is no reachable real clip of reaching to a table, assembling, bending, stooping,
kneeling or sitting (see ``notes/data-sources.md``), so every goal primitive of Table I is
*made* on the canonical skeleton for the exact target:

* **Body model.** A pose is given by the pelvis position, a trunk flexion angle (spread
  over the lumbar and thoracic spine: 50 % below the spine joint, 85 % below the chest,
  100 % above), the ankle and toe positions of both feet, and the palm positions of both
  hands. Knees and elbows come from analytic two-bone IK (:func:`.ik.two_bone_ik`), so
  every bone keeps its canonical length in every frame.
* **Posture rules.** For hand targets the trunk flexion and the knee bend (pelvis drop)
  are chosen on a grid minimizing ``flexion^2 + (drop / 0.14 H)^2 + 0.5 (d / arm - 0.8)^2``
  subject to the hand being within 93 % of the arm's length from the shoulder, the legs
  being able to reach the planted feet, and balance. ``bend`` flexes the trunk with nearly
  straight knees so that the head comes within chest height of the floor while the
  buttocks stay above knee height; ``stoop`` bends the knees until the buttocks are
  below knee height and flexes the trunk (Table I).
* **Balance.** After a posture is chosen the pelvis is shifted back or forth until the
  whole-body centre of mass (Winter's segment masses, :func:`.ik.center_of_mass`) lies
  over the middle half of the support polygon of the feet.
* **Hand paths.** Between key poses the palm moves with the minimum-jerk profile (Flash &
  Hogan 1985). The shoulder-to-palm vector is interpolated (direction slerped, length
  interpolated) relative to the moving shoulder, so the path stays within reach and swings
  in an arc rather than through the shoulder, plus a small seeded outward/upward bow; the
  body posture leads the hand slightly.

All targets are in the primitive's **start frame**: the root's floor position at the
origin, facing +x, left = +y, z = height above the floor. Every goal primitive starts in
``start_pose`` (default: the standing pose gait start primitives begin with) and, except
``sit`` (ends seated) and ``standUp`` (starts seated), ends in it again.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from functools import lru_cache

import numpy as np

from ltl_human_motion.motion.gait import LIBRARY_FPS
from ltl_human_motion.motion.ik import center_of_mass, min_jerk, two_bone_ik
from ltl_human_motion.motion.ops import relative_root
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, Skeleton
from ltl_human_motion.motion.timing import fitts_time, min_move_time
from ltl_human_motion.motion.types import MotionPrimitive
from ltl_human_motion.vocabulary import HAND_TASKS

__all__ = [
    "GOAL_TASKS",
    "HAND_TASKS",
    "LOW_BOARD_HEIGHT",
    "PUSH_LEVEL_TASKS",
    "ObstacleClearance",
    "chest_height",
    "knee_height",
    "make_goal_primitive",
    "max_reach",
    "min_reach_height",
    "posture_clear",
    "reach_placement",
    "seat_height_range",
]

POSTURE_TASKS: tuple[str, ...] = ("bend", "stoop", "kneel", "sit", "standUp", "wait")
GOAL_TASKS: tuple[str, ...] = HAND_TASKS + POSTURE_TASKS

_J = JOINT_INDEX
_SIDES = ("l", "r")
_REACH_FRACTION = 0.93          # hand never further than this fraction of the arm length
_ASSEMBLE_HALF_GAP = 0.035      # m, hands either side of an assembly target
_INSERT_TRAVEL = 0.08           # m, straight push of insert / pull of extract
_MAX_TRAVEL = 0.3               # m, longest push or pull asked for (a forearm's length)
_APPROACH_LIFT = 0.08           # m, grasp/release/move come down onto low targets
#: Peak palm speed of a goal reach, m/s at 1.75 m: under the 2.5 m/s limit of
#: planning.biomechanics with room for the seeded bow and the body's own motion.
HAND_GOAL_PEAK_SPEED = 1.8
#: Fastest a hand or wrist of a model-made hand goal primitive moves over 1/30 s, m/s at
#: 1.75 m (scaled by stature): 10 % under the verifier's 2.5 m/s hand limit in goal tasks
#: (planning.biomechanics), room for the offset blending of its junctions.
HAND_RETIME_SPEED = 2.25
#: The same for an acting arm's elbow: 10 % under the verifier's 3.5 m/s for other
#: joints. The palm rising close in front of the body to a board above the shoulders
#: (:func:`_rise_points`) swings the elbow up faster than the palm moves.
ELBOW_RETIME_SPEED = 3.15
#: Length of the arced palm path (slerped about the shoulder, plus the bow and the
#: approach from above) over the straight distance.
_ARC_PATH_FACTOR = 1.35
#: Extra outward bow of the palm path for a target below the hips, fraction of stature
#: (full up to 0.45 H, none from 0.6 H): the hand passes outside the thigh.
_LOW_REACH_WIDE = 0.05
#: Factors on :data:`_LOW_REACH_WIDE` a hand task tries, in order, where the swing past the
#: thigh still passes the forearm through it (the thigh rises towards a deeply flexed
#: trunk; 1.75-1.95 m workers reaching near their feet from the carry stance).
_WIDER_SWINGS = (1.0, 2.0, 3.0)
#: Hand paths of ``make_goal_primitive``: ``"arc"`` swings the palm about the shoulder
#: straight to the target; ``"level"`` first brings it, near the body, to the height it
#: comes in at, then moves it in horizontally (over a shelf board's edge, under the
#: board above), and out the same way before the body straightens.
HAND_PATHS: tuple[str, ...] = ("arc", "level")
#: Tasks whose hand may take the level path (the palm comes in over a support).
LEVEL_PATH_TASKS: tuple[str, ...] = ("grasp", "release", "move")
#: Tasks whose ``"level"`` path makes the straight push (insert) or pull (extract) start
#: or end in front of the furniture under the target (a fixture in a machine's housing:
#: the 1.55 m worker's hand, coming up from the hip, hit the base's front edge).
PUSH_LEVEL_TASKS: tuple[str, ...] = ("insert", "extract")
#: Fraction of the reach time at which extract's level path is at the start of its
#: straight way in (the rest goes in straight, as the pull comes out); insert's comes
#: back out straight in the same fraction of its return time.
_PUSH_IN_AT = 0.6
#: Tasks whose hands may take the level path into a region (no part to come down onto):
#: the palms rise near the body to the target's height and come in over a bench top or
#: table edge below it instead of swinging up through its front (a short worker's hands
#: in the carry stance, and a part held in them, are below a 0.92 m bench top).
LEVEL_REGION_TASKS: tuple[str, ...] = ("assemble", "leftHand", "rightHand")
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
#: A board over a part this close above its grasp point (m) leaves no room for a palm
#: that points down as the arm does (the wrist a hand's length above it, in the board):
#: the palm comes in level (:func:`_goal_hand_dir`; a part in a shelf compartment).
_LEVEL_PALM_GAP = 0.25
#: Reach time of the level path over the arc's (its path is about this much longer).
_LEVEL_TIME = 1.3
#: Clearance (m) a reaching posture keeps between body parts at contact, over the
#: self-penetration check of planning.biomechanics (capsule axis outside the other
#: capsule): the seeded timing and the blend of the start pose move the arm by a few mm.
_SELF_CLEARANCE = 0.005
#: A board this low over a hand target (underside height above the floor, fraction of
#: stature; 0.63 m at 1.75 m) is below the shoulders of a stoop (0.7-0.9 m at 1.75 m,
#: measured on the under_shelf cell): the hand goes down in front of its edge and in
#: under it, from a deep crouch (:func:`make_goal_primitive`'s ``board``).
LOW_BOARD_HEIGHT = 0.36
#: Clearance (m) the contact posture of a reach under a low board keeps from the board
#: beyond the body's capsules (the seeded timing and the start pose's blend move the
#: body by a few cm).
_BOARD_CLEARANCE = 0.02
#: Horizontal distance of the under path's drop point in front of the board's edge, m
#: (the hand capsule's radius and a margin).
_BOARD_FRONT = 0.10
#: How much nearer the worker a low board's edge may be than where reach_placement puts
#: it, m: the walk ends within a few cm and degrees of the standing place, and the edge
#: across a turned worker comes nearer on one side.
_BOARD_PLACE_MARGIN = 0.04
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
#: Degrees the posture search keeps inside the hip and knee ranges of motion of
#: planning.biomechanics (blending and foot locking move the legs by a degree or two).
_ROM_MARGIN = 3.0
#: The elbow folds at most this far, radians: the range of motion's 150 deg less
#: ``_ROM_MARGIN`` (a hand path rising over a shelf's edge close to the shoulder folded a
#: 1.55 m worker's elbow to 151-164 deg; the wrist stays that far from the shoulder).
_ELBOW_MAX_FLEXION = float(np.radians(150.0 - _ROM_MARGIN))
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


def chest_height(skeleton: Skeleton) -> float:
    """Table I ``chestHeight``: the chest joint's height when standing."""
    return float(skeleton.rest_positions()[_J["chest"], 2])


def knee_height(skeleton: Skeleton) -> float:
    """Table I ``kneeHeight``: the knee joint's height when standing."""
    return float(skeleton.rest_positions()[_J["l_knee"], 2])


def seat_height_range(skeleton: Skeleton) -> tuple[float, float]:
    """Seat heights (m) ``sit`` can use: 0.20 H to 0.34 H."""
    return 0.20 * skeleton.stature, 0.34 * skeleton.stature


@lru_cache(maxsize=64)
def _bones(skeleton: Skeleton) -> np.ndarray:
    """``skeleton.bone_lengths()`` (J,), computed once per skeleton (read-only)."""
    b = skeleton.bone_lengths()
    b.flags.writeable = False
    return b


def _arm_length(skeleton: Skeleton) -> float:
    b = _bones(skeleton)
    return float(b[_J["l_elbow"]] + b[_J["l_wrist"]] + b[_J["l_hand"]])


def max_reach(task: str, skeleton: Skeleton) -> float:
    """Highest target (m above the floor) ``task`` can reach; for ``sit``/``standUp`` the
    highest seat. Tasks without a target (bend, stoop, kneel, wait) return ``inf``."""
    _check_task(task)
    if task in ("sit", "standUp"):
        return seat_height_range(skeleton)[1]
    if task in ("bend", "stoop", "kneel", "wait"):
        return float("inf")
    shoulder = skeleton.rest_positions()[_J["l_shoulder"], 2]
    return float(shoulder + 0.97 * _REACH_FRACTION * _arm_length(skeleton))


def min_reach_height(task: str, skeleton: Skeleton) -> float:
    """Lowest target height (m) for ``task`` (0 for hand tasks: the floor)."""
    _check_task(task)
    if task in ("sit", "standUp"):
        return seat_height_range(skeleton)[0]
    return 0.0


def _check_task(task: str) -> None:
    if task not in GOAL_TASKS:
        if task in ("walk", "carry"):
            raise ValueError(f"{task!r} is a gait task: use the gait library, not a goal "
                             f"primitive")
        raise ValueError(f"unknown goal task {task!r}; expected one of {', '.join(GOAL_TASKS)}")


# ------------------------------------------------------------------------ body model
def _rot_y(angle: np.ndarray) -> np.ndarray:
    """Rotations about +y, shape (..., 3, 3) for ``angle`` of shape (...)."""
    angle = np.asarray(angle, dtype=np.float64)
    c, s = np.cos(angle), np.sin(angle)
    out = np.zeros((*angle.shape, 3, 3))
    out[..., 0, 0] = c
    out[..., 0, 2] = s
    out[..., 1, 1] = 1.0
    out[..., 2, 0] = -s
    out[..., 2, 2] = c
    return out


#: Largest forward tilt of the pelvis in a crouch's trunk flexion, rad (20 degrees): past
#: it the lumbar spine bends alone. In a crouch the thighs already flex the hips; without
#: the cap a crouch with the trunk flexed to reach the floor folds them past their 125
#: degree range of motion (planning.biomechanics). The trunk's own flexion stays within
#: its 80 degrees (at most 63 at the posture search's largest pitch).
PELVIS_TILT_MAX = 0.35
#: Pelvis drops below standing, fractions of stature, between which the cap fades in: a
#: bend or a shallow crouch tilts the pelvis with the trunk; the hips pass 120 degrees
#: only from a drop of about 0.22 H (the posture grid at 1.55 and 1.75 m).
_CROUCH_DROP = (0.12, 0.22)
#: Cost added to a posture under a low board whose pelvis tilts in full (past the hips'
#: 125 degree range of motion at the depth such reaches take): larger than any capped
#: posture's, so it is taken only where none reaches.
_UNCAPPED_COST = 100.0
#: Cost added to a posture kneeling on both knees (:func:`_kneel_set`): a reach under a
#: low board that no crouch within the hips' range of motion makes is done kneeling,
#: sat back and leant forward (thighs near vertical, so the hips flex by the pelvis's
#: tilt and the sit-back only); before the full-tilt crouch, past that range.
_KNEEL_COST = 50.0
#: Largest trunk flexion of a kneeling reach, rad (92 degrees: the chest 78 degrees
#: forward, the head a few degrees past horizontal, peering under the board).
_KNEEL_PITCH_MAX = 1.6
#: Seconds to go down onto both knees (one foot steps back, that knee goes down, then the
#: other), as long again to get up: kneeling down and getting up take about as long as
#: a sit-to-stand, 1.5-3 s (issue 13's timing; Janssen et al. 2002 for sit-to-stand).
KNEEL_DOWN_SECONDS = 2.0
#: Height of a knee joint resting on the floor and of a kneeling leg's ankle (toes tucked
#: under), fractions of stature (:func:`_kneel_legs`).
_KNEE_ON_FLOOR = 0.026
_KNEELING_ANKLE = 0.075

_TRUNK = (("spine", "pelvis", 0.5), ("chest", "spine", 0.85), ("neck", "chest", 1.0),
          ("head", "neck", 1.0), ("l_clavicle", "chest", 1.0), ("l_shoulder", "l_clavicle", 1.0),
          ("r_clavicle", "chest", 1.0), ("r_shoulder", "r_clavicle", 1.0))


def _trunk(skeleton: Skeleton, pelvis: np.ndarray, pitch: np.ndarray,
           cap: bool | np.ndarray = True, hips: np.ndarray | None = None,
           kneel: bool | np.ndarray = False) -> np.ndarray:
    """Pelvis, spine, head, clavicles, shoulders and hips of frames (T,) -> (T, J, 3);
    ``cap`` (bool, or (T,) of bool): a crouch's pelvis tilts at most
    :data:`PELVIS_TILT_MAX` (a reach under a low board that no capped posture makes
    tilts it in full, past the hips' range of motion). In a crouch (a pelvis drop past
    ``_CROUCH_DROP[0]``) the hips turn with the pelvis's tilt; they keep the offsets
    ``hips`` (2, 3) from it where given (on a seat, which holds the thighs where they
    rest: :meth:`_Start.hips`), and their standing offsets where ``kneel`` (bool, or (T,)
    of bool: on the knees, which hold them while the trunk leans)."""
    capped = np.asarray(cap, dtype=bool)
    rest = skeleton.rest_positions()
    T = pelvis.shape[0]
    out = np.zeros((T, len(rest), 3))
    out[:, 0] = pelvis
    drop = (rest[0, 2] - pelvis[..., 2]) / skeleton.stature
    crouch = np.clip((drop - _CROUCH_DROP[0]) / (_CROUCH_DROP[1] - _CROUCH_DROP[0]), 0.0, 1.0)
    rot: dict[float, np.ndarray] = {}          # one rotation per distinct flexion fraction
    tilt = 0.5 * pitch
    for name, parent, frac in _TRUNK:
        j, p = _J[name], _J[parent]
        if frac not in rot:
            angle = frac * pitch
            if name == "spine":                 # the pelvis's own tilt (hip flexion)
                angle = angle - capped * crouch * np.maximum(angle - PELVIS_TILT_MAX, 0.0)
                tilt = angle
            rot[frac] = _rot_y(angle)
        out[:, j] = out[:, p] + rot[frac] @ (rest[j] - rest[p])
    # in a crouch the hips turn with the pelvis's tilt (standing bends keep them level)
    turn = _rot_y(crouch * tilt * ~np.asarray(kneel, dtype=bool)) if hips is None else None
    for k, name in enumerate(("l_hip", "r_hip")):
        out[:, _J[name]] = pelvis + (turn @ (rest[_J[name]] - rest[0]) if hips is None
                                     else hips[k])
    return out


def _body(skeleton: Skeleton, pelvis: np.ndarray, pitch: np.ndarray, ankles: np.ndarray,
          toes: np.ndarray, knee_pole: np.ndarray, hands: np.ndarray, hand_dir: np.ndarray,
          elbow_pole: np.ndarray, trunk: np.ndarray | None = None) -> np.ndarray:
    """Full pose of every frame.

    Parameters
    ----------
    pelvis : (T, 3); pitch : (T,); ankles, toes, knee_pole, hands, hand_dir, elbow_pole :
    (T, 2, 3) with index 0 = left, 1 = right.
    trunk : (T, J, 3), optional
        ``_trunk(skeleton, pelvis, pitch)`` if already computed (it is not modified).

    Returns
    -------
    ndarray, shape (T, J, 3)
    """
    b = _bones(skeleton)
    out = _trunk(skeleton, pelvis, pitch) if trunk is None else trunk.copy()
    for k, s in enumerate(_SIDES):
        hip, knee, ank, toe = (_J[f"{s}_{n}"] for n in ("hip", "knee", "ankle", "toe"))
        kn, an = two_bone_ik(out[:, hip], ankles[:, k], b[knee], b[ank], knee_pole[:, k],
                             max_stretch=1.0)
        out[:, knee], out[:, ank] = kn, an
        fdir = toes[:, k] - an
        out[:, toe] = an + b[toe] * fdir / np.linalg.norm(fdir, axis=-1, keepdims=True)
        sh, el, wr, ha = (_J[f"{s}_{n}"] for n in ("shoulder", "elbow", "wrist", "hand"))
        hd = hand_dir[:, k] / np.linalg.norm(hand_dir[:, k], axis=-1, keepdims=True)
        elbow, wrist = two_bone_ik(out[:, sh], hands[:, k] - b[ha] * hd, b[el], b[wr],
                                   elbow_pole[:, k], max_stretch=1.0,
                                   max_flexion=_ELBOW_MAX_FLEXION)
        out[:, el], out[:, wr], out[:, ha] = elbow, wrist, wrist + b[ha] * hd
    return out


class _Start:
    """Quantities of the start pose the model interpolates from."""

    def __init__(self, skeleton: Skeleton, start_pose: np.ndarray | None) -> None:
        rest = skeleton.rest_positions()
        if start_pose is None:
            p0 = rest.copy()
        else:
            p0 = np.asarray(start_pose, dtype=np.float64)
            if p0.shape != rest.shape or not np.all(np.isfinite(p0)):
                raise ValueError(f"start_pose must be a finite array of shape {rest.shape}, "
                                 f"got {p0.shape}")
            p0 = p0.copy()
            if np.linalg.norm(p0[0]) < 1e-6:       # root-relative pose: stand it on the floor
                feet = [_J[n] for n in ("l_ankle", "l_toe", "r_ankle", "r_toe")]
                p0[:, 2] += np.max(rest[feet, 2] - p0[feet, 2])
            p0[:, :2] -= p0[0, :2]
        self.pose = p0
        self.pelvis = p0[0].copy()
        self.ankles = np.stack([p0[_J["l_ankle"]], p0[_J["r_ankle"]]])
        self.toes = np.stack([p0[_J["l_toe"]], p0[_J["r_toe"]]])
        self.hands = np.stack([p0[_J["l_hand"]], p0[_J["r_hand"]]])
        self.shoulders = np.stack([p0[_J["l_shoulder"]], p0[_J["r_shoulder"]]])
        self.hand_rel = self.hands - self.shoulders
        hd = self.hands - np.stack([p0[_J["l_wrist"]], p0[_J["r_wrist"]]])
        self.hand_dir = hd / np.linalg.norm(hd, axis=-1, keepdims=True)
        self.elbow_pole = np.stack([p0[_J["l_elbow"]], p0[_J["r_elbow"]]]) - self.shoulders
        self.knee_pole = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
        self.seated = bool(p0[0, 2] < SEATED_PELVIS_MAX * skeleton.stature)

    def hips(self) -> np.ndarray | None:
        """The hips' offsets (2, 3) from the pelvis that a seated posture keeps, or None
        (standing: they turn with the pelvis, :func:`_trunk`)."""
        if not self.seated:
            return None
        return self.pose[[_J["l_hip"], _J["r_hip"]]] - self.pose[0]


#: A start pose whose pelvis is lower than this fraction of the stature is seated: above
#: the highest seat (0.34 H, :func:`seat_height_range`) by the pelvis joint's 0.085 H over
#: the seat (0.15 m at 1.75 m, measured on the sit model), below the standing 0.53 H.
SEATED_PELVIS_MAX = 0.45


def _support_x(ankles: np.ndarray, toes: np.ndarray, stature: float) -> tuple[float, float]:
    """Safe range of the centre of mass along x: the middle half of the feet's extent."""
    heel = float(np.min(ankles[..., 0])) - 0.035 * stature
    front = float(np.max(toes[..., 0])) + 0.01 * stature
    quarter = 0.25 * (front - heel)
    return heel + quarter, front - quarter


def _balance_shift(skeleton: Skeleton, pelvis: np.ndarray, pitch: np.ndarray,
                   st: _Start, hands: np.ndarray | None = None,
                   cap: bool | np.ndarray = True) -> np.ndarray:
    """Pelvis x shift (T,) that keeps the centre of mass over the feet (2 iterations)."""
    T = pelvis.shape[0]
    shift = np.zeros(T)
    lo, hi = _support_x(st.ankles, st.toes, skeleton.stature)
    if st.seated:
        # The seat bears the weight: the centre of mass may be anywhere from over it to
        # the feet (sliding the pelvis forward on it pushes the knees into a desk).
        lo = min(lo, float(st.pelvis[0]))
    for _ in range(3):
        pel = pelvis.copy()
        pel[:, 0] += shift
        tr = _trunk(skeleton, pel, pitch, cap, st.hips())
        sh = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
        hnd = sh + st.hand_rel if hands is None else hands
        pose = _body(skeleton, pel, pitch, np.broadcast_to(st.ankles, (T, 2, 3)),
                     np.broadcast_to(st.toes, (T, 2, 3)), np.broadcast_to(st.knee_pole,
                                                                          (T, 2, 3)),
                     hnd, np.broadcast_to(st.hand_dir, (T, 2, 3)),
                     np.broadcast_to(st.elbow_pole, (T, 2, 3)), tr)
        cx = center_of_mass(pose)[:, 0]
        shift += (np.clip(cx, lo, hi) - cx) / 0.8
    return shift


# ------------------------------------------------------------------- posture search
#: Target-independent part of :func:`_grid` per (skeleton, start pose); see :func:`_grid_base`.
_GRID_CACHE: dict[tuple, tuple[np.ndarray, ...]] = {}


def _grid_base(skeleton: Skeleton, st: _Start, low_board: bool = False
               ) -> tuple[np.ndarray, ...]:
    """The candidate postures of :func:`_grid`, which do not depend on the targets.

    Balance shifts, trunk poses, the posture cost and the leg/head feasibility depend only
    on the skeleton and the start pose, of which a worker has a few (walking and carrying
    stance), so they are computed once per pair and kept (read-only arrays). Under a low
    board (``low_board``) the capped postures, within the hip and knee ranges of motion,
    come with two more sets: kneeling on both knees (:func:`_kneel_set`, from a standing
    start), and the crouch with the pelvis tilted in full and the ranges not asked for
    (the deepest reach in under the board), at :data:`_UNCAPPED_COST` more, so that one
    is taken only where no other posture reaches.

    Returns
    -------
    P, D, shift, base_cost : ndarray, shape (C,)
    shoulders : ndarray, shape (C, 2, 3)
        Left and right shoulder of each candidate.
    feasible, capped, kneel : ndarray of bool, shape (C,)
        Whether the candidate can be taken; whether its pelvis tilt is capped; whether
        it kneels.
    """
    key = (skeleton, st.pose.tobytes(), low_board)
    hit = _GRID_CACHE.get(key)
    if hit is not None:
        return hit
    if low_board:
        full = _grid_set(skeleton, st, False)
        full[3][:] += _UNCAPPED_COST
        sets = [_grid_set(skeleton, st, True)] + ([] if st.seated
                                                  else [_kneel_set(skeleton, st)]) + [full]
        out = tuple(np.concatenate(arrays) for arrays in zip(*sets))
    else:
        out = _grid_set(skeleton, st, True)
    for arr in out:
        arr.flags.writeable = False
    if len(_GRID_CACHE) >= 32:
        _GRID_CACHE.clear()
    _GRID_CACHE[key] = out
    return out


def _grid_set(skeleton: Skeleton, st: _Start, cap: bool) -> tuple[np.ndarray, ...]:
    """One set of :func:`_grid_base`'s candidates: capped pelvis tilt within the hip and
    knee ranges of motion, or (not ``cap``) full tilt with the ranges not asked for."""
    H = skeleton.stature
    b = _bones(skeleton)
    leg = b[_J["l_knee"]] + b[_J["l_ankle"]]
    pitch_v = np.linspace(0.0, 1.45, 30)
    drop_v = np.linspace(0.0, 0.36 * H, 25)
    P, D = np.meshgrid(pitch_v, drop_v, indexing="ij")
    P, D = P.ravel(), D.ravel()
    pelvis = np.tile(st.pelvis, (P.size, 1))
    pelvis[:, 2] -= D
    shift = _balance_shift(skeleton, pelvis, P, st, cap=cap)
    pelvis[:, 0] += shift
    tr = _trunk(skeleton, pelvis, P, cap, st.hips())
    cost = P ** 2 + (D / (0.14 * H)) ** 2
    feasible = np.ones(P.size, bool)
    for k, s in enumerate(_SIDES):
        hip = tr[:, _J[f"{s}_hip"]]
        d = np.linalg.norm(hip - st.ankles[k], axis=-1)
        feasible &= (d <= leg * 1.0000001) & (d >= 0.30 * leg)
    # the head must not go below the hands' height band (no diving into the floor)
    feasible &= tr[:, _J["head"], 2] > 0.12 * H
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    if cap:
        feasible &= _legs_in_range(skeleton, st, pelvis, P, tr, shoulders)
    return P, D, shift, cost, shoulders, feasible, np.full(P.size, cap), np.zeros(P.size, bool)


def _standing_legs(st: _Start, C: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The start pose's ankles, toes and knee poles for C postures, each (C, 2, 3)."""
    return (np.broadcast_to(st.ankles, (C, 2, 3)), np.broadcast_to(st.toes, (C, 2, 3)),
            np.broadcast_to(st.knee_pole, (C, 2, 3)))


def _posture_legs(skeleton: Skeleton, st: _Start, trunk: np.ndarray,
                  kneel: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Ankles, toes and knee poles (each (C, 2, 3)) of postures with trunks (C, J, 3):
    the start pose's, or where ``kneel`` ((C,) of bool) on both knees
    (:func:`_kneel_legs`)."""
    C = trunk.shape[0]
    legs = _standing_legs(st, C)
    if kneel is None or not np.any(kneel):
        return legs
    hips = np.stack([trunk[:, _J["l_hip"]], trunk[:, _J["r_hip"]]], 1)
    knelt = _kneel_legs(skeleton, hips)[:3]
    on = np.asarray(kneel, dtype=bool)[:, None, None]
    return tuple(np.where(on, k, s) for k, s in zip(knelt, legs))


def _legs_in_range(skeleton: Skeleton, st: _Start, pelvis: np.ndarray, pitch: np.ndarray,
                   trunk: np.ndarray, shoulders: np.ndarray,
                   legs: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
                   ) -> np.ndarray:
    """Whether the hips and knees of postures (C,) (pelvis (C, 3), pitch (C,), their
    trunk (C, J, 3) and shoulders (C, 2, 3); ``legs``: ankles, toes and knee poles (each
    (C, 2, 3)), default the start pose's) stay within the biomechanical range of motion
    less :data:`_ROM_MARGIN` (a deep crouch with a flexed trunk folds the hip past
    125 degrees), shape (C,) of bool."""
    from ltl_human_motion.planning.biomechanics import BiomechanicsLimits, joint_angles
    C = pitch.size
    legs = _standing_legs(st, C) if legs is None else legs
    poses = _body(skeleton, pelvis, pitch, *legs,
                  shoulders + st.hand_rel, np.broadcast_to(st.hand_dir, (C, 2, 3)),
                  np.broadcast_to(st.elbow_pole, (C, 2, 3)), trunk)
    angles = joint_angles(poses, [f"{s}_{n}" for s in _SIDES
                                  for n in ("hip_flexion", "knee_flexion")])
    rom = BiomechanicsLimits().rom
    ok = np.ones(C, bool)
    for s in _SIDES:
        for name in ("hip_flexion", "knee_flexion"):
            lo, hi = rom[name]
            a = angles[f"{s}_{name}"]
            ok &= (a >= lo + _ROM_MARGIN) & (a <= hi - _ROM_MARGIN)
    return ok


def _kneel_legs(skeleton: Skeleton, hips: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Feet of kneeling on both knees under hips (C, 2, 3): each knee on the floor in
    front of its hip (a thigh's length from it), the shank back from it to the ankle,
    the toes tucked under on the floor (as :func:`_kneel_path`'s kneeling leg). Returns
    ankles, toes, knee poles (each (C, 2, 3)) and whether both knees reach the floor
    (C,) of bool."""
    H = skeleton.stature
    b = _bones(skeleton)
    thigh, shank, foot = b[_J["l_knee"]], b[_J["l_ankle"]], b[_J["l_toe"]]
    knee_z, ankle_z = _KNEE_ON_FLOOR * H, _KNEELING_ANKLE * H
    toe_z = skeleton.rest_positions()[_J["l_toe"], 2]
    above = hips[..., 2] - knee_z
    ok = np.all((above <= thigh) & (above > 0.0), axis=-1)
    knee = hips.copy()
    knee[..., 0] += np.sqrt(np.clip(thigh ** 2 - above ** 2, 0.0, None))
    ankles = knee.copy()
    ankles[..., 0] -= np.sqrt(shank ** 2 - (ankle_z - knee_z) ** 2)
    ankles[..., 2] = ankle_z
    toes = ankles.copy()
    toes[..., 0] += np.sqrt(foot ** 2 - (ankle_z - toe_z) ** 2)
    toes[..., 2] = toe_z
    pole = np.broadcast_to(np.array([0.35, 0.0, -1.0]), hips.shape).copy()
    return ankles, toes, pole, ok


def _kneel_set(skeleton: Skeleton, st: _Start) -> tuple[np.ndarray, ...]:
    """Kneeling candidates of :func:`_grid_base` (its return values): trunk flexion up to
    :data:`_KNEEL_PITCH_MAX`, the hips from a thigh's length over the knees (upright) to
    sat back 60 degrees, the knees from 0.1 m behind to 0.4 m in front of the standing
    ankles; within the hip and knee ranges of motion (:data:`_ROM_MARGIN`), the head
    clear of the floor. Cost: :data:`_KNEEL_COST`, the trunk flexion and the feet's
    steps back."""
    H = skeleton.stature
    b = _bones(skeleton)
    thigh = b[_J["l_knee"]]
    rest = skeleton.rest_positions()
    hip_z = rest[_J["l_hip"], 2] - rest[0, 2]
    P, A, K = (a.ravel() for a in np.meshgrid(
        np.linspace(0.0, _KNEEL_PITCH_MAX, 33),
        thigh * np.cos(np.radians(np.linspace(0.0, 60.0, 13))),
        np.linspace(-0.1, 0.4, 6), indexing="ij"))
    pelvis = np.tile(st.pelvis, (P.size, 1))
    pelvis[:, 2] = _KNEE_ON_FLOOR * H + A - hip_z
    pelvis[:, 0] = float(st.ankles[:, 0].mean()) + K - np.sqrt(thigh ** 2 - A ** 2)
    D, shift = st.pelvis[2] - pelvis[:, 2], pelvis[:, 0] - st.pelvis[0]
    tr = _trunk(skeleton, pelvis, P, False, kneel=True)
    ankles, toes, pole, feasible = _kneel_legs(
        skeleton, np.stack([tr[:, _J["l_hip"]], tr[:, _J["r_hip"]]], 1))
    feasible &= tr[:, _J["head"], 2] > 0.12 * H
    shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)
    feasible &= _legs_in_range(skeleton, st, pelvis, P, tr, shoulders,
                               (ankles, toes, pole))
    step = np.abs(st.ankles[None, :, 0] - ankles[..., 0]).max(axis=1)
    cost = P ** 2 + (D / (0.14 * H)) ** 2 + step + _KNEEL_COST
    return (P, D, shift, cost, shoulders, feasible, np.zeros(P.size, bool),
            np.ones(P.size, bool))


def _board_depth(poses: np.ndarray, board: tuple[float, float, float],
                 stature: float, parts: np.ndarray | None = None) -> np.ndarray:
    """How deep the body's capsules (or the capsules ``parts``, indices) of poses
    (C, J, 3) go into a board beyond x = edge between heights bottom and top
    (``board = (edge, bottom, top)``, start frame), plus ``_BOARD_CLEARANCE``, metres
    (C,); negative: clear."""
    from ltl_human_motion.scene.occupancy import capsule_ends, capsule_radii
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
    from ltl_human_motion.scene.occupancy import part_indices
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
    from ltl_human_motion.scene.occupancy import BODY_PARTS
    keep = np.array([BODY_PARTS.index(name) for name in _SUPPORT_FREE_PARTS])
    return _slab_depth(poses, (*support[:3], -1.0, support[3]), stature, keep)


def _slab_depth(poses: np.ndarray, slab: tuple[float, float, float, float, float],
                stature: float, parts: np.ndarray | None = None) -> np.ndarray:
    """How deep the body's capsules (``parts``: indices (K,), default all) of poses
    (C, J, 3) go into ``slab = (nx, ny, offset, bottom, top)`` (start frame: where
    ``nx * x + ny * y >= offset`` between heights bottom and top), plus
    ``_BOARD_CLEARANCE``, metres (C,); negative: clear."""
    from ltl_human_motion.scene.occupancy import capsule_ends, capsule_radii
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


def _grid(skeleton: Skeleton, st: _Start, targets: np.ndarray, active: tuple[int, ...],
          task: str | None = None, board: tuple[float, float, float] | None = None,
          obstacles: ObstacleClearance | None = None, strict: bool = False,
          furniture: tuple[tuple[float, ...] | None, tuple[float, ...] | None] | None = None
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Costs of trunk flexion / pelvis drop candidates for hand targets.

    A candidate is infeasible when a hand cannot reach its target, or when its posture
    with the hands on the targets (:func:`_contact_poses`) puts a body part through
    another (a low reach with the hand in the thigh) or into the low ``board`` (edge,
    bottom, top) over the targets; unless no candidate keeps out of it (the planner's
    exact check decides then), when the trunk or legs go into the furniture under the
    targets (``furniture[0]``, :func:`_support_depth`) or the body into a board over them
    (``furniture[1]``, (nx, ny, offset, bottom, top), :func:`_slab_depth`); and, with
    ``obstacles``, when it or the trunk and legs on the way to it come nearer an obstacle
    than ``_OBSTACLE_CLEARANCE`` (:func:`_obstacle_blocked`; unless every candidate does
    and not ``strict``; where the cheapest candidate is clear the others are not
    measured).

    Returns pitch (C,), drop (C,), shift (C,), cost (C,) (inf where infeasible),
    whether the pelvis tilt is capped (C,) and whether the posture kneels (C,)
    (:func:`_grid_base`).
    """
    arm = _arm_length(skeleton)
    P, D, shift, cost, shoulders, feasible, capped, kneel = _grid_base(skeleton, st,
                                                                        board is not None)
    for k in active:
        d = np.linalg.norm(targets[k] - shoulders[:, k], axis=-1)
        feasible = feasible & (d <= _REACH_FRACTION * arm)
        cost = cost + 0.5 * (d / arm - 0.8) ** 2
    if board is not None:
        feasible = feasible & _turns_before_edge(shoulders, active, board)
    idx = np.flatnonzero(feasible)
    if idx.size:
        from ltl_human_motion.planning.biomechanics import self_penetration
        poses = _contact_poses(skeleton, st, P[idx], D[idx], shift[idx], targets, active,
                               task, cap=capped[idx], kneel=kneel[idx])
        blocked = self_penetration(poses, skeleton.stature)[0].max(axis=1) > -_SELF_CLEARANCE
        if board is not None:
            blocked |= _board_depth(poses, board, skeleton.stature) > 0.0
            blocked |= _board_way_blocked(skeleton, st, (P[idx], D[idx], shift[idx]), active,
                                          board, capped[idx], kneel[idx])
        under, over = furniture or (None, None)
        for depth in ([] if under is None else [_support_depth(poses, under, skeleton.stature)]) \
                + ([] if over is None else [_slab_depth(poses, over, skeleton.stature)]):
            # The furniture under the targets, then the board over them (a shelf's).
            if not np.all(blocked | (depth > 0.0)):
                blocked |= depth > 0.0
        if obstacles is not None and not np.all(blocked):
            free = np.flatnonzero(~blocked)
            # The cheapest candidate first: where it is clear it is the posture (the
            # others are not measured); else every candidate.
            free = np.r_[free[np.argmin(cost[idx[free]])], free]
            for some in (free[:1], free[1:]):
                hit = _obstacle_blocked(skeleton, st, (P[idx[some]], D[idx[some]],
                                                       shift[idx[some]]), poses[some],
                                        active, obstacles, capped[idx[some]],
                                        kneel[idx[some]])
                if not hit[0] and some.size == 1:
                    break
                if some.size > 1 and (strict or not np.all(hit)):
                    blocked[some[hit]] = True
        feasible = feasible.copy()
        feasible[idx[blocked]] = False
    cost = np.where(feasible, cost, np.inf)
    return P, D, shift, cost, capped, kneel


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
    from ltl_human_motion.scene.occupancy import BODY_PARTS
    fixed = {f"{_SIDES[k]}_{n}" for k in active for n in ("hand", "palm")} | {"l_foot",
                                                                               "r_foot"}
    whole = tuple(p for p in BODY_PARTS if p not in fixed)
    hit = obstacles(contact, whole) <= _OBSTACLE_CLEARANCE
    way = _way_poses(skeleton, st, posture, cap, (), kneel)
    S, C = len(_POSTURE_WAY), posture[0].size
    near = obstacles(way, _WAY_PARTS).reshape(S, C) <= _OBSTACLE_CLEARANCE
    return hit | near.any(axis=0)


def posture_clear(task: str, target: np.ndarray, skeleton: Skeleton,
                  obstacles: ObstacleClearance, *, start_pose: np.ndarray | None = None,
                  hand: str = "auto", board: tuple[float, float, float] | None = None
                  ) -> bool:
    """Whether some posture of hand task ``task`` reaches ``target`` (3,) (start frame)
    with the body clear of ``obstacles`` as :func:`make_goal_primitive`'s search keeps
    it, without that search's fallback (a cheap test of a standing place before the
    worker walks there). ``start_pose``, ``hand`` and ``board`` as there."""
    st = _Start(skeleton, start_pose)
    targets, active, _ = _hand_targets(task, np.asarray(target, dtype=np.float64), hand)
    board = _check_board(board) if board is not None and task in LEVEL_PATH_TASKS else None
    cost = _grid(skeleton, st, targets, active, task, board, obstacles, strict=True)[3]
    return bool(np.isfinite(cost).any())


def _goal_hand_dir(task: str | None, k: int, rel_goal: np.ndarray, level: bool = False
                   ) -> np.ndarray:
    """Palm direction(s) (..., 3) of hand ``k`` on its target, ``rel_goal`` (..., 3) the
    shoulder-to-target vector(s); ``level``: horizontal (a hand come in over furniture
    above the shoulders, whose wrist a palm pointing up as the arm does puts below the
    board's top at its edge, or under a board close over the target, whose wrist a palm
    pointing down puts in the board)."""
    if task == "assemble":
        reach_dir = np.broadcast_to(np.array([0.75, -0.35 if k == 0 else 0.35, -0.55]),
                                    rel_goal.shape)
    else:
        reach_dir = rel_goal / np.maximum(np.linalg.norm(rel_goal, axis=-1, keepdims=True),
                                          1e-9)
    goal_dir = reach_dir + np.array([0.0, 0.0, -0.3])
    if level:
        goal_dir = goal_dir.copy()
        goal_dir[..., 2] = 0.0
    return goal_dir / np.linalg.norm(goal_dir, axis=-1, keepdims=True)


def _goal_elbow_pole(k: int) -> np.ndarray:
    """Elbow pole (3,) of hand ``k`` while it is on its target."""
    return np.array([-0.35, 1.0 if k == 0 else -1.0, -0.45])


def _contact_poses(skeleton: Skeleton, st: _Start, pitch: np.ndarray, drop: np.ndarray,
                   shift: np.ndarray, targets: np.ndarray, active: tuple[int, ...],
                   task: str | None, cap: bool | np.ndarray = True,
                   kneel: np.ndarray | None = None) -> np.ndarray:
    """Poses (C, J, 3) of posture candidates (C,) with the active hands on ``targets``
    (2, 3) and a free hand by the hip, as :func:`_hand_task` holds them at contact;
    ``kneel`` ((C,) of bool): the candidates on their knees (:func:`_kneel_legs`), the
    free palm on the floor (:func:`_prop_point`)."""
    C = pitch.size
    pelvis = np.tile(st.pelvis, (C, 1))
    pelvis[:, 2] -= drop
    pelvis[:, 0] += shift
    tr = _trunk(skeleton, pelvis, pitch, cap, st.hips(), False if kneel is None else kneel)
    hands = np.empty((C, 2, 3))
    hand_dir = np.broadcast_to(st.hand_dir, (C, 2, 3)).copy()
    elbow_pole = np.broadcast_to(st.elbow_pole, (C, 2, 3)).copy()
    for k, s in enumerate(_SIDES):
        if k in active:
            hands[:, k] = targets[k]
            hand_dir[:, k] = _goal_hand_dir(task, k, targets[k] - tr[:, _J[f"{s}_shoulder"]])
            elbow_pole[:, k] = _goal_elbow_pole(k)
        else:
            hands[:, k] = pelvis + (st.hands[k] - st.pelvis) + np.array([0.0, 0.0, 0.04])
            if kneel is not None and np.any(kneel) and _hangs(st, k):
                prop = _prop_point(tr[:, _J[f"{s}_shoulder"]], skeleton.stature,
                                   _arm_length(skeleton))
                hands[:, k] = np.where(np.asarray(kneel)[:, None], prop, hands[:, k])
    return _body(skeleton, pelvis, pitch, *_posture_legs(skeleton, st, tr, kneel),
                 hands, hand_dir, elbow_pole, tr)


def _hand_targets(task: str, target: np.ndarray, hand: str) -> tuple[np.ndarray, tuple, str]:
    """Palm targets (2, 3), active hand indices and the meta hand name."""
    t = np.asarray(target, dtype=np.float64)
    targets = np.stack([t, t])
    if task == "assemble" or hand == "both":
        targets[0, 1] += _ASSEMBLE_HALF_GAP
        targets[1, 1] -= _ASSEMBLE_HALF_GAP
        return targets, (0, 1), "both"
    if task == "leftHand":
        side = "l"
    elif task == "rightHand":
        side = "r"
    elif hand == "auto":
        side = "l" if t[1] > 0.0 else "r"
    elif hand in ("l_hand", "left", "l"):
        side = "l"
    elif hand in ("r_hand", "right", "r"):
        side = "r"
    else:
        raise ValueError(f"hand must be 'auto', 'l_hand', 'r_hand' or 'both', got {hand!r}")
    return targets, ((0,) if side == "l" else (1,)), f"{side}_hand"


#: Postures a hand task tries, cheapest first, for one whose whole motion keeps the arms
#: out of the body (the posture search checks the contact pose; the way out, with the
#: body rising and the hand coming home, can pass a forearm through a thigh).
_POSTURE_TRIES = 4


def _reach_postures(skeleton: Skeleton, st: _Start, targets: np.ndarray, active: tuple,
                    task: str, target: np.ndarray,
                    board: tuple[float, float, float] | None = None,
                    obstacles: ObstacleClearance | None = None,
                    furniture: tuple | None = None
                    ) -> list[tuple[float, float, float, bool, bool]]:
    """Trunk flexion, pelvis drop and shift of the cheapest feasible postures
    (:func:`_grid`, at most :data:`_POSTURE_TRIES`, cheapest first), whether each one's
    pelvis tilt is capped and whether it kneels; ValueError where none reaches."""
    P, D, S, cost, capped, kneel = _grid(skeleton, st, targets, active, task, board, obstacles,
                                  furniture=furniture)
    order = np.argsort(cost, kind="stable")[:_POSTURE_TRIES]
    order = order[np.isfinite(cost[order])]
    if order.size == 0:
        raise ValueError(
            f"{task}: target {np.round(target, 3).tolist()} (start frame) is out of reach for a "
            f"{skeleton.stature:.2f} m worker; place the worker with reach_placement()")
    return [(float(P[i]), float(D[i]), float(S[i]), bool(capped[i]), bool(kneel[i]))
            for i in order]


# ----------------------------------------------------------------------- timelines
def _profile(t: np.ndarray, keys: list[tuple[float, float]]) -> np.ndarray:
    """Piecewise minimum-jerk interpolation of scalar key values ``[(time, value), ...]``."""
    out = np.full_like(t, keys[0][1], dtype=np.float64)
    for (t0, v0), (t1, v1) in itertools.pairwise(keys):
        if t1 <= t0:
            continue
        m = (t >= t0) & (t <= t1)
        out[m] = v0 + (v1 - v0) * min_jerk((t[m] - t0) / (t1 - t0))
    out[t > keys[-1][0]] = keys[-1][1]
    return out


def _interp_keys(t: np.ndarray, keys: list[tuple[float, np.ndarray]]) -> np.ndarray:
    """Piecewise minimum-jerk interpolation of array key values (same shapes)."""
    first = np.asarray(keys[0][1], dtype=np.float64)
    out = np.broadcast_to(first, (t.size, *first.shape)).copy()
    for (t0, v0), (t1, v1) in itertools.pairwise(keys):
        if t1 <= t0:
            continue
        m = (t >= t0) & (t <= t1)
        s = min_jerk((t[m] - t0) / (t1 - t0)).reshape((-1,) + (1,) * first.ndim)
        out[m] = np.asarray(v0) + s * (np.asarray(v1) - np.asarray(v0))
    out[t > keys[-1][0]] = np.asarray(keys[-1][1])
    return out


def _arc_keys(t: np.ndarray, keys: list[tuple[float, np.ndarray]]) -> np.ndarray:
    """Like :func:`_interp_keys` for shoulder-to-palm vectors (..., 3): the direction is
    slerped and the length interpolated, so the palm swings in an arc about the shoulder
    (never through it), with the minimum-jerk timing."""
    first = np.asarray(keys[0][1], dtype=np.float64)
    out = np.broadcast_to(first, (t.size, *first.shape)).copy()
    for (t0, v0), (t1, v1) in itertools.pairwise(keys):
        if t1 <= t0:
            continue
        m = (t >= t0) & (t <= t1)
        s = min_jerk((t[m] - t0) / (t1 - t0)).reshape((-1,) + (1,) * (first.ndim - 1))[..., None]
        v0, v1 = np.asarray(v0, dtype=np.float64), np.asarray(v1, dtype=np.float64)
        n0 = np.linalg.norm(v0, axis=-1, keepdims=True)
        n1 = np.linalg.norm(v1, axis=-1, keepdims=True)
        u0, u1 = v0 / np.maximum(n0, 1e-9), v1 / np.maximum(n1, 1e-9)
        omega = np.arccos(np.clip(np.sum(u0 * u1, axis=-1, keepdims=True), -1.0, 1.0))
        so = np.sin(omega)
        small = so < 1e-6
        a = np.where(small, 1.0 - s, np.sin((1.0 - s) * omega) / np.where(small, 1.0, so))
        b = np.where(small, s, np.sin(s * omega) / np.where(small, 1.0, so))
        u = a * u0 + b * u1
        u /= np.maximum(np.linalg.norm(u, axis=-1, keepdims=True), 1e-12)
        out[m] = u * ((1.0 - s) * n0 + s * n1)
    out[t > keys[-1][0]] = np.asarray(keys[-1][1])
    return out


def _n_frames(total: float, fps: float) -> int:
    return round(total * fps) + 1


def _finish(name: str, task: str, world: np.ndarray, st: _Start, fps: float, source: str,
            meta: dict, start_exact: bool = True, end_exact: bool = True) -> MotionPrimitive:
    """Blend the model residual against ``start_pose`` in at the ends, build the primitive."""
    T = world.shape[0]
    t = np.arange(T) / fps
    ramp = 0.3
    corrected = world.copy()
    for exact, ref, w in ((start_exact, world[0], 1.0 - min_jerk(t / ramp)),
                          (end_exact, world[-1], 1.0 - min_jerk((t[-1] - t) / ramp))):
        if not exact:
            continue
        pose = st.pose.copy()
        pose[:, :2] += ref[0, :2] - pose[0, :2]
        residual = pose - ref
        if np.max(np.abs(residual)) > 0.0:
            corrected += w[:, None, None] * residual[None]
    world = corrected
    yaw = np.zeros(T)
    root = np.concatenate([world[:, 0, :], yaw[:, None]], axis=1)
    root = relative_root(root)
    root[:, :2] = world[:, 0, :2] - world[0, 0, :2]
    poses = world - world[:, :1, :]
    meta = dict(meta)
    meta.setdefault("kind", "goal")
    return MotionPrimitive(name=name, task=task, poses=poses, root=root, fps=fps,
                           source=source, meta=meta)


# ------------------------------------------------------------------------- builders
def _frames(skeleton: Skeleton, st: _Start, t: np.ndarray, pelvis: np.ndarray,
            pitch: np.ndarray, hands: np.ndarray, hand_dir: np.ndarray,
            elbow_pole: np.ndarray, ankles: np.ndarray | None = None,
            toes: np.ndarray | None = None, knee_pole: np.ndarray | None = None,
            trunk: np.ndarray | None = None) -> np.ndarray:
    T = t.size
    ankles = np.broadcast_to(st.ankles, (T, 2, 3)) if ankles is None else ankles
    toes = np.broadcast_to(st.toes, (T, 2, 3)) if toes is None else toes
    knee_pole = np.broadcast_to(st.knee_pole, (T, 2, 3)) if knee_pole is None else knee_pole
    return _body(skeleton, pelvis, pitch, ankles, toes, knee_pole, hands, hand_dir, elbow_pole,
                 trunk)


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
                 stature: float = DEFAULT_STATURE, head: np.ndarray | None = None
                 ) -> np.ndarray | None:
    """Shoulder-to-palm points (2, 3) in front of the edge of the furniture under the
    targets (``support`` (nx, ny, offset, top), start frame, :func:`_slab_depth`),
    towards each active hand's target (along the edge to the hand's own side where that
    passes the face, ``_RISE_HEAD_CLEAR``): where the level path's palms rise before they
    come straight up and in over the furniture. Each is as high above the shoulder as
    keeps it ``_LEVEL_MIN_EXTENSION`` of ``arm`` from it (the elbow not folded on the
    way up), and no higher than ``_RISE_BELOW`` under the furniture's top. None unless
    that top is above every active shoulder of ``sh1`` (2, 3) (below, the palms come
    down onto it) and each edge leaves ``_RISE_LEAST`` in front of the shoulder."""
    if support is None:
        return None
    nx, ny, offset, top = support
    rise = np.zeros((2, 3))
    for k in active:
        flat = targets[k, :2] - sh1[k, :2]
        dh = float(np.linalg.norm(flat))
        toward = (nx * flat[0] + ny * flat[1]) / dh if dh > 1e-9 else 0.0
        if top <= sh1[k, 2] or toward < 0.3:
            return None
        ahead = (offset - (nx * sh1[k, 0] + ny * sh1[k, 1])) / toward - _RISE_FRONT
        if ahead < _RISE_LEAST:
            return None
        rise[k, :2] = flat / dh * min(ahead, dh)
        if head is not None:
            rise[k, :2] += _head_clear_shift(sh1, k, rise[k, :2], (nx, ny), head,
                                             _RISE_HEAD_CLEAR * stature / DEFAULT_STATURE)
        least = _LEVEL_MIN_EXTENSION * arm
        rise[k, 2] = min(np.sqrt(max(least ** 2 - float(np.sum(rise[k, :2] ** 2)), 0.0)),
                         top - sh1[k, 2] - _RISE_BELOW)
    return rise


def _segment_origin_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Distance of the origin from the segment a-b (points (3,))."""
    d = b - a
    s = float(np.clip(-np.dot(a, d) / max(float(np.dot(d, d)), 1e-12), 0.0, 1.0))
    return float(np.linalg.norm(a + s * d))


def _checked_target(task: str, target: np.ndarray | None, skeleton: Skeleton) -> np.ndarray:
    """``target`` (3,) of a hand task as floats; ValueError if missing, malformed or out of
    the task's height range."""
    if target is None:
        raise ValueError(f"{task} needs a target position (3,) in the start frame")
    target = np.asarray(target, dtype=np.float64)
    if target.shape != (3,) or not np.all(np.isfinite(target)):
        raise ValueError(f"target must be a finite array of shape (3,), got {target.shape}")
    if target[2] < 0.0 or target[2] > max_reach(task, skeleton):
        raise ValueError(f"{task}: target height {target[2]:.3f} m is outside [0, "
                         f"{max_reach(task, skeleton):.3f}] m for a {skeleton.stature:.2f} m "
                         f"worker")
    return target


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
        return keys, t1 + push, frozenset()
    if task == "extract":
        pull = min(0.5, 0.6 * (t2 - t1))
        keys = [(0.0, rel_home), (t1, rel_goal), (t2 - pull, rel_goal), (t2, rel_pre),
                (total, rel_home)]
        if level:           # in the straight way it pulls out (PUSH_LEVEL_TASKS)
            keys.insert(1, (_PUSH_IN_AT * t1, rel_pre))
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


def _push_travel(task: str, target: np.ndarray, st: _Start, hand: str,
                 travel: float | None, path: str,
                 support: tuple[float, float, float, float] | None) -> tuple[float, bool]:
    """Length of the straight push of insert or pull of extract, metres: ``travel``
    (default ``_INSERT_TRAVEL``); on the ``"level"`` path (:data:`PUSH_LEVEL_TASKS`) over
    furniture (``support``, :func:`_support_depth`), long enough (up to ``_MAX_TRAVEL``)
    that the push starts and the pull ends ``_BOARD_FRONT`` in front of its edge, where
    the hand comes from and goes back to the hip without passing under the edge (and
    extract goes in the same straight way). Also whether the hand takes that level
    path."""
    travel = _INSERT_TRAVEL if travel is None else float(travel)
    if support is None or path != "level" or task not in PUSH_LEVEL_TASKS:
        return travel, False
    t = np.asarray(target, dtype=np.float64)
    targets, active, _ = _hand_targets(task, t, hand)
    a = targets[active[0]] - st.shoulders[active[0]]
    a[2] = 0.0
    a /= max(float(np.linalg.norm(a)), 1e-9)
    nx, ny, offset, _ = support
    towards = nx * a[0] + ny * a[1]                   # how fast the push goes in
    if towards <= 1e-6:
        return travel, False
    need = (nx * t[0] + ny * t[1] - offset + _BOARD_FRONT) / towards
    return float(np.clip(need, travel, _MAX_TRAVEL)), True


def _push_direction(task: str, target: np.ndarray, st: _Start, active: tuple[int, ...]
                    ) -> np.ndarray:
    """The horizontal unit direction (3,) from the acting shoulder to ``target`` (3,) along
    which insert pushes into it (from a point before it) and extract pulls back from it;
    zeros for other tasks."""
    if task not in ("insert", "extract"):
        return np.zeros(3)
    a = target - st.shoulders[active[0]]
    a[2] = 0.0
    n = np.linalg.norm(a)
    return a / n if n > 1e-6 else np.array([1.0, 0.0, 0.0])


def _hand_task(task: str, target: np.ndarray, skeleton: Skeleton, st: _Start,
               rng: np.random.Generator, duration: float | None, hand: str,
               fps: float, path: str = "arc", travel: float | None = None,
               board: tuple[float, float, float] | None = None,
               obstacles: ObstacleClearance | None = None,
               furniture: tuple | None = None) -> MotionPrimitive:
    H = skeleton.stature
    travel, pushed = _push_travel(task, target, st, hand, travel, path,
                                  None if furniture is None else furniture[0])
    board = board if task in LEVEL_PATH_TASKS else None
    support = None if furniture is None or task not in LEVEL_PATH_TASKS else furniture[0]
    ceiling = None if furniture is None or task not in LEVEL_PATH_TASKS else furniture[1]
    # Over furniture above the shoulders every path rises in front of its edge first.
    over = support is not None and support[3] > float(st.shoulders[:, 2].max())
    level = pushed or ((path == "level" or board is not None or over)
                       and task in LEVEL_PATH_TASKS) \
        or (path == "level" and task in LEVEL_REGION_TASKS)
    target = _checked_target(task, target, skeleton)
    lid = min(np.inf if board is None else board[1], np.inf if ceiling is None else ceiling[3])
    flat_palm = lid - float(target[2]) < _LEVEL_PALM_GAP
    targets, active, hand_name = _hand_targets(task, target, hand)
    approach = _push_direction(task, target, st, active)
    postures = _reach_postures(skeleton, st, targets, active, task, target, board, obstacles,
                               furniture)
    # the cheapest posture, swinging wider past the thigh where the arm would pass through
    # it, then the next postures; last the kneeling ones without the free hand's prop
    # (on the way up its forearm can pass through the thigh coming forward)
    tries = [(postures[0], w, True) for w in _WIDER_SWINGS] + \
        [(p, 1.0, True) for p in postures[1:]] + [(p, 1.0, False) for p in postures if p[4]]
    draws = rng.bit_generator.state
    for posture, wide, prop in tries:
        rng.bit_generator.state = draws
        world, f1, f2, contact_t = _reach_motion(
            task, skeleton, st, targets, active, posture,
            (level, travel, approach, board, support, flat_palm), rng, duration, fps, wide,
            prop)
        penetrates = _self_penetrates(world, H)
        if not penetrates:
            break
    T = world.shape[0]
    contact = min(round(contact_t * fps), T - 1)
    meta = {"contact_frame": contact, "hand": hand_name, "target": target.tolist(),
            "hold_frames": [f1, f2], "trunk_flexion": posture[0], "pelvis_drop": posture[1],
            "posture": _posture_name(world[f1], skeleton), "self_penetrating": penetrates}
    return _finish(f"{task}_{_fmt(target)}", task, world, st, fps,
                   f"goals.make_goal_primitive({task!r}, target={_fmt(target)})", meta)


def _self_penetrates(world: np.ndarray, stature: float) -> bool:
    """Whether a body capsule's bone axis enters another, non-neighbouring one in any frame
    of ``world`` (T, J, 3) (the verifier's self-penetration check)."""
    from ltl_human_motion.planning.biomechanics import self_penetration
    return bool(np.max(self_penetration(world, stature)[0]) > 0.0)


def _reach_motion(task: str, skeleton: Skeleton, st: _Start, targets: np.ndarray,
                  active: tuple[int, ...], posture: tuple[float, float, float, bool],
                  path: tuple, rng: np.random.Generator, duration: float | None, fps: float,
                  wide: float = 1.0, prop: bool = True) -> tuple[np.ndarray, int, int, float]:
    """Frames (T, J, 3) of a hand task's reach into ``posture`` (pitch, drop, shift,
    capped), its hold and its return; the first and last hold frame and the contact time
    (s). ``posture`` may kneel (:func:`_kneel_progress`). ``path``: (level, travel,
    approach (2, 3) or None, board, support, flat_palm) of :func:`_hand_task`; ``wide``
    scales the low reach's swing outside the thigh (:func:`_hand_path`); ``prop``: a
    kneeling worker's free hand props the trunk (:func:`_free_hands`)."""
    H = skeleton.stature
    arm = _arm_length(skeleton)
    level, travel, approach, board, support, flat_palm = path
    pitch1, drop1, kneel = posture[0], posture[1], posture[4]
    dist = max(np.linalg.norm(targets[k] - st.hands[k]) for k in active)
    t_reach, hold, t_ret = _reach_times(task, dist, pitch1, drop1, H, level, duration, rng)
    if kneel:       # the body is down at half the reach time and up again as long after
        t_reach, t_ret = (max(v, 2.0 * KNEEL_DOWN_SECONDS) for v in (t_reach, t_ret))
    # Timed for the arced path's palm speed; where the posture's trunk motion or a level
    # path makes a hand or wrist faster than HAND_RETIME_SPEED (an elbow faster than
    # ELBOW_RETIME_SPEED), the reach and return are slowed by what they exceed and the
    # motion made again (at most twice), from the same random draws (the same path,
    # only slower).
    draws = rng.bit_generator.state
    for _ in range(3):
        rng.bit_generator.state = draws
        total = t_reach + hold + t_ret
        T = _n_frames(total, fps)
        t = np.arange(T) / fps
        t1, t2 = t_reach, t_reach + hold
        sb, lean, legs, pelvis, pitch, tr = _body_path(skeleton, st, t, (t1, t2, total),
                                                       posture, level, active[0])
        shoulders = np.stack([tr[:, _J["l_shoulder"]], tr[:, _J["r_shoulder"]]], 1)   # (T,2,3)
        f1 = min(round(t1 * fps), T - 1)
        f2 = min(round(t2 * fps), T - 1)
        sh1 = shoulders[f1]
        # hand key positions relative to the shoulder
        rel_home = st.hand_rel
        rel_goal = rel_home.copy()
        rel_pre = rel_home.copy()
        for k in active:
            rel_goal[k] = targets[k] - sh1[k]
            rel_pre[k] = targets[k] - travel * approach - sh1[k]
        rise = _rise_points(targets, active, sh1, support, arm, H,
                            tr[f1, [_J["neck"], _J["head"]]]) if level and board is None else None
        keys, contact_t, straight = _hand_keys(task, targets, active, sh1, rel_home, rel_goal,
                                               rel_pre, (t1, t2, total), level, board, H, arm,
                                               rise)
        rel = _hand_path(t, keys, (t1, t2, total), active, targets, shoulders, sh1, st, level,
                         board, dist, H, arm, rng, wide, straight)
        if task in ("leftHand", "rightHand", "assemble") and hold > 0.4:
            _add_manipulation(rel, t, t1, t2, active, rng)
        hands = shoulders + rel
        _free_hands(hands, active, st, pelvis, sb, lean if kneel and prop else None, sh1, H,
                    arm)
        hand_dir, elbow_pole = _hand_orientation(task, active, st, t, (t1, t2, total), rel_goal,
                                                 flat_palm or rise is not None)
        if kneel and prop:
            _prop_orientation(hand_dir, elbow_pole, lean,
                              tuple(k for k in range(2) if k in active or not _hangs(st, k)))
        world = _frames(skeleton, st, t, pelvis, pitch, hands, hand_dir, elbow_pole, *legs,
                        trunk=tr)
        peak = max(_peak_hand_speed(world, active, fps),
                   _peak_hand_speed(world, active, fps, ("elbow",))
                   * HAND_RETIME_SPEED / ELBOW_RETIME_SPEED)
        limit = HAND_RETIME_SPEED * H / DEFAULT_STATURE
        if peak <= limit or duration is not None:
            break
        t_reach *= 1.03 * peak / limit
        t_ret *= 1.03 * peak / limit
    return world, f1, f2, contact_t


def _body_path(skeleton: Skeleton, st: _Start, t: np.ndarray,
               times: tuple[float, float, float], posture: tuple, level: bool, first: int
               ) -> tuple[np.ndarray, ...]:
    """The body of a hand task at times ``t`` (T,) (``times`` = reach end, hold end,
    total; ``posture`` as :func:`_reach_motion`'s): the pelvis's progress to the posture
    and the trunk lean's (each (T,)), the ankles, toes and knee poles (each (T, 2, 3), or
    None: the start pose's), the pelvis (T, 3), the trunk pitch (T,) and the trunk
    (T, J, 3). The posture leads the hand: it is reached at 85 % of the reach time (level
    path: half, before the hand comes in, and kept until it is out again); a kneeling
    one kneels down in that time (:func:`_kneel_progress`, ``first`` the foot stepping
    back first)."""
    t1, t2, total = times
    pitch1, drop1, shift1, capped, kneel = posture
    t_ret = total - t2
    body_keys = ([(0.0, 0.0), (0.5 * t1, 1.0), (t2 + 0.5 * t_ret, 1.0), (total, 0.0)] if level
                 else [(0.0, 0.0), (0.85 * t1, 1.0), (t2 + 0.15 * t_ret, 1.0), (total, 0.0)])
    sb = _profile(t, body_keys)
    lean, legs = sb, (None, None, None)
    if kneel:
        sb, lean, legs = _kneel_progress(skeleton, st, t, (0.5 * t1, t2 + 0.5 * t_ret, total),
                                         (drop1, shift1), first)
    pelvis = np.tile(st.pelvis, (t.size, 1))
    pelvis[:, 2] -= drop1 * sb
    pelvis[:, 0] += shift1 * sb
    pitch = pitch1 * lean
    return sb, lean, legs, pelvis, pitch, _trunk(skeleton, pelvis, pitch, capped, st.hips(),
                                                 kneel)


def _free_hands(hands: np.ndarray, active: tuple[int, ...], st: _Start, pelvis: np.ndarray,
                sb: np.ndarray, lean: np.ndarray | None, sh1: np.ndarray, stature: float,
                arm: float) -> None:
    """Set the hands (T, 2, 3) that are not ``active`` in place: by the hip while the
    trunk leans (they do not swing forward into the furniture the other hand reaches
    over; ``sb`` (T,): the body's progress); kneeling (``lean`` (T,) given), a hand that
    hangs free (:func:`_hangs`) goes down onto the floor under the shoulder (``sh1``
    (2, 3) in the posture) as the trunk leans, to prop it (:func:`_prop_point`)."""
    for k in range(2):
        if k in active:
            continue
        hands[:, k] = pelvis + (st.hands[k] - st.pelvis) + np.array([0.0, 0.0, 0.04]) * \
            sb[:, None]
        if lean is not None and _hangs(st, k):
            hands[:, k] += lean[:, None] * (_prop_point(sh1[k], stature, arm) - hands[:, k])


def _add_manipulation(rel: np.ndarray, t: np.ndarray, t1: float, t2: float,
                      active: tuple[int, ...], rng: np.random.Generator) -> None:
    """Add small manipulation movements (1 cm, 0.7-1.4 Hz) to the acting hands' shoulder
    offsets ``rel`` (T, 2, 3) while they are in the region, between times t1 and t2."""
    env = _profile(t, [(t1, 0.0), (t1 + 0.2, 1.0), (t2 - 0.2, 1.0), (t2, 0.0)])
    env = np.where((t > t1) & (t < t2), env, 0.0)
    for k in active:
        f = rng.uniform(0.7, 1.4, size=3)
        ph = rng.uniform(0.0, 2 * np.pi, size=3)
        amp = np.array([0.010, 0.008, 0.008])
        wob = amp * np.sin(2 * np.pi * f * t[:, None] + ph)
        rel[:, k] += env[:, None] * wob


def _peak_hand_speed(world: np.ndarray, active: tuple[int, ...], fps: float,
                     parts: tuple[str, ...] = ("hand", "wrist")) -> float:
    """Largest speed (m/s) of an acting arm's ``parts`` (default the palm and wrist) in
    ``world`` (T, J, 3), as displacements over 1/30 s (the verifier's window)."""
    w = max(1, round(fps / 30.0))
    if len(world) <= w:
        return 0.0
    joints = [_J[f"{_SIDES[k]}_{n}"] for k in active for n in parts]
    d = world[w:, joints] - world[:-w, joints]
    return float(np.sqrt(np.max(np.sum(d * d, axis=-1)))) * fps / w


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


def _check_board(board: tuple[float, float, float]) -> tuple[float, float, float]:
    """``board`` as three floats (edge, bottom, top); ValueError if malformed."""
    b = np.asarray(board, dtype=np.float64)
    if b.shape != (3,) or not np.all(np.isfinite(b)) or not b[1] <= b[2]:
        raise ValueError(f"board must be (edge, bottom, top) with bottom <= top, got {board!r}")
    return float(b[0]), float(b[1]), float(b[2])


def _check_furniture(board: tuple | None, support: tuple | None, ceiling: tuple | None
                     ) -> tuple[tuple[float, ...] | None, tuple | None]:
    """``board`` (edge, bottom, top), and ``support`` (nx, ny, offset, top) and ``ceiling``
    (nx, ny, offset, bottom, top) as one pair (None without either), as floats;
    ValueError if malformed."""
    board = None if board is None else _check_board(board)
    out = []
    for name, value, n in (("support", support, 4), ("ceiling", ceiling, 5)):
        v = None if value is None else np.asarray(value, dtype=np.float64)
        if v is not None and (v.shape != (n,) or not np.all(np.isfinite(v))):
            raise ValueError(f"{name} must be {n} finite numbers, got {value!r}")
        out.append(None if v is None else tuple(float(x) for x in v))
    return board, (None if out == [None, None] else tuple(out))


def _fmt(target: np.ndarray | None) -> str:
    if target is None:
        return "none"
    return "[" + ",".join(f"{v:.3f}" for v in np.asarray(target)) + "]"


def _posture_name(pose: np.ndarray, skeleton: Skeleton) -> str:
    """Table I posture of a pose: 'stoop', 'bend' or 'upright' (joint-based)."""
    head_low = pose[_J["head"], 2] < chest_height(skeleton)
    butt_low = min(pose[_J["l_hip"], 2], pose[_J["r_hip"], 2]) < knee_height(skeleton)
    if head_low and butt_low:
        return "stoop"
    if head_low:
        return "bend"
    return "upright"


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


def make_goal_primitive(task: str, target: np.ndarray | None, skeleton: Skeleton, *,
                        start_pose: np.ndarray | None = None,
                        rng: np.random.Generator | None = None, duration: float | None = None,
                        hand: str = "auto", fps: float = LIBRARY_FPS,
                        path: str = "arc", travel: float | None = None,
                        board: tuple[float, float, float] | None = None,
                        obstacles: ObstacleClearance | None = None,
                        support: tuple | None = None, ceiling: tuple | None = None
                        ) -> MotionPrimitive:
    """A goal primitive for one Table I task, made for the exact target.

    Parameters
    ----------
    task : str
        One of :data:`GOAL_TASKS`: grasp, release, move, leftHand, rightHand, assemble,
        insert, extract, bend, stoop, kneel, sit, standUp, wait.
    target : array-like, shape (3,), or None
        In the primitive's start frame (root floor position at the origin, facing +x,
        z = height above the floor). Hand tasks: where the palm goes (assemble: the middle
        between both palms; insert: the end of the push, which starts 8 cm before it along
        the horizontal shoulder-target direction; extract: where the hand takes the part,
        it is then pulled back 8 cm). sit: the point of the seat surface under the
        buttocks (must be behind the worker); standUp: the seat (only its height is used;
        the worker starts seated above the origin). bend/stoop/kneel: optional hand target
        reached in the low posture. wait: ignored.
    skeleton : Skeleton
    start_pose : array-like, shape (J, 3), optional
        Pose to start from (and return to): start-frame positions, or a root-relative
        pose (pelvis at the origin) which is then stood on the floor. Default: the standing
        pose of the gait library. For standUp it is the pose *ended in*.
    rng : numpy.random.Generator, optional
        Seeded variation of timing, hand-path bow, manipulation and sway (default seed 0).
    duration : float, optional
        Total length in seconds (hand and down-up tasks: the hold absorbs the change;
        sit/standUp: the descent/ascent; wait: the wait). ValueError when too short.
    hand : {"auto", "l_hand", "r_hand", "both"}
        Acting hand; auto = left for targets with y > 0, else right (kneel: its knee).
    fps : float
    path : {"arc", "level"}
        Hand path of grasp, release and move (:data:`HAND_PATHS`; insert and extract over
        a ``support``: :data:`PUSH_LEVEL_TASKS`); other tasks ignore it.
    travel : float, optional
        Length of insert's straight push and extract's pull, metres (default 8 cm).
    board : (edge, bottom, top), optional
        A low board over the target of grasp, release or move (start frame: front edge
        at x = edge, underside and top at heights bottom and top, metres): the posture
        keeps clear of it; the hand comes in level under it from in front of its edge.
    obstacles : ObstacleClearance, optional
        The obstacles around the worker, kept clear of where a posture does.
    support, ceiling : (nx, ny, offset, top), (nx, ny, offset, bottom, top), optional
        The furniture under a hand target and a board over it (:func:`_slab_depth`);
        over a support above the shoulders the level path rises (:func:`_rise_points`).

    Returns
    -------
    MotionPrimitive
        ``meta``: ``contact_frame`` (where the task's termination condition first holds),
        ``hand`` (l_hand, r_hand, both or none), ``target``, ``hold_frames``, ``posture``.

    Raises
    ------
    ValueError
        Unknown task, malformed or unreachable target, too short duration.
    """
    _check_options(task, skeleton, fps, duration, path)
    rng = np.random.default_rng(0) if rng is None else rng
    st = _Start(skeleton, start_pose)
    if task in HAND_TASKS:
        if travel is not None and not 0.0 < float(travel) <= _MAX_TRAVEL:
            raise ValueError(f"travel must be in (0, {_MAX_TRAVEL}] m, got {travel!r}")
        board, furniture = _check_furniture(board, support, ceiling)
        return _hand_task(task, target, skeleton, st, rng, duration, hand, fps, path, travel,
                          board, obstacles, furniture)
    if task in ("bend", "stoop", "kneel"):
        return _down_up(task, skeleton, st, rng, duration, fps, target, hand)
    if task == "wait":
        return _wait(skeleton, st, rng, duration, fps)
    if task == "sit":
        return _sit_primitive(skeleton, st, rng, duration, fps, target)
    return _stand_up(skeleton, st, rng, duration, fps, target)


def _check_options(task: str, skeleton: Skeleton, fps: float, duration: float | None,
                   path: str) -> None:
    """ValueError unless the arguments of :func:`make_goal_primitive` are well formed."""
    _check_task(task)
    if not isinstance(skeleton, Skeleton):
        raise ValueError(f"skeleton must be a Skeleton, got {type(skeleton).__name__}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps!r}")
    if duration is not None and not duration > 0:
        raise ValueError(f"duration must be positive, got {duration!r}")
    if path not in HAND_PATHS:
        raise ValueError(f"path must be one of {', '.join(HAND_PATHS)}, got {path!r}")


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


@lru_cache(maxsize=512)
def _placement(task: str, height: float, stature: float, hand: str,
               board: tuple[float, float, float] | None = None,
               start: bytes | None = None, full_tilt: bool = True) -> tuple[float, float]:
    """:func:`reach_placement` (``start``: the start pose's float64 bytes, or None)."""
    skeleton = Skeleton(stature)
    H = stature
    if task in ("sit", "standUp"):
        return -0.10 * H, 0.0
    if task in ("bend", "stoop", "kneel", "wait"):
        return 0.0, 0.0
    both = task == "assemble" or hand == "both"
    lateral = 0.0 if both else (0.07 * H if (task == "leftHand" or hand in ("l_hand", "left"))
                                else -0.07 * H)
    st = _Start(skeleton, None if start is None
                else np.frombuffer(start, dtype=np.float64).reshape(-1, 3))
    best = (np.inf, None)
    # Under a low board: with _BOARD_PLACE_MARGIN where that leaves a place, else without;
    # a place for a capped or kneeling posture before one for a full pelvis tilt
    # (_grid_base).
    tries = [(0.0, False)] if board is None else [
        (m, full) for full in ((False, True) if full_tilt else (False,))
        for m in (_BOARD_PLACE_MARGIN, 0.0)]
    for margin, full in tries:
        for x in np.linspace(0.12 * H, 0.45 * H, 12):
            target = np.array([x, lateral, height])
            targets, active, _ = _hand_targets(task, target, "both" if both else (
                "l_hand" if lateral > 0 else "r_hand"))
            _, _, _, cost, capped, kneel = _grid(
                skeleton, st, targets, active, task,
                None if board is None else (x - board[0] - margin, board[1], board[2]))
            c = float(np.min(cost if full else np.where(capped | kneel, cost, np.inf)))
            if c < best[0]:
                best = (c, float(x))
        if best[1] is not None:
            break
    if best[1] is None:
        raise ValueError(f"{task}: no standing place reaches a target at height {height:.3f} m")
    return best[1], lateral


def reach_placement(task: str, target_height: float, skeleton: Skeleton,
                    hand: str = "auto", board: tuple[float, float, float] | None = None,
                    start_pose: np.ndarray | None = None, full_tilt: bool = True
                    ) -> tuple[float, float]:
    """Where to put the target relative to the standing root for a comfortable posture.

    Parameters
    ----------
    task : str
    target_height : float
        Height of the target above the floor (for sit/standUp: the seat height).
    skeleton : Skeleton
    hand : str
        ``"auto"`` uses the right hand for one-handed tasks (leftHand: left).
    board : (depth, bottom, top), optional
        A low board over the target of grasp, release or move: the target lies ``depth``
        behind its front edge, under its underside at height ``bottom`` (top: ``top``).
        The worker then stands where the crouched body stays in front of the edge.
    start_pose : ndarray, shape (J, 3), optional
        The pose the goal primitive will start from (as :func:`make_goal_primitive`
        takes it); default the skeleton's rest pose. A reach under a low board is tight
        enough that the start's feet and arms decide whether a place reaches.
    full_tilt : bool
        Under a low board, whether a place may need the pelvis tilted in full, past the
        hips' range of motion (only where no place reaches without it).

    Returns
    -------
    distance_in_front, lateral_offset : float
        The target should be at ``(distance_in_front, lateral_offset, target_height)`` in
        the goal primitive's start frame (x forward, y left); equivalently the worker stands
        ``distance_in_front`` behind the target, facing it, with the target
        ``lateral_offset`` to the left. sit: negative distance (the seat is behind).
        Tasks without a target return (0, 0).

    Raises
    ------
    ValueError
        Unknown task, or the height is outside ``[min_reach_height, max_reach]``.
    """
    _check_task(task)
    h = float(target_height)
    lo, hi = min_reach_height(task, skeleton), max_reach(task, skeleton)
    if not (lo - 1e-9 <= h <= hi + 1e-9):
        raise ValueError(f"{task}: target height {h:.3f} m is outside [{lo:.3f}, {hi:.3f}] m "
                         f"for a {skeleton.stature:.2f} m worker")
    if board is not None and task in LEVEL_PATH_TASKS:
        board = tuple(round(v, 4) for v in _check_board(board))
    else:
        board = None
    start = None if start_pose is None else \
        np.ascontiguousarray(start_pose, dtype=np.float64).tobytes()
    return _placement(task, round(h, 4), float(skeleton.stature), hand, board, start,
                      bool(full_tilt))

