"""Seeded random work cells and specifications, labelled feasible or infeasible.

A generated cell is furnished like a real one: furniture stands against the walls
facing the middle (tables and benches with an assembly region just above the top,
shelves with boards from knee to overhead height, low boards with parts under them,
desks with a chair, tall cabinets), loose obstacles (crates, pillars, carts) stand in
the middle, parts rest on tops, boards or the floor, bins sit on tables, stools and
floor stations take free floor. Every part is supported by what it lies on.

Labels come from the construction, checked with a deliberately comfortable worker (a
0.5 m wide walking body, a standing reach of 0.55 m beyond the edge of a part, grasp
points at most 1.7 m up): a target counts as feasible only if such a worker can get
to it from the start; loose obstacles that would cut it off are drawn again. Some
cells stand on a floor at another height than 0 or are written in the paper's y-up
frame (the same layout, so the same labels). Some
cells also hold what no worker can do, by construction: a part on top of a 2.6 m
cabinet (``reach``), a part in a closed 1.6 m pen wider than any reach
(``enclosed``), a tray smaller than a part (``size``).

Use :func:`generate_scenarios` (deterministic in its seed); each
:class:`Scenario` carries the cell as YAML text (for ``synthesize(spec, yaml)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.scenarios.corpus import DWYER_PATTERNS
from ltl_human_motion.scene.termination import parse_task

__all__ = ["GeneratedPair", "Scenario", "generate_scenario", "generate_scenarios"]

#: Half-width of the comfortable walking body used to label targets feasible, metres.
COMFORT_RADIUS = 0.25
#: Cell size of the floor grid of that check, metres (coarse: the radius is generous).
COMFORT_RESOLUTION = 0.1
#: A comfortable standing reach beyond the near edge of a target, metres.
COMFORT_REACH = 0.55
#: Highest grasp point of a part labelled feasible (the 1.55 m worker's overhead reach
#: is about 1.9 m; 1.7 m is the corpus's "overhead" shelf).
MAX_FEASIBLE_HEIGHT = 1.70
#: Statures the generated cells are drawn for.
STATURES = (1.55, 1.75, 1.95)
#: How often a generated cell stands on a floor at a height other than 0 (a platform
#: or a pit), and how often it is written in the paper's y-up frame.
FLOOR_SHIFT_PROBABILITY = 0.15
PAPER_FRAME_PROBABILITY = 0.15
#: Single-task pairs drawn per cell (of all the cell's feasible tasks).
MAX_SINGLES = 8
#: Tasks without a target, done where the worker stands.
IN_PLACE = ("wait(2.0)", "standUp", "bend", "stoop", "kneel")


@dataclass(frozen=True)
class GeneratedPair:
    """A specification for a generated cell with its label (see :class:`~ltl_human_motion.
    scenarios.corpus.Pair`)."""

    spec: str
    expect: str
    family: str
    reason: str | None = None


@dataclass
class Scenario:
    """One generated cell and its labelled specifications.

    Attributes
    ----------
    name : str
    yaml : str
        The cell description (z up).
    stature : float
        The worker the labels are for.
    pairs : list of GeneratedPair
    seed : int
    """

    name: str
    yaml: str
    stature: float
    pairs: list[GeneratedPair] = field(default_factory=list)
    seed: int = 0


def _r(x: float) -> float:
    return round(float(x), 3)


def _box(pos, size, yaw: float = 0.0) -> dict:
    d = {"shape": "box", "position": [_r(v) for v in pos], "size": [_r(v) for v in size]}
    if yaw:
        d["yaw"] = _r(yaw)
    return d


class _Builder:
    """Lays out one cell; rejects placements that overlap what is already there."""

    def __init__(self, rng: np.random.Generator, name: str) -> None:
        self.rng = rng
        self.name = name
        self.half = np.array([rng.uniform(2.6, 3.6), rng.uniform(2.6, 3.4)])
        self.obstacles: dict[str, dict] = {}
        self.objects: dict[str, dict] = {}
        self.regions: dict[str, dict] = {
            "R0": {"lo": [-0.3, -0.3, 0.0], "hi": [0.3, 0.3, 0.1]}}
        self.taken: list[tuple[np.ndarray, np.ndarray]] = [   # floor rectangles in use
            (np.array([-0.8, -0.8]), np.array([0.8, 0.8]))]
        self.targets: list[tuple[str, np.ndarray, np.ndarray]] = []  # feasible boxes
        self.parts: list[str] = []          # parts labelled feasible
        self.bad_parts: list[tuple[str, str]] = []     # (part, reason)
        self.asm_regions: list[str] = []
        self.floor_regions: list[str] = []
        self.bins: list[tuple[str, float]] = []        # (bin, smallest inner width)
        self.small: list[tuple[str, float]] = []       # too-small containers
        self.seats: list[str] = []
        self.counter = 0

    def new(self, prefix: str) -> str:
        self.counter += 1
        return f"{prefix}{self.counter}"

    def free(self, lo: np.ndarray, hi: np.ndarray, gap: float = 0.1) -> bool:
        if np.any(lo < -self.half) or np.any(hi > self.half):
            return False
        return all(np.any(lo - gap >= thi) or np.any(hi + gap <= tlo)
                   for tlo, thi in self.taken)

    def wall_slot(self, width: float, depth: float) -> tuple[np.ndarray, np.ndarray,
                                                               np.ndarray] | None:
        """A floor rectangle against a random wall: (lo (2,), hi (2,), inward normal)."""
        for _ in range(30):
            side = int(self.rng.integers(4))
            axis, sign = side % 2, (1 if side < 2 else -1)
            normal = np.zeros(2)
            normal[axis] = -sign                              # pointing into the cell
            along = self.rng.uniform(-self.half[1 - axis] + width / 2 + 0.1,
                                     self.half[1 - axis] - width / 2 - 0.1)
            centre = np.zeros(2)
            centre[axis] = sign * (self.half[axis] - depth / 2 - 0.02)
            centre[1 - axis] = along
            ext = np.zeros(2)
            ext[axis], ext[1 - axis] = depth / 2, width / 2
            lo, hi = centre - ext, centre + ext
            if self.free(lo, hi, gap=0.9):                    # room to stand between pieces
                self.taken.append((lo, hi))
                return lo, hi, normal
        return None

    # ------------------------------------------------------------------ parts
    def part_on(self, lo: np.ndarray, hi: np.ndarray, z: float, normal: np.ndarray,
                feasible: bool = True, reason: str = "", inset: float | None = None) -> str:
        """A part resting at height ``z`` on the surface [lo, hi] (2,), near its front."""
        rng = self.rng
        name = self.new("P")
        s = float(rng.uniform(0.05, 0.12))
        inset = float(rng.uniform(0.06, 0.15)) if inset is None else inset
        centre = (lo + hi) / 2
        front = centre.copy()
        axis = int(np.argmax(np.abs(normal)))
        half_depth = (hi[axis] - lo[axis]) / 2
        front[axis] = centre[axis] + normal[axis] * (half_depth - inset - s / 2)
        span = (hi[1 - axis] - lo[1 - axis]) / 2 - s
        front[1 - axis] += rng.uniform(-span, span) * 0.8
        if rng.random() < 0.7:
            shape = {"shape": "box", "size": [_r(s), _r(s), _r(s)]}
            height = s
        else:
            shape = {"shape": "cylinder", "size": [_r(s / 2), _r(s)]}
            height = s
        pos = np.array([front[0], front[1], z + height / 2 + 0.003])
        self.objects[name] = {"position": [_r(v) for v in pos], **shape,
                              "grasp_points": [[0.0, 0.0, _r(height / 2)]]}
        if feasible:
            self.parts.append(name)
            self.targets.append((name, pos - s / 2, pos + s / 2))
        else:
            self.bad_parts.append((name, reason))
        return name

    # ------------------------------------------------------------------ furniture
    def table(self) -> None:
        rng = self.rng
        slot = self.wall_slot(rng.uniform(0.8, 1.6), rng.uniform(0.5, 0.8))
        if slot is None:
            return
        lo, hi, n = slot
        top = float(rng.uniform(0.7, 0.95))
        name = self.new("table")
        c = (lo + hi) / 2
        self.obstacles[name] = {"color": "peru", **_box([c[0], c[1], top / 2],
                                                         [*(hi - lo), top])}
        for _ in range(int(rng.integers(0, 3))):
            self.part_on(lo, hi, top, n)
        if rng.random() < 0.8:                                # assembly region above it
            reg = self.new("R")
            axis = int(np.argmax(np.abs(n)))
            rc = c.copy()
            rc[axis] = c[axis] + n[axis] * ((hi[axis] - lo[axis]) / 2 - 0.15)
            z0 = top + float(rng.uniform(0.02, 0.12))
            self.regions[reg] = {"lo": [_r(rc[0] - 0.1), _r(rc[1] - 0.1), _r(z0)],
                                 "hi": [_r(rc[0] + 0.1), _r(rc[1] + 0.1), _r(z0 + 0.2)]}
            self.asm_regions.append(reg)
            self.targets.append((reg, np.array([rc[0] - 0.1, rc[1] - 0.1, z0]),
                                 np.array([rc[0] + 0.1, rc[1] + 0.1, z0 + 0.2])))
        if rng.random() < 0.5:                                # a bin on the table
            b = self.new("bin")
            w = np.array([rng.uniform(0.18, 0.35), rng.uniform(0.15, 0.25),
                          rng.uniform(0.12, 0.18)])
            axis = int(np.argmax(np.abs(n)))
            bc = c.copy()
            bc[axis] = c[axis] + n[axis] * ((hi[axis] - lo[axis]) / 2 - 0.1 - w[axis] / 2)
            bc[1 - axis] += float(rng.uniform(-0.2, 0.2))
            pos = [bc[0], bc[1], top + w[2] / 2 + 0.003]
            self.objects[b] = {"position": [_r(v) for v in pos], "shape": "box",
                               "size": [_r(v) for v in w], "movable": False}
            self.bins.append((b, float(w.min())))
            self.targets.append((b, np.array(pos) - w / 2, np.array(pos) + w / 2))
        if rng.random() < 0.25:                               # a tray too small for parts
            t = self.new("tray")
            w = 0.04
            axis = int(np.argmax(np.abs(n)))
            tc = c.copy()
            tc[axis] = c[axis] + n[axis] * ((hi[axis] - lo[axis]) / 2 - 0.08)
            tc[1 - axis] += float(rng.uniform(-0.3, 0.3))
            self.objects[t] = {"position": [_r(tc[0]), _r(tc[1]), _r(top + w / 2 + 0.003)],
                               "shape": "box", "size": [w, w, w], "movable": False}
            self.small.append((t, w))

    def shelf(self) -> None:
        rng = self.rng
        width, depth = float(rng.uniform(0.8, 1.6)), float(rng.uniform(0.35, 0.5))
        slot = self.wall_slot(width, depth)
        if slot is None:
            return
        lo, hi, n = slot
        c = (lo + hi) / 2
        axis = int(np.argmax(np.abs(n)))
        boards = sorted(rng.choice([0.4, 0.6, 0.9, 1.1, 1.35, 1.6],
                                   size=int(rng.integers(2, 4)), replace=False))
        parts = []
        for z in boards:
            parts.append(_box([c[0], c[1], z - 0.01], [*(hi - lo), 0.02]))
        height = float(max(boards) + rng.uniform(0.3, 0.5))
        for k in (-1, 1):                                     # side panels
            pc = c.copy()
            pc[1 - axis] = c[1 - axis] + k * ((hi[1 - axis] - lo[1 - axis]) / 2 - 0.02)
            size = np.array(hi - lo)
            size[1 - axis] = 0.04
            parts.append(_box([pc[0], pc[1], height / 2], [*size, height]))
        back = c.copy()
        back[axis] = c[axis] - n[axis] * ((hi[axis] - lo[axis]) / 2 - 0.02)
        bsize = np.array(hi - lo)
        bsize[axis] = 0.04
        parts.append(_box([back[0], back[1], height / 2], [*bsize, height]))
        self.obstacles[self.new("shelf")] = {"color": "slategray", "parts": parts}
        shrink = np.zeros(2)
        shrink[1 - axis] = 0.05                               # keep off the side panels
        for z in boards:
            gap_above = min([b for b in boards if b > z], default=height) - z
            if z + 0.12 <= MAX_FEASIBLE_HEIGHT and gap_above > 0.3 and rng.random() < 0.8:
                self.part_on(lo + shrink, hi - shrink, float(z), n)

    def low_board(self) -> None:
        """A board 0.35-0.45 m up on legs with a part on the floor under its front."""
        rng = self.rng
        slot = self.wall_slot(rng.uniform(0.8, 1.2), rng.uniform(0.45, 0.6))
        if slot is None:
            return
        lo, hi, n = slot
        c = (lo + hi) / 2
        z = float(rng.uniform(0.35, 0.45))
        parts = [_box([c[0], c[1], z + 0.01], [*(hi - lo), 0.02])]
        for sx in (lo[0] + 0.02, hi[0] - 0.02):
            for sy in (lo[1] + 0.02, hi[1] - 0.02):
                parts.append(_box([sx, sy, z / 2], [0.04, 0.04, z]))
        self.obstacles[self.new("lowboard")] = {"color": "gray", "parts": parts}
        axis = int(np.argmax(np.abs(n)))
        shrink = np.zeros(2)
        shrink[1 - axis] = 0.1
        self.part_on(lo + shrink, hi - shrink, 0.0, n, inset=float(rng.uniform(0.08, 0.15)))

    def cabinet(self) -> None:
        """A tall cabinet with a part on top, out of everyone's reach."""
        rng = self.rng
        slot = self.wall_slot(rng.uniform(0.6, 1.0), rng.uniform(0.4, 0.6))
        if slot is None:
            return
        lo, hi, n = slot
        c = (lo + hi) / 2
        top = float(rng.uniform(2.6, 2.8))
        self.obstacles[self.new("cabinet")] = {"color": "dimgray",
                                               **_box([c[0], c[1], top / 2], [*(hi - lo), top])}
        self.part_on(lo, hi, top, n, feasible=False, reason="reach",
                     inset=float(rng.uniform(0.15, 0.25)))

    def pen(self) -> None:
        """A closed 1.6 m fence, 2.8 m square, in a corner, with a part in the middle."""
        sx, sy = (1 if self.rng.random() < 0.5 else -1), (1 if self.rng.random() < 0.5 else -1)
        size = 2.8
        self.half[0] = max(self.half[0], size + 1.8)          # room beside the start
        corner = np.array([sx * self.half[0], sy * self.half[1]])
        lo = np.minimum(corner, corner - np.array([sx, sy]) * size)
        hi = np.maximum(corner, corner - np.array([sx, sy]) * size)
        if not self.free(lo, hi, gap=0.9):
            return
        self.taken.append((lo, hi))
        c = (lo + hi) / 2
        t, h = 0.05, 1.6
        parts = [_box([c[0], lo[1] + t / 2, h / 2], [size, t, h]),
                 _box([c[0], hi[1] - t / 2, h / 2], [size, t, h]),
                 _box([lo[0] + t / 2, c[1], h / 2], [t, size, h]),
                 _box([hi[0] - t / 2, c[1], h / 2], [t, size, h])]
        self.obstacles[self.new("pen")] = {"color": "gold", "parts": parts}
        name = self.new("P")
        self.objects[name] = {"position": [_r(c[0]), _r(c[1]), 0.05], "shape": "box",
                              "size": [0.1, 0.1, 0.1], "grasp_points": [[0.0, 0.0, 0.05]]}
        self.bad_parts.append((name, "enclosed"))

    def loose(self) -> dict[str, dict]:
        """Crates, pillars and carts in the middle (candidates; checked by the caller)."""
        rng = self.rng
        out = {}
        taken = list(self.taken)
        for _ in range(int(rng.integers(0, 4))):
            kind = rng.choice(["crate", "pillar", "cart"])
            xy = rng.uniform(-self.half + 0.6, self.half - 0.6)
            if kind == "pillar":
                r = float(rng.uniform(0.1, 0.25))
                spec = {"shape": "cylinder", "position": [_r(xy[0]), _r(xy[1]), 1.25],
                        "size": [_r(r), 2.5], "color": "gray"}
                ext = np.array([r, r])
            else:
                size = np.array([rng.uniform(0.4, 0.9), rng.uniform(0.4, 0.7),
                                 rng.uniform(0.4, 1.0)])
                yaw = float(rng.uniform(-math.pi / 4, math.pi / 4))
                spec = {**_box([xy[0], xy[1], size[2] / 2], size, yaw), "color": "burlywood"}
                ext = np.full(2, float(np.hypot(size[0], size[1]) / 2))
            if self.free(xy - ext, xy + ext, gap=0.2):
                out[self.new(str(kind))] = (spec, (xy - ext, xy + ext))
                self.taken.append((xy - ext, xy + ext))
        self.taken = taken
        return out

    def floor_region(self, small: bool = False) -> str | None:
        rng = self.rng
        side = 0.25 if small else float(rng.uniform(0.6, 0.9))
        for _ in range(30):
            xy = rng.uniform(-self.half + side / 2 + 0.3, self.half - side / 2 - 0.3)
            lo, hi = xy - side / 2, xy + side / 2
            if self.free(lo, hi, gap=0.4):
                self.taken.append((lo, hi))
                name = self.new("Rsmall" if small else "Zone")
                top = 0.25 if small else 2.0
                self.regions[name] = {"lo": [_r(lo[0]), _r(lo[1]), 0.0],
                                      "hi": [_r(hi[0]), _r(hi[1]), top]}
                if not small:
                    self.floor_regions.append(name)
                    self.targets.append((name, np.array([*lo, 0.0]), np.array([*hi, top])))
                return name
        return None

    def stool(self) -> None:
        rng = self.rng
        r, h = float(rng.uniform(0.15, 0.2)), float(rng.uniform(0.42, 0.5))
        for _ in range(30):
            xy = rng.uniform(-self.half + 0.8, self.half - 0.8)
            if self.free(xy - r, xy + r, gap=0.7):
                self.taken.append((xy - r, xy + r))
                name = self.new("stool")
                self.objects[name] = {
                    "position": [_r(xy[0]), _r(xy[1]), _r(h / 2)], "shape": "cylinder",
                    "size": [_r(r), _r(h)], "movable": False,
                    "sitting_surface": {"lo": [_r(-r + 0.02), _r(-r + 0.02), _r(h / 2 - 0.025)],
                                        "hi": [_r(r - 0.02), _r(r - 0.02), _r(h / 2)]}}
                self.seats.append(name)
                self.targets.append((name, np.array([*(xy - r), 0.0]),
                                     np.array([*(xy + r), h])))
                return

    def cell_dict(self, final: str) -> dict:
        return {"name": self.name, "description": "generated by ltl_human_motion.scenarios."
                "generator", "frame": "zup", "floor_z": 0.0,
                "workspace": {"lo": [_r(-self.half[0]), _r(-self.half[1]), 0.0],
                              "hi": [_r(self.half[0]), _r(self.half[1]), 3.0]},
                "start_region": "R0", "final_region": final, "objects": self.objects,
                "regions": self.regions, "obstacles": self.obstacles,
                "shorthands": {"assemble(R)": "leftHand(R) & rightHand(R)"}}


