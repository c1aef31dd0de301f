"""Conversions between the core's numpy arrays and ROS messages (TF, capsules, markers).

Skeleton TF frames (see also ``docs/ros.md``):

* ``<world>`` -> ``human_<id>/pelvis``: the pelvis position, rotated by the body heading
  (yaw about +z; x forward, y left, z up).
* ``human_<id>/<parent>`` -> ``human_<id>/<joint>`` for every other joint, following
  ``motion.skeleton.PARENTS``: the bone vector, with the **identity** rotation. So every
  joint frame has the heading orientation of the pelvis frame (x forward, y to the
  worker's left, z up), and a joint's position in any ancestor frame is the sum of the
  bone vectors in between. Joint frames are not bone-aligned: the canonical skeleton
  stores positions, not joint rotations, so any bone alignment would be an arbitrary
  choice of twist.
"""

from __future__ import annotations

from collections.abc import Sequence
from functools import lru_cache
from typing import Any

import numpy as np
from builtin_interfaces.msg import Duration, Time
from geometry_msgs.msg import Point, Quaternion, TransformStamped
from scipy.spatial.transform import Rotation
from std_msgs.msg import ColorRGBA
from visualization_msgs.msg import Marker

from ltl_human_motion.kernel import rotations
from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.motion.skeleton import JOINT_NAMES, PARENTS
from ltl_human_motion.msg import Capsule
from ltl_human_motion.scene.cell import Cell, Obstacle
from ltl_human_motion.scene.shapes import Shape

_Z = np.array([0.0, 0.0, 1.0])


def human_prefix(human_id: str) -> str:
    """The TF prefix of one human, ``human_<id>``."""
    return f"human_{human_id}"


def joint_frame(human_id: str, joint: str) -> str:
    """The TF frame of one joint, e.g. ``human_1/r_hand``."""
    return f"{human_prefix(human_id)}/{joint}"


def quaternion_from_yaw(yaw: float) -> Quaternion:
    """Rotation about +z as a Quaternion message."""
    w, x, y, z = (float(v) for v in rotations.quaternion_from_yaw(yaw))
    return Quaternion(x=x, y=y, z=z, w=w)


def quaternion_z_to(vector: np.ndarray) -> Quaternion:
    """The shortest rotation taking +z onto ``vector`` (3,) (a cylinder's axis)."""
    v = np.asarray(vector, dtype=np.float64)
    if np.linalg.norm(v) < 1e-12:
        return Quaternion(w=1.0)
    x, y, z, w = (float(c) for c in Rotation.align_vectors(v[None], _Z[None])[0].as_quat())
    return Quaternion(x=x, y=y, z=z, w=w)


def point(xyz: Sequence[float] | np.ndarray) -> Point:
    """A geometry_msgs Point from three numbers."""
    return Point(x=float(xyz[0]), y=float(xyz[1]), z=float(xyz[2]))


def color(r: float, g: float, b: float, a: float = 1.0) -> ColorRGBA:
    """A ColorRGBA message."""
    return ColorRGBA(r=float(r), g=float(g), b=float(b), a=float(a))


def skeleton_transforms(positions: np.ndarray, yaw: float, human_id: str, world_frame: str,
                        stamp: Time) -> list[TransformStamped]:
    """TF transforms of one pose: world -> pelvis, then parent -> joint for every joint.

    Parameters
    ----------
    positions : ndarray, shape (J, 3)
        World joint positions of the canonical skeleton.
    yaw : float
        Body heading (radians about +z).
    """
    positions = np.asarray(positions, dtype=np.float64)
    if positions.shape != (len(JOINT_NAMES), 3):
        raise ValueError(f"positions must have shape ({len(JOINT_NAMES)}, 3), got "
                         f"{positions.shape}")
    parents = np.array(PARENTS)
    bones = positions[1:] - positions[parents[1:]]                    # world axes
    local = bones @ matrix_from_yaw(yaw)                              # R(yaw)^T @ bone
    out = []
    root = TransformStamped()
    root.header.stamp = stamp
    root.header.frame_id = world_frame
    root.child_frame_id = joint_frame(human_id, JOINT_NAMES[0])
    t = root.transform.translation
    t.x, t.y, t.z = (float(v) for v in positions[0])
    root.transform.rotation = quaternion_from_yaw(yaw)
    out.append(root)
    for j in range(1, len(JOINT_NAMES)):
        tf = TransformStamped()
        tf.header.stamp = stamp
        tf.header.frame_id = joint_frame(human_id, JOINT_NAMES[parents[j]])
        tf.child_frame_id = joint_frame(human_id, JOINT_NAMES[j])
        t = tf.transform.translation
        t.x, t.y, t.z = (float(v) for v in local[j - 1])
        tf.transform.rotation.w = 1.0
        out.append(tf)
    return out


