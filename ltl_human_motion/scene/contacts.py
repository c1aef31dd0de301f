"""Which body part meets which obstacle: the words of a collision.

A collision test answers yes or no per frame (:func:`~.predicates.collision`); a user
who is refused wants to know what hit what. :func:`deepest_contact` finds the frame
where the body goes deepest into an obstacle and names the body capsule and the
obstacle, so that planning errors and verification reports can say, for example,
"the head enters shelf by 3.1 cm at t = 1.25 s".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ltl_human_motion.motion.capsules import BODY_PARTS
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.scene.predicates import body_clearance

__all__ = ["Contact", "deepest_contact"]

_SIDES = {"l": "left", "r": "right"}
_PLURAL = {"buttocks"}


@dataclass(frozen=True)
class Contact:
    """The deepest meeting of a body capsule and an obstacle.

    Attributes
    ----------
    frame : int
        Frame index in the positions given.
    part : str
        Body capsule (:data:`~ltl_human_motion.motion.capsules.BODY_PARTS`), e.g. ``"head"``,
        ``"r_lower_arm"``.
    obstacle : str
        Name of the obstacle in the cell.
    depth : float
        How far the capsule enters the obstacle, metres (0 when it only touches).
    """

    frame: int
    part: str
    obstacle: str
    depth: float

    def describe(self, fps: float | None = None) -> str:
        """The contact in words; with ``fps`` the frame is given as a time."""
        side, _, rest = self.part.partition("_")
        part = f"{_SIDES[side]} {rest}" if side in _SIDES and rest else self.part
        part = part.replace("_", " ")
        verb = "enter" if part in _PLURAL else "enters"
        when = f"t = {self.frame / fps:.2f} s" if fps else f"frame {self.frame}"
        return f"the {part} {verb} {self.obstacle} by {100 * self.depth:.1f} cm at {when}"


def deepest_contact(positions: np.ndarray, cell: Cell, *,
                    stature: float = DEFAULT_STATURE) -> Contact | None:
    """The frame, body capsule and obstacle of the deepest body-obstacle contact.

    Parameters
    ----------
    positions : array-like, shape (T, J, 3) or (J, 3)
        Joint positions in the cell's frame.
    cell : Cell
    stature : float
        Sizes the body capsules.

    Returns
    -------
    contact : Contact or None
        None when no frame meets an obstacle (clearance above 0 everywhere).
    """
    pos = np.asarray(positions, dtype=np.float64)
    if pos.ndim == 2:
        pos = pos[None]
    if pos.ndim != 3 or pos.shape[-1] != 3:
        raise ValueError(f"positions must have shape (T, J, 3) or (J, 3), got {pos.shape}")
    if not cell.obstacles or not len(pos):
        return None
    clearance = body_clearance(pos, cell, stature=stature, exact_below=0.0)
    frame = int(np.argmin(clearance))
    if clearance[frame] > 0.0:
        return None
    seg, rad = capsules_from_positions(pos[frame], stature)
    pairs = cell.part_set.pair_clearance(seg, rad)            # (K, P)
    k, p = np.unravel_index(int(np.argmin(pairs)), pairs.shape)
    owner = np.repeat(np.arange(len(cell.obstacles)),
                      [len(ob.parts) for ob in cell.obstacles])
    return Contact(frame=frame, part=BODY_PARTS[k], obstacle=cell.obstacles[owner[p]].name,
                   depth=float(max(0.0, -pairs[k, p])))
