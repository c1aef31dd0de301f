"""Seeded "unseen-style" cells: the layouts issue 33 found missing from the corpus.

Six families, each its own name in the results:

``chamber``
    a machine (``cnc``) against a wall with its door open (hinged or sliding): a cavity
    with a floor, walls and a roof, a door opening 0.5-0.9 m wide whose bottom is
    0.8-1.1 m up, and a dual vise 0.1-0.3 m inside it (``vise_a`` holds ``done``,
    ``vise_b`` is empty): extract, insert, grasp inside; a casting wider than the opening
    that cannot be moved into the cavity (``size``).
``boards``
    a bench under a wall shelf whose boards hang just above the targets, dividers beside
    them, a low rack with a board just above its 0.3 m board; a board above the short
    worker's reach (``reach``, for the statures it is out of reach of).
``desk``
    a desk for seated work (a chair) or standing work, a bin holding a part, a jig, a
    riser board; a tray smaller than a part (``size``).
``conveyor``
    a belt at 0.8-1.0 m along a wall: parts picked from it and placed on it, a table, a
    floor pallet; behind a wall-to-wall line, an accumulation table whose far part has no
    floor within anyone's reach (``no_floor``).
``aisle``
    an aisle 0.8-1.0 m wide between two racks with parts on both sides at 0.3, 0.9 and
    1.4 m; a part on a rack's top (``reach``).
``twohanded``
    a two-handed carton on a pallet or a table, a packing table, an assembly region; a
    region smaller than the carton (``size``).

Every cell is built in a local frame (its main furniture at the +x wall) and turned by a
random multiple of 90 degrees; a family's even and odd cells alternate its two kinds
(hinged or sliding door, seated or standing desk, aisle with a dead end or open, carton
on a pallet or a table). Cells are the same for every stature; each
:class:`UnseenScenario` carries the labels of one stature, computed from geometry by
:mod:`ltl_human_motion.scenarios.labels` (tasks whose label is ambiguous for a stature
are left out and counted in ``dropped``). Deterministic in the seed; the generator of
:mod:`ltl_human_motion.scenarios.generator` is untouched (its cells stay the same).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.scenarios.labels import Labeller, Opening
from ltl_human_motion.scene.termination import parse_task

__all__ = ["FAMILIES", "STATURES", "LabelledPair", "UnseenCell", "UnseenScenario",
           "build_cell", "generate_unseen", "label_cell"]

FAMILIES = ("chamber", "boards", "desk", "conveyor", "aisle", "twohanded")
STATURES = (1.55, 1.75, 1.95)
#: Height of every cell's workspace, metres.
CEILING = 3.0
_WALL = 0.05


@dataclass(frozen=True)
class LabelledPair:
    """A specification with its geometric label for one stature.

    ``kind`` is what it exercises (``single:extract``, ``job:tend``, ``infeasible:size``);
    ``tasks`` the Table I tasks it needs; ``why`` the label's justification."""

    spec: str
    expect: str
    kind: str
    tasks: tuple[str, ...]
    reason: str | None = None
    why: str = ""


@dataclass
class UnseenCell:
    """One built cell: YAML text (z up), its openings and the candidate specifications
    ``(kind, spec, tasks)`` before labelling."""

    name: str
    family: str
    yaml: str
    openings: tuple[Opening, ...]
    candidates: list[tuple[str, str, tuple[str, ...]]]
    seed: int
    index: int


@dataclass
class UnseenScenario:
    """A cell with the labelled pairs of one stature."""

    name: str
    family: str
    yaml: str
    stature: float
    pairs: list[LabelledPair] = field(default_factory=list)
    seed: int = 0
    index: int = 0
    dropped: list[tuple[str, str]] = field(default_factory=list)   # (spec, why)


def _r(x: float) -> float:
    return round(float(x), 3)


