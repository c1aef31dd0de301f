"""REBA, RULA, OWAS and NIOSH lifting of a synthesized motion: per frame, per task, per motion.

Postural thresholds the methods leave to the observer (what counts as "twisted",
"abducted", "raised", "unilateral") are named below with the value used here.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ltl_human_motion.assess import owas, reba, rula
from ltl_human_motion.assess.angles import BodyAngles, body_angles
from ltl_human_motion.assess.handling import held_masks, lifts
from ltl_human_motion.assess.niosh import lift as niosh_lift
from ltl_human_motion.motion.skeleton import JOINT_INDEX

if TYPE_CHECKING:
    from ltl_human_motion.planning.result import SynthesizedMotion

__all__ = ["ABDUCTED_DEG", "ErgonomicsReport", "ErgonomicsSettings", "assess_motion",
           "task_kind"]

#: deg. Trunk twist or side bend, or neck side bend, beyond this counts as "twisted" /
#: "side flexed" (REBA and RULA name the condition, not an angle; 10 deg is our choice).
TWIST_DEG = 10.0
#: deg. Upper arm sideways elevation beyond this counts as "abducted" (our choice, the
#: 20 deg of the methods' first flexion band).
ABDUCTED_DEG = 20.0
#: deg. Clavicle elevation beyond this counts as "shoulder raised" (our choice).
RAISED_DEG = 10.0
#: m. Ankle height difference beyond this, outside walking, counts as unilateral
#: weight bearing (one foot off the floor; our choice).
UNILATERAL_M = 0.05
#: m. A wrist this far outside its shoulder works "out to the side" (RULA lower arm +1).
OUT_TO_SIDE_M = 0.15
#: s. A cycle shorter than this repeats more than 4 times a minute: REBA activity +1 and
#: RULA muscle use +1 ("repeated more than 4 times per minute", both papers).
REPEAT_CYCLE_S = 15.0
#: s. A posture held longer than this is static (both papers: "held for longer than 1 min").
STATIC_S = 60.0

_WALK_KINDS = ("walk", "carry", "enter")


def task_kind(task: str) -> str:
    """Name of a task without its arguments: ``"grasp(O1)"`` -> ``"grasp"``."""
    return task.split("(", 1)[0].strip()


@dataclass(frozen=True)
class ErgonomicsSettings:
    """How loads are handled: REBA coupling (good/fair/poor/unacceptable), NIOSH coupling
    (good/fair/poor) and work duration (1h/2h/8h)."""

    reba_coupling: str = "fair"
    niosh_coupling: str = "fair"
    duration: str = "8h"

    def __post_init__(self) -> None:
        if self.reba_coupling not in reba.COUPLING:
            raise ValueError(f"reba_coupling must be one of {sorted(reba.COUPLING)}, got "
                             f"{self.reba_coupling!r}")
        if self.niosh_coupling not in ("good", "fair", "poor"):
            raise ValueError(f"niosh_coupling must be good, fair or poor, got "
                             f"{self.niosh_coupling!r}")
        if self.duration not in ("1h", "2h", "8h"):
            raise ValueError(f"duration must be 1h, 2h or 8h, got {self.duration!r}")


@dataclass
class ErgonomicsReport:
    """Scores of one motion.

    Attributes
    ----------
    reba, rula : ndarray of int, shape (T,)
        Per-frame scores.
    owas : ndarray of int, shape (T,)
        Per-frame OWAS action category (1-4).
    load : ndarray, shape (T,)
        kg in hand per frame.
    angles : BodyAngles
    per_task : list of dict
        One entry per timeline step plus ``"walking"`` for the approach gait.
    lifts : list of dict
        NIOSH multipliers, RWL and LI at origin and destination of every lift.
    summary : dict
        Motion-level figures (worst and mean scores, time shares per action level, worst
        lifting index).
    """

    reba: np.ndarray
    rula: np.ndarray
    load: np.ndarray
    angles: BodyAngles
    per_task: list[dict[str, Any]] = field(default_factory=list)
    lifts: list[dict[str, Any]] = field(default_factory=list)
    summary: dict[str, Any] = field(default_factory=dict)
    owas: np.ndarray | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON-friendly summary (no per-frame arrays)."""
        return {"summary": self.summary, "per_task": self.per_task, "lifts": self.lifts}


