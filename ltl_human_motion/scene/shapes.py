"""Solid shapes of the cell: boxes, vertical cylinders, spheres and triangle meshes.

Every shape answers the same questions, vectorized over points and segments:
``contains``, ``signed_distance``, ``distance``, ``segment_distance`` and
``capsule_clearance``. Primitives are exact (convex point distance minimised along a
segment); meshes use an exact point-triangle distance, a generalized winding number for
containment, and python-fcl for capsule distances.

Boxes and cylinders may turn about the vertical axis only (``yaw``, radians): the cells
of the paper contain upright furniture and parts, and vertical symmetry keeps the floor
footprints of the planner simple.
"""

from __future__ import annotations

import functools
from abc import ABC, abstractmethod
from dataclasses import dataclass, field

import numpy as np

from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.scene.geometry import (
    box_gap,
    min_along_segment,
    point_box_signed_distance,
    point_circle_signed_distance,
    point_cylinder_signed_distance,
    point_polygon_signed_distance,
    point_segment_distance,
    segment_aabb_distance,
)

__all__ = [
    "Box",
    "Cylinder",
    "Footprint",
    "MeshShape",
    "Shape",
    "Sphere",
    "shape_distance",
    "shape_enclosed_in",
    "shapes_intersect",
]


#: Capsule clearances below this (metres) are computed exactly; see
#: :meth:`Shape.capsule_clearance`.
EXACT_BELOW = 0.25


def _vec3(x: np.ndarray, name: str) -> np.ndarray:
    arr = np.asarray(x, dtype=np.float64)
    if arr.shape != (3,):
        raise ValueError(f"{name} must have shape (3,), got {arr.shape}")
    return arr


def _points(points: np.ndarray) -> np.ndarray:
    p = np.asarray(points, dtype=np.float64)
    if p.ndim == 0 or p.shape[-1] != 3:
        raise ValueError(f"points must have shape (..., 3), got {p.shape}")
    return p


def _fcl():
    try:
        import fcl
    except ImportError as exc:  # pragma: no cover - python-fcl is a declared extra
        raise MissingDependencyError(
            "mesh collision checks need python-fcl: pip install python-fcl") from exc
    return fcl


def _fcl_capsule(fcl, a: np.ndarray, b: np.ndarray, radius: float):
    """An fcl capsule object whose axis runs from ``a`` to ``b``."""
    axis = b - a
    length = float(np.linalg.norm(axis))
    z = np.array([0.0, 0.0, 1.0])
    if length < 1e-12:
        rot = np.eye(3)
    else:
        u = axis / length
        v = np.cross(z, u)
        s, c = np.linalg.norm(v), float(np.dot(z, u))
        if s < 1e-12:
            rot = np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
        else:
            k = v / s
            kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
            rot = np.eye(3) + s * kx + (1 - c) * kx @ kx
    geom = fcl.Capsule(max(float(radius), 1e-9), length)
    return fcl.CollisionObject(geom, fcl.Transform(rot, (a + b) / 2.0))


@dataclass(frozen=True)
class Footprint:
    """Floor-plane (xy) footprint of a shape: a convex polygon or a disc.

    Attributes
    ----------
    vertices : ndarray, shape (V, 2) or None
        Counter-clockwise convex polygon.
    center : ndarray, shape (2,) or None
    radius : float
        Disc radius (0 for polygons).
    """

    vertices: np.ndarray | None = None
    center: np.ndarray | None = None
    radius: float = 0.0

    def signed_distance(self, xy: np.ndarray) -> np.ndarray:
        """Signed distance of floor points to the footprint, shape (...) for (..., 2)."""
        xy = np.asarray(xy, dtype=np.float64)
        if xy.ndim == 0 or xy.shape[-1] != 2:
            raise ValueError(f"xy must have shape (..., 2), got {xy.shape}")
        if self.vertices is not None:
            return point_polygon_signed_distance(xy, self.vertices)
        return point_circle_signed_distance(xy, self.center, self.radius)

    def outline(self, n: int = 48) -> np.ndarray:
        """Closed outline for plotting, shape (M, 2)."""
        if self.vertices is not None:
            return np.vstack([self.vertices, self.vertices[:1]])
        t = np.linspace(0.0, 2.0 * np.pi, n + 1)
        return self.center + self.radius * np.stack([np.cos(t), np.sin(t)], axis=-1)