class _Layout:
    """A cell in its local frame: obstacles, objects and regions as boxes (lo, hi)."""

    def __init__(self, rng: np.random.Generator, name: str, index: int = 0) -> None:
        self.rng = rng
        self.name = name
        self.even = index % 2 == 0     # alternates a family's two kinds (door, seat, ...)
        self.half = np.array([rng.uniform(2.4, 3.0), rng.uniform(2.4, 3.0)])
        self.obstacles: dict[str, tuple[str, list[tuple[np.ndarray, np.ndarray]]]] = {}
        self.objects: dict[str, dict] = {}
        self.regions: dict[str, tuple[np.ndarray, np.ndarray]] = {
            "R0": (np.array([-0.3, -0.3, 0.0]), np.array([0.3, 0.3, 0.1]))}
        self.openings: list[tuple[str, np.ndarray, np.ndarray, float, float]] = []
        self.candidates: list[tuple[str, str, tuple[str, ...]]] = []

    def u(self, a: float, b: float) -> float:
        return float(self.rng.uniform(a, b))

    def solid(self, name: str, color: str, *boxes) -> None:
        """Add boxes ``(lo, hi)`` (3,) to obstacle ``name``."""
        parts = self.obstacles.setdefault(name, (color, []))[1]
        parts.extend((np.asarray(lo, float), np.asarray(hi, float)) for lo, hi in boxes)

    def table(self, name: str, lo_xy, hi_xy, top: float, legs: bool = True) -> None:
        """A table top 4 cm thick on four legs (or a solid cabinet)."""
        (x0, y0), (x1, y1) = lo_xy, hi_xy
        if not legs:
            self.solid(name, "peru", ([x0, y0, 0.0], [x1, y1, top]))
            return
        boxes = [([x0, y0, top - 0.04], [x1, y1, top])]
        for x in (x0, x1 - 0.05):
            for y in (y0, y1 - 0.05):
                boxes.append(([x, y, 0.0], [x + 0.05, y + 0.05, top - 0.04]))
        self.solid(name, "peru", *boxes)

    def part(self, name: str, centre_xy, bottom: float, size, **extra) -> None:
        size = np.asarray(size, float)
        c = np.array([centre_xy[0], centre_xy[1], bottom + size[2] / 2 + 0.003])
        self.objects[name] = {"lo": c - size / 2, "hi": c + size / 2,
                              "grasp_points": [[0.0, 0.0, _r(size[2] / 2)]], **extra}

    def container(self, name: str, lo, hi) -> None:
        self.objects[name] = {"lo": np.asarray(lo, float), "hi": np.asarray(hi, float),
                              "movable": False}

    def region(self, name: str, lo, hi) -> None:
        self.regions[name] = (np.asarray(lo, float), np.asarray(hi, float))

    def zone(self, name: str = "Zone", side: float | None = None) -> None:
        """A floor region near the -x wall (the far side from the main furniture)."""
        side = self.u(0.8, 1.0) if side is None else side
        x0 = -self.half[0] + 0.3
        y = self.u(-self.half[1] + 0.4 + side / 2, self.half[1] - 0.4 - side / 2)
        self.region(name, [x0, y - side / 2, 0.0], [x0 + side, y + side / 2, 2.0])

    def task(self, kind: str, spec: str, *tasks: str) -> None:
        self.candidates.append((kind, spec, tasks or (spec.removeprefix("F "),)))

    def single(self, *tasks: str) -> None:
        for t in tasks:
            self.task(f"single:{parse_task(t)[0]}", f"F {t}", t)

    def job(self, name: str, *tasks: str) -> None:
        text = tasks[-1]
        for t in reversed(tasks[:-1]):
            text = f"{t} & F({text})"
        self.task(f"job:{name}", f"F({text})", *tasks)


# ------------------------------------------------------------------------ turning
def _turn(k: int):
    c, s = [(1, 0), (0, 1), (-1, 0), (0, -1)][k % 4]

    def point(p):
        return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])

    def bounds(lo, hi):
        a, b = point(lo), point(hi)
        return np.minimum(a, b), np.maximum(a, b)
    return point, bounds


def _box_dict(lo, hi) -> dict:
    return {"shape": "box", "position": [_r(v) for v in (lo + hi) / 2],
            "size": [_r(v) for v in hi - lo]}