def _shift_z(d: dict, dz: float) -> dict:
    """The cell dict with everything raised by ``dz`` (a floor at ``floor_z = dz``)."""
    def up(p):
        return [p[0], p[1], _r(p[2] + dz)]
    d = {**d, "floor_z": _r(dz)}
    d["workspace"] = {"lo": up(d["workspace"]["lo"]), "hi": up(d["workspace"]["hi"])}
    d["objects"] = {k: {**v, "position": up(v["position"])} for k, v in d["objects"].items()}
    d["regions"] = {k: {"lo": up(v["lo"]), "hi": up(v["hi"])} for k, v in d["regions"].items()}

    def shape(s):
        return {**s, "position": up(s["position"])}
    d["obstacles"] = {k: ({**v, "parts": [shape(s) for s in v["parts"]]} if "parts" in v
                          else shape(v)) for k, v in d["obstacles"].items()}
    return d


def _to_paper_yup(d: dict) -> dict:
    """The cell dict written in the paper's y-up frame, ``(x, y, z) -> (x, z, -y)``: the
    inverse of the conversion the cell loader applies (``frame: paper_yup``)."""
    def pt(p):
        return [p[0], p[2], _r(-p[1])]

    def bounds(lo, hi):
        a, b = np.array(pt(lo)), np.array(pt(hi))
        return [_r(v) for v in np.minimum(a, b)], [_r(v) for v in np.maximum(a, b)]

    def shape(s):
        out = {**s, "position": pt(s["position"])}
        if s["shape"] == "box":
            sx, sy, sz = s["size"]
            out["size"] = [sx, sz, sy]
        return out
    d = {**d, "frame": "paper_yup"}
    lo, hi = bounds(d["workspace"]["lo"], d["workspace"]["hi"])
    d["workspace"] = {"lo": lo, "hi": hi}
    objects = {}
    for k, v in d["objects"].items():
        o = shape(v)
        if "grasp_points" in v:
            o["grasp_points"] = [pt(g) for g in v["grasp_points"]]
        if "sitting_surface" in v:
            slo, shi = bounds(v["sitting_surface"]["lo"], v["sitting_surface"]["hi"])
            o["sitting_surface"] = {"lo": slo, "hi": shi}
        objects[k] = o
    d["objects"] = objects
    d["regions"] = {k: dict(zip(("lo", "hi"), bounds(v["lo"], v["hi"])))
                    for k, v in d["regions"].items()}
    d["obstacles"] = {k: ({**v, "parts": [shape(s) for s in v["parts"]]} if "parts" in v
                          else shape(v)) for k, v in d["obstacles"].items()}
    return d


