"""The scene: work cells (YAML), frames, body occupancy, predicates, Table I conditions.

Core module: no ROS. Everything is z up (REP 103); cells written in the paper's y-up
frame are converted once when loaded (:func:`zup_from_yup`).
"""

from ltl_human_motion.motion.capsules import (
    BODY_CAPSULES,
    BODY_PARTS,
    PART_ALIASES,
    capsule_radii,
    part_indices,
)
from ltl_human_motion.scene.cell import Cell, Obstacle, Region, SceneObject
from ltl_human_motion.scene.cell_yaml import (
    cell_by_name,
    cell_from_yaml,
    cell_search_paths,
    load_cell,
)
from ltl_human_motion.scene.frames import (
    ZUP_FROM_YUP,
    extents_zup_from_yup,
    yup_from_zup,
    zup_from_yup,
)
from ltl_human_motion.scene.geometry import (
    capsule_capsule_distance,
    point_box_distance,
    point_segment_distance,
    segment_box_distance,
    segment_segment_distance,
)
from ltl_human_motion.scene.occupancy import (
    body_radius_xy,
    capsules_from_positions,
    occ,
)
from ltl_human_motion.scene.predicates import (
    body_clearance,
    collision,
    distance_to,
    enclose,
    enclose_object,
    enter,
    enter_object,
    ground_enter,
    object_clearance,
    object_collides,
)
from ltl_human_motion.scene.shapes import (
    Box,
    Cylinder,
    Footprint,
    MeshShape,
    Shape,
    Sphere,
    shape_distance,
    shape_enclosed_in,
    shapes_intersect,
)
from ltl_human_motion.scene.termination import (
    DEFAULT_EPS,
    chest_height,
    expand_task,
    knee_height,
    parse_task,
    termination_holds,
    termination_series,
)
from ltl_human_motion.vocabulary import TASK_ARGUMENTS, TASK_NAMES

__all__ = [
    "BODY_CAPSULES",
    "BODY_PARTS",
    "DEFAULT_EPS",
    "PART_ALIASES",
    "TASK_ARGUMENTS",
    "TASK_NAMES",
    "ZUP_FROM_YUP",
    "Box",
    "Cell",
    "Cylinder",
    "Footprint",
    "MeshShape",
    "Obstacle",
    "Region",
    "SceneObject",
    "Shape",
    "Sphere",
    "body_clearance",
    "body_radius_xy",
    "capsule_capsule_distance",
    "capsule_radii",
    "capsules_from_positions",
    "cell_by_name",
    "cell_from_yaml",
    "cell_search_paths",
    "chest_height",
    "collision",
    "distance_to",
    "enclose",
    "enclose_object",
    "enter",
    "enter_object",
    "expand_task",
    "extents_zup_from_yup",
    "ground_enter",
    "knee_height",
    "load_cell",
    "object_clearance",
    "object_collides",
    "occ",
    "parse_task",
    "part_indices",
    "point_box_distance",
    "point_segment_distance",
    "segment_box_distance",
    "segment_segment_distance",
    "shape_distance",
    "shape_enclosed_in",
    "shapes_intersect",
    "termination_holds",
    "termination_series",
    "yup_from_zup",
    "zup_from_yup",
]