def _emit(lay: _Layout, k: int) -> tuple[dict, tuple[Opening, ...]]:
    """The cell dict (z up) and its openings, turned by ``k`` quarter turns."""
    _, bounds = _turn(k)
    ws = bounds(np.array([-lay.half[0], -lay.half[1], 0.0]),
                np.array([lay.half[0], lay.half[1], CEILING]))
    obstacles = {}
    for name, (color, parts) in lay.obstacles.items():
        obstacles[name] = {"color": color,
                           "parts": [_box_dict(*bounds(lo, hi)) for lo, hi in parts]}
    objects = {}
    for name, spec in lay.objects.items():
        lo, hi = bounds(spec["lo"], spec["hi"])
        out = _box_dict(lo, hi)
        for key, value in spec.items():
            if key == "sitting_surface":
                slo, shi = bounds(*value)
                out[key] = {"lo": [_r(v) for v in slo], "hi": [_r(v) for v in shi]}
            elif key not in ("lo", "hi"):
                out[key] = value
        objects[name] = out
    regions = {}
    for name, (lo, hi) in lay.regions.items():
        rlo, rhi = bounds(lo, hi)
        regions[name] = {"lo": [_r(v) for v in rlo], "hi": [_r(v) for v in rhi]}
    openings = []
    for machine, lo, hi, width, height in lay.openings:
        olo, ohi = bounds(lo, hi)
        openings.append(Opening(machine, np.round(olo, 3), np.round(ohi, 3), _r(width),
                                _r(height), k % 2))
    final = "Zone" if "Zone" in regions else "R0"
    cell = {"name": lay.name, "description": "generated by ltl_human_motion.scenarios.unseen",
            "frame": "zup", "floor_z": 0.0,
            "workspace": {"lo": [_r(v) for v in ws[0]], "hi": [_r(v) for v in ws[1]]},
            "start_region": "R0", "final_region": final, "objects": objects,
            "regions": regions, "obstacles": obstacles,
            "shorthands": {"assemble(R)": "leftHand(R) & rightHand(R)"}}
    return cell, tuple(openings)


