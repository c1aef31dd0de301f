"""Work cells: objects, regions, static obstacles, start/final regions, shorthands.

A cell is described in YAML (see ``config/paper_cell.yaml``)::

    name: paper_cell
    frame: zup                 # or paper_yup: converted once with zup_from_yup
    floor_z: 0.0
    workspace: {lo: [-3, -3, 0], hi: [3, 3, 2.5]}
    start_region: R0
    final_region: R1           # optional
    objects:
      O1: {position: [-1.0, -1.0, 0.2], shape: box, size: [0.1, 0.1, 0.1],
           grasp_points: [[0, 0, 0.05]]}
    regions:
      R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 2.0]}
      R1: {lo: [0.9, -1.1, 0.9], hi: [1.1, -0.9, 1.1]}
    obstacles:
      workbench: {shape: box, position: [1.1, -1.0, 0.425], size: [0.6, 1.2, 0.85]}
      drill_press:
        parts:
          - {shape: cylinder, position: [1.5, 1.5, 0.8], size: [0.06, 1.6]}
    shorthands:
      assemble(R): leftHand(R) & rightHand(R)

Shapes: ``box`` (``size`` = full side lengths x, y, z), ``cylinder`` (vertical axis,
``size`` = [radius, height]), ``sphere`` (``size`` = [radius]) or ``mesh`` (``mesh`` = a
file path relative to the YAML file, loaded with trimesh, optional ``scale``; the file
is in the cell's frame and ``position`` translates it). ``position`` is the centre of a
primitive. ``yaw`` (radians, about the vertical axis) turns boxes. Regions are
axis-aligned boxes (``lo``/``hi``) or meshes. Object ``grasp_points`` and
``sitting_surface`` (``lo``/``hi``) are offsets from the object's position.

With ``frame: paper_yup`` every coordinate is given in the paper's y-up frame and is
converted once at load time: points and offsets by
:func:`~ltl_human_motion.scene.frames.zup_from_yup`, box sizes by swapping y and z,
box bounds by converting both corners and re-sorting; cylinder sizes and yaw angles
are unchanged (the vertical axis maps to the vertical axis).

Every error names the file and the key, e.g.
``paper_cell.yaml: objects.O1.position: expected 3 numbers, got 2``.
"""

from __future__ import annotations

import math
import os
import re
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ltl_human_motion.errors import CellError
from ltl_human_motion.scene.clearance import EXACT_BELOW, PartSet, part_set
from ltl_human_motion.scene.frames import ZUP_FROM_YUP, extents_zup_from_yup, zup_from_yup
from ltl_human_motion.scene.geometry import min_along_segment
from ltl_human_motion.scene.shapes import Box, Cylinder, Footprint, MeshShape, Shape, Sphere
from ltl_human_motion.scene.tasks import TASK_ARGUMENTS
from ltl_human_motion.scene.yaml_limits import YamlLimitError, load_yaml_limited
from ltl_human_motion.scene.yaml_limits import short_repr as _r

__all__ = [
    "Cell",
    "Obstacle",
    "Region",
    "SceneObject",
    "cell_by_name",
    "cell_from_yaml",
    "cell_search_paths",
    "load_cell",
]

_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_SHORTHAND_KEY = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(?:\(([^()]*)\))?\s*$")
_ATOM = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)\s*\(([^()]*)\)")
_FRAMES = ("zup", "paper_yup")
#: Any number of a cell (metres, or a size, a scale): a production cell is tens of metres
#: across; beyond this, grids and meshes overflow (issue 17: x = 1e300).
MAX_CELL_COORDINATE = 1000.0
#: Floor extent of the workspace per axis (m): the clearance maps sample it every 5 cm,
#: so 100 m is 2000 x 2000 cells (32 MB); +-1e6 m asked for 17.8 PiB.
MAX_WORKSPACE_EXTENT = 100.0
#: Entries per section. The shipped cells have under 20 of each; 10,000 tiny obstacles
#: took minutes of clearance maps.
MAX_CELL_ENTRIES = {"objects": 200, "regions": 200, "obstacles": 500}
_SIMPLIFY = {
    "objects": "Keep the objects the tasks handle; others can be obstacles.",
    "regions": "Merge regions that the tasks treat alike.",
    "obstacles": "Simplify the cell: merge neighbouring obstacles into boxes that cover "
                 "them, and drop those smaller than about 5 cm (below the body's scale).",
}


# --------------------------------------------------------------------------- types

