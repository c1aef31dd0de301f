"""The body model of the goal primitives: trunk, limbs, start pose and balance.

A pose is the pelvis position, a trunk flexion angle spread over the spine, the ankle
and toe positions of both feet and the palm positions of both hands; knees and elbows
come from analytic two-bone IK (:func:`.ik.two_bone_ik`), so every bone keeps its length.
Also the start pose's quantities (:class:`_Start`), balance over the feet, the legs of a
posture (standing or kneeling on both knees, :func:`_kneel_legs`) and their range of
motion, and a palm's direction and elbow pole on its target.
"""

from __future__ import annotations

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_angle
from ltl_human_motion.motion.goals.tasks import _J, _SIDES, _bones
from ltl_human_motion.motion.ik import center_of_mass, two_bone_ik
from ltl_human_motion.motion.skeleton import Skeleton

#: Degrees the posture search keeps inside the hip and knee ranges of motion of
#: planning.biomechanics (blending and foot locking move the legs by a degree or two).
_ROM_MARGIN = 3.0


#: The elbow folds at most this far, radians: the range of motion's 150 deg less
#: ``_ROM_MARGIN`` (a hand path rising over a shelf's edge close to the shoulder folded a
#: 1.55 m worker's elbow to 151-164 deg; the wrist stays that far from the shoulder).
_ELBOW_MAX_FLEXION = float(np.radians(150.0 - _ROM_MARGIN))


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
            rot[frac] = matrix_from_angle(1, angle)
        out[:, j] = out[:, p] + rot[frac] @ (rest[j] - rest[p])
    # in a crouch the hips turn with the pelvis's tilt (standing bends keep them level)
    turn = (matrix_from_angle(1, crouch * tilt * ~np.asarray(kneel, dtype=bool))
            if hips is None else None)
    for k, name in enumerate(("l_hip", "r_hip")):
        out[:, _J[name]] = pelvis + (turn @ (rest[_J[name]] - rest[0]) if hips is None
                                     else hips[k])
    return out


def _body(skeleton: Skeleton, pelvis: np.ndarray, pitch: np.ndarray, ankles: np.ndarray,
          toes: np.ndarray, knee_pole: np.ndarray, hands: np.ndarray, hand_dir: np.ndarray,
          elbow_pole: np.ndarray, trunk: np.ndarray | None = None,
          frame: float | None = None) -> np.ndarray:
    """Full pose of every frame.

    Parameters
    ----------
    pelvis : (T, 3); pitch : (T,); ankles, toes, knee_pole, hands, hand_dir, elbow_pole :
    (T, 2, 3) with index 0 = left, 1 = right.
    trunk : (T, J, 3), optional
        ``_trunk(skeleton, pelvis, pitch)`` if already computed (it is not modified).
    frame : float, optional
        Seconds between the T poses where they are the frames of a motion (the elbow
        poles are kept from flipping between frames, :func:`_elbow_pole`); None for
        separate candidates.

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
        aim = hands[:, k] - b[ha] * hd
        pole = elbow_pole[:, k] if frame is None \
            else _elbow_pole(out[:, sh], aim, elbow_pole[:, k], k, (b[el], b[wr]), frame)
        elbow, wrist = two_bone_ik(out[:, sh], aim, b[el], b[wr], pole, max_stretch=1.0,
                                   max_flexion=_ELBOW_MAX_FLEXION)
        out[:, el], out[:, wr], out[:, ha] = elbow, wrist, wrist + b[ha] * hd
    return out


#: Where an elbow pole comes within this share of its length of the shoulder-wrist line
#: in a motion with the elbow bent at least :data:`POLE_BENT` off that line (a pole along
#: the arm leaves the side the elbow bends to undefined, and an arm passing its pole
#: flipped the elbow to the other side in one frame: a 1.95 m worker's carton move, the
#: elbow at 11 m/s, which the reach's retiming answered by slowing the move to 42 s), the
#: elbow's swivel about that line is interpolated in time over the frames where the share
#: is below :data:`POLE_DEGENERATE` and the arm bent, from its angle at the frame before
#: them to its angle at the frame after them (:func:`_elbow_pole`).
POLE_FLIP = 0.1
POLE_DEGENERATE = 0.3
#: m/s the elbow swings at most about the shoulder-wrist line where its swivel is
#: interpolated.
SWIVEL_SPEED = 1.0
#: Metres the elbow is off the shoulder-wrist line below which its swivel does not
#: matter (the arm is nearly straight).
POLE_BENT = 0.005


def _swivel_reference(u: np.ndarray, k: int) -> np.ndarray:
    """Unit vectors (..., 3) perpendicular to the unit shoulder-wrist directions ``u``
    (..., 3) of arm ``k`` (0 left), continuous in ``u`` but at one direction (across the
    trunk and behind it, where no arm reaches): elbow down with the arm forward and out,
    carried over the sphere of arm directions by the rotation from there. The angle of
    the elbow's swivel is measured from it."""
    side = 1.0 if k == 0 else -1.0
    a = np.array([0.6, 0.8 * side, 0.0])
    e = np.array([0.0, 0.0, -1.0])
    axis = np.cross(a, u)
    cos = np.clip(u @ a, -1.0 + 1e-6, None)[..., None]
    turned = np.cross(axis, e)
    ref = e + turned + np.cross(axis, turned) / (1.0 + cos)
    ref = ref - np.sum(ref * u, axis=-1, keepdims=True) * u
    return ref / np.maximum(np.linalg.norm(ref, axis=-1, keepdims=True), 1e-12)