# ------------------------------------------------------------------------ families
def _chamber(lay: _Layout) -> None:
    """A machine with an open door, a dual vise inside, a casting wider than the door."""
    u, hx = lay.u, lay.half[0]
    ow, ob, oh, t_in = u(0.5, 0.9), u(0.8, 1.1), u(0.6, 0.8), u(0.1, 0.3)
    vx, vy, vz = u(0.14, 0.2), u(0.14, 0.2), u(0.09, 0.12)
    cast = min(ow, oh) + u(0.06, 0.12)
    w_in = max(ow + 2 * u(0.08, 0.2), cast + 0.08)
    h_in = max(oh + u(0.0, 0.12), cast + 0.08)
    d_in = max(u(0.6, 0.85), t_in + vx + 0.1, cast + 0.1)
    ym = u(-0.5, 0.5)
    hx = lay.half[0] = max(hx, d_in + 0.12 + 2.0)     # the open door clear of the start
    xb = hx - 0.02
    xf = xb - d_in - 2 * _WALL
    wo = w_in / 2 + _WALL
    top = ob + h_in
    lay.solid("cnc", "steelblue",
              ([xf, ym - wo, 0.0], [xb, ym + wo, ob]),                       # base
              ([xf, ym - wo, top], [xb, ym + wo, top + 0.08]),               # roof
              ([xf, ym + w_in / 2, ob], [xb, ym + wo, top]),                 # side walls
              ([xf, ym - wo, ob], [xb, ym - w_in / 2, top]),
              ([xb - _WALL, ym - w_in / 2, ob], [xb, ym + w_in / 2, top]),   # back
              ([xf, ym + ow / 2, ob], [xf + _WALL, ym + w_in / 2, top]),     # front flanges
              ([xf, ym - w_in / 2, ob], [xf + _WALL, ym - ow / 2, top]))
    if h_in > oh + 0.005:                                                    # header
        lay.solid("cnc", "steelblue", ([xf, ym - ow / 2, ob + oh], [xf + _WALL, ym + ow / 2, top]))
    s = 1 if lay.rng.random() < 0.5 else -1
    if lay.even:                                     # hinged door, swung open 90 degrees
        y = ym + s * (wo + 0.015)
        lay.solid("cnc", "steelblue", ([xf - ow - 0.1, y - 0.015, ob], [xf, y + 0.015, ob + oh]))
    else:                                            # sliding door parked beside the opening
        ya, yb = sorted((ym + s * ow / 2, ym + s * (ow / 2 + ow + 0.05)))
        lay.solid("cnc", "steelblue", ([xf - 0.07, ya, ob], [xf - 0.03, yb, ob + oh + 0.05]))
    cavity = (np.array([xf + _WALL, ym - w_in / 2, ob]), np.array([xb - _WALL, ym + w_in / 2, top]))
    lay.openings.append(("cnc", *cavity, ow, oh))
    x0 = xf + _WALL + t_in
    lay.container("vise_a", [x0, ym - 0.03 - vy, ob + 0.002], [x0 + vx, ym - 0.03, ob + 0.002 + vz])
    lay.container("vise_b", [x0, ym + 0.03, ob + 0.002], [x0 + vx, ym + 0.03 + vy, ob + 0.002 + vz])
    sd = u(0.05, min(vx, vy, vz) - 0.03)
    lay.part("done", (x0 + vx / 2, ym - 0.03 - vy / 2), ob + 0.012, [sd] * 3, mass=0.5)
    # a table at a side wall with the blank, and a pallet with the casting at the other
    side = 1 if ym < 0 else -1
    yt = side * (lay.half[1] - 0.02)
    ttop, tx = u(0.75, 0.9), u(-0.6, 0.2)
    lay.table("table", (tx, min(yt, yt - side * 0.65)), (tx + 1.0, max(yt, yt - side * 0.65)), ttop)
    front = yt - side * 0.65
    sb = u(0.05, min(vx, vy, vz) - 0.03)
    lay.part("blank", (tx + 0.3, front + side * u(0.1, 0.2)), ttop, [sb] * 3, mass=0.5)
    ry = front + side * 0.15
    lay.region("R_tab", [tx + 0.55, ry - 0.12, ttop + 0.02], [tx + 0.8, ry + 0.12, ttop + 0.2])
    yp = -side * (lay.half[1] - 0.02)
    pd = max(0.8, cast + 0.1)
    lay.solid("pallet", "burlywood", ([tx, min(yp, yp + side * pd), 0.0],
                                      [tx + 1.0, max(yp, yp + side * pd), 0.14]))
    lay.part("casting", (tx + 0.5, yp + side * pd / 2), 0.14, [cast] * 3, mass=8.0,
             two_handed=True)
    lay.region("R_bay", cavity[0] + 0.01, cavity[1] - 0.01)
    lay.zone()
    lay.single("grasp(done)", "extract(done, vise_a)", "insert(blank, vise_b)",
               "move(blank, R_bay)")
    lay.job("unload", "extract(done, vise_a)", "move(done, R_tab)")
    lay.job("tend", "extract(done, vise_a)", "move(done, R_tab)", "insert(blank, vise_b)")
    lay.task("infeasible:size", "F move(casting, R_bay)", "move(casting, R_bay)")


def _wall_shelf(lay: _Layout, x_wall: float, y0: float, y1: float, z: float,
                depth: float) -> None:
    lay.solid("wall_shelf", "slategray", ([x_wall - depth, y0, z - 0.025], [x_wall, y1, z]))