@dataclass(frozen=True, eq=False)
class Region:
    """A region of the cell: an axis-aligned box or a closed mesh.

    Attributes
    ----------
    name : str
    shape : Shape
        A :class:`Box` (axis-aligned) or :class:`MeshShape`.
    """

    name: str
    shape: Shape

    @property
    def is_box(self) -> bool:
        return isinstance(self.shape, Box)

    @property
    def lo(self) -> np.ndarray:
        """Lower corner of the bounds, shape (3,)."""
        return self.shape.aabb()[0]

    @property
    def hi(self) -> np.ndarray:
        """Upper corner of the bounds, shape (3,)."""
        return self.shape.aabb()[1]

    @property
    def center(self) -> np.ndarray:
        """Centre of the bounds, shape (3,)."""
        lo, hi = self.shape.aabb()
        return (lo + hi) / 2.0

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Whether points (..., 3) lie in the region, bool array (...)."""
        return self.shape.contains(points)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance from points (..., 3) to the region, 0 inside; shape (...)."""
        return self.shape.distance(points)

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (negative inside), shape (...)."""
        return self.shape.signed_distance(points)


@dataclass(frozen=True, eq=False)
class SceneObject:
    """A (movable) object of the cell.

    Attributes
    ----------
    name : str
    position : ndarray, shape (3,)
        Initial position (the shape's reference point, the centre for primitives).
    shape : Shape
        The occupancy at ``position``.
    grasp_offsets : ndarray, shape (G, 3)
        Grasp points relative to ``position`` (at least one, default the centre).
    movable : bool
    sitting_offsets : ndarray, shape (2, 3) or None
        ``lo``/``hi`` of the sitting surface relative to ``position``.
    color : str or None
    mass : float
        Mass in kg (default 1 kg): the load of ergonomic scores and lifting equations.
    two_handed : bool
        True when the part takes both hands to hold (task planning counts both as busy).
    """

    name: str
    position: np.ndarray
    shape: Shape
    grasp_offsets: np.ndarray = field(default_factory=lambda: np.zeros((1, 3)))
    movable: bool = True
    sitting_offsets: np.ndarray | None = None
    color: str | None = None
    mass: float = 1.0
    two_handed: bool = False

    @property
    def occupancy(self) -> Shape:
        """occ(O) at the initial position."""
        return self.shape

    @property
    def grasp_points(self) -> np.ndarray:
        """World grasp points at the initial position, shape (G, 3)."""
        return self.position + self.grasp_offsets

    def occupancy_at(self, position: np.ndarray) -> Shape:
        """occ(O) with the object at ``position`` (3,)."""
        position = np.asarray(position, dtype=np.float64)
        if position.shape != (3,):
            raise ValueError(f"position must have shape (3,), got {position.shape}")
        return self.shape.translated(position - self.position)

    def grasp_points_at(self, position: np.ndarray) -> np.ndarray:
        """Grasp points with the object at ``position`` (3,), shape (G, 3)."""
        return np.asarray(position, dtype=np.float64) + self.grasp_offsets

    def sitting_surface_at(self, position: np.ndarray | None = None) -> Box:
        """sittingSurface(O): the given surface, or the top 2 cm of the object's bounds."""
        pos = self.position if position is None else np.asarray(position, dtype=np.float64)
        if self.sitting_offsets is not None:
            return Box.from_bounds(pos + self.sitting_offsets[0], pos + self.sitting_offsets[1])
        lo, hi = self.occupancy_at(pos).aabb()
        return Box.from_bounds(np.array([lo[0], lo[1], hi[2] - 0.02]), hi)


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A static obstacle made of one or more solid parts.

    Attributes
    ----------
    name : str
    parts : tuple of Shape
    color : str or None
    """

    name: str
    parts: tuple[Shape, ...]
    color: str | None = None

    def capsule_clearance(self, segments: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """Smallest clearance of capsules (..., 2, 3) to any part, shape (...)."""
        return np.min(np.stack([p.capsule_clearance(segments, radii) for p in self.parts]),
                      axis=0)

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Whether points (..., 3) are inside any part, bool (...)."""
        return np.any(np.stack([p.contains(points) for p in self.parts]), axis=0)

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance of points (..., 3) to the obstacle, shape (...)."""
        return np.min(np.stack([p.distance(points) for p in self.parts]), axis=0)

    def footprints(self) -> tuple[Footprint, ...]:
        """Floor footprints, one per part."""
        return tuple(p.footprint() for p in self.parts)

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds ``(lo (3,), hi (3,))`` of all parts."""
        boxes = [p.aabb() for p in self.parts]
        return (np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0))

    def to_trimesh(self):
        """All parts as one ``trimesh.Trimesh``."""
        import trimesh
        return trimesh.util.concatenate([p.to_trimesh() for p in self.parts])


