"""Captions and per-frame labels of a dataset item, from its task sequence and the cell.

A caption is one English sentence per item made from templates, no network model: the
tasks in order (with the walks between them), the objects, regions and obstacles by name
(or by the phrase the specs file's ``descriptions`` gives them), the acting hand, and
sitting or kneeling, e.g. "The worker walks to the left table, picks up P1 with the right
hand, carries it to the kit tray and puts it in." Caption 0 is the canonical wording; the
others are paraphrases drawn with ``numpy.random.default_rng([seed, k])``, so the same
item always gets the same sentences.

Per-frame labels (T = frames of the motion):

* ``task_label`` (T,) int16: the step of the task sequence the frame works towards
  (the walk to a task belongs to that task; -1 after the last task);
* ``phase`` (T,) int8: :data:`PHASES` index, ``0`` walk (gait primitives: walking,
  carrying, turning), ``1`` reach (a hand task's goal primitive before the task's
  condition holds), ``2`` manipulate (from then until the acting hand (a posture
  task: the pelvis) moves faster than :data:`HOLD_SPEED` again; a grasp's lift is
  part of it), ``3`` transition (everything else: standing, raising or lowering the
  arms, going down into a posture, withdrawing the hand).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ltl_human_motion.vocabulary import HAND_TASKS

__all__ = ["HOLD_SPEED", "PHASES", "CellNames", "FrameLabels", "GoalStep", "captions",
           "frame_labels"]

#: Phase names, in the order of their codes in the ``phase`` array.
PHASES = ("walk", "reach", "manipulate", "transition")
WALK, REACH, MANIPULATE, TRANSITION = range(4)
#: Speed (m/s) of the acting joint above which a manipulation is over.
HOLD_SPEED = 0.25
#: Shortest walk (s) before a task that a caption mentions.
MIN_WALK = 0.5
#: Segment names that are neither walking nor a task: standing, arm transitions.
_STILL = re.compile(r"^(stand|arms_to_)")
_TASK = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\((.*)\))?\s*$")
_CODE = re.compile(r"^[A-Z]+[0-9]*$")
_SIDES = ("left", "right", "front", "back", "near", "far", "upper", "lower", "top", "bottom")
_HAND_TASKS = (*HAND_TASKS, "carry")


@dataclass(frozen=True)
class GoalStep:
    """One goal primitive of a motion (a task of the sequence or a grasp the planner
    added before it), as the pipeline reports it in ``stats.steps``.

    Attributes
    ----------
    step : int
        Index into the task sequence.
    task : str
        The task as written, e.g. ``"grasp(P1)"``.
    kind : str
        Task name (``"grasp"``, ``"insert"``, ...).
    hand : str or None
        ``"l_hand"``, ``"r_hand"``, ``"both"``, ``"none"`` or None.
    goal : tuple of int
        Frames ``[start, end)`` of the goal primitive in the motion.
    contact, lift : int or None
        Frame where the task's condition first holds; for a grasp, where the part leaves
        its support.
    """

    step: int
    task: str
    kind: str
    hand: str | None
    goal: tuple[int, int]
    contact: int | None = None
    lift: int | None = None

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> GoalStep:
        return cls(int(data["step"]), str(data["task"]), str(data["kind"]), data.get("hand"),
                   (int(data["goal"][0]), int(data["goal"][1])),
                   None if data.get("contact") is None else int(data["contact"]),
                   None if data.get("lift") is None else int(data["lift"]))

    def to_dict(self) -> dict[str, Any]:
        return {"step": self.step, "task": self.task, "kind": self.kind, "hand": self.hand,
                "goal": list(self.goal), "contact": self.contact, "lift": self.lift}

    @property
    def args(self) -> tuple[str, ...]:
        return _parse_task(self.task)[1]


def _parse_task(text: str) -> tuple[str, tuple[str, ...]]:
    m = _TASK.match(text)
    if not m:
        return text, ()
    args = tuple(a.strip() for a in (m.group(2) or "").split(",") if a.strip())
    return m.group(1), args


# --------------------------------------------------------------------------- frame labels

@dataclass(frozen=True)
class FrameLabels:
    """Per-frame labels of one motion.

    Attributes
    ----------
    task : ndarray of int16, shape (T,)
        Step of the task sequence each frame works towards; -1 after the last.
    phase : ndarray of int8, shape (T,)
        Index into :data:`PHASES`.
    """

    task: np.ndarray
    phase: np.ndarray


def _acting_joints(hand: str | None, kind: str) -> list[int]:
    from ltl_human_motion.motion.skeleton import JOINT_INDEX
    if hand in ("l_hand", "r_hand"):
        return [JOINT_INDEX[hand]]
    if hand == "both" or kind in _HAND_TASKS:
        return [JOINT_INDEX["l_hand"], JOINT_INDEX["r_hand"]]
    return [JOINT_INDEX["pelvis"]]


def frame_labels(n_frames: int, step_ends: Sequence[int], steps: Sequence[GoalStep],
                 segments: Sequence[Sequence[Any]], positions: np.ndarray, fps: float
                 ) -> FrameLabels:
    """Task and phase of every frame (see the module docstring).

    Parameters
    ----------
    n_frames : int
        T.
    step_ends : sequence of int
        End frame (exclusive) of each step of the task sequence (its timeline).
    steps : sequence of GoalStep
    segments : sequence of (name, start, end)
        The placed primitives (``stats.segments``); overlaps go to the later one.
    positions : ndarray, shape (T, J, 3)
        Joint positions, metres.
    fps : float
    """
    T = int(n_frames)
    task = np.full(T, -1, dtype=np.int16)
    start = 0
    for i, end in enumerate(step_ends):
        end = min(max(int(end), start), T)
        task[start:end] = i
        start = end
    phase = np.full(T, TRANSITION, dtype=np.int8)
    goal_spans = {(s.goal[0], s.goal[1]) for s in steps}
    for name, a, b in segments:
        a, b = max(int(a), 0), min(int(b), T)
        if (a, b) in goal_spans:
            continue
        phase[a:b] = TRANSITION if _STILL.match(str(name)) else WALK
    pos = np.asarray(positions, dtype=np.float64)
    for s in steps:
        a, b = max(s.goal[0], 0), min(s.goal[1], T)
        if b <= a:
            continue
        contact = a if s.contact is None else min(max(s.contact, a), b)
        kind = _kind(s.kind)
        hands = s.hand not in (None, "none") or kind in _HAND_TASKS
        phase[a:b] = TRANSITION
        phase[a:contact] = REACH if hands else TRANSITION
        held = max(contact, s.lift if s.lift is not None else contact)
        joints = _acting_joints(s.hand, kind)
        if held + 1 < b:
            v = np.linalg.norm(np.diff(pos[held:b, joints], axis=0), axis=-1).max(axis=1)
            moving = np.flatnonzero(v * fps > HOLD_SPEED)
            end = held + int(moving[0]) + 1 if moving.size else b
            if s.lift is not None:
                end = max(end, s.lift)
        else:
            end = b
        phase[contact:min(end, b)] = MANIPULATE
    return FrameLabels(task, phase)


# --------------------------------------------------------------------------- names

def _humanize(name: str) -> str:
    """``table_left`` -> ``the left table``; ``P1`` stays ``P1``."""
    if _CODE.match(name):
        return name
    words = [w for w in re.split(r"[_\s]+|(?<=[a-z])(?=[A-Z])", name) if w]
    words = [w.lower() if not _CODE.match(w) else w for w in words]
    sides = [w for w in words if w in _SIDES]
    rest = [w for w in words if w not in _SIDES]
    return "the " + " ".join(sides + rest)


def _the(text: str) -> str:
    """A description as a noun phrase: 'kit tray' -> 'the kit tray'."""
    first = text.split(" ", 1)[0].lower()
    if first in ("the", "a", "an", "this", "that") or _CODE.match(text):
        return text
    return "the " + text[0].lower() + text[1:] if text[:1].isupper() and not \
        text[1:2].isupper() else "the " + text


@dataclass(frozen=True)
class CellNames:
    """How captions name the things of one cell.

    Attributes
    ----------
    phrases : dict of str to str
        Object, region and obstacle name -> noun phrase (its description, else the name:
        ``P1``, ``the left table``).
    support : dict of str to str
        Object name -> phrase of the obstacle it rests on (``the left table``).
    cell : str
        The cell as a phrase (``the kitting cell``).
    """

    phrases: dict[str, str] = field(default_factory=dict)
    support: dict[str, str] = field(default_factory=dict)
    cell: str = "the cell"

    @classmethod
    def from_cell(cls, cell: Any, descriptions: Mapping[str, str] | None = None) -> CellNames:
        """Names of ``cell`` (a :class:`~ltl_human_motion.scene.cell.Cell`); a name in
        ``descriptions`` is called by its description."""
        descriptions = dict(descriptions or {})

        def phrase(name: str) -> str:
            return _the(descriptions[name]) if name in descriptions else _humanize(name)

        phrases = {n: phrase(n) for n in (*cell.objects, *cell.regions,
                                          *(o.name for o in cell.obstacles))}
        for name, region in cell.regions.items():
            if name in descriptions or not _CODE.match(name):
                continue
            inside = [o for o in sorted(cell.objects) if not cell.objects[o].movable
                      and bool(np.all(region.lo <= cell.objects[o].position))
                      and bool(np.all(cell.objects[o].position <= region.hi))]
            if inside:
                phrases[name] = phrases[inside[0]]
        support = {}
        for name, obj in cell.objects.items():
            lo, _ = obj.shape.aabb()
            best = None
            for obstacle in cell.obstacles:
                for part in obstacle.parts:
                    plo, phi = part.aabb()
                    gap = float(lo[2] - phi[2])
                    if -0.02 <= gap <= 0.15 and np.all(plo[:2] <= obj.position[:2]) \
                            and np.all(obj.position[:2] <= phi[:2]) \
                            and (best is None or gap < best[0]):
                        best = (gap, obstacle.name)
            if best is not None:
                support[name] = phrases[best[1]]
        words = " ".join(w for w in re.split(r"[_\s]+", cell.name) if w)
        cell_phrase = "the " + words.lower() + ("" if words.lower().endswith("cell")
                                                  else " cell")
        return cls(phrases, support, cell_phrase)

    def of(self, name: str) -> str:
        return self.phrases.get(name, name)


# --------------------------------------------------------------------------- captions

_SUBJECTS = ("The worker", "A worker", "The person", "The operator", "Someone")
#: Hand phrases: with one hand, with both; the third style only after a grasp's verb.
_HANDS = ((" with the {side} hand", " with both hands"),
          (" using the {side} hand", " using both hands"),
          (" in the {side} hand", " with both hands"))
_TEMPLATES: dict[str, tuple[str, ...]] = {
    "walk_to": ("walks to {dest}", "goes over to {dest}", "heads to {dest}",
                "steps over to {dest}"),
    "walk_along": ("moves along {dest}", "steps along {dest}", "shifts along {dest}"),
    "grasp": ("picks up {obj}{hand}", "takes {obj}{hand}", "grabs {obj}{hand}",
              "lifts {obj}{hand}"),
    "fetch": ("walks to {obj} and picks it up{hand}", "goes over to {obj} and takes it{hand}",
              "heads to {obj} and grabs it{hand}", "steps over to {obj} and lifts it{hand}"),
    "insert": ("puts {obj} into {dest}{hand}", "inserts {obj} into {dest}{hand}",
               "places {obj} in {dest}{hand}"),
    "carry_insert": ("carries {obj} to {dest} and puts it in", "brings {obj} over to "
                     "{dest} and inserts it", "takes {obj} to {dest} and places it inside"),
    "move": ("puts {obj} in {dest}{hand}", "places {obj} in {dest}{hand}",
             "sets {obj} down in {dest}{hand}"),
    "carry_move": ("carries {obj} to {dest} and puts it down", "brings {obj} to {dest} and "
                   "sets it down", "takes {obj} over to {dest} and places it there"),
    "release": ("lets go of {obj}", "releases {obj}", "puts {obj} down"),
    "extract": ("pulls {obj} out of {dest}{hand}", "takes {obj} out of {dest}{hand}",
                "removes {obj} from {dest}{hand}"),
    "assemble": ("assembles the parts at {dest} with both hands", "puts the parts together "
                 "at {dest} with both hands", "works at {dest} with both hands"),
    "leftHand": ("reaches into {dest} with the left hand", "puts the left hand into {dest}",
                 "moves the left hand into {dest}"),
    "rightHand": ("reaches into {dest} with the right hand", "puts the right hand into "
                  "{dest}", "moves the right hand into {dest}"),
    "sit": ("sits down on {obj}", "takes a seat on {obj}", "sits on {obj}"),
    "standUp": ("stands up", "gets up", "rises to standing"),
    "kneel": ("kneels down", "gets down on one knee", "kneels on the floor"),
    "bend": ("bends over", "bends forward", "leans down"),
    "stoop": ("stoops", "crouches down", "stoops down"),
    "wait": ("waits {obj} seconds", "pauses for {obj} seconds", "stands still for {obj} "
             "seconds"),
    "walk": ("walks to {dest}", "goes to {dest}", "heads over to {dest}"),
    "carry": ("carries {obj} to {dest}", "brings {obj} to {dest}", "takes {obj} over to "
              "{dest}"),
}
_POSTURE = {"sitting": (" while sitting", " from the seat", " seated"),
            "kneeling": (" while kneeling", " on one knee", " kneeling")}
_JOIN = ((", ", " and "), (", then ", " and finally "), (", ", " and then "))


def _hand_phrase(hand: str | None, style: int, key: str) -> str:
    style = style if key == "grasp" else style % 2
    if hand in ("l_hand", "r_hand"):
        return _HANDS[style][0].format(side="left" if hand == "l_hand" else "right")
    if hand == "both":
        return _HANDS[style][1]
    return ""


@dataclass(frozen=True)
class _Clause:
    key: str
    obj: str = ""
    dest: str = ""
    hand: str | None = None
    posture: str | None = None


def _clauses(sequence: Sequence[str], steps: Sequence[GoalStep], phase: np.ndarray | None,
             names: CellNames, fps: float) -> list[_Clause]:
    """The things the worker does, in order, with the walks to them."""
    by_step: dict[int, list[GoalStep]] = {}
    for s in steps:
        by_step.setdefault(s.step, []).append(s)
    out: list[_Clause] = []
    held: set[str] = set()
    posture: str | None = None
    last_end = 0
    for i, text in enumerate(sequence):
        goals = by_step.get(i)
        if not goals:
            name, args = _parse_task(text)
            out.append(_Clause(name, names.of(args[0]) if args else "",
                               names.of(args[-1]) if args else ""))
            continue
        for s in goals:
            kind, args = _kind(s.kind), s.args
            walked = phase is not None and int(np.count_nonzero(
                phase[last_end:s.goal[0]] == WALK)) >= MIN_WALK * fps
            last_end = s.goal[1]
            if walked and posture is not None and kind != "standUp":
                out.append(_Clause("standUp"))      # the planner stood up to walk
            if kind == "standUp" or walked:
                posture = None
            obj = names.of(args[0]) if args else ""
            dest = names.of(args[-1]) if len(args) > 1 or kind in (
                "walk", "assemble", "leftHand", "rightHand") else ""
            if kind == "wait":
                obj = args[0] if args else "a few"
            key = kind
            if kind in ("insert", "move") and args and args[0] in held and walked:
                key = f"carry_{kind}"
                if out and out[-1].key == "grasp" and out[-1].obj == obj:
                    obj = "it"
            elif walked and kind == "grasp" and args and args[0] not in names.support:
                key = "fetch"
            elif walked and kind not in ("walk", "carry"):
                place = names.support.get(args[0], obj) if kind == "grasp" and args else \
                    (dest or obj)
                if place:
                    walks = [c for c in out if c.key in ("walk_to", "walk_along")]
                    along = bool(walks) and walks[-1].dest == place \
                        and not any(c.key.startswith("carry") for c in out[out.index(
                            walks[-1]):])
                    out.append(_Clause("walk_along" if along else "walk_to", dest=place))
            hand = s.hand if kind in _HAND_TASKS else None
            out.append(_Clause(key, obj, dest, hand,
                               posture if kind in _HAND_TASKS else None))
            if kind == "grasp" and args:
                held.add(args[0])
            elif kind in ("insert", "move", "release") and args:
                held.discard(args[0])
            if kind == "sit":
                posture = "sitting"
            elif kind == "kneel":
                posture = "kneeling"
    return out


def _kind(kind: str) -> str:
    """The task name of a step's kind (``"walk (by rightHand)"`` -> ``"walk"``)."""
    m = re.match(r"[A-Za-z_][A-Za-z0-9_]*", kind)
    return m.group(0) if m else kind