def _boards(lay: _Layout) -> None:
    """A bench under a wall shelf, dividers, a low rack; a board out of short reach."""
    u, hx = lay.u, lay.half[0]
    bd, bw, yb, zt = u(0.6, 0.7), u(1.4, 2.0), u(-0.5, 0.5), u(0.85, 0.95)
    sd = u(0.3, 0.35)
    xw = hx - 0.02
    y0, y1 = yb - bw / 2, yb + bw / 2
    lay.table("bench", (xw - bd, y0), (xw, y1), zt, legs=False)
    z1 = zt + u(0.28, 0.4)
    z2 = min(max(u(1.38, 1.55), z1 + 0.25), 1.58)
    z3 = z2 + u(0.22, 0.3)
    zhi = u(2.1, 2.5)
    for z in (z1, z2, z3, zhi):
        _wall_shelf(lay, xw, y0, y1, z, sd)
    s = [u(0.05, 0.09) for _ in range(4)]
    yp = [u(y0 + 0.2, yb - 0.15), u(yb + 0.15, y1 - 0.2)]
    for y in yp:                                    # dividers beside the board parts
        gap = u(0.05, 0.12)
        lay.solid("wall_shelf", "slategray", ([xw - sd, y + 0.05 + gap, z1],
                                              [xw, y + 0.07 + gap, zhi - 0.025]))
    lay.part("P_bench", (xw - sd + s[0] / 2 + u(0.0, 0.04), yb), zt, [s[0]] * 3)
    lay.part("P_b1", (xw - sd + u(0.06, 0.12), yp[0]), z1, [s[1]] * 3)
    lay.part("P_b2", (xw - sd + u(0.06, 0.12), yp[1]), z2, [s[2]] * 3)
    lay.part("P_top", (xw - sd + u(0.06, 0.12), yb), zhi, [0.08] * 3)
    lay.region("R_bench", [xw - bd + 0.05, yb - 0.12, zt + 0.02],
               [xw - bd + 0.3, yb + 0.12, zt + 0.2])
    # a low rack at a side wall: a 0.3 m plinth with a board just above it
    side = 1 if lay.rng.random() < 0.5 else -1
    yw = side * (lay.half[1] - 0.02)
    yf = yw - side * 0.4
    rx = u(-0.8, 0.4)
    ya, yz = min(yw, yf), max(yw, yf)
    zr = 0.3 + u(0.25, 0.32)
    lay.solid("low_rack", "slategray", ([rx, ya, 0.0], [rx + 0.9, yz, 0.3]),
              ([rx, ya, zr - 0.025], [rx + 0.9, yz, zr]),
              ([rx - 0.03, ya, 0.0], [rx, yz, zr]), ([rx + 0.9, ya, 0.0], [rx + 0.93, yz, zr]))
    lay.part("P_low", (rx + 0.45, yf + side * u(0.06, 0.12)), 0.3, [s[3]] * 3)
    lay.zone()
    lay.single("grasp(P_bench)", "grasp(P_b1)", "grasp(P_b2)", "grasp(P_low)",
               "move(P_b2, R_bench)", "carry(P_low, Zone)", "assemble(R_bench)")
    lay.job("board_assemble", "grasp(P_b1)", "assemble(R_bench)")
    lay.task("infeasible:reach", "F grasp(P_top)", "grasp(P_top)")


def _desk(lay: _Layout) -> None:
    """A desk for seated or standing work with a bin, a jig, a riser and a small tray."""
    u, hx = lay.u, lay.half[0]
    seated = lay.even
    dd, dw, yd = u(0.7, 0.8), u(1.2, 1.6), u(-0.6, 0.6)
    top = u(0.70, 0.76) if seated else u(0.9, 1.0)
    xw = hx - 0.02
    xf = xw - dd
    lay.table("desk", (xf, yd - dw / 2), (xw, yd + dw / 2), top)
    if lay.rng.random() < 0.5:                      # a riser board at the back
        zr = top + u(0.3, 0.4)
        lay.solid("desk", "peru", ([xw - 0.25, yd - dw / 2, zr - 0.02], [xw, yd + dw / 2, zr]),
                  ([xw - 0.25, yd - dw / 2, top], [xw, yd - dw / 2 + 0.02, zr]),
                  ([xw - 0.25, yd + dw / 2 - 0.02, top], [xw, yd + dw / 2, zr]))
    sp = [u(0.05, 0.07), u(0.05, 0.08)]
    bx, by, bz = u(0.2, 0.3), u(0.25, 0.32), u(0.1, 0.15)
    xb = xf + u(0.1, 0.25)
    yb = yd - 0.58
    lay.container("bin_a", [xb, yb, top + 0.002], [xb + bx, yb + by, top + 0.002 + bz])
    lay.part("P_bin", (xb + bx / 2, yb + by / 2), top + 0.012, [sp[0]] * 3, mass=0.2)
    tray = u(0.03, 0.04)
    xt = xf + u(0.08, 0.15)
    lay.container("tray", [xt, yd - 0.2, top + 0.002], [xt + tray, yd - 0.2 + tray,
                                                         top + 0.002 + tray])
    js = max(sp) + u(0.03, 0.05)
    xj = xf + u(0.1, 0.2)
    lay.container("jig", [xj, yd - 0.1, top + 0.002], [xj + js, yd - 0.1 + js, top + 0.002 + js])
    lay.region("R_desk", [xf + 0.05, yd + 0.08, top + 0.03], [xf + 0.25, yd + 0.28, top + 0.2])
    lay.part("P_desk", (xf + u(0.08, 0.15), yd + 0.45), top, [sp[1]] * 3, mass=0.2)
    lay.zone()
    lay.single("extract(P_bin, bin_a)", "insert(P_desk, jig)", "grasp(P_desk)",
               "assemble(R_desk)")
    if seated:
        hs = u(0.44, 0.5)
        cx = xf - u(0.22, 0.3)
        lay.part("chair", (cx, yd), 0.0, [0.44, 0.44, hs], movable=False,
                 sitting_surface=(np.array([-0.2, -0.2, hs / 2 - 0.02]),
                                  np.array([0.2, 0.2, hs / 2])))
        del lay.objects["chair"]["grasp_points"]
        lay.single("sit(chair)")
        lay.job("seated_kit", "sit(chair)", "extract(P_bin, bin_a)", "insert(P_bin, jig)")
    else:
        lay.job("standing_kit", "extract(P_bin, bin_a)", "insert(P_bin, jig)")
    lay.task("infeasible:size", "F insert(P_desk, tray)", "insert(P_desk, tray)")