@dataclass(frozen=True, eq=False)
class Cell:
    """A work cell (Sec. IV of the paper), z up.

    Attributes
    ----------
    name : str
    source : str
        File the cell came from (or ``"<inline>"``).
    objects : dict of str to SceneObject
    regions : dict of str to Region
        Includes the start and final regions.
    obstacles : tuple of Obstacle
    start_region : Region
        R0: the body has to be in it at the first frame.
    final_region : Region or None
        R_xi: ``F enter(R_final)`` is added to every specification.
    shorthands : dict of str to (tuple of str, str)
        ``name -> (params, body)``, e.g. ``"assemble" -> (("R",), "leftHand(R) & rightHand(R)")``.
    floor_z : float
    workspace_lo, workspace_hi : ndarray, shape (3,)
    frame : str
        The frame the file was written in (``"zup"`` or ``"paper_yup"``); the cell itself
        is always z up.
    description : str
    """

    name: str
    source: str
    objects: dict[str, SceneObject]
    regions: dict[str, Region]
    obstacles: tuple[Obstacle, ...]
    start_region: Region
    final_region: Region | None
    shorthands: dict[str, tuple[tuple[str, ...], str]]
    floor_z: float = 0.0
    workspace_lo: np.ndarray = field(default_factory=lambda: np.array([-5.0, -5.0, 0.0]))
    workspace_hi: np.ndarray = field(default_factory=lambda: np.array([5.0, 5.0, 3.0]))
    frame: str = "zup"
    description: str = ""

    # ---------------------------------------------------------------- look-ups
    def region(self, name: str) -> Region:
        """The region called ``name`` (ValueError listing the known ones)."""
        try:
            return self.regions[name]
        except KeyError:
            raise ValueError(f"cell {self.name!r} has no region {name!r}; regions: "
                             f"{', '.join(self.regions) or '(none)'}") from None

    def object(self, name: str) -> SceneObject:
        """The object called ``name`` (ValueError listing the known ones)."""
        try:
            return self.objects[name]
        except KeyError:
            raise ValueError(f"cell {self.name!r} has no object {name!r}; objects: "
                             f"{', '.join(self.objects) or '(none)'}") from None

    def obstacle(self, name: str) -> Obstacle:
        """The obstacle called ``name``."""
        for ob in self.obstacles:
            if ob.name == name:
                return ob
        raise ValueError(f"cell {self.name!r} has no obstacle {name!r}; obstacles: "
                         f"{', '.join(o.name for o in self.obstacles) or '(none)'}")

    @property
    def workspace(self) -> tuple[np.ndarray, np.ndarray]:
        """Workspace bounds ``(lo (3,), hi (3,))``."""
        return self.workspace_lo, self.workspace_hi

    # ---------------------------------------------------------------- planner helpers
    def footprints(self) -> tuple[Footprint, ...]:
        """Floor footprints of all obstacle parts."""
        return tuple(fp for ob in self.obstacles for fp in ob.footprints())

    def floor_clearance(self, xy: np.ndarray) -> np.ndarray:
        """Signed floor-plane distance from points to the nearest obstacle footprint.

        Parameters
        ----------
        xy : array-like, shape (N, 2) or (..., 2)

        Returns
        -------
        d : ndarray, shape (N,) or (...)
            Negative inside a footprint; ``inf`` when the cell has no obstacles.
        """
        xy = np.asarray(xy, dtype=np.float64)
        if xy.ndim == 0 or xy.shape[-1] != 2:
            raise ValueError(f"xy must have shape (N, 2), got {xy.shape}")
        fps = self.footprints()
        if not fps:
            return np.full(xy.shape[:-1], np.inf)
        return np.min(np.stack([fp.signed_distance(xy) for fp in fps]), axis=0)

    def in_workspace(self, xy: np.ndarray, radius: float = 0.0) -> np.ndarray:
        """Whether floor points (..., 2) lie in the workspace shrunk by ``radius``."""
        xy = np.asarray(xy, dtype=np.float64)
        lo, hi = self.workspace_lo[:2] + radius, self.workspace_hi[:2] - radius
        return np.all((xy >= lo) & (xy <= hi), axis=-1)

    def segment_blocked(self, xy_a: np.ndarray, xy_b: np.ndarray, radius: float,
                        check_workspace: bool = True) -> np.ndarray | bool:
        """Whether a disc of ``radius`` swept from ``xy_a`` to ``xy_b`` hits a footprint.

        Parameters
        ----------
        xy_a, xy_b : array-like, shape (2,) or (N, 2)
        radius : float
            Body radius in the floor plane (footprints are inflated by it).
        check_workspace : bool
            Also block segments that leave the workspace (shrunk by ``radius``).

        Returns
        -------
        blocked : bool or ndarray of bool, shape (N,)
        """
        a = np.asarray(xy_a, dtype=np.float64)
        b = np.asarray(xy_b, dtype=np.float64)
        if a.shape[-1:] != (2,) or b.shape[-1:] != (2,):
            raise ValueError(f"xy_a and xy_b must have shape (N, 2), got {a.shape}, {b.shape}")
        if radius < 0:
            raise ValueError(f"radius must be non-negative, got {radius!r}")
        a, b = np.broadcast_arrays(a, b)
        blocked = np.zeros(a.shape[:-1], dtype=bool)
        for fp in self.footprints():
            blocked |= min_along_segment(fp.signed_distance, a, b) < radius
        if check_workspace:
            blocked |= ~(self.in_workspace(a, radius) & self.in_workspace(b, radius))
        return bool(blocked) if blocked.ndim == 0 else blocked

    def obstacle_clearance(self, segments: np.ndarray, radii: np.ndarray,
                           exact_below: float = EXACT_BELOW) -> np.ndarray:
        """Smallest clearance of capsules (..., 2, 3) to any obstacle, shape (...).

        Exact below ``exact_below`` (see :meth:`Shape.capsule_clearance`), a lower bound
        at or above it; ``inf`` without obstacles. All parts are checked in one
        vectorized pass (:class:`~ltl_human_motion.scene.clearance.PartSet`).
        """
        seg = np.asarray(segments, dtype=np.float64)
        if not self.obstacles:
            return np.full(seg.shape[:-2], np.inf)
        return self.part_set.capsule_clearance(seg, radii, exact_below)

    @property
    def part_set(self) -> PartSet:
        """The obstacles' parts as arrays for vectorized checks (built once per layout)."""
        return part_set(self.obstacles)

    def lookup(self, name: str) -> Region | SceneObject:
        """A region or an object by name (regions first)."""
        if name in self.regions:
            return self.regions[name]
        if name in self.objects:
            return self.objects[name]
        raise ValueError(f"cell {self.name!r} has no region or object {name!r}")