def _render(clause: _Clause, style: int, rng: np.random.Generator | None) -> str:
    def pick(options: Sequence[str]) -> str:
        return options[0] if rng is None else options[int(rng.integers(len(options)))]

    templates = _TEMPLATES.get(clause.key)
    if templates is None:
        body = f"does {clause.key}" + (f" with {clause.obj}" if clause.obj else "")
    else:
        body = pick(templates).format(obj=clause.obj, dest=clause.dest,
                                      hand=_hand_phrase(clause.hand, style, clause.key))
    if clause.posture:
        body += pick(_POSTURE[clause.posture])
    return body


def _there(parts: list[str], clauses: list[_Clause]) -> list[str]:
    """'walks to R1, assembles the parts at R1' -> '..., assembles the parts there'."""
    out = list(parts)
    for i in range(1, len(clauses)):
        if clauses[i - 1].key == "walk_to" and clauses[i].dest \
                and clauses[i - 1].dest == clauses[i].dest:
            out[i] = out[i].replace(f" at {clauses[i].dest}", " there")
    return out


def _sentence(subject: str, parts: list[str], join: tuple[str, str]) -> str:
    if not parts:
        return f"{subject} stands still."
    if len(parts) == 1:
        text = parts[0]
    else:
        last = ", " if " and " in parts[-1] and join[1] == " and " else join[1]
        text = join[0].join(parts[:-1]) + last + parts[-1]
    return f"{subject} {text}."