def _conveyor(lay: _Layout) -> None:
    """A belt along a wall; behind a wall-to-wall line, a table out of everyone's reach."""
    u, hx, hy = lay.u, lay.half[0], lay.half[1]
    bw, zb = u(0.45, 0.7), u(0.8, 1.0)
    through = lay.rng.random() < 0.6
    depth = u(1.8, 1.95) if through else bw
    if through:
        hx = lay.half[0] = hx + 0.6
    xw = hx - 0.02
    xc = xw - depth
    y0, y1 = (-hy + 0.01, hy - 0.01) if through else (-u(1.0, 1.6), u(1.0, 1.6))
    lay.solid("conveyor", "dimgray", ([xc, y0, 0.0], [xc + bw, y1, zb - 0.06]),
              ([xc, y0, zb - 0.06], [xc + bw, y1, zb]))
    if through:
        lay.solid("accumulation_table", "gray", ([xc + bw, y0, 0.0], [xw, y1, zb - 0.02]))
        lay.part("P_far", (xw - 0.1, u(-0.5, 0.5)), zb - 0.02, [0.08] * 3)
        lay.task("infeasible:no_floor", "F grasp(P_far)", "grasp(P_far)")
    else:
        lay.solid("conveyor", "dimgray", ([xc + bw - 0.03, y0, zb], [xc + bw, y1, zb + 0.05]))
    ys = sorted([u(y0 + 0.4, -0.35), u(0.35, y1 - 0.4)])
    s = [u(0.05, 0.1), u(0.05, 0.1), u(0.05, 0.09)]
    lay.part("P_c1", (xc + u(0.06, 0.2) + s[0] / 2, ys[0]), zb, [s[0]] * 3)
    lay.part("P_c2", (xc + u(0.06, 0.2) + s[1] / 2, ys[1]), zb, [s[1]] * 3)
    yr = (ys[0] + ys[1]) / 2
    lay.region("R_belt", [xc + 0.04, yr - 0.12, zb + 0.005], [xc + 0.28, yr + 0.12, zb + 0.2])
    side = 1 if lay.rng.random() < 0.5 else -1
    yt = side * (hy - 0.02)
    tx, ttop = u(-0.8, 0.0), u(0.75, 0.9)
    lay.table("table", (tx, min(yt, yt - side * 0.6)), (tx + 0.9, max(yt, yt - side * 0.6)), ttop)
    lay.part("P_tab", (tx + 0.25, yt - side * u(0.45, 0.52)), ttop, [s[2]] * 3)
    ry = yt - side * 0.45
    lay.region("R_tab", [tx + 0.5, ry - 0.12, ttop + 0.02], [tx + 0.75, ry + 0.12, ttop + 0.2])
    yp = -side * (hy - 0.02)
    lay.solid("pallet", "burlywood", ([tx, min(yp, yp + side * 0.8), 0.0],
                                      [tx + 1.0, max(yp, yp + side * 0.8), 0.14]))
    py = yp + side * 0.45
    lay.region("R_pal", [tx + 0.3, py - 0.2, 0.15], [tx + 0.7, py + 0.2, 0.45])
    lay.zone()
    lay.single("grasp(P_c1)", "move(P_c1, R_tab)", "move(P_tab, R_belt)",
               "carry(P_c2, Zone)", "move(P_c2, R_pal)")
    lay.job("belt_to_pallet", "grasp(P_c1)", "move(P_c1, R_pal)")
    lay.job("feed_belt", "move(P_tab, R_belt)", "carry(P_c2, Zone)")


