"""Motion data, retargeting, gait and goal primitives, the motion automaton and library.

Core package: never imports ROS. Loaders (one module per format, each ``load(path, ...)``
returning a :class:`Motion` retargeted onto the canonical skeleton): :mod:`.bvh`,
:mod:`.asfamc`, :mod:`.deepmimic`, :mod:`.npz`.
"""

from ltl_human_motion.motion.automaton import (
    DEFAULT_DELTA,
    DEFAULT_K_COMP,
    MotionAutomaton,
    align_windows,
    build_transitions,
    pair_distance,
    transition_distances,
    window_positions,
)
from ltl_human_motion.motion.gait import (
    LIBRARY_FPS,
    OVERLAP,
    PRIMITIVE_FRAMES,
    carry_poses,
    standing_pose,
)
from ltl_human_motion.motion.goals import (
    GOAL_TASKS,
    HAND_TASKS,
    chest_height,
    knee_height,
    make_goal_primitive,
    max_reach,
    min_reach_height,
    reach_placement,
    seat_height_range,
)
from ltl_human_motion.motion.ik import center_of_mass, min_jerk, two_bone_ik
from ltl_human_motion.motion.library import (
    DEFAULT_LIBRARY_DELTA,
    MotionLibrary,
    build_library,
    cache_dir,
    load_library,
    load_motion,
)
from ltl_human_motion.motion.ops import compose, decompose
from ltl_human_motion.motion.quality import QualityThresholds, check_primitives, primitive_metrics
from ltl_human_motion.motion.retarget import (
    enforce_bone_lengths,
    mirror_positions,
    retarget_points,
)
from ltl_human_motion.motion.skeleton import (
    JOINT_INDEX,
    JOINT_NAMES,
    MIRROR_PERMUTATION,
    PARENTS,
    Skeleton,
)
from ltl_human_motion.motion.types import (
    Motion,
    MotionPrimitive,
    end_pose,
    world_positions,
    yaw_matrix,
)

__all__ = [
    "DEFAULT_DELTA", "DEFAULT_K_COMP", "DEFAULT_LIBRARY_DELTA", "GOAL_TASKS", "HAND_TASKS",
    "JOINT_INDEX", "JOINT_NAMES", "LIBRARY_FPS", "MIRROR_PERMUTATION", "OVERLAP", "PARENTS",
    "PRIMITIVE_FRAMES", "Motion", "MotionAutomaton", "MotionLibrary", "MotionPrimitive",
    "QualityThresholds", "Skeleton", "align_windows", "build_library", "build_transitions",
    "cache_dir", "carry_poses", "center_of_mass", "check_primitives", "chest_height",
    "compose", "decompose", "end_pose", "enforce_bone_lengths", "knee_height",
    "load_library", "load_motion", "make_goal_primitive", "max_reach", "min_jerk",
    "min_reach_height", "mirror_positions", "pair_distance",
    "primitive_metrics", "reach_placement", "retarget_points", "seat_height_range",
    "standing_pose", "transition_distances", "two_bone_ik", "window_positions",
    "world_positions", "yaw_matrix",
]