# --------------------------------------------------------------------------- parsing

class _Parser:
    """Hand-written validation of the YAML mapping; every error names file and key."""

    def __init__(self, source: str, base_dir: Path, frame: str) -> None:
        self.source = source
        self.base_dir = base_dir
        self.frame = frame

    def error(self, key: str, message: str) -> CellError:
        return CellError(f"{self.source}: {key}: {message}" if key else f"{self.source}: {message}")

    def mapping(self, value: Any, key: str, allowed: set[str] | frozenset[str],
                required: tuple[str, ...] = ()) -> Mapping[str, Any]:
        if not isinstance(value, Mapping):
            raise self.error(key, f"expected a mapping, got {type(value).__name__}")
        for k in value:
            if not isinstance(k, str):
                raise self.error(key, f"keys must be strings, got {_r(k)}")
            if k not in allowed:
                raise self.error(f"{key}.{k}" if key else k,
                                 f"unknown key; expected one of {', '.join(sorted(allowed))}")
        for k in required:
            if k not in value:
                raise self.error(key, f"missing required key {_r(k)}")
        return value

    def number(self, value: Any, key: str) -> float:
        if isinstance(value, str):
            # YAML 1.1 reads "1e-3" (no dot) as a string; accept numeric strings.
            try:
                value = float(value)
            except ValueError:
                raise self.error(key, f"expected a number, got {_r(value)}") from None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(key, f"expected a number, got {_r(value)}")
        if not math.isfinite(float(value)):
            raise self.error(key, f"expected a finite number, got {_r(value)}")
        if abs(float(value)) > MAX_CELL_COORDINATE:
            raise self.error(key, f"{float(value):g} lies beyond +-{MAX_CELL_COORDINATE:g} "
                                  "(MAX_CELL_COORDINATE, metres)")
        return float(value)

    def numbers(self, value: Any, key: str, n: int | tuple[int, ...]) -> np.ndarray:
        counts = (n,) if isinstance(n, int) else n
        if not isinstance(value, (list, tuple)):
            raise self.error(key, f"expected {self._count(counts)} numbers, got {_r(value)}")
        if len(value) not in counts:
            raise self.error(key, f"expected {self._count(counts)} numbers, got {len(value)}")
        return np.array([self.number(v, f"{key}[{i}]") for i, v in enumerate(value)])

    @staticmethod
    def _count(counts: tuple[int, ...]) -> str:
        return " or ".join(str(c) for c in counts)

    def point(self, value: Any, key: str) -> np.ndarray:
        p = self.numbers(value, key, 3)
        return zup_from_yup(p) if self.frame == "paper_yup" else p

    def bounds(self, lo_v: Any, hi_v: Any, key: str) -> tuple[np.ndarray, np.ndarray]:
        lo = self.point(lo_v, f"{key}.lo")
        hi = self.point(hi_v, f"{key}.hi")
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        raw_lo, raw_hi = self.numbers(lo_v, f"{key}.lo", 3), self.numbers(hi_v, f"{key}.hi", 3)
        if np.any(raw_hi <= raw_lo):
            raise self.error(key, f"needs lo < hi on every axis, got lo={raw_lo.tolist()}, "
                                  f"hi={raw_hi.tolist()}")
        return lo, hi

    def name(self, value: Any, key: str) -> str:
        if not isinstance(value, str) or not _NAME.match(value):
            raise self.error(key, f"expected a name (letters, digits, _), got {_r(value)}")
        return value

    def color(self, spec: Mapping[str, Any], key: str) -> str | None:
        c = spec.get("color")
        if c is not None and not isinstance(c, str):
            raise self.error(f"{key}.color", f"expected a colour name or #rrggbb, got {_r(c)}")
        return c

    def load_mesh(self, value: Any, key: str, scale: float):
        if not isinstance(value, str) or not value:
            raise self.error(key, f"expected a file path, got {_r(value)}")
        path = Path(value)
        if not path.is_absolute():
            path = self.base_dir / path
        if not path.is_file():
            raise self.error(key, f"mesh file not found: {path}")
        import trimesh
        try:
            mesh = trimesh.load(str(path), force="mesh")
        except Exception as exc:  # trimesh raises many types for corrupt files
            raise self.error(key, f"cannot load mesh {path}: {exc}") from exc
        if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
            raise self.error(key, f"{path} holds no triangles")
        mesh = mesh.copy()
        mesh.apply_scale(scale)
        if self.frame == "paper_yup":
            tf = np.eye(4)
            tf[:3, :3] = ZUP_FROM_YUP
            mesh.apply_transform(tf)
        return mesh

    _SHAPE_KEYS = frozenset({"shape", "position", "size", "yaw", "mesh", "scale"})

    def shape(self, spec: Mapping[str, Any], key: str) -> Shape:
        kind = spec.get("shape", "mesh" if "mesh" in spec else None)
        if kind not in ("box", "cylinder", "sphere", "mesh"):
            raise self.error(f"{key}.shape",
                             f"expected box, cylinder, sphere or mesh, got {_r(kind)}")
        if kind != "mesh" and "position" not in spec:
            raise self.error(key, "missing required key 'position'")
        position = self.point(spec.get("position", [0, 0, 0]), f"{key}.position")
        yaw = self.number(spec.get("yaw", 0.0), f"{key}.yaw")
        if kind == "mesh":
            if "mesh" not in spec:
                raise self.error(key, "shape mesh needs a 'mesh' file")
            for k in ("size",):
                if k in spec:
                    raise self.error(f"{key}.{k}", "not allowed for a mesh (use 'scale')")
            scale = self.number(spec.get("scale", 1.0), f"{key}.scale")
            if scale <= 0:
                raise self.error(f"{key}.scale", f"expected a positive number, got {scale}")
            mesh = self.load_mesh(spec["mesh"], f"{key}.mesh", scale)
            if yaw:
                c, s = np.cos(yaw), np.sin(yaw)
                tf = np.eye(4)
                tf[:2, :2] = [[c, -s], [s, c]]
                mesh.apply_transform(tf)
            return MeshShape(mesh, position)
        for k in ("mesh", "scale"):
            if k in spec:
                raise self.error(f"{key}.{k}", f"only allowed with shape: mesh, not {kind}")
        if "size" not in spec:
            raise self.error(key, f"shape {kind} needs a 'size'")
        skey = f"{key}.size"
        if kind == "box":
            size = self.numbers(spec["size"], skey, 3)
            if self.frame == "paper_yup":
                size = extents_zup_from_yup(size)
            if np.any(size <= 0):
                raise self.error(skey, f"expected positive side lengths, got {size.tolist()}")
            return Box(position, size, yaw)
        if yaw:
            raise self.error(f"{key}.yaw", f"not allowed for a {kind} (it is symmetric)")
        if kind == "cylinder":
            size = self.numbers(spec["size"], skey, 2)
            if np.any(size <= 0):
                raise self.error(skey, f"expected positive [radius, height], got {size.tolist()}")
            return Cylinder(position, size[0], size[1])
        size = self.numbers(spec["size"], skey, 1)
        if size[0] <= 0:
            raise self.error(skey, f"expected a positive [radius], got {size.tolist()}")
        return Sphere(position, size[0])

    def obj(self, name: str, spec: Any) -> SceneObject:
        key = f"objects.{name}"
        spec = self.mapping(spec, key, self._SHAPE_KEYS | {"grasp_points", "movable",
                                                          "sitting_surface", "color",
                                                          "mass", "two_handed"},
                            required=("position",))
        shape = self.shape(spec, key)
        position = self.point(spec["position"], f"{key}.position")
        grasp = spec.get("grasp_points", [[0.0, 0.0, 0.0]])
        if not isinstance(grasp, list) or not grasp:
            raise self.error(f"{key}.grasp_points", f"expected a list of points, got {_r(grasp)}")
        offsets = np.array([self.point(g, f"{key}.grasp_points[{i}]")
                            for i, g in enumerate(grasp)])
        movable = spec.get("movable", True)
        if not isinstance(movable, bool):
            raise self.error(f"{key}.movable", f"expected true or false, got {_r(movable)}")
        sitting = None
        if "sitting_surface" in spec:
            skey = f"{key}.sitting_surface"
            s = self.mapping(spec["sitting_surface"], skey, {"lo", "hi"}, ("lo", "hi"))
            sitting = np.stack(self.bounds(s["lo"], s["hi"], skey))
        mass = self.number(spec.get("mass", 1.0), f"{key}.mass")
        if mass <= 0.0:
            raise self.error(f"{key}.mass", f"expected a positive mass in kg, got {_r(mass)}")
        two_handed = spec.get("two_handed", False)
        if not isinstance(two_handed, bool):
            raise self.error(f"{key}.two_handed", f"expected true or false, got {_r(two_handed)}")
        return SceneObject(name, position, shape, offsets, movable, sitting,
                           self.color(spec, key), mass, two_handed)

    def region(self, name: str, spec: Any) -> Region:
        key = f"regions.{name}"
        spec = self.mapping(spec, key, {"lo", "hi", "mesh", "scale", "position", "color"})
        if "mesh" in spec:
            for k in ("lo", "hi"):
                if k in spec:
                    raise self.error(f"{key}.{k}", "give either lo/hi or mesh, not both")
            scale = self.number(spec.get("scale", 1.0), f"{key}.scale")
            mesh = self.load_mesh(spec["mesh"], f"{key}.mesh", scale)
            position = self.point(spec.get("position", [0, 0, 0]), f"{key}.position")
            return Region(name, MeshShape(mesh, position))
        for k in ("scale", "position"):
            if k in spec:
                raise self.error(f"{key}.{k}", "only allowed for mesh regions")
        if "lo" not in spec or "hi" not in spec:
            raise self.error(key, "a region needs lo and hi (a box) or mesh")
        lo, hi = self.bounds(spec["lo"], spec["hi"], key)
        return Region(name, Box.from_bounds(lo, hi))

    def obstacle(self, name: str, spec: Any) -> Obstacle:
        key = f"obstacles.{name}"
        if isinstance(spec, Mapping) and "parts" in spec:
            spec = self.mapping(spec, key, {"parts", "color"})
            parts = spec["parts"]
            if not isinstance(parts, list) or not parts:
                raise self.error(f"{key}.parts", "expected a non-empty list of shapes")
            shapes = []
            for i, part in enumerate(parts):
                pkey = f"{key}.parts[{i}]"
                shapes.append(self.shape(self.mapping(part, pkey, self._SHAPE_KEYS), pkey))
            return Obstacle(name, tuple(shapes), self.color(spec, key))
        spec = self.mapping(spec, key, self._SHAPE_KEYS | {"color"})
        return Obstacle(name, (self.shape(spec, key),), self.color(spec, key))


