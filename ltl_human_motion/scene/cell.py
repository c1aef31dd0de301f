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

This module holds the data model (:class:`Cell`, :class:`Region`, :class:`SceneObject`,
:class:`Obstacle`); the YAML loader, with its named limits, is
:mod:`ltl_human_motion.scene.cell_yaml` (:func:`load_cell`, :func:`cell_from_yaml`,
:func:`cell_by_name`, :func:`cell_search_paths`), which imports this module.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ltl_human_motion.scene.clearance import EXACT_BELOW, PartSet, part_set
from ltl_human_motion.scene.geometry import min_along_segment
from ltl_human_motion.scene.shapes import Box, Footprint, Shape

__all__ = ["Cell", "Obstacle", "Region", "SceneObject"]


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
    inputs : dict of str to str
        The cell's own Boolean input propositions (robot or cell events a reactive
        specification reads, docs/reactive.md) and their ``std_msgs/Bool`` topics.
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
    inputs: dict[str, str] = field(default_factory=dict)

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

    def floor_at_zero(self) -> Cell:
        """This cell moved down by ``floor_z``, so that its floor is at z = 0.

        The planner and the motion model work on a floor at z = 0; a cell on a platform
        or in a pit is planned in this frame and its motion lifted back by ``floor_z``
        (one conversion, at the edge). Returns the cell itself when ``floor_z`` is 0.
        """
        if self.floor_z == 0.0:
            return self
        down = np.array([0.0, 0.0, -float(self.floor_z)])
        regions = {n: replace(r, shape=r.shape.translated(down))
                   for n, r in self.regions.items()}
        objects = {n: replace(o, position=o.position + down, shape=o.shape.translated(down))
                   for n, o in self.objects.items()}
        obstacles = tuple(replace(ob, parts=tuple(p.translated(down) for p in ob.parts))
                          for ob in self.obstacles)
        final = None if self.final_region is None else regions[self.final_region.name]
        return replace(self, objects=objects, regions=regions, obstacles=obstacles,
                       start_region=regions[self.start_region.name], final_region=final,
                       floor_z=0.0, workspace_lo=self.workspace_lo + down,
                       workspace_hi=self.workspace_hi + down)

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