def captions(sequence: Sequence[str], steps: Sequence[GoalStep], names: CellNames,
             seed: int, n: int = 4, phase: np.ndarray | None = None, fps: float = 120.0
             ) -> list[str]:
    """``n`` captions of one item: the canonical sentence, then seeded paraphrases.

    Parameters
    ----------
    sequence : sequence of str
        The task sequence, e.g. ``["grasp(P1)", "insert(P1, kit)"]``.
    steps : sequence of GoalStep
    names : CellNames
    seed : int
        The item's seed; paraphrase ``k`` draws from ``default_rng([seed, k])``.
    n : int
        Number of captions, >= 1.
    phase : ndarray of int8, shape (T,), optional
        The phase labels; walks of at least :data:`MIN_WALK` seconds before a task are
        mentioned (none without them).
    fps : float
    """
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    clauses = _clauses(sequence, steps, phase, names, fps)
    out = []
    for k in range(n):
        if k == 0:
            parts = _there([_render(c, 0, None) for c in clauses], clauses)
            out.append(_sentence(_SUBJECTS[0], parts, _JOIN[0]))
            continue
        rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, k])
        hand_style = int(rng.integers(len(_HANDS)))
        parts = _there([_render(c, hand_style, rng) for c in clauses], clauses)
        subject = _SUBJECTS[int(rng.integers(len(_SUBJECTS)))]
        join = _JOIN[int(rng.integers(len(_JOIN)))]
        text = _sentence(subject, parts, join)
        if rng.random() < 0.3:
            text = f"In {names.cell}, {text[0].lower()}{text[1:]}"
        out.append(text)
    return out