_TOP_KEYS = {"name", "description", "frame", "floor_z", "workspace", "start_region",
             "final_region", "objects", "regions", "obstacles", "shorthands"}


def _parse_cell(data: Any, source: str, base_dir: Path, default_name: str) -> Cell:
    pre = _Parser(source, base_dir, "zup")
    data = pre.mapping(data, "", _TOP_KEYS, required=("regions", "start_region"))
    frame = data.get("frame", "zup")
    if frame not in _FRAMES:
        raise pre.error("frame", f"expected zup or paper_yup, got {_r(frame)}")
    p = _Parser(source, base_dir, frame)

    name = data.get("name", default_name)
    if not isinstance(name, str) or not name:
        raise p.error("name", f"expected a non-empty string, got {_r(name)}")
    description = data.get("description", "")
    if not isinstance(description, str):
        raise p.error("description", f"expected a string, got {_r(description)}")
    floor_z = p.number(data.get("floor_z", 0.0), "floor_z")

    ws = p.mapping(data.get("workspace", {"lo": [-5, -5, 0], "hi": [5, 5, 3]}), "workspace",
                   {"lo", "hi"}, ("lo", "hi"))
    ws_lo, ws_hi = p.bounds(ws["lo"], ws["hi"], "workspace")
    if np.any(ws_hi[:2] - ws_lo[:2] > MAX_WORKSPACE_EXTENT):
        raise p.error("workspace", f"spans {(ws_hi - ws_lo)[:2].tolist()} m; at most "
                                   f"{MAX_WORKSPACE_EXTENT:g} m per floor axis are allowed "
                                   "(MAX_WORKSPACE_EXTENT): a cell, not a factory")

    def section(key: str) -> Mapping[str, Any]:
        value = data.get(key) or {}
        if not isinstance(value, Mapping):
            raise p.error(key, f"expected a mapping of name to description, got "
                               f"{type(value).__name__}")
        for k in value:
            p.name(k, f"{key}.{k}")
        return value

    for key in ("objects", "regions", "obstacles"):
        if len(section(key)) > MAX_CELL_ENTRIES[key]:
            raise p.error(key, f"{len(section(key))} entries; at most {MAX_CELL_ENTRIES[key]} "
                               f"are allowed (MAX_CELL_ENTRIES). {_SIMPLIFY[key]}")
    objects = {n: p.obj(n, s) for n, s in section("objects").items()}
    regions = {n: p.region(n, s) for n, s in section("regions").items()}
    obstacles = tuple(p.obstacle(n, s) for n, s in section("obstacles").items())
    clash = sorted(set(objects) & set(regions))
    if clash:
        raise p.error("regions", f"names used for both an object and a region: {clash}")
    for n in list(objects) + list(regions):
        if n in TASK_ARGUMENTS:
            raise p.error(f"objects.{n}" if n in objects else f"regions.{n}",
                          "a task name cannot name an object or a region")

    def region_ref(key: str, required: bool) -> Region | None:
        value = data.get(key)
        if value is None:
            if required:
                raise p.error(key, "missing")
            return None
        if not isinstance(value, str) or value not in regions:
            raise p.error(key, f"unknown region {_r(value)}; expected a region name: "
                               f"{', '.join(regions)}")
        return regions[value]

    start = region_ref("start_region", True)
    final = region_ref("final_region", False)
    inside = (start.lo[:2] >= ws_lo[:2] - 1e-9) & (start.hi[:2] <= ws_hi[:2] + 1e-9)
    if not np.all(inside):
        raise p.error("start_region", f"region {start.name!r} lies outside the workspace")

    shorthands: dict[str, tuple[tuple[str, ...], str]] = {}
    raw = data.get("shorthands") or {}
    if not isinstance(raw, Mapping):
        raise p.error("shorthands", "expected a mapping such as 'assemble(R): leftHand(R) & "
                                    "rightHand(R)'")
    for k, body in raw.items():
        key = f"shorthands.{k}"
        m = _SHORTHAND_KEY.match(str(k))
        if not m:
            raise p.error(key, "expected name(param, ...) as the key")
        sname = m.group(1)
        params = tuple(x.strip() for x in (m.group(2) or "").split(",") if x.strip())
        for x in params:
            if not _NAME.match(x):
                raise p.error(key, f"bad parameter name {_r(x)}")
        if len(set(params)) != len(params):
            raise p.error(key, "parameter names must differ")
        if sname in TASK_ARGUMENTS or sname in shorthands:
            raise p.error(key, f"{_r(sname)} is already a task or shorthand")
        if not isinstance(body, str) or not body.strip():
            raise p.error(key, f"expected the body as a string, got {_r(body)}")
        atoms = _ATOM.findall(body)
        if not atoms:
            raise p.error(key, f"body {_r(body)} contains no task")
        for task, args in atoms:
            if task not in TASK_ARGUMENTS and task not in shorthands:
                raise p.error(key, f"unknown task {_r(task)} in body {_r(body)}")
            for arg in (a.strip() for a in args.split(",") if a.strip()):
                if arg not in params and arg not in objects and arg not in regions:
                    try:
                        float(arg)
                    except ValueError:
                        raise p.error(key, f"{_r(arg)} in body {_r(body)} is neither a parameter "
                                           f"nor an object or region") from None
        shorthands[sname] = (params, body.strip())

    return Cell(name=name, source=source, objects=objects, regions=regions,
                obstacles=obstacles, start_region=start, final_region=final,
                shorthands=shorthands, floor_z=floor_z, workspace_lo=ws_lo,
                workspace_hi=ws_hi, frame=frame, description=description)


