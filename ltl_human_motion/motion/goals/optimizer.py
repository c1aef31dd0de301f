"""Whole-body inverse kinematics with clearance, range-of-motion and contact constraints.

A goal motion is a reference (the hand-shaped model's joint positions, frames (T, J, 3))
that the worker's kinematic model tracks frame by frame as a quadratic program
(differential IK, pinocchio + pink, solved by daqp):

* **Model.** The URDF of :func:`.urdf.worker_urdf` for the stature (66 revolute joints,
  three per bone) on a free-flyer root: 72 degrees of freedom. Bone lengths are exact by
  construction.
* **Tasks** (weighted least squares): the acting palms and wrists at the reference's
  positions, the pelvis and the centre of mass near the reference's, a posture term
  pulling every joint towards the reference's angles.
* **Constraints** (every step): the feet stay planted (equality: the toe links' poses,
  which fix each foot, where the reference has them); the centre of mass over the feet's
  support polygon as the verifier's balance check outlines it (a velocity damper on its
  distance inside each edge); the verifier's ranges of motion of the anatomical angles
  (dampers on the angles, differentiated through the joint positions) and the URDF's
  joint ranges
  (widened only where the reference itself goes beyond them), joint and root speed
  bounds; and
  clearance, a velocity damper (Faverjon & Tournassoud 1987; Kanoun et al. 2011) on the
  distance ``d`` of every body capsule, and of a part in hand, to every obstacle part
  within ``influence``: ``d(q + dq) - margin >= (1 - xi) (d(q) - margin)``, linearized
  with ``grad d`` from the same exact capsule distance the verifier uses (finite
  differences of the capsule's end points, pushed through the links' Jacobians).

Where the reference keeps every capsule at least ``influence`` from every obstacle no
constraint is active and the program's solution is the reference itself, which is then
returned unchanged (no solve). The program is solved at ``rate`` per second and the
frames between are interpolated in configuration space; after the task's last hold the
posture term rises so that the motion ends in the reference's last pose (a residual is
faded out over the last :data:`RETURN_SECONDS`).

Why pinocchio + pink (``docs/ARCHITECTURE.md``): they load the URDF of
:mod:`~ltl_human_motion.motion.urdf` as it is, and pink's ``build_ik`` returns a plain
``qpsolvers`` problem to which our own clearance rows are appended, so the distances are
the verifier's own (no second collision model to keep in step with the capsules).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ltl_human_motion.motion.goals.constraints import (
    ObstacleField,
    SelfPairs,
    balance_rows,
    clearance_rows,
    reference_clearance,
    rom_rows,
    self_rows,
    speed_rows,
    support_edges,
)
from ltl_human_motion.motion.goals.kinematics import (
    BODY_ID,
    BodyKinematics,
    HeldPart,
    body_kinematics,
)
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.urdf import link_name, root_poses

__all__ = ["POSTURE_GAINS", "RETURN_SECONDS", "TrackingResult", "WholeBodyOptions",
           "track_reference"]


@dataclass(frozen=True)
class WholeBodyOptions:
    """Weights and constraint settings of :func:`track_reference`.

    margin: clearance kept from every obstacle part but by the planted feet (which keep
    0), m (over the verifier's 0 by what the
    junction blends and foot locking move a goal motion's first and last frames);
    hand_margin that of the hands and forearms, which reach into tight places (a chamber,
    a bin), and part_margin that of a part in hand (it rests on the furniture it is taken
    from until it is lifted).
    influence: pairs nearer than this get a constraint, m. damper: fraction ``xi`` of the
    remaining clearance one step may use. iterations: QP steps per solved frame; rate:
    solved frames per second. The weights are those of the tasks (palm, wrist, pelvis,
    centre of mass, posture: see :data:`POSTURE_GAINS`) and the Tikhonov damping;
    joint_speed (rad/s) and root_speed (m/s, rad/s) bound each step; speed_limits (J,)
    m/s bound every joint's speed (the verifier's, with room); self_pairs are the body's
    own capsule pairs kept apart (constrained within ``self_influence`` m of their least
    distance); the centre of mass is kept over the feet's support polygon, at most
    ``balance_slack`` m outside it (5 mm inside the verifier's margin), constrained within
    ``balance_influence`` m of its edges (None: not constrained); ``ranges``
    ((angle, lo, hi) degrees, the verifier's ranges of motion by anatomical angle) keep
    each angle ``range_margin`` inside them, constrained within ``range_influence``
    degrees of a limit (None: only the URDF's joint limits).
    """

    margin: float = 0.02
    hand_margin: float = 0.01
    part_margin: float = 0.004
    influence: float = 0.12
    damper: float = 0.3
    iterations: int = 1
    hand_weight: float = 1.0
    wrist_weight: float = 0.2
    pelvis_weight: float = 0.05
    posture_weight: float = 1e-2
    damping: float = 1e-3
    com_weight: float = 0.05
    joint_speed: float = 4.0
    rate: float = 40.0
    root_speed: float = 1.0
    speed_limits: tuple[float, ...] | None = None
    self_pairs: SelfPairs | None = None
    self_influence: float = 0.05
    balance_influence: float | None = 0.05
    balance_slack: float = 0.015
    ranges: tuple[tuple[str, float, float], ...] | None = None
    range_influence: float = 5.0
    range_margin: float = 0.5


@dataclass(frozen=True)
class TrackingResult:
    """What :func:`track_reference` made: positions (T, J, 3); whether any constraint
    was active; the least clearance over all frames (m; inf where no obstacle was ever
    within ``influence``); the largest distance (m) of a tracked palm from its reference
    and its frame; how far (m) the program's last frame was from the reference's before
    the fade; QP steps with no feasible solution; the frames from the first one solved
    to the last one near an obstacle; how fast (m/s) the program was closing on the
    reference's last pose over its last :data:`RETURN_SECONDS` (negative: moving away)."""

    positions: np.ndarray
    constrained: bool
    least_clearance: float
    worst_miss: float = 0.0
    worst_frame: int = 0
    end_miss: float = 0.0
    failed_steps: int = 0
    window: tuple[int, int] = (0, 0)
    closing: float = 0.0


def _missed(out: np.ndarray, ref: np.ndarray, tracked: tuple[str, ...],
            give_up: tuple[tuple[int, ...], float], after: int, upto: int) -> bool:
    """Whether a tracked palm of ``out`` (T, J, 3) is further than ``give_up``'s
    tolerance from ``ref``'s at one of its frames in (``after``, ``upto``]."""
    frames, tolerance = give_up
    idx = [JOINT_INDEX[j] for j in tracked]
    return any(float(np.linalg.norm(out[f, idx] - ref[f, idx], axis=-1).max()) > tolerance
               for f in frames if after < f <= upto)


#: Frames the program starts before the first frame with an obstacle within
#: ``influence`` (the solution equals the reference up to there).
_LEAD_FRAMES = 2
#: Weight of the posture term at the end of a motion, and how long (s) it takes to rise
#: there from the release frame (:func:`track_reference`).
RETURN_WEIGHT = 1.0
RETURN_SECONDS = 0.3
#: Joint positions (m) within which the solution is back on the reference, after which
#: the rest of the reference is taken as it is.
_CONVERGED = 5e-4


#: The posture term's weight of the joints of each anatomical joint, over the arms':
#: a person reaches past an obstacle with the arm, not by bending the trunk sideways or
#: shrugging (the verifier's ranges of motion are far narrower for the trunk).
POSTURE_GAINS: dict[str, float] = {
    "lumbar": 30.0, "thoracic": 30.0, "cervicothoracic": 10.0, "neck": 3.0,
    "sternal": 10.0, "sternoclavicular": 5.0, "pelvis": 10.0, "hip": 3.0, "knee": 3.0,
    "ankle": 3.0}


def _posture_weights(kin: BodyKinematics, base: float) -> np.ndarray:
    """Weights (nv - 6,) of the posture term per revolute joint (pinocchio's order)."""
    model = kin.model
    out = np.full(model.nv - 6, float(base))
    for j in range(2, model.njoints):
        out[model.idx_vs[j] - 6] = base * POSTURE_GAINS.get(_anatomical(model.names[j]), 1.0)
    return out


#: Anatomical joints that follow the reference's angles: the clavicles and shoulders
#: are rigid in the chest's frame on the canonical skeleton, a frame set by the
#: shoulders and the neck (synthesis rebuilds them so,
#: :func:`~ltl_human_motion.motion.retarget.enforce_bone_lengths`), so a shrug or a turn
#: of the neck's base the program made would move the arms after it.
RIGID_JOINTS: tuple[str, ...] = ("sternal", "sternoclavicular", "cervicothoracic")


def _rigid_joints(kin: BodyKinematics) -> np.ndarray:
    """Indices into the revolute joints' velocities (nv - 6,) of :data:`RIGID_JOINTS`."""
    model = kin.model
    return np.array([model.idx_vs[j] - 6 for j in range(2, model.njoints)
                     if _anatomical(model.names[j]) in RIGID_JOINTS], dtype=int)


def _anatomical(joint: str) -> str:
    """The anatomical joint of a URDF joint name, without side: ``l_sternal_z_wbik`` ->
    ``sternal``."""
    name = joint.rsplit("_", 2)[0]
    return name[2:] if name[:2] in ("l_", "r_") else name


class _Tracker:
    """The per-frame program of :func:`track_reference`."""

    def __init__(self, kin: BodyKinematics, ref: np.ndarray, tracked: tuple[str, ...],
                 opts: WholeBodyOptions, fps: float, palms: np.ndarray | None = None,
                 stature: float | None = None) -> None:
        import pinocchio as pin
        from pink.tasks import ComTask, FrameTask, PostureTask
        self.kin, self.ref, self.opts, self.dt = kin, ref, opts, 1.0 / fps
        self.stature = stature
        self.ranges = None if opts.ranges is None else {k: (lo, hi) for k, lo, hi in opts.ranges}
        # The frames the verifier's balance check reads (both feet planted, the pelvis
        # still): the balance rows hold there only.
        self.static = np.zeros(len(ref), dtype=bool)
        if stature is not None and opts.balance_influence is not None:
            from ltl_human_motion.motion.biomechanics import balance_margins
            self.static[balance_margins(ref, fps, stature)[0]] = True
        self.roots = root_poses(ref)
        self.q_ref = kin.configurations(ref, self.roots)
        self.q_ref[:, 7:] = np.unwrap(self.q_ref[:, 7:], axis=0)
        self.ref_data = kin.model.createData()
        self.tracked = tuple(tracked) + tuple(j.replace("hand", "wrist") for j in tracked)
        # Where the task points are (T, 2 * len(tracked), 3): the reference's, or the
        # palms given with their wrists moved along.
        self.targets = ref[:, [JOINT_INDEX[j] for j in self.tracked]]
        if palms is not None:
            moved = np.asarray(palms) - self.targets[:, :len(tracked)]
            self.targets = self.targets + np.concatenate([moved, moved], axis=1)
        weights = (opts.hand_weight,) * len(tracked) + (opts.wrist_weight,) * len(tracked)
        self.points = [FrameTask(link_name(j, BODY_ID), position_cost=w, orientation_cost=0.0)
                       for j, w in zip(self.tracked, weights, strict=True)]
        self.pelvis = FrameTask(link_name("pelvis", BODY_ID), position_cost=opts.pelvis_weight,
                                orientation_cost=opts.pelvis_weight)
        self.posture_weights = _posture_weights(kin, opts.posture_weight)
        self.posture = PostureTask(cost=self.posture_weights)
        self.com = ComTask(cost=np.array([opts.com_weight, opts.com_weight, 0.0]))
        self.feet_joints = ("l_toe", "r_toe")
        self.feet = [FrameTask(link_name(j, BODY_ID), position_cost=1.0, orientation_cost=0.0)
                     for j in self.feet_joints]
        self._pin = pin
        # The URDF's ranges, widened to what the reference itself uses (a ball joint's
        # Euler angles can leave them where the clinical angles do not): the program
        # never takes a joint further out than the reference does.
        model = kin.model
        lo = np.minimum(model.lowerPositionLimit[7:], self.q_ref[:, 7:].min(axis=0))
        hi = np.maximum(model.upperPositionLimit[7:], self.q_ref[:, 7:].max(axis=0))
        self.range = (lo, hi)
        self.speed = opts.joint_speed * self.dt
        self.rigid = _rigid_joints(kin)
        self.root_speed = opts.root_speed * self.dt

    def bounds(self, q: np.ndarray, t: int, frames: int = 1) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper bounds (nv,) of a step over ``frames`` frames from ``q`` to
        frame ``t``: range of motion and speed of the revolute joints, speed of the root;
        :data:`RIGID_JOINTS` go to the reference's angles."""
        lb = np.full(self.kin.model.nv, -self.root_speed * frames)
        ub = np.full(self.kin.model.nv, self.root_speed * frames)
        lo, hi = self.range
        lb[6:] = np.maximum(lo - q[7:], -self.speed * frames)
        ub[6:] = np.minimum(hi - q[7:], self.speed * frames)
        lb, ub = np.minimum(lb, 0.0), np.maximum(ub, 0.0)
        to_ref = self.q_ref[t, 7:][self.rigid] - q[7:][self.rigid]
        lb[6 + self.rigid] = ub[6 + self.rigid] = to_ref
        return lb, ub

    def set_frame(self, t: int) -> list:
        """Point every task at the reference's frame ``t``; the tasks (soft)."""
        pin = self._pin
        for task, point in zip(self.points, self.targets[t], strict=True):
            task.set_target(pin.SE3(np.eye(3), point))
        model, data = self.kin.model, self.ref_data
        self.com.set_target(pin.centerOfMass(model, data, self.q_ref[t]))
        pin.updateFramePlacements(model, data)
        for task, j in zip(self.feet, self.feet_joints, strict=True):
            task.set_target(data.oMf[int(self.kin.frames[JOINT_INDEX[j]])].copy())
        self.pelvis.set_target(pin.SE3(self.roots[t, :3, :3], self.roots[t, :3, 3]))
        self.posture.set_target(self.q_ref[t])
        return [*self.points, self.pelvis, self.posture, self.com]

    def rows(self, pos: np.ndarray, field_: ObstacleField, held: HeldPart | None,
             frames: int, t: int) -> tuple[np.ndarray, np.ndarray, bool]:
        """The inequality rows ``G dq <= h`` of a step over ``frames`` frames from the
        configuration whose joint positions (J, 3) are ``pos`` and whose kinematics
        ``kin.data`` holds (:meth:`.BodyKinematics.positions` made both) to frame ``t``:
        clearance to the obstacles and within the body, ranges of motion,
        balance (where the reference stands still at ``t``, no worse than its), joint
        speeds; and whether an
        obstacle, a body pair, a range's limit or an edge of the support polygon is near
        enough to constrain it."""
        opts, kin = self.opts, self.kin
        G, h, _ = clearance_rows(kin, pos, field_, held, opts.influence, opts.damper,
                                 (opts.margin, opts.hand_margin, opts.part_margin))
        parts = [(G, h)]
        if opts.self_pairs is not None:
            parts.append(self_rows(kin, pos, opts.self_pairs, opts.self_influence,
                                   opts.damper))
        if opts.ranges is not None:
            parts.append(rom_rows(kin, pos, self.ranges, opts.range_influence,
                                  opts.range_margin, opts.damper))
        if self.static[t]:
            parts.append(balance_rows(kin, pos, support_edges(pos, self.stature),
                                      opts.balance_influence, opts.damper, self.ref[t],
                                      opts.balance_slack))
        active = sum(len(x[1]) for x in parts) > 0
        if opts.speed_limits is not None:
            parts.append(speed_rows(kin, np.asarray(opts.speed_limits), self.dt * frames))
        return np.vstack([x[0] for x in parts]), np.concatenate([x[1] for x in parts]), active

    def step(self, conf, tasks: list, rows: tuple[np.ndarray, np.ndarray], t: int,
             frames: int = 1) -> bool:
        """One QP step over ``frames`` frames from ``conf`` (pink Configuration) to frame
        ``t``, integrated in place; False if no step satisfies the constraints (then ``conf`` is
        unchanged)."""
        import pink
        import qpsolvers
        G, h = rows
        dt = self.dt * frames
        # The program of the step, built once (the relaxed retry solves a fresh copy).
        built = pink.build_ik(conf, tasks, dt, damping=self.opts.damping, limits=[],
                              constraints=self.feet)
        parts = tuple(None if a is None else a.copy()
                      for a in (built.P, built.q, built.G, built.h, built.A, built.b))
        lb, ub = self.bounds(conf.q, t, frames)
        for relax in (False, True):
            problem = built if not relax else qpsolvers.Problem(
                *(None if a is None else a.copy() for a in parts))
            problem.lb, problem.ub = (lb, ub) if not relax else (lb.copy(), ub.copy())
            if len(h):
                hh = np.maximum(h, 0.0) if relax else h
                problem.G = G if problem.G is None else np.vstack([problem.G, G])
                problem.h = hh if problem.h is None else np.concatenate([problem.h, hh])
            sol = qpsolvers.solve_problem(problem, solver="daqp")
            if sol.found:
                conf.integrate_inplace(sol.x / dt, dt)
                return True
        return False


def _blend_end(out: np.ndarray, ref: np.ndarray, frames: int) -> np.ndarray:
    """``out`` (T, J, 3) with its last frame's residual against ``ref``'s last frame faded
    in over the last ``frames`` frames (minimum jerk), so that it ends exactly there."""
    from ltl_human_motion.motion.ik import min_jerk
    frames = max(min(frames, len(out) - 1), 1)
    w = min_jerk(np.linspace(0.0, 1.0, frames + 1))[1:]
    blended = out.copy()
    blended[-frames:] += w[:, None, None] * (ref[-1] - out[-1])[None]
    return blended


def _window(ref: np.ndarray, near: np.ndarray, palms: np.ndarray | None,
            tracked: tuple[str, ...]) -> tuple[int, int]:
    """The frames of ``ref`` (T, J, 3) the program solves: from ``_LEAD_FRAMES`` before
    the first frame an obstacle is near (``near`` (T,), finite there) or the ``palms``
    (T, K, 3) leave the reference's ``tracked`` palms, to the last such frame."""
    first = int(np.argmax(np.isfinite(near)))
    last_near = len(ref) - 1 - int(np.argmax(np.isfinite(near[::-1])))
    if palms is not None:
        moved = np.any(np.abs(np.asarray(palms) - ref[:, [JOINT_INDEX[j] for j in tracked]])
                       > 0.0, axis=(1, 2))
        if moved.any():
            first = min(first, int(np.argmax(moved)))
            last_near = max(last_near, len(ref) - 1 - int(np.argmax(moved[::-1])))
    return max(first - _LEAD_FRAMES, 0), last_near


def track_reference(reference: np.ndarray, stature: float, field_: ObstacleField, *,
                    tracked: tuple[str, ...] = ("l_hand", "r_hand"),
                    options: WholeBodyOptions | None = None, fps: float = 30.0,
                    held: HeldPart | None = None, held_from: int = 0,
                    release_from: int | None = None,
                    palms: np.ndarray | None = None,
                    give_up: tuple[tuple[int, ...], float] | None = None) -> TrackingResult:
    """Positions (T, J, 3) of the worker's model tracking ``reference`` (T, J, 3) under
    the constraints of the module docstring.

    ``tracked``: the joints (palms) whose reference positions are the task; ``held``: a
    part carried by a hand from frame ``held_from`` on, kept clear like the body. From
    frame ``release_from`` (default: the last quarter) the posture term's weight rises
    to :data:`RETURN_WEIGHT` within :data:`RETURN_SECONDS`, so that the motion ends in
    the reference's last pose, where the next primitive starts. ``palms`` (T,
    len(tracked), 3): the tracked palms' path where it is not the reference's (made
    clear of the obstacles, :func:`.palm_path.clear_palm_path`; the wrists move along).
    ``give_up`` (frames, tolerance m): stop once a tracked palm is further than that from
    its reference at one of those frames (the caller refuses such a motion; the frames
    after it are the reference's).
    """
    import pink
    import pinocchio as pin

    opts = options or WholeBodyOptions()
    ref = np.asarray(reference, dtype=np.float64)
    kin = body_kinematics(stature)
    near = reference_clearance(kin, ref, field_, opts.influence, held, held_from)
    if not np.isfinite(near).any():
        return TrackingResult(ref, False, np.inf)
    first, last_near = _window(ref, near, palms, tracked)
    tracker = _Tracker(kin, ref, tracked, opts, fps, palms, stature)
    release = int(0.75 * len(ref)) if release_from is None else int(release_from)
    conf = pink.Configuration(kin.model, kin.data, tracker.q_ref[first].copy())
    out = ref.copy()
    constrained, failed = False, 0
    stride = max(round(fps / opts.rate), 1)
    t, q_prev = first, conf.q.copy()
    pos = kin.positions(conf.q)
    while t < len(ref) - 1:
        step = min(stride, len(ref) - 1 - t)
        t += step
        ramp = min(max((t - release) / (RETURN_SECONDS * fps), 0.0), 1.0)
        tracker.posture.cost = tracker.posture_weights \
            + ramp * (RETURN_WEIGHT - tracker.posture_weights)
        tasks = tracker.set_frame(t)
        for i in range(opts.iterations):
            if i:
                pos = kin.positions(conf.q)
            G, h, active = tracker.rows(pos, field_, held if t >= held_from else None,
                                        step, t)
            constrained |= active
            failed += not tracker.step(conf, tasks, (G, h), t, step)
        for k in range(1, step):
            out[t - step + k] = kin.positions(pin.interpolate(kin.model, q_prev, conf.q,
                                                              k / step))
        out[t] = pos = kin.positions(conf.q)
        q_prev = conf.q.copy()
        if t > last_near and np.abs(out[t] - ref[t]).max() < _CONVERGED:
            out[t:] = ref[t:]
            break
        if give_up is not None and _missed(out, ref, tracked, give_up, t - step, t):
            out[t + 1:] = ref[t + 1:]
            break
    end_miss = float(np.abs(out[-1] - ref[-1]).max())
    back = min(int(RETURN_SECONDS * fps), len(ref) - 1)
    closing = (float(np.abs(out[-1 - back] - ref[-1]).max()) - end_miss) / max(back / fps, 1e-9)
    if end_miss > 0.0:
        out = _blend_end(out, ref, int(RETURN_SECONDS * fps))
    final = reference_clearance(kin, out, field_, opts.influence, held, held_from)
    miss = np.zeros(len(ref))
    for k, j in enumerate(tracked):
        miss = np.maximum(miss, np.linalg.norm(out[:, JOINT_INDEX[j]] - tracker.targets[:, k],
                                               axis=-1))
    least = float(final.min())
    return TrackingResult(out, constrained, least, float(miss.max()), int(miss.argmax()),
                          end_miss, failed, (first, last_near), closing)