def _accessible(cell_yaml: str, targets) -> bool:
    """Whether every target box has comfortable floor near it, connected to R0."""
    from ltl_human_motion.planning.feasibility import floor_components
    from ltl_human_motion.scene.cell_yaml import cell_from_yaml
    cell = cell_from_yaml(cell_yaml, source="<generated>")
    grid, labels = floor_components(cell, COMFORT_RADIUS, COMFORT_RESOLUTION)
    flat = grid.free.ravel()
    start = flat & (np.abs(grid.centres) <= 0.3).all(axis=-1)
    if not start.any():
        return False
    ok_cells = np.isin(labels, np.unique(labels[start])) & flat
    pts = grid.centres[ok_cells]
    for _name, tlo, thi in targets:
        d = np.maximum(np.maximum(tlo[:2] - pts, 0.0), np.maximum(pts - thi[:2], 0.0))
        if not np.any(np.hypot(d[:, 0], d[:, 1]) <= COMFORT_REACH + COMFORT_RADIUS):
            return False
    return True


def _unordered_tasks(feasible: list[str], parts: set[str],
                     rng: np.random.Generator, k: int = 4) -> list[str] | None:
    """``k`` tasks for a Dwyer tuple, no two of them on the same part.

    Two tasks on one part have a physical order (``carry(P1, Z)`` needs ``P1`` in hand
    and leaves it there, so ``grasp(P1)`` cannot follow it): a random pattern may ask for
    the other order, and the pair would not be feasible as labelled. None when the
    cell's tasks do not allow ``k`` such tasks.
    """
    chosen: list[str] = []
    used: set[str] = set()
    for i in rng.permutation(len(feasible)):
        task = feasible[int(i)]
        on = set(parse_task(task)[1]) & parts
        if on & used:
            continue
        chosen.append(task)
        used |= on
        if len(chosen) == k:
            return chosen
    return None


