"""Verification of every synthesized motion before it is returned.

Checks (each a key of the report):

``start``        frame 0 of the body enters the start region R0;
``collision``    no frame collides with an obstacle (body capsules and carried objects);
``termination``  every task's Table I termination condition holds within its step;
``ltl``          the trace of predicates observed on the motion satisfies the
                 specification (with the always-on conjuncts), checked by the
                 independent lasso evaluator;
``smoothness``   no joint moves faster than a human can (no jumps);
``feet``         the feet never go below the floor and never all leave it for long;
``joint_speed``, ``range_of_motion``, ``self_penetration``, ``balance``, ``foot_skate``
                 biomechanical plausibility of the whole blended motion (per-joint speed
                 limits by body part and activity, anatomical range of motion, no body
                 part through another, static balance, foot skate): see
                 :mod:`~ltl_human_motion.motion.biomechanics` for the limits and their
                 sources. On by default (``VerificationOptions.biomechanics``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from ltl_human_motion.errors import VerificationError
from ltl_human_motion.motion.biomechanics import (
    BiomechanicsLimits,
    check_biomechanics,
    frame_labels,
    seated_frames,
)
from ltl_human_motion.motion.capsules import capsule_radii
from ltl_human_motion.motion.skeleton import JOINT_INDEX, MAX_STATURE
from ltl_human_motion.scene.geometry import point_bounds

if TYPE_CHECKING:
    from ltl_human_motion.ltl.formula import Atom
    from ltl_human_motion.ltl.sequences import TaskSequence
    from ltl_human_motion.ltl.spec import Specification

FOOT_JOINTS = ("l_ankle", "l_toe", "r_ankle", "r_toe")


@dataclass(frozen=True)
class VerificationOptions:
    """Limits of the checks.

    Attributes
    ----------
    eps : float
        Radius of B(eps) in Table I, metres.
    max_joint_speed : float
        Fastest allowed joint speed, m/s (an 8 cm jump between frames at 120 Hz is
        10 m/s; swinging toes reach 5-8 m/s).
    floor_tolerance : float
        How far a foot joint may dip below the floor, metres.
    max_flight : float
        Longest time both feet may be more than ``flight_height`` above the floor, s.
    flight_height : float
    biomechanics : bool
        Run the biomechanical checks (default on; off measures or reproduces the
        motions of the looser verification of earlier releases: docs/design-notes.md,
        "Human plausibility").
    limits : BiomechanicsLimits
        Their limits (:mod:`~ltl_human_motion.motion.biomechanics`).
    """

    eps: float = 0.05
    max_joint_speed: float = 10.0
    floor_tolerance: float = 0.02
    max_flight: float = 0.15
    flight_height: float = 0.12
    biomechanics: bool = True
    limits: BiomechanicsLimits = field(default_factory=BiomechanicsLimits)


#: Largest body capsule radius (m) at the tallest stature (0.162 m).
_MAX_RADIUS = float(capsule_radii(MAX_STATURE).max())


def near_frames(positions: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                margin: float = 0.0, boxes: tuple[np.ndarray, np.ndarray] | None = None
                ) -> np.ndarray:
    """Frames whose body bounding box comes within ``margin`` of the box [lo, hi].

    A cheap broad phase: frames not returned cannot enter, touch or collide with
    anything inside the box.

    Parameters
    ----------
    positions : ndarray, shape (T, J, 3)
    lo, hi : array-like, shape (3,)
    margin : float
    boxes : (ndarray (T, 3), ndarray (T, 3)), optional
        :func:`~ltl_human_motion.scene.geometry.point_bounds` of ``positions`` if known.

    Returns
    -------
    frames : ndarray of int
    """
    body_lo, body_hi = point_bounds(positions) if boxes is None else boxes
    hit = np.all((body_lo - _MAX_RADIUS - margin <= np.asarray(hi))
                 & (body_hi + _MAX_RADIUS + margin >= np.asarray(lo)), axis=1)
    return np.flatnonzero(hit)


def _check(passed: bool, detail: str, **values: object) -> dict:
    return {"passed": bool(passed), "detail": detail, **values}


def step_windows(synth, n_steps: int) -> list[tuple[int, int]]:
    """Frame window of each task step: from the end of the previous step to its own end."""
    windows = []
    prev_end = 0
    for seg in synth.timeline[:n_steps]:
        windows.append((prev_end, max(seg.end_frame, prev_end + 1)))
        prev_end = seg.end_frame
    return windows


def observed_letters(synth, cell, spec: Specification, steps: Sequence[Atom],
                     termination: list[bool], stature: float) -> list[frozenset[str]]:
    """The letter of each step as observed on the motion.

    A task atom holds at a step when that step executed the task and its termination
    condition held; ``enter(R)`` holds when the body's occupancy meets R in the window.
    """
    from ltl_human_motion.ltl.spec import letter_of
    from ltl_human_motion.scene.predicates import enter

    pos = synth.motion.positions
    windows = step_windows(synth, len(steps))
    regions = list(cell.regions.values())
    body_lo, body_hi = point_bounds(pos)
    letters = []
    for task, ok, (a, b) in zip(steps, termination, windows):
        letter: set[str] = set()
        if ok:
            letter |= {key for key in letter_of(task, spec.vocabulary)
                       if not key.startswith("enter(")}
        window = pos[a:b]
        for region in regions:
            cand = near_frames(window, region.lo, region.hi,
                               boxes=(body_lo[a:b], body_hi[a:b]))
            # Most entered regions are entered for many frames: try every 8th first.
            if cand.size and (np.any(enter(window[cand[::8]], region, stature=stature))
                              or np.any(enter(window[cand], region, stature=stature))):
                letter.add(f"enter({region.name})")
        letters.append(frozenset(letter))
    return letters


def verify_motion(synth, cell, spec: Specification, sequence: TaskSequence,
                  options: VerificationOptions = VerificationOptions(), *,
                  held: dict[str, np.ndarray] | None = None, stature: float = 1.75,
                  blend_frames: int = 0, raise_on_failure: bool = True) -> dict:
    """Run every check on ``synth``; return the report, raising on failure if asked.

    Parameters
    ----------
    synth : SynthesizedMotion
    cell : Cell
    spec : Specification
        With the always-on conjuncts (``spec.formula``).
    sequence : TaskSequence
        The executed task steps (``sequence.tasks``, in order) and the lasso structure
        (prefix, cycle, repetitions).
    options : VerificationOptions
    held : dict of str to ndarray of bool, shape (T,), optional
        Frames at which each object is carried (its occupancy then counts for collision).
    stature : float
    blend_frames : int
        Frames a goal primitive blends in over; ``wait`` is measured from their end.
    raise_on_failure : bool

    Returns
    -------
    report : dict
        ``{check: {"passed": bool, "detail": str, ...}}`` plus ``"passed"``.

    Raises
    ------
    VerificationError
        Naming the first failed check, when ``raise_on_failure``.
    """
    from ltl_human_motion.scene.predicates import enter

    pos = synth.motion.positions
    fps = synth.motion.fps
    steps = sequence.tasks
    report: dict = {}

    start_ok = bool(enter(pos[0], cell.start_region, stature=stature))
    report["start"] = _check(start_ok, f"frame 0 {'enters' if start_ok else 'is outside'} "
                             f"the start region {cell.start_region.name}")
    report["collision"] = _collision_check(synth, cell, held, stature)
    report["termination"], term_ok = _termination_check(synth, cell, steps, options,
                                                        stature, blend_frames)
    report["ltl"] = _ltl_check(synth, cell, spec, sequence, term_ok, stature)
    report["smoothness"] = _smoothness_check(synth, options)
    report["feet"] = _feet_check(pos, fps, cell.floor_z, options)

    if options.biomechanics:
        report.update(check_biomechanics(
            pos, fps, stature=stature, labels=frame_labels(len(pos), synth.timeline),
            floor_z=cell.floor_z, seated=seated_frames(len(pos), synth.timeline),
            limits=options.limits))

    report["passed"] = all(c["passed"] for c in report.values() if isinstance(c, dict))
    if raise_on_failure and not report["passed"]:
        raise failure_error(report)
    return report


def colliding_frames(synth, cell, held: dict[str, np.ndarray] | None,
                     stature: float) -> np.ndarray:
    """Whether each frame of ``synth`` collides (body capsules, and the objects carried
    at the frames ``held`` gives), exact on every frame, shape (T,) of bool."""
    from ltl_human_motion.scene.predicates import collision

    pos = synth.motion.positions
    if not cell.obstacles:
        return np.zeros(len(pos), dtype=bool)
    carried = {name: np.where(np.asarray(mask)[:, None], synth.objects[name], np.nan)
               for name, mask in (held or {}).items() if np.any(mask)}
    # The capsule test itself skips (frame, part) pairs whose bounding boxes are apart.
    return collision(pos, cell, stature=stature, carried=carried)


def _collision_check(synth, cell, held: dict[str, np.ndarray] | None,
                     stature: float) -> dict:
    """The ``collision`` entry of :func:`verify_motion`: exact on every frame."""
    from ltl_human_motion.scene.contacts import deepest_contact

    pos = synth.motion.positions
    hits = colliding_frames(synth, cell, held, stature)
    n_hit = int(np.sum(hits))
    if n_hit == 0:
        return _check(True, "no frame collides", frames=0)
    fps = synth.motion.fps
    contact = deepest_contact(pos, cell, stature=stature)
    deepest = f"; deepest: {contact.describe(fps)}" if contact is not None \
        else "; a carried part meets an obstacle"
    return _check(False, f"{n_hit} frames collide, first at t = "
                  f"{int(np.argmax(hits)) / fps:.2f} s{deepest}", frames=n_hit)


def _termination_check(synth, cell, steps: Sequence[Atom],
                       options: VerificationOptions, stature: float,
                       blend_frames: int) -> tuple[dict, list[bool]]:
    """The ``termination`` entry of :func:`verify_motion` and, per step, whether it held."""
    from ltl_human_motion.scene.termination import termination_series

    pos = synth.motion.positions
    windows = step_windows(synth, len(steps))
    term_ok: list[bool] = []
    failed_tasks = []
    for task, (a, b), seg in zip(steps, windows, synth.timeline):
        if task.name == "wait":
            a = seg.start_frame + blend_frames      # t*: the wait starts once blended in
        objects_state = {k: v[a:b] for k, v in synth.objects.items()}
        holds = termination_series(task.name, task.args, pos[a:b], cell, objects_state,
                                   eps=options.eps, stature=stature, fps=synth.motion.fps)
        ok = bool(np.any(holds))
        term_ok.append(ok)
        if not ok:
            failed_tasks.append(f"{seg.task} (frames {a}-{b})")
    return _check(not failed_tasks, "every task's termination condition holds"
                  if not failed_tasks else
                  "termination condition not met: " + ", ".join(failed_tasks)), term_ok


def _ltl_check(synth, cell, spec: Specification, sequence: TaskSequence,
               term_ok: list[bool], stature: float) -> dict:
    """The ``ltl`` entry of :func:`verify_motion`: the observed lasso against the formula."""
    from ltl_human_motion.ltl.evaluator import evaluate_lasso

    letters = observed_letters(synth, cell, spec, sequence.tasks, term_ok, stature)
    n_pre = len(sequence.prefix) + (sequence.repetitions - 1) * len(sequence.cycle)
    u, v = letters[:n_pre], letters[n_pre:]
    ltl_ok = bool(v) and evaluate_lasso(spec.formula, u, v)
    return _check(ltl_ok, "the observed trace satisfies the specification" if ltl_ok
                  else "the observed trace violates the specification",
                  trace=[sorted(x) for x in letters])


def _smoothness_check(synth, options: VerificationOptions) -> dict:
    """The ``smoothness`` entry of :func:`verify_motion`: the fastest joint between frames."""
    pos = synth.motion.positions
    step = np.diff(pos, axis=0)                                         # (T-1, J, 3)
    speed = np.sqrt(step[..., 0] * step[..., 0] + step[..., 1] * step[..., 1]
                    + step[..., 2] * step[..., 2]) * synth.motion.fps     # (T-1, J)
    vmax = float(speed.max()) if speed.size else 0.0
    worst = synth.motion.skeleton.names[int(np.argmax(speed.max(axis=0)))] if speed.size else ""
    return _check(vmax <= options.max_joint_speed,
                  f"fastest joint {worst} at {vmax:.2f} m/s (limit "
                  f"{options.max_joint_speed} m/s)", max_speed=vmax)


def _feet_check(pos: np.ndarray, fps: float, floor_z: float,
                options: VerificationOptions) -> dict:
    """The ``feet`` entry of :func:`verify_motion`: no foot below the floor, no long flight.

    ``pos`` is (T, J, 3).
    """
    feet = pos[:, [JOINT_INDEX[j] for j in FOOT_JOINTS], 2] - floor_z
    lowest = float(feet.min())
    flying = feet.min(axis=1) > options.flight_height
    # Longest run of flying frames: the gaps between the edges of the runs.
    edges = np.flatnonzero(np.diff(np.concatenate([[0], flying.astype(np.int8), [0]])))
    longest = int(np.max(edges[1::2] - edges[::2])) if edges.size else 0
    feet_ok = lowest >= -options.floor_tolerance and longest / fps <= options.max_flight
    return _check(feet_ok, f"lowest foot joint {lowest:+.3f} m, longest flight "
                  f"{longest / fps:.2f} s", lowest=lowest, flight=longest / fps)


def failure_error(report: dict) -> VerificationError:
    """The error of a failed report of :func:`verify_motion`, naming every failed check."""
    failed = [k for k, c in report.items() if isinstance(c, dict) and not c["passed"]]
    details = "; ".join(f"{k}: {report[k]['detail']}" for k in failed)
    return VerificationError(f"verification failed ({', '.join(failed)}): {details}",
                             failed[0])