def _elbow_pole(shoulder: np.ndarray, wrist: np.ndarray, pole: np.ndarray, k: int,
                bones: tuple[float, float], frame: float) -> np.ndarray:
    """Elbow poles (T, 3) of arm ``k`` over the frames of a motion ``frame`` seconds apart
    from ``pole`` (T, 3), with the shoulders and wrist targets (T, 3) and the upper and
    lower arm's lengths ``bones`` (m): where the pole comes within :data:`POLE_FLIP` of a
    bent arm, its swivel angle (from :func:`_swivel_reference`) over each run of frames
    with the arm bent and the pole below :data:`POLE_DEGENERATE` (widened where the elbow
    would swing faster than :data:`SWIVEL_SPEED`) goes linearly, the short way, from the
    frame before the run to the frame after it (held where the run starts or ends the
    motion; where the run is the whole motion, held at its angle where the pole is
    furthest off the arm); ``pole`` elsewhere (a nearly straight arm's elbow is where
    the pole puts it, whatever its side)."""
    u = wrist - shoulder
    dist = np.linalg.norm(u, axis=-1)
    u = u / np.maximum(dist, 1e-12)[:, None]
    unit = pole / np.maximum(np.linalg.norm(pole, axis=-1, keepdims=True), 1e-12)
    off = unit - np.sum(unit * u, axis=-1, keepdims=True) * u
    share = np.linalg.norm(off, axis=-1)
    l1, l2 = bones
    fold = float(np.sqrt(l1 * l1 + l2 * l2 + 2.0 * l1 * l2 * np.cos(_ELBOW_MAX_FLEXION)))
    d = np.clip(dist, fold, l1 + l2)
    along = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d)
    offset = np.sqrt(np.maximum(l1 * l1 - along * along, 0.0))
    bent = offset >= POLE_BENT
    if len(share) < 2 or not np.any((share < POLE_FLIP) & bent):
        return pole
    r = _swivel_reference(u, k)
    b = np.cross(u, r)
    angle = np.arctan2(np.sum(off * b, axis=-1), np.sum(off * r, axis=-1))
    low = (share < POLE_DEGENERATE) & bent
    T = len(low)
    phi = angle.copy()
    for lo, hi in _swivel_runs(low, angle, offset, frame):
        if lo == 0 and hi == T:
            phi[:] = angle[int(np.argmax(share))]
            continue
        before, turn = _swivel_turn(angle, lo, hi)
        phi[lo:hi] = before + (np.arange(lo, hi) - lo + 1) / (hi - lo + 1) * turn
    changed = phi != angle
    out = pole.copy()
    out[changed] = (np.cos(phi)[:, None] * r + np.sin(phi)[:, None] * b)[changed]
    return out


def _swivel_turn(angle: np.ndarray, lo: int, hi: int) -> tuple[float, float]:
    """The swivel ``angle`` (T,) at the frame before the run [lo, hi) (after it where the
    run starts the motion) and the short way (rad) from there to the frame after it
    (none where the run ends the motion)."""
    T = len(angle)
    before = angle[lo - 1] if lo > 0 else angle[min(hi, T - 1)]
    after = angle[hi] if hi < T else before
    return float(before), float((after - before + np.pi) % (2.0 * np.pi) - np.pi)


def _swivel_runs(low: np.ndarray, angle: np.ndarray, offset: np.ndarray, frame: float
                 ) -> list[tuple[int, int]]:
    """The runs [lo, hi) of ``low`` (T,) frames, each widened on both sides (and merged
    with the runs it meets) until turning the swivel ``angle`` (T,) from the frame before
    it to the frame after it at the elbow's largest ``offset`` (T,) from the arm's line
    keeps under :data:`SWIVEL_SPEED` (frames ``frame`` seconds apart)."""
    T = len(low)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], low.astype(np.int8), [0]])))
    runs = [(int(lo), int(hi)) for lo, hi in zip(edges[::2], edges[1::2], strict=True)]
    out: list[tuple[int, int]] = []
    for lo, hi in runs:
        if out and lo <= out[-1][1]:
            lo = out.pop()[0]
        while True:
            span = float(offset[max(lo - 1, 0):hi + 1].max()) \
                * abs(_swivel_turn(angle, lo, hi)[1])
            if span <= SWIVEL_SPEED * (hi - lo + 1) * frame or (lo == 0 and hi == T):
                break
            lo, hi = max(lo - 1, 0), min(hi + 1, T)
            if out and lo <= out[-1][1]:
                lo = out.pop()[0]
        out.append((lo, hi))
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
    from ltl_human_motion.motion.biomechanics import BiomechanicsLimits, joint_angles
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


def _frames(skeleton: Skeleton, st: _Start, t: np.ndarray, pelvis: np.ndarray,
            pitch: np.ndarray, hands: np.ndarray, hand_dir: np.ndarray,
            elbow_pole: np.ndarray, ankles: np.ndarray | None = None,
            toes: np.ndarray | None = None, knee_pole: np.ndarray | None = None,
            trunk: np.ndarray | None = None) -> np.ndarray:
    T = t.size
    ankles = np.broadcast_to(st.ankles, (T, 2, 3)) if ankles is None else ankles
    toes = np.broadcast_to(st.toes, (T, 2, 3)) if toes is None else toes
    knee_pole = np.broadcast_to(st.knee_pole, (T, 2, 3)) if knee_pole is None else knee_pole
    frame = float(t[1] - t[0]) if T > 1 else None
    return _body(skeleton, pelvis, pitch, ankles, toes, knee_pole, hands, hand_dir, elbow_pole,
                 trunk, frame)