def _specs(b: _Builder, rng: np.random.Generator) -> list[GeneratedPair]:
    """Labelled specifications for a built cell."""
    feasible: list[str] = []
    for p in b.parts:
        feasible.append(f"grasp({p})")
        if b.floor_regions:
            feasible.append(f"carry({p}, {rng.choice(b.floor_regions)})")
        if b.asm_regions:
            feasible.append(f"move({p}, {rng.choice(b.asm_regions)})")
        fitting = [name for name, w in b.bins if w >= 0.13]   # parts are at most 0.12 m
        if fitting:
            feasible.append(f"insert({p}, {rng.choice(fitting)})")
    for r in b.asm_regions:
        feasible.append(f"assemble({r})")
    for r in b.floor_regions:
        feasible.append(f"walk({r})")
    for s in b.seats:
        feasible.append(f"sit({s})")
    feasible.append(str(rng.choice(IN_PLACE)))
    singles = [str(t) for t in rng.choice(feasible, size=min(MAX_SINGLES, len(feasible)),
                                          replace=False)]
    pairs = [GeneratedPair(f"F {t}", "feasible", f"gen:single:{t.split('(')[0]}")
             for t in singles]
    if len(feasible) >= 4:
        for pname in rng.choice(list(DWYER_PATTERNS), size=2, replace=False):
            tasks = _unordered_tasks(feasible, set(b.parts), rng)
            if tasks is None:
                continue
            binding = dict(zip("PSQR", tasks))
            text = "".join(f"({binding[c]})" if c in binding else c
                           for c in DWYER_PATTERNS[str(pname)])
            pairs.append(GeneratedPair(text, "feasible", f"gen:dwyer:{pname}"))
    if len(feasible) >= 3:
        chain = list(rng.choice(feasible, size=int(rng.integers(2, 4)), replace=False))
        text = chain[-1]
        for t in reversed(chain[:-1]):
            text = f"{t} & F({text})"
        pairs.append(GeneratedPair(f"F({text})", "feasible", "gen:job"))
    for p, reason in b.bad_parts:
        pairs.append(GeneratedPair(f"F grasp({p})", "infeasible", f"gen:infeasible:{reason}",
                                   reason))
    for t, _w in b.small:
        if b.parts:
            pairs.append(GeneratedPair(f"F insert({b.parts[0]}, {t})", "infeasible",
                                       "gen:infeasible:size", "size"))
    return pairs