class Shape(ABC):
    """A solid in the world frame (metres, z up)."""

    kind: str = ""

    @property
    @abstractmethod
    def center(self) -> np.ndarray:
        """Reference point, shape (3,) (the centre of primitives)."""

    @abstractmethod
    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance (negative inside), shape (...) for points (..., 3)."""

    @abstractmethod
    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds ``(lo (3,), hi (3,))``."""

    @abstractmethod
    def moved_to(self, center: np.ndarray) -> Shape:
        """The same shape with its reference point at ``center`` (3,)."""

    @abstractmethod
    def vertices(self) -> np.ndarray:
        """Points whose convex hull contains the shape (exact for polytopes), (V, 3)."""

    @abstractmethod
    def to_trimesh(self):
        """A ``trimesh.Trimesh`` of the surface (for rendering and fcl)."""

    @abstractmethod
    def footprint(self) -> Footprint:
        """Floor-plane footprint (projection onto z = 0, convex)."""

    def translated(self, offset: np.ndarray) -> Shape:
        """The shape moved by ``offset`` (3,)."""
        return self.moved_to(self.center + _vec3(offset, "offset"))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Whether points lie in the closed solid, bool array of shape (...)."""
        return self.signed_distance(points) <= 0.0

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Distance from points to the solid (0 inside), shape (...)."""
        return np.maximum(self.signed_distance(points), 0.0)

    def segment_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Distance between segments ``[a, b]`` (..., 3) and the solid (0 if they meet)."""
        return min_along_segment(self.distance, _points(a), _points(b))

    def capsule_clearance(self, segments: np.ndarray, radii: np.ndarray,
                          exact_below: float = EXACT_BELOW) -> np.ndarray:
        """Segment distance minus radius; ``<= 0`` iff the capsule meets the solid.

        Parameters
        ----------
        segments : array-like, shape (..., 2, 3)
        radii : array-like, broadcast against (...)
        exact_below : float
            Clearances below this are exact; capsules whose bounding box is farther
            from the shape's bounding box get that (smaller) box gap instead, a lower
            bound that is at least ``exact_below``.

        Returns
        -------
        clearance : ndarray, shape (...)
        """
        seg = np.asarray(segments, dtype=np.float64)
        if seg.ndim < 2 or seg.shape[-2:] != (2, 3):
            raise ValueError(f"segments must have shape (..., 2, 3), got {seg.shape}")
        radii = np.broadcast_to(np.asarray(radii, dtype=np.float64), seg.shape[:-2])
        lo, hi = self.aabb()
        a, b = seg[..., 0, :], seg[..., 1, :]
        bound = box_gap(np.minimum(a, b), np.maximum(a, b), lo, hi) - radii
        near = bound < exact_below
        if not np.any(near):
            return bound
        out = bound.copy()
        out[near] = self._exact_capsule_clearance(seg[near], radii[near])
        return out

    def _exact_capsule_clearance(self, seg: np.ndarray, radii: np.ndarray) -> np.ndarray:
        """Exact clearance of capsules (N, 2, 3) with radii (N,), shape (N,)."""
        return self.segment_distance(seg[..., 0, :], seg[..., 1, :]) - radii

    def to_fcl(self):
        """An ``fcl.CollisionObject`` for this shape (python-fcl needed)."""
        fcl = _fcl()
        mesh = self.to_trimesh()
        bvh = fcl.BVHModel()
        bvh.beginModel(len(mesh.vertices), len(mesh.faces))
        bvh.addSubModel(np.asarray(mesh.vertices, dtype=np.float64),
                        np.asarray(mesh.faces, dtype=np.int32))
        bvh.endModel()
        return fcl.CollisionObject(bvh, fcl.Transform())

    def extent_in_frame(self, yaw: float, origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of the shape in a frame turned by ``yaw`` about z at ``origin``.

        Returns
        -------
        lo, hi : ndarray, shape (3,)
        """
        local = (self.vertices() - origin) @ matrix_from_yaw(yaw)
        return local.min(axis=0), local.max(axis=0)


