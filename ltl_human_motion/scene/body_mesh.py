"""A shaded body for display: a triangle mesh built from the occupancy capsules.

Every capsule of :data:`~ltl_human_motion.motion.capsules.BODY_CAPSULES` (sized by
stature, as the occupancy is) becomes a smooth capsule: a trimesh UV sphere whose lower
half is placed at one joint and upper half at the other, so the band between them is
the capsule's cylinder. The palms and knee spheres duplicate other parts and are left
out. Parts are coloured as clothing (shirt, trousers, shoes) and skin (head, hands).

The same mesh serves the matplotlib figures and animations (:mod:`ltl_human_motion.viz`)
and the RViz markers (a ``TRIANGLE_LIST`` of :func:`body_mesh` per frame); it imports no
plotting or ROS module.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ltl_human_motion.motion.capsules import BODY_CAPSULES, capsule_radii
from ltl_human_motion.motion.skeleton import DEFAULT_STATURE, JOINT_INDEX, N_JOINTS

__all__ = ["BODY_COLORS", "BODY_DISPLAY_SCALE", "body_mesh", "body_part_names"]

#: Colours (RGB, 0-1) of the parts: skin, a work shirt, trousers and safety shoes.
BODY_COLORS: dict[str, tuple[float, float, float]] = {
    "skin": (0.87, 0.70, 0.58), "shirt": (0.20, 0.42, 0.70), "trousers": (0.22, 0.24, 0.30),
    "shoes": (0.10, 0.10, 0.10),
}
_SKIN = ("head", "l_hand", "r_hand")
_SHIRT = ("abdomen", "torso", "l_clavicle", "r_clavicle", "l_upper_arm", "r_upper_arm",
          "l_lower_arm", "r_lower_arm")
_SHOES = ("l_foot", "r_foot")
_SKIPPED = ("l_palm", "r_palm", "l_knee", "r_knee")
#: Display radius / occupancy radius: the occupancy adds about 1 cm for clothing and
#: margin (:mod:`~ltl_human_motion.scene.occupancy`), the picture shows the body.
BODY_DISPLAY_SCALE = 0.9


def body_part_names() -> tuple[str, ...]:
    """The parts drawn, in mesh order."""
    return tuple(c[0] for c in BODY_CAPSULES if c[0] not in _SKIPPED)


def _group(part: str) -> str:
    if part in _SKIN:
        return "skin"
    if part in _SHIRT:
        return "shirt"
    if part in _SHOES:
        return "shoes"
    return "trousers"


@lru_cache(maxsize=8)
def _template(count: tuple[int, int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit sphere vertices (V, 3), faces (F, 3) and the upper-half mask (V,)."""
    import trimesh
    sphere = trimesh.creation.uv_sphere(radius=1.0, count=list(count))
    v = np.asarray(sphere.vertices, dtype=np.float64)
    f = np.asarray(sphere.faces, dtype=np.int64)
    upper = v[:, 2] > 0.0
    for arr in (v, f, upper):
        arr.flags.writeable = False
    return v, f, upper


def body_mesh(positions: np.ndarray, stature: float = DEFAULT_STATURE,
              detail: tuple[int, int] = (8, 12)
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Triangles of the body in one pose.

    Parameters
    ----------
    positions : array-like, shape (J, 3)
        Joint positions of the canonical skeleton.
    stature : float
        Body height (m); the radii scale with it.
    detail : (int, int)
        Latitude and longitude counts of each capsule's sphere template.

    Returns
    -------
    vertices : ndarray, shape (P * V, 3)
    faces : ndarray of int, shape (P * F, 3)
    colors : ndarray, shape (P * F, 3)
        RGB of every face (by part: skin, shirt, trousers, shoes).
    """
    p = np.asarray(positions, dtype=np.float64)
    if p.shape != (N_JOINTS, 3):
        raise ValueError(f"positions must have shape ({N_JOINTS}, 3), got {p.shape}")
    tv, tf, upper = _template(tuple(int(c) for c in detail))
    radii = capsule_radii(stature) * BODY_DISPLAY_SCALE
    verts, faces, colors = [], [], []
    for k, (part, ja, jb, _) in enumerate(BODY_CAPSULES):
        if part in _SKIPPED:
            continue
        a, b = p[JOINT_INDEX[ja]], p[JOINT_INDEX[jb]]
        axis = b - a
        length = float(np.linalg.norm(axis))
        w = axis / length if length > 1e-9 else np.array([0.0, 0.0, 1.0])
        helper = np.array([1.0, 0.0, 0.0]) if abs(w[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        u = np.cross(w, helper)
        u /= np.linalg.norm(u)
        rot = np.stack([u, np.cross(w, u), w], axis=1)                 # template z -> w
        pts = radii[k] * tv @ rot.T
        pts += np.where(upper[:, None], b, a)
        faces.append(tf + sum(len(x) for x in verts))
        verts.append(pts)
        colors.append(np.tile(BODY_COLORS[_group(part)], (len(tf), 1)))
    return np.concatenate(verts), np.concatenate(faces), np.concatenate(colors)