def body_capsules(positions: np.ndarray, stature: float) -> tuple[np.ndarray, np.ndarray,
                                                                  list[str]]:
    """Capsules of the body: segments (..., K, 2, 3), radii (K,), part names (K,).

    Thin adapter over ``scene.occupancy.capsules_from_positions`` and ``BODY_CAPSULES``.
    """
    segments, radii = _occupancy_module().capsules_from_positions(positions, stature=stature)
    return (np.asarray(segments, dtype=np.float64), np.asarray(radii, dtype=np.float64),
            capsule_part_names())


def capsule_part_names() -> list[str]:
    """Part names (K,) of the body capsules, in ``BODY_CAPSULES`` order."""
    from ltl_human_motion.motion.capsules import BODY_PARTS

    return list(BODY_PARTS)


@lru_cache(maxsize=1)
def _occupancy_module() -> Any:
    from ltl_human_motion.scene import occupancy

    return occupancy


def capsule_messages(segments: np.ndarray, radii: np.ndarray) -> list[Capsule]:
    """Capsule messages from segments (K, 2, 3) and radii (K,)."""
    return [Capsule(a=point(seg[0]), b=point(seg[1]), radius=float(r))
            for seg, r in zip(segments, radii)]


class MarkerFactory:
    """Builds markers that share a frame, a stamp and a lifetime."""

    def __init__(self, frame_id: str, stamp: Time, lifetime: float = 0.0) -> None:
        self.frame_id = frame_id
        self.stamp = stamp
        sec = int(lifetime)
        self.lifetime = Duration(sec=sec, nanosec=int((lifetime - sec) * 1e9))

    def make(self, ns: str, marker_id: int, kind: int, rgba: ColorRGBA,
             scale: Sequence[float] = (1.0, 1.0, 1.0)) -> Marker:
        m = Marker()
        m.header.frame_id = self.frame_id
        m.header.stamp = self.stamp
        m.ns, m.id, m.type, m.action = ns, int(marker_id), int(kind), Marker.ADD
        m.pose.orientation.w = 1.0
        m.scale.x, m.scale.y, m.scale.z = (float(v) for v in scale)
        m.color = rgba
        m.lifetime = self.lifetime
        return m

    def line_list(self, ns: str, marker_id: int, pairs: np.ndarray, rgba: ColorRGBA,
                  width: float) -> Marker:
        """LINE_LIST through point pairs, shape (N, 2, 3)."""
        m = self.make(ns, marker_id, Marker.LINE_LIST, rgba, (width, 0.0, 0.0))
        m.points = [point(p) for p in np.asarray(pairs).reshape(-1, 3)]
        return m

    def sphere_list(self, ns: str, marker_id: int, centres: np.ndarray, rgba: ColorRGBA,
                    diameter: float) -> Marker:
        m = self.make(ns, marker_id, Marker.SPHERE_LIST, rgba, (diameter,) * 3)
        m.points = [point(p) for p in np.asarray(centres).reshape(-1, 3)]
        return m

    def capsules(self, ns: str, segments: np.ndarray, radii: np.ndarray,
                 rgba: ColorRGBA) -> list[Marker]:
        """Capsules as one CYLINDER each (ids 0..K-1) plus one SPHERE_LIST of end caps per
        distinct radius (ids K, K+1, ...): few markers, so cheap to build and draw."""
        segments, radii = np.asarray(segments), np.asarray(radii)
        out = []
        for k, (seg, r) in enumerate(zip(segments, radii)):
            axis = seg[1] - seg[0]
            length = float(np.linalg.norm(axis))
            if length < 1e-4:          # a sphere (e.g. a knee): only the end cap shows
                length = 1e-4
            cyl = self.make(ns, k, Marker.CYLINDER, rgba, (2 * r, 2 * r, length))
            cyl.pose.position = point((seg[0] + seg[1]) / 2)
            cyl.pose.orientation = quaternion_z_to(axis)
            out.append(cyl)
        keys = np.round(radii, 6)
        for g, r in enumerate(np.unique(keys)):
            caps = segments[keys == r].reshape(-1, 3)
            out.append(self.sphere_list(ns, len(radii) + g, caps, rgba, 2 * float(r)))
        return out

    def cube(self, ns: str, marker_id: int, centre: np.ndarray, size: np.ndarray,
             rgba: ColorRGBA) -> Marker:
        m = self.make(ns, marker_id, Marker.CUBE, rgba, np.maximum(np.asarray(size), 1e-3))
        m.pose.position = point(centre)
        return m

    def text(self, ns: str, marker_id: int, position: np.ndarray, text: str, height: float,
             rgba: ColorRGBA) -> Marker:
        m = self.make(ns, marker_id, Marker.TEXT_VIEW_FACING, rgba, (0.0, 0.0, height))
        m.pose.position = point(position)
        m.text = text
        return m

    def triangles(self, ns: str, marker_id: int, vertices: np.ndarray, faces: np.ndarray,
                  rgba: ColorRGBA) -> Marker:
        """TRIANGLE_LIST of a mesh (vertices (V, 3), faces (F, 3))."""
        m = self.make(ns, marker_id, Marker.TRIANGLE_LIST, rgba)
        tri = np.asarray(vertices, dtype=np.float64)[np.asarray(faces, dtype=np.int64)]
        m.points = [point(p) for p in tri.reshape(-1, 3)]
        return m