@dataclass(frozen=True, eq=False)
class Box(Shape):
    """A box with side lengths ``extents`` centred at ``center``, turned by ``yaw``.

    Attributes
    ----------
    center_ : ndarray, shape (3,)
    extents : ndarray, shape (3,)
        Full side lengths along the box's own x, y, z.
    yaw : float
        Rotation about +z in radians.
    """

    center_: np.ndarray
    extents: np.ndarray
    yaw: float = 0.0
    kind: str = field(default="box", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "center_", _vec3(self.center_, "center"))
        ext = _vec3(self.extents, "extents")
        if np.any(ext <= 0):
            raise ValueError(f"box extents must be positive, got {ext.tolist()}")
        object.__setattr__(self, "extents", ext)
        object.__setattr__(self, "yaw", float(self.yaw))

    @classmethod
    def from_bounds(cls, lo: np.ndarray, hi: np.ndarray) -> Box:
        """Axis-aligned box from corners ``lo`` (3,) and ``hi`` (3,)."""
        lo, hi = _vec3(lo, "lo"), _vec3(hi, "hi")
        if np.any(hi <= lo):
            raise ValueError(f"box needs lo < hi on every axis, got lo={lo.tolist()}, "
                             f"hi={hi.tolist()}")
        return cls((lo + hi) / 2.0, hi - lo)

    @property
    def center(self) -> np.ndarray:
        return self.center_

    @property
    def half(self) -> np.ndarray:
        """Half extents, shape (3,)."""
        return self.extents / 2.0

    @property
    def axis_aligned(self) -> bool:
        return abs(np.sin(self.yaw)) < 1e-12 and np.cos(self.yaw) > 0

    @property
    def rotation(self) -> np.ndarray:
        """Box-to-world rotation, shape (3, 3)."""
        return matrix_from_yaw(self.yaw)

    def to_local(self, points: np.ndarray) -> np.ndarray:
        """World points (..., 3) expressed in the box frame (origin at the centre)."""
        return (_points(points) - self.center_) @ self.rotation

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        return point_box_signed_distance(self.to_local(points), -self.half, self.half)

    def segment_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        from ltl_human_motion.kernel.segments import compiled_module
        la, lb = np.broadcast_arrays(self.to_local(a), self.to_local(b))
        nb = compiled_module("ltl_human_motion.scene._clearance_numba")
        if nb is None or not (np.isfinite(la).all() and np.isfinite(lb).all()):
            return segment_aabb_distance(la, lb, -self.half, self.half)
        # the closed form's numbers, compiled (a box's verification reads every frame)
        flat_a = np.ascontiguousarray(la.reshape(-1, 3))
        flat_b = np.ascontiguousarray(lb.reshape(-1, 3))
        out = np.empty(len(flat_a))
        nb.segment_aabb_distance(flat_a, flat_b, np.repeat(-self.half[None], len(out), 0),
                                 np.repeat(self.half[None], len(out), 0), out)
        return out.reshape(la.shape[:-1])

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        if self.axis_aligned:
            # The corners centre +- half, as min/max of the vertices give them.
            return self.center_ - self.half, self.center_ + self.half
        v = self.vertices()
        return v.min(axis=0), v.max(axis=0)

    def moved_to(self, center: np.ndarray) -> Box:
        return Box(_vec3(center, "center"), self.extents, self.yaw)

    def vertices(self) -> np.ndarray:
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)],
                         dtype=np.float64)
        return self.center_ + (signs * self.half) @ self.rotation.T

    def to_trimesh(self):
        import trimesh
        tf = np.eye(4)
        tf[:3, :3] = self.rotation
        tf[:3, 3] = self.center_
        return trimesh.creation.box(extents=self.extents, transform=tf)

    def footprint(self) -> Footprint:
        corners = self.vertices()[::2, :2]                  # the four z = lo corners
        order = [0, 2, 3, 1]                                # (-,-), (+,-), (+,+), (-,+)
        return Footprint(vertices=corners[order])

    def to_fcl(self):
        fcl = _fcl()
        return fcl.CollisionObject(fcl.Box(*self.extents),
                                   fcl.Transform(self.rotation, self.center_))