def _frame_scores(a: BodyAngles, load: np.ndarray, holding: np.ndarray, walking: np.ndarray,
                  sitting: np.ndarray, repeated: bool, static: bool,
                  settings: ErgonomicsSettings) -> tuple[np.ndarray, np.ndarray]:
    twisted = (a.trunk_twist > TWIST_DEG) | (a.trunk_side_bend > TWIST_DEG)
    knee = np.where(walking, a.knee_flexion.min(axis=1), a.knee_flexion.max(axis=1))
    unilateral = (a.ankle_height_difference > UNILATERAL_M) & ~walking & ~sitting
    trunk = reba.trunk_score(a.trunk_flexion, twisted)
    neck = reba.neck_score(a.neck_flexion, a.neck_side_bend > TWIST_DEG)
    legs = reba.legs_score(unilateral, knee, sitting)
    abducted = a.upper_arm_abduction > ABDUCTED_DEG
    raised = a.shoulder_raise > RAISED_DEG
    coupling = np.where(holding, reba.COUPLING[settings.reba_coupling], 0)
    activity = int(repeated) + int(static)
    best_reba = None
    for s in (0, 1):
        r = reba.reba_score(trunk, neck, legs,
                            reba.upper_arm_score(a.upper_arm_flexion[:, s], abducted[:, s],
                                                 raised[:, s]),
                            reba.lower_arm_score(a.elbow_flexion[:, s]),
                            reba.wrist_score(a.wrist_flexion[:, s]),
                            reba.load_score(load), coupling, activity)["reba"]
        best_reba = r if best_reba is None else np.maximum(best_reba, r)
    muscle = int(repeated or static)
    force = rula.force_score(load, repeated or static)
    r_neck = rula.neck_score(a.neck_flexion, False, a.neck_side_bend > TWIST_DEG)
    r_trunk = rula.trunk_score(a.trunk_flexion, a.trunk_twist > TWIST_DEG,
                               a.trunk_side_bend > TWIST_DEG, sitting)
    r_legs = np.where(unilateral, 2, 1)
    best_rula = None
    for s in (0, 1):
        across = (a.wrist_across[:, s] > 0) | (a.wrist_out[:, s] > OUT_TO_SIDE_M)
        r = rula.rula_score(rula.upper_arm_score(a.upper_arm_flexion[:, s], raised[:, s],
                                                 abducted[:, s]),
                            rula.lower_arm_score(a.elbow_flexion[:, s], across),
                            rula.wrist_score(a.wrist_flexion[:, s]), 1,
                            r_neck, r_trunk, r_legs, muscle, force, muscle, force)["rula"]
        best_rula = r if best_rula is None else np.maximum(best_rula, r)
    return best_reba.astype(np.int64), best_rula.astype(np.int64)


def _stats(x: np.ndarray, fps: float) -> dict[str, Any]:
    if not len(x):
        return {"max": None, "mean": None, "time_of_max": None}
    i = int(np.argmax(x))
    return {"max": int(x[i]), "mean": float(np.mean(x)), "time_of_max": i / fps}


def _lift_ends(pos: np.ndarray, hand: int, frames: tuple[int, int]) -> list[dict[str, float]]:
    j = JOINT_INDEX["l_hand" if hand == 0 else "r_hand"]
    out = []
    for f in frames:
        ankles = 0.5 * (pos[f, JOINT_INDEX["l_ankle"]] + pos[f, JOINT_INDEX["r_ankle"]])
        hip = pos[f, JOINT_INDEX["l_hip"]] - pos[f, JOINT_INDEX["r_hip"]]
        fwd = np.array([hip[1], -hip[0]])         # lateral x up, on the floor
        reach = pos[f, j, :2] - ankles[:2]
        h = float(np.linalg.norm(reach))
        ang = float(np.degrees(np.arccos(np.clip(reach @ fwd / max(h * np.linalg.norm(fwd),
                                                                    1e-12), -1, 1))))
        out.append({"H": 100 * h, "V": 100 * float(pos[f, j, 2]), "A": ang})
    return out