def delete_markers(keys: Sequence[tuple[str, int]], frame_id: str, stamp: Time) -> list[Marker]:
    """DELETE markers for (ns, id) pairs."""
    out = []
    for ns, marker_id in keys:
        m = Marker()
        m.header.frame_id, m.header.stamp = frame_id, stamp
        m.ns, m.id, m.action = ns, int(marker_id), Marker.DELETE
        out.append(m)
    return out


def object_size(cell: Cell | None, name: str, default: float = 0.08) -> np.ndarray:
    """Bounding-box size (3,) of a cell object for its marker (a small cube if unknown)."""
    obj = cell.objects.get(name) if cell is not None else None
    if obj is None:
        return np.full(3, default)
    lo, hi = obj.shape.aabb()
    size = np.asarray(hi, dtype=np.float64) - np.asarray(lo, dtype=np.float64)
    if size.shape != (3,) or not np.all(np.isfinite(size)) or np.any(size <= 0):
        return np.full(3, default)
    return size


def _mesh_of(thing: Shape | Obstacle) -> Any:
    """A trimesh of a region's shape or of an obstacle, or None when none can be made."""
    try:
        return thing.to_trimesh()
    except (ImportError, NotImplementedError, ValueError):
        return None


def cell_markers(cell: Cell, factory: MarkerFactory) -> list[Marker]:
    """Markers of a cell: regions as translucent CUBEs (meshes for non-box regions) with
    a label, obstacles as TRIANGLE_LISTs of their trimesh meshes (their bounding CUBE
    when no mesh can be made)."""
    out: list[Marker] = []
    region_rgba, label_rgba = color(0.1, 0.8, 0.2, 0.25), color(1.0, 1.0, 1.0, 0.9)
    for k, (name, region) in enumerate(sorted(cell.regions.items())):
        lo = np.asarray(region.lo, dtype=np.float64)
        hi = np.asarray(region.hi, dtype=np.float64)
        mesh = None if region.is_box else _mesh_of(region.shape)
        if mesh is not None:
            out.append(factory.triangles("cell/regions", k, mesh.vertices, mesh.faces,
                                         region_rgba))
        else:
            out.append(factory.cube("cell/regions", k, (lo + hi) / 2, hi - lo, region_rgba))
        top = np.array([(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2] + 0.1])
        out.append(factory.text("cell/region_labels", k, top, str(name), 0.12, label_rgba))
    obstacle_rgba = color(0.55, 0.45, 0.35, 0.9)
    for k, obstacle in enumerate(cell.obstacles):
        mesh = _mesh_of(obstacle)
        if mesh is not None and len(mesh.faces) > 0:
            out.append(factory.triangles("cell/obstacles", k, mesh.vertices, mesh.faces,
                                         obstacle_rgba))
        else:
            lo, hi = (np.asarray(v, dtype=np.float64) for v in obstacle.aabb())
            out.append(factory.cube("cell/obstacles", k, (lo + hi) / 2, hi - lo, obstacle_rgba))
    return out