def _aisle(lay: _Layout) -> None:
    """Two racks with parts at 0.3, 0.9 and 1.4 m on both sides of a 0.8-1.0 m aisle."""
    u = lay.u
    aw, rd, ya = u(0.8, 1.0), u(0.4, 0.5), u(-0.3, 0.3)
    x0 = u(0.9, 1.3)
    x1 = x0 + u(1.6, 2.2)
    lay.half[0] = x1 + (0.02 if lay.even else u(1.0, 1.3))     # a dead end or open
    ztop = u(2.3, 2.45)
    names = []
    for side, rack in ((1, "rack_left"), (-1, "rack_right")):
        yi, yo = ya + side * aw / 2, ya + side * (aw / 2 + rd)
        lo_y, hi_y = min(yi, yo), max(yi, yo)
        boxes = [([x0, lo_y, 0.0], [x1, hi_y, 0.3])]
        for z in (0.9, 1.4, ztop):
            boxes.append(([x0, lo_y, z - 0.025], [x1, hi_y, z]))
        back = yo - side * 0.03
        boxes.append(([x0, min(back, yo), 0.0], [x1, max(back, yo), ztop]))
        boxes += [([x0, lo_y, 0.0], [x0 + 0.03, hi_y, ztop]),
                  ([x1 - 0.03, lo_y, 0.0], [x1, hi_y, ztop])]
        lay.solid(rack, "slategray", *boxes)
        heights = lay.rng.choice([0.3, 0.9, 1.4], size=2, replace=False)
        xs = sorted(lay.rng.uniform(x0 + 0.25, x1 - 0.25, size=2))
        for z, x in zip(heights, xs):
            s = u(0.06, 0.1)
            name = f"P_{'l' if side > 0 else 'r'}{round(float(z) * 10):02d}"
            lay.part(name, (x, yi + side * (u(0.05, 0.12) + s / 2)), float(z), [s] * 3)
            names.append(name)
    lay.part("P_top", (u(x0 + 0.3, x1 - 0.3), ya + aw / 2 + rd / 2), ztop, [0.08] * 3)
    lay.region("R_in", [x0 + 0.3, ya - aw / 2 + 0.12, 0.0], [x0 + 0.9, ya + aw / 2 - 0.12, 2.0])
    side = 1 if lay.rng.random() < 0.5 else -1
    yt = side * (lay.half[1] - 0.02)
    tx, ttop = u(-1.0, -0.2), u(0.75, 0.9)
    lay.table("table", (tx, min(yt, yt - side * 0.6)), (tx + 1.0, max(yt, yt - side * 0.6)), ttop)
    ry = yt - side * 0.4
    lay.region("R_tab", [tx + 0.4, ry - 0.12, ttop + 0.02], [tx + 0.65, ry + 0.12, ttop + 0.2])
    lay.zone()
    lay.single(*(f"grasp({n})" for n in names), f"carry({names[0]}, Zone)", "walk(R_in)",
               f"move({names[3]}, R_tab)")
    lay.job("aisle_pick_two", f"grasp({names[1]})", f"grasp({names[2]})",
            f"carry({names[2]}, Zone)")
    lay.task("infeasible:reach", "F grasp(P_top)", "grasp(P_top)")