def assess_motion(synth: SynthesizedMotion, masses: Mapping[str, float] | None = None,
                  settings: ErgonomicsSettings | None = None, cycles: int = 1
                  ) -> ErgonomicsReport:
    """Score every frame of ``synth`` and summarise per task and per motion.

    Parameters
    ----------
    synth : SynthesizedMotion
    masses : mapping of str to float, optional
        kg per part (a cell's ``objects[name].mass``); default 1 kg each.
    settings : ErgonomicsSettings, optional
    cycles : int
        Work cycles in the motion (sets the repetition rate and the lift frequency).
    """
    settings = settings or ErgonomicsSettings()
    masses = dict(masses or {})
    pos = synth.positions
    fps = synth.fps
    T = len(pos)
    a = body_angles(pos, synth.motion.skeleton.stature)
    held = held_masks(pos, synth.objects)
    load = np.zeros(T)
    holding = np.zeros(T, dtype=bool)
    for name, (mask, _) in held.items():
        load += mask * float(masses.get(name, 1.0))
        holding |= mask
    idx = synth.task_index
    kinds = [task_kind(synth.task_label(i)) for i in range(len(synth.timeline))]
    walking = idx < 0
    sitting = np.zeros(T, dtype=bool)
    waits = []
    for seg, kind in zip(synth.timeline, kinds):
        if kind in _WALK_KINDS:
            walking[seg.start_frame:seg.end_frame] = True
        if kind == "sit":
            sitting[seg.start_frame:] = True
        if kind == "standUp":
            sitting[seg.start_frame:] = False
        if kind == "wait":
            waits.append(seg.n_frames / fps)
    cycle_time = synth.duration / max(int(cycles), 1)
    repeated = cycle_time < REPEAT_CYCLE_S
    static = bool(waits) and max(waits) > STATIC_S
    reba_f, rula_f = _frame_scores(a, load, holding, walking, sitting, repeated, static,
                                   settings)
    kneeling = np.zeros(T, dtype=bool)
    for seg, kind in zip(synth.timeline, kinds):
        if kind == "kneel":
            kneeling[seg.start_frame:seg.end_frame] = True
    # a knee below its own ankle rests on the floor (a reach under a low board kneels)
    for s in "lr":
        kneeling |= pos[:, JOINT_INDEX[f"{s}_knee"], 2] < pos[:, JOINT_INDEX[f"{s}_ankle"], 2]
    owas_f = owas.action_category(
        owas.back_code(a.trunk_flexion, a.trunk_twist),
        owas.arms_code(a.upper_arm_flexion[:, 0], a.upper_arm_flexion[:, 1]),
        owas.legs_code(a.knee_flexion[:, 0], a.knee_flexion[:, 1],
                       (a.ankle_height_difference > UNILATERAL_M) & ~walking, sitting,
                       kneeling, walking),
        owas.load_code(load))
    per_task = []
    for i, seg in enumerate(synth.timeline):
        sl = slice(seg.start_frame, seg.end_frame)
        per_task.append({"step": i, "task": synth.task_label(i), "kind": kinds[i],
                         "start": seg.start_frame / fps, "duration": seg.n_frames / fps,
                         "reba": _stats(reba_f[sl], fps), "rula": _stats(rula_f[sl], fps),
                         "owas": _stats(owas_f[sl], fps)})
    gait = idx < 0
    per_task.append({"step": -1, "task": "walking", "kind": "walk",
                     "duration": float(gait.sum()) / fps,
                     "reba": _stats(reba_f[gait], fps), "rula": _stats(rula_f[gait], fps)})
    n_lifts = lifts(pos, synth.objects, held)
    freq = len(n_lifts) / (cycle_time * max(int(cycles), 1) / 60.0) if T else 0.0
    lift_rows = []
    for lf in n_lifts:
        ends = _lift_ends(pos, lf.hand, (lf.start, lf.end - 1))
        d = abs(ends[1]["V"] - ends[0]["V"])
        mass = float(masses.get(lf.obj, 1.0))
        res = [niosh_lift(mass, e["H"], e["V"], d, e["A"], freq, settings.duration,
                          settings.niosh_coupling, v_origin_cm=ends[0]["V"]).to_dict()
               for e in ends]
        lift_rows.append({"object": lf.obj, "start": lf.start / fps, "end": lf.end / fps,
                          "hand": "left" if lf.hand == 0 else "right", "origin": res[0],
                          "destination": res[1], "LI": max(res[0]["LI"], res[1]["LI"])})
    levels_reba = reba.action_level(reba_f)
    levels_rula = rula.action_level(rula_f)
    summary = {
        "frames": T, "fps": fps,
        "reba": _stats(reba_f, fps), "rula": _stats(rula_f, fps),
        "owas": _stats(owas_f, fps),
        "owas_time_share_by_category": {str(k): float(np.mean(owas_f == k))
                                        for k in range(1, 5)},
        "reba_time_share_by_level": {str(k): float(np.mean(levels_reba == k))
                                     for k in range(5)},
        "rula_time_share_by_level": {str(k): float(np.mean(levels_rula == k))
                                     for k in range(1, 5)},
        "lifts": len(lift_rows), "lift_frequency_per_min": freq,
        "max_lifting_index": max((r["LI"] for r in lift_rows), default=0.0),
        "max_load_kg": float(load.max()) if T else 0.0,
        "repeated": bool(repeated), "static": static,
    }
    return ErgonomicsReport(reba_f, rula_f, load, a, per_task, lift_rows, summary, owas_f)
