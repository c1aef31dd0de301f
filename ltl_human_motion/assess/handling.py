"""What the worker holds, frame by frame: held masks, load in hand, lifts.

A synthesized motion moves a part rigidly with the hand that holds it
(:func:`ltl_human_motion.planning.pipeline._object_tracks`), so a part is held exactly when
its offset to a hand stays constant while it is near that hand.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ltl_human_motion.kernel.vectors import norm3
from ltl_human_motion.motion.skeleton import JOINT_INDEX

__all__ = ["HOLD_RADIUS", "Lift", "held_masks", "lifts", "load_in_hand"]

#: m. A part counts as held only within this distance of the hand (a hand grips a part
#: from its grasp point on the part's surface; the paper cell's parts are 10 cm cubes).
HOLD_RADIUS = 0.30
#: m. Frame-to-frame change of the part-hand offset below which the part moves with the
#: hand (the offset is constant to rounding when attached).
_RIGID = 1e-7
_HANDS = (JOINT_INDEX["l_hand"], JOINT_INDEX["r_hand"])


@dataclass(frozen=True)
class Lift:
    """One handling of a part: from the grasp (``start``) to the release (``end``,
    exclusive), with the hand that held it (0 left, 1 right)."""

    obj: str
    start: int
    end: int
    hand: int


def _hand_holds(obj: np.ndarray, hand: np.ndarray) -> np.ndarray:
    off = obj - hand
    still = np.zeros(len(obj), dtype=bool)
    if len(obj) > 1:
        step = norm3(np.diff(off, axis=0)) < _RIGID
        moved = norm3(np.diff(obj, axis=0)) > _RIGID
        rigid = step & moved
        still[1:] |= rigid
        still[:-1] |= rigid
    return still & (norm3(off) < HOLD_RADIUS)


def _fill_pauses(mask: np.ndarray, obj: np.ndarray) -> np.ndarray:
    """Close gaps in ``mask`` during which the part did not move (hand and part at rest)."""
    out = mask.copy()
    idx = np.flatnonzero(mask)
    gaps = np.flatnonzero(np.diff(idx) > 1)
    for a, b in zip(idx[gaps], idx[gaps + 1]):
        if np.allclose(obj[a:b + 1], obj[a], atol=_RIGID):
            out[a:b] = True
    return out


def held_masks(positions: np.ndarray, objects: Mapping[str, np.ndarray]
               ) -> dict[str, tuple[np.ndarray, int]]:
    """Frames at which each part is held, and by which hand.

    Parameters
    ----------
    positions : ndarray, shape (T, 23, 3)
    objects : mapping of str to ndarray, shape (T, 3)

    Returns
    -------
    dict
        name -> (mask (T,) bool, hand index 0 left / 1 right / -1 never held).
    """
    out = {}
    for name, traj in objects.items():
        best, hand = np.zeros(len(traj), dtype=bool), -1
        for h, j in enumerate(_HANDS):
            m = _hand_holds(traj, positions[:, j])
            if m.sum() > best.sum():
                best, hand = m, h
        out[name] = (_fill_pauses(best, traj) if hand >= 0 else best, hand)
    return out


def load_in_hand(positions: np.ndarray, objects: Mapping[str, np.ndarray],
                 masses: Mapping[str, float]) -> np.ndarray:
    """Mass (kg) held per frame, shape (T,): the sum over held parts (default 1 kg)."""
    load = np.zeros(positions.shape[0])
    for name, (mask, _) in held_masks(positions, objects).items():
        load += mask * float(masses.get(name, 1.0))
    return load


def lifts(positions: np.ndarray, objects: Mapping[str, np.ndarray],
          held: Mapping[str, tuple[np.ndarray, int]] | None = None) -> list[Lift]:
    """Every held interval of every part, in time order (``held``: the result of
    :func:`held_masks`, computed when not given)."""
    out = []
    held = held_masks(positions, objects) if held is None else held
    for name, (mask, hand) in held.items():
        padded = np.concatenate([[False], mask, [False]]).astype(np.int8)
        edges = np.flatnonzero(np.diff(padded))
        out += [Lift(name, int(a), int(b), hand) for a, b in zip(edges[::2], edges[1::2])
                if b - a >= 2]
    return sorted(out, key=lambda x: x.start)