def generate_scenario(seed: int, index: int = 0) -> Scenario:
    """One random cell with its labelled specifications (deterministic in the seeds)."""
    import yaml
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, int(index)])
    name = f"gen_{seed}_{index}"
    for _attempt in range(20):
        b = _Builder(rng, name)
        if rng.random() < 0.25:
            b.pen()
        makers = [b.table, b.table, b.shelf, b.low_board, b.shelf, b.table]
        rng.shuffle(makers)
        for make in makers[:int(rng.integers(3, 6))]:
            make()
        if rng.random() < 0.3:
            b.cabinet()
        for _ in range(int(rng.integers(1, 3))):
            b.floor_region()
        if rng.random() < 0.3:
            b.floor_region(small=True)
        if rng.random() < 0.5:
            b.stool()
        if not b.parts or not (b.floor_regions or b.asm_regions):
            continue
        final = str(rng.choice(b.floor_regions + b.asm_regions))
        base = b.cell_dict(final)
        # Loose obstacles that would cut a target off are drawn again (up to 5 times).
        for _ in range(5):
            loose = b.loose()
            trial = dict(base, obstacles={**b.obstacles, **{k: v for k, (v, _) in loose.items()}})
            text = yaml.safe_dump(trial, sort_keys=False)
            if _accessible(text, b.targets):
                break
        else:
            text = yaml.safe_dump(base, sort_keys=False)
            if not _accessible(text, b.targets):
                continue
        stature = float(rng.choice(STATURES))
        pairs = _specs(b, rng)
        # The same cell raised onto a platform, or written in the paper's frame: the
        # labels do not change (the layout is the same).
        if rng.random() < FLOOR_SHIFT_PROBABILITY or rng.random() < PAPER_FRAME_PROBABILITY:
            data = yaml.safe_load(text)
            if rng.random() < 0.5:
                data = _shift_z(data, float(rng.choice([-0.4, 0.5, 1.2])))
            else:
                data = _to_paper_yup(data)
            text = yaml.safe_dump(data, sort_keys=False)
        return Scenario(name, text, stature, pairs, int(seed))
    raise RuntimeError(f"generator: no usable cell for seed {seed}, index {index}")


def generate_scenarios(n: int, seed: int = 0) -> list[Scenario]:
    """``n`` random scenarios, deterministic in ``seed``."""
    return [generate_scenario(seed, i) for i in range(int(n))]