def cell_from_yaml(text: str, source: str = "<inline>",
                   base_dir: str | os.PathLike[str] | None = None) -> Cell:
    """Parse a cell from YAML text.

    Parameters
    ----------
    text : str
    source : str
        Name used in error messages (and ``Cell.source``).
    base_dir : path, optional
        Folder that relative mesh paths are resolved against (default: the current one).

    Raises
    ------
    CellError
        Malformed YAML or cell description; the message names ``source`` and the key.
    """
    try:
        data = load_yaml_limited(text)
    except YamlLimitError as exc:
        raise CellError(f"{source}: {exc}") from None
    default_name = Path(source).stem if source != "<inline>" else "cell"
    return _parse_cell(data, source, Path(base_dir) if base_dir is not None else Path.cwd(),
                       default_name)


def load_cell(path: str | os.PathLike[str]) -> Cell:
    """Load a cell from a YAML file; mesh paths are relative to the file."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise CellError(f"{path}: cannot read cell file: {exc.strerror or exc}") from exc
    except UnicodeDecodeError as exc:
        raise CellError(f"{path}: not UTF-8 text (byte 0x{exc.object[exc.start]:02x} at "
                        f"offset {exc.start}); save the cell file as UTF-8") from None
    return cell_from_yaml(text, source=str(path), base_dir=path.parent)


def cell_search_paths() -> list[Path]:
    """Folders searched by :func:`cell_by_name`, in order.

    The source tree's ``config/`` (beside the package), then ``share/ltl_human_motion/
    config`` in any ancestor of the installed package (colcon install space), in
    ``sys.prefix`` and in every ``AMENT_PREFIX_PATH`` entry.
    """
    here = Path(__file__).resolve()
    paths = [here.parents[2] / "config"]
    for parent in here.parents:
        paths.append(parent / "share" / "ltl_human_motion" / "config")
    paths.append(Path(sys.prefix) / "share" / "ltl_human_motion" / "config")
    for prefix in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep):
        if prefix:
            paths.append(Path(prefix) / "share" / "ltl_human_motion" / "config")
    seen: list[Path] = []
    for p in paths:
        if p not in seen:
            seen.append(p)
    return seen


def cell_by_name(name: str) -> Cell:
    """Load the shipped cell ``config/<name>.yaml`` (e.g. ``"paper_cell"``).

    Raises
    ------
    CellError
        No such cell; the message lists the folders searched and the cells found.
    """
    if not isinstance(name, str) or not _NAME.match(name.removesuffix(".yaml")):
        raise CellError(f"cell name must be a plain name such as 'paper_cell', got {_r(name)}")
    stem = name.removesuffix(".yaml")
    found: set[str] = set()
    for folder in cell_search_paths():
        candidate = folder / f"{stem}.yaml"
        if candidate.is_file():
            return load_cell(candidate)
        if folder.is_dir():
            # Other YAML files live there too (bringup parameters, batch specs, robots).
            found.update(p.stem for p in folder.glob("*.yaml")
                         if "start_region:" in p.read_text(encoding="utf-8", errors="replace"))
    raise CellError(f"no cell named {stem!r}; known cells: {', '.join(sorted(found)) or '(none)'}")