@dataclass(frozen=True, eq=False)
class Cylinder(Shape):
    """A solid cylinder with a vertical axis.

    Attributes
    ----------
    center_ : ndarray, shape (3,)
        Centre of the axis.
    radius, height : float
    """

    center_: np.ndarray
    radius: float
    height: float
    kind: str = field(default="cylinder", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "center_", _vec3(self.center_, "center"))
        if not (self.radius > 0 and self.height > 0):
            raise ValueError(f"cylinder radius and height must be positive, got "
                             f"{self.radius!r}, {self.height!r}")
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "height", float(self.height))

    @property
    def center(self) -> np.ndarray:
        return self.center_

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        return point_cylinder_signed_distance(_points(points), self.center_, self.radius,
                                              self.height / 2.0)

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        h = np.array([self.radius, self.radius, self.height / 2.0])
        return self.center_ - h, self.center_ + h

    def moved_to(self, center: np.ndarray) -> Cylinder:
        return Cylinder(_vec3(center, "center"), self.radius, self.height)

    def vertices(self, n: int = 32) -> np.ndarray:
        # Circumscribed polygon (radius / cos(pi/n)) so the hull contains the cylinder.
        t = np.arange(n) * 2.0 * np.pi / n
        r = self.radius / np.cos(np.pi / n)
        ring = np.stack([r * np.cos(t), r * np.sin(t)], axis=-1)
        h = self.height / 2.0
        top = np.column_stack([ring, np.full(n, h)])
        bottom = np.column_stack([ring, np.full(n, -h)])
        return self.center_ + np.vstack([bottom, top])

    def extent_in_frame(self, yaw: float, origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = (self.center_ - origin) @ matrix_from_yaw(yaw)
        h = np.array([self.radius, self.radius, self.height / 2.0])
        return c - h, c + h

    def to_trimesh(self):
        import trimesh
        tf = np.eye(4)
        tf[:3, 3] = self.center_
        return trimesh.creation.cylinder(radius=self.radius, height=self.height,
                                         sections=32, transform=tf)

    def footprint(self) -> Footprint:
        return Footprint(center=self.center_[:2].copy(), radius=self.radius)

    def to_fcl(self):
        fcl = _fcl()
        return fcl.CollisionObject(fcl.Cylinder(self.radius, self.height),
                                   fcl.Transform(self.center_))


@dataclass(frozen=True, eq=False)
class Sphere(Shape):
    """A solid ball.

    Attributes
    ----------
    center_ : ndarray, shape (3,)
    radius : float
    """

    center_: np.ndarray
    radius: float
    kind: str = field(default="sphere", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "center_", _vec3(self.center_, "center"))
        if not self.radius > 0:
            raise ValueError(f"sphere radius must be positive, got {self.radius!r}")
        object.__setattr__(self, "radius", float(self.radius))

    @property
    def center(self) -> np.ndarray:
        return self.center_

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        return np.linalg.norm(_points(points) - self.center_, axis=-1) - self.radius

    def segment_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        d = point_segment_distance(self.center_, _points(a), _points(b))
        return np.maximum(d - self.radius, 0.0)

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        return self.center_ - self.radius, self.center_ + self.radius

    def moved_to(self, center: np.ndarray) -> Sphere:
        return Sphere(_vec3(center, "center"), self.radius)

    def vertices(self) -> np.ndarray:
        return self.to_trimesh().vertices * 1.0

    def extent_in_frame(self, yaw: float, origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        c = (self.center_ - origin) @ matrix_from_yaw(yaw)
        return c - self.radius, c + self.radius

    def to_trimesh(self):
        import trimesh
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=self.radius)
        # Scale so the polyhedron circumscribes the ball (face planes at >= radius).
        normals = mesh.face_normals
        inner = np.min(np.abs(np.sum(mesh.triangles[:, 0] * normals, axis=-1)))
        mesh.apply_scale(self.radius / inner)
        mesh.apply_translation(self.center_)
        return mesh

    def footprint(self) -> Footprint:
        return Footprint(center=self.center_[:2].copy(), radius=self.radius)

    def to_fcl(self):
        fcl = _fcl()
        return fcl.CollisionObject(fcl.Sphere(self.radius), fcl.Transform(self.center_))


def _point_triangle_distance(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Distance from points (N, 3) to triangles (F, 3, 3), shape (N, F)."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]                     # (F, 3)
    n = np.cross(b - a, c - a)
    nn = np.maximum(np.sum(n * n, axis=-1), 1e-300)
    q = p[:, None, :]                                              # (N, 1, 3)
    plane = np.sum((q - a) * n, axis=-1) / nn                      # (N, F)
    proj = q - plane[..., None] * n
    # Barycentric inside test via edge cross products.
    inside = np.ones(plane.shape, dtype=bool)
    for u, v in ((a, b), (b, c), (c, a)):
        inside &= np.sum(np.cross(v - u, proj - u) * n, axis=-1) >= 0.0
    d_plane = np.abs(plane) * np.sqrt(nn)
    d_edge = np.minimum(np.minimum(point_segment_distance(q, a, b),
                                   point_segment_distance(q, b, c)),
                        point_segment_distance(q, c, a))
    return np.where(inside, d_plane, d_edge)


def _winding_number(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Generalized winding number of closed triangle meshes at points (N, 3), shape (N,)."""
    A = tri[None, :, 0] - p[:, None]
    B = tri[None, :, 1] - p[:, None]
    C = tri[None, :, 2] - p[:, None]
    la, lb, lc = (np.linalg.norm(X, axis=-1) for X in (A, B, C))
    det = np.sum(A * np.cross(B, C), axis=-1)
    den = (la * lb * lc + np.sum(A * B, axis=-1) * lc + np.sum(B * C, axis=-1) * la
           + np.sum(C * A, axis=-1) * lb)
    return np.sum(2.0 * np.arctan2(det, den), axis=-1) / (4.0 * np.pi)


@dataclass(frozen=True, eq=False)
class MeshShape(Shape):
    """A closed triangle mesh, stored relative to ``center_``.

    Attributes
    ----------
    mesh : trimesh.Trimesh
        Surface in local coordinates (world = local + center_).
    center_ : ndarray, shape (3,)
    """

    mesh: object
    center_: np.ndarray = field(default_factory=lambda: np.zeros(3))
    kind: str = field(default="mesh", init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "center_", _vec3(self.center_, "center"))
        if len(getattr(self.mesh, "faces", ())) == 0:
            raise ValueError("mesh has no faces")

    @property
    def center(self) -> np.ndarray:
        return self.center_

    @property
    def triangles(self) -> np.ndarray:
        """World triangles, shape (F, 3, 3)."""
        return np.asarray(self.mesh.triangles, dtype=np.float64) + self.center_

    def _chunks(self, p: np.ndarray, fn) -> np.ndarray:
        flat = p.reshape(-1, 3)
        tri = self.triangles
        step = max(1, 2_000_000 // max(len(tri), 1))
        out = [fn(flat[i:i + step], tri) for i in range(0, len(flat), step)]
        return (np.concatenate(out) if out else np.zeros(0)).reshape(p.shape[:-1])

    def contains(self, points: np.ndarray) -> np.ndarray:
        p = _points(points)
        return self._chunks(p, lambda q, t: _winding_number(q, t) > 0.5)

    def signed_distance(self, points: np.ndarray) -> np.ndarray:
        p = _points(points)
        d = self._chunks(p, lambda q, t: _point_triangle_distance(q, t).min(axis=1))
        return np.where(self.contains(p), -d, d)

    def _exact_capsule_clearance(self, seg: np.ndarray, radii: np.ndarray) -> np.ndarray:
        fcl = _fcl()
        mesh_obj = self._fcl_object
        flat = seg.reshape(-1, 2, 3)
        r = radii.reshape(-1)
        out = np.empty(len(flat))
        for i, (s, rad) in enumerate(zip(flat, r)):
            cap = _fcl_capsule(fcl, s[0], s[1], rad)
            d = fcl.distance(mesh_obj, cap, fcl.DistanceRequest(), fcl.DistanceResult())
            out[i] = d if d >= 0 else -1e-6
        # A capsule wholly inside the closed surface does not touch a triangle.
        inside = self.contains(flat[:, 0])
        out = np.where(inside, np.minimum(out, -1e-6), out)
        return out.reshape(seg.shape[:-2])

    def segment_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        a, b = np.broadcast_arrays(_points(a), _points(b))
        flat = np.stack([a, b], axis=-2).reshape(-1, 2, 3)
        d = self._exact_capsule_clearance(flat, np.zeros(len(flat)))
        return np.maximum(d, 0.0).reshape(a.shape[:-1])

    @functools.cached_property
    def _fcl_object(self):
        return self.to_fcl()

    def __getstate__(self) -> dict:
        state = self.__dict__.copy()
        state.pop("_fcl_object", None)          # fcl objects cannot be pickled
        return state

    def aabb(self) -> tuple[np.ndarray, np.ndarray]:
        b = np.asarray(self.mesh.bounds, dtype=np.float64)
        return b[0] + self.center_, b[1] + self.center_

    def moved_to(self, center: np.ndarray) -> MeshShape:
        return MeshShape(self.mesh, _vec3(center, "center"))

    def vertices(self) -> np.ndarray:
        return np.asarray(self.mesh.vertices, dtype=np.float64) + self.center_

    def to_trimesh(self):
        m = self.mesh.copy()
        m.apply_translation(self.center_)
        return m

    def footprint(self) -> Footprint:
        from scipy.spatial import ConvexHull
        xy = self.vertices()[:, :2]
        hull = ConvexHull(xy)
        return Footprint(vertices=xy[hull.vertices])


def shape_distance(a: Shape, b: Shape) -> float:
    """Distance between two solids (0 when they touch or overlap)."""
    if isinstance(a, Box) and isinstance(b, Box) and a.axis_aligned and b.axis_aligned:
        alo, ahi = a.aabb()
        blo, bhi = b.aabb()
        gap = np.maximum(np.maximum(alo - bhi, blo - ahi), 0.0)
        return float(np.linalg.norm(gap))
    if isinstance(a, Sphere) and isinstance(b, Sphere):
        return max(float(np.linalg.norm(a.center - b.center)) - a.radius - b.radius, 0.0)
    if isinstance(b, Sphere):
        a, b = b, a
    if isinstance(a, Sphere):
        return max(float(b.distance(a.center)) - a.radius, 0.0)
    # One solid wholly inside a closed mesh does not touch its surface: test containment.
    if bool(np.any(b.contains(a.vertices()[:1]))) or bool(np.any(a.contains(b.vertices()[:1]))):
        return 0.0
    fcl = _fcl()
    d = fcl.distance(a.to_fcl(), b.to_fcl(), fcl.DistanceRequest(), fcl.DistanceResult())
    return max(float(d), 0.0)


def shapes_intersect(a: Shape, b: Shape, margin: float = 0.0) -> bool:
    """Whether ``a`` meets ``b`` enlarged by a ball of radius ``margin``: a ∩ (b ⊕ B(margin))."""
    return shape_distance(a, b) <= margin


def shape_enclosed_in(inner: Shape, outer: Shape, tol: float = 1e-9) -> bool:
    """Whether ``inner`` ⊆ ``outer``.

    Exact for boxes, cylinders and spheres inside boxes, cylinders and spheres; for a
    mesh ``outer`` every vertex of ``inner`` (curved shapes: a circumscribing
    tessellation) must lie inside, which is exact when ``outer`` is convex.
    """
    if isinstance(outer, Box):
        lo, hi = inner.extent_in_frame(outer.yaw, outer.center)
        return bool(np.all(lo >= -outer.half - tol) and np.all(hi <= outer.half + tol))
    if isinstance(outer, Cylinder):
        dz_lo, dz_hi = inner.aabb()[0][2], inner.aabb()[1][2]
        h = outer.height / 2.0
        if dz_lo < outer.center[2] - h - tol or dz_hi > outer.center[2] + h + tol:
            return False
        if isinstance(inner, (Cylinder, Sphere)):
            radial = np.linalg.norm(inner.center[:2] - outer.center[:2]) + inner.radius
        else:
            radial = np.max(np.linalg.norm(inner.vertices()[:, :2] - outer.center[:2], axis=-1))
        return bool(radial <= outer.radius + tol)
    if isinstance(outer, Sphere):
        d = inner.center - outer.center
        if isinstance(inner, Sphere):
            far = np.linalg.norm(d) + inner.radius
        elif isinstance(inner, Cylinder):
            h = inner.height / 2.0
            far = np.hypot(np.linalg.norm(d[:2]) + inner.radius, max(abs(d[2] - h), abs(d[2] + h)))
        else:
            far = np.max(np.linalg.norm(inner.vertices() - outer.center, axis=-1))
        return bool(far <= outer.radius + tol)
    return bool(np.all(outer.contains(inner.vertices())))