def _twohanded(lay: _Layout) -> None:
    """A two-handed carton on a pallet or a table, a packing table, an assembly region."""
    u, hx, hy = lay.u, lay.half[0], lay.half[1]
    cw, cd, ch = u(0.3, 0.45), u(0.25, 0.35), u(0.2, 0.35)
    xw = hx - 0.02
    yc = u(-0.8, 0.8)
    if lay.even:
        base = 0.14
        lay.solid("pallet", "burlywood", ([xw - 0.8, yc - 0.6, 0.0], [xw, yc + 0.6, base]))
    else:
        base = u(0.75, 0.85)
        lay.table("stand", (xw - 0.7, yc - 0.6), (xw, yc + 0.6), base)
    lay.part("carton", (xw - 0.7 + 0.1 + cd / 2, yc), base, [cd, cw, ch], mass=round(u(3, 9), 1),
             two_handed=True)
    side = 1 if lay.rng.random() < 0.5 else -1
    yt = side * (hy - 0.02)
    tx, ttop = u(-1.0, 0.3), u(0.8, 0.95)
    yf = yt - side * 0.8
    lay.table("packing_table", (tx, min(yt, yf)), (tx + 1.4, max(yt, yf)), ttop, legs=False)
    m = [u(0.06, 0.12) for _ in range(3)]
    ry = yf + side * (0.06 + (cw + m[1]) / 2)
    lay.region("R_pack", [tx + 0.1, ry - (cw + m[1]) / 2, ttop + 0.005],
               [tx + 0.1 + cd + m[0], ry + (cw + m[1]) / 2, ttop + 0.005 + ch + m[2]])
    ay = yf + side * 0.15
    lay.region("R_asm", [tx + 0.95, ay - 0.1, ttop + 0.03], [tx + 1.15, ay + 0.1, ttop + 0.2])
    sy = yf + side * 0.12
    lay.region("R_small", [tx + 0.7, sy - 0.075, ttop + 0.005],
               [tx + 0.85, sy + 0.075, ttop + 0.15])
    lay.zone(side=u(0.9, 1.0))
    lay.single("grasp(carton)", "carry(carton, Zone)", "move(carton, R_pack)", "assemble(R_asm)")
    lay.job("pack", "grasp(carton)", "move(carton, R_pack)")
    lay.job("pack_assemble", "move(carton, R_pack)", "assemble(R_asm)")
    lay.task("infeasible:size", "F move(carton, R_small)", "move(carton, R_small)")


_BUILDERS = {"chamber": _chamber, "boards": _boards, "desk": _desk, "conveyor": _conveyor,
             "aisle": _aisle, "twohanded": _twohanded}


def build_cell(family: str, seed: int = 0, index: int = 0) -> UnseenCell:
    """One cell of ``family`` (deterministic in ``seed`` and ``index``)."""
    import yaml
    if family not in _BUILDERS:
        raise ValueError(f"unknown family {family!r}; expected one of {', '.join(FAMILIES)}")
    rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, int(index),
                                 FAMILIES.index(family) + 1000])
    name = f"unseen_{family}_{seed}_{index}"
    lay = _Layout(rng, name, index)
    _BUILDERS[family](lay)
    cell, openings = _emit(lay, int(rng.integers(4)))
    text = yaml.safe_dump(cell, sort_keys=False, default_flow_style=None)
    return UnseenCell(name, family, text, openings,
                      list(lay.candidates), int(seed), int(index))


def label_cell(cell: UnseenCell, stature: float,
               labeller: Labeller | None = None) -> UnseenScenario:
    """The cell's candidates labelled for one stature (ambiguous ones in ``dropped``)."""
    if labeller is None:
        from ltl_human_motion.scene.cell_yaml import cell_from_yaml
        labeller = Labeller(cell_from_yaml(cell.yaml, source=f"<{cell.name}>"), cell.openings)
    scen = UnseenScenario(cell.name, cell.family, cell.yaml, float(stature), seed=cell.seed,
                          index=cell.index)
    for kind, spec, tasks in cell.candidates:
        label = labeller.label(tasks, stature)
        if label.expect == "ambiguous":
            scen.dropped.append((spec, label.why))
            continue
        scen.pairs.append(LabelledPair(spec, label.expect, kind, tuple(tasks), label.reason,
                                       label.why))
    return scen


def generate_unseen(cells_per_family: int = 2, seed: int = 0,
                    families: tuple[str, ...] = FAMILIES,
                    statures: tuple[float, ...] = STATURES) -> list[UnseenScenario]:
    """``cells_per_family`` cells of each family, each labelled for every stature."""
    from ltl_human_motion.scene.cell_yaml import cell_from_yaml
    out = []
    for family in families:
        for index in range(int(cells_per_family)):
            cell = build_cell(family, seed, index)
            labeller = Labeller(cell_from_yaml(cell.yaml, source=f"<{cell.name}>"),
                                cell.openings)
            out.extend(label_cell(cell, h, labeller) for h in statures)
    return out
