"""Goal primitives made by a body model: inverse kinematics plus posture rules.

There is no reachable real clip of reaching to a table, assembling, bending, stooping,
kneeling or sitting (see ``notes/data-sources.md``), so every goal primitive of Table I is
*made* on the canonical skeleton for the exact target:

* **Body model.** A pose is given by the pelvis position, a trunk flexion angle (spread
  over the lumbar and thoracic spine: 50 % below the spine joint, 85 % below the chest,
  100 % above), the ankle and toe positions of both feet, and the palm positions of both
  hands. Knees and elbows come from analytic two-bone IK (:func:`.ik.two_bone_ik`), so
  every bone keeps its canonical length in every frame.
* **Posture rules.** For hand targets the trunk flexion and the knee bend (pelvis drop)
  are chosen on a grid minimizing ``flexion^2 + (drop / 0.14 H)^2 + 0.5 (d / arm - 0.8)^2``
  subject to the hand being within 93 % of the arm's length from the shoulder, the legs
  being able to reach the planted feet, and balance. ``bend`` flexes the trunk with nearly
  straight knees so that the head comes within chest height of the floor while the
  buttocks stay above knee height; ``stoop`` bends the knees until the buttocks are
  below knee height and flexes the trunk (Table I).
* **Balance.** After a posture is chosen the pelvis is shifted back or forth until the
  whole-body centre of mass (Winter's segment masses, :func:`.ik.center_of_mass`) lies
  over the middle half of the support polygon of the feet.
* **Hand paths.** Between key poses the palm moves with the minimum-jerk profile (Flash &
  Hogan 1985). The shoulder-to-palm vector is interpolated (direction slerped, length
  interpolated) relative to the moving shoulder, so the path stays within reach and swings
  in an arc rather than through the shoulder, plus a small seeded outward/upward bow; the
  body posture leads the hand slightly.

All targets are in the primitive's **start frame**: the root's floor position at the
origin, facing +x, left = +y, z = height above the floor. Every goal primitive starts in
``start_pose`` (default: the standing pose gait start primitives begin with) and, except
``sit`` (ends seated) and ``standUp`` (starts seated), ends in it again.

Modules: :mod:`.tasks` (task names, Table I thresholds, checks), :mod:`.body` (the body
model), :mod:`.kneeling`, :mod:`.timelines` (minimum-jerk interpolation), :mod:`.postures`
(the posture search) and :mod:`.posture_checks` (boards, furniture, obstacles),
:mod:`.hand_paths` (reference hand paths), :mod:`.hand_tasks` and :mod:`.down_up` (the
primitives), :mod:`.placement` (:func:`reach_placement`) and :mod:`.primitive`
(:func:`make_goal_primitive`). This package re-exports the public API and the private
names other modules and tests use
(``goals._grid``, ``goals._Start`` ...: ``name as name`` below).
"""

from __future__ import annotations

from ltl_human_motion.motion.goals.body import PELVIS_TILT_MAX, SEATED_PELVIS_MAX
from ltl_human_motion.motion.goals.body import _Start as _Start
from ltl_human_motion.motion.goals.body import _trunk as _trunk
from ltl_human_motion.motion.goals.down_up import SIT_DOWN_SECONDS, STAND_UP_SECONDS
from ltl_human_motion.motion.goals.hand_paths import HAND_GOAL_PEAK_SPEED
from ltl_human_motion.motion.goals.hand_tasks import ELBOW_RETIME_SPEED, HAND_RETIME_SPEED
from ltl_human_motion.motion.goals.hand_tasks import _peak_hand_speed as _peak_hand_speed
from ltl_human_motion.motion.goals.kneeling import KNEEL_DOWN_SECONDS
from ltl_human_motion.motion.goals.placement import _placement as _placement
from ltl_human_motion.motion.goals.placement import reach_placement
from ltl_human_motion.motion.goals.posture_checks import _OBSTACLE_CLEARANCE as _OBSTACLE_CLEARANCE
from ltl_human_motion.motion.goals.posture_checks import ObstacleClearance
from ltl_human_motion.motion.goals.posture_checks import _support_depth as _support_depth
from ltl_human_motion.motion.goals.postures import _GRID_CACHE as _GRID_CACHE
from ltl_human_motion.motion.goals.postures import _contact_poses as _contact_poses
from ltl_human_motion.motion.goals.postures import _grid as _grid
from ltl_human_motion.motion.goals.postures import _kneel_set as _kneel_set
from ltl_human_motion.motion.goals.postures import posture_clear
from ltl_human_motion.motion.goals.primitive import make_goal_primitive
from ltl_human_motion.motion.goals.tasks import _J as _J
from ltl_human_motion.motion.goals.tasks import (
    GOAL_TASKS,
    HAND_PATHS,
    HAND_TASKS,
    LEVEL_PATH_TASKS,
    LEVEL_REGION_TASKS,
    LOW_BOARD_HEIGHT,
    POSTURE_TASKS,
    PUSH_LEVEL_TASKS,
    chest_height,
    knee_height,
    max_reach,
    min_reach_height,
    seat_height_range,
)
from ltl_human_motion.motion.goals.tasks import _arm_length as _arm_length

__all__ = [
    "ELBOW_RETIME_SPEED",
    "GOAL_TASKS",
    "HAND_GOAL_PEAK_SPEED",
    "HAND_PATHS",
    "HAND_RETIME_SPEED",
    "HAND_TASKS",
    "KNEEL_DOWN_SECONDS",
    "LEVEL_PATH_TASKS",
    "LEVEL_REGION_TASKS",
    "LOW_BOARD_HEIGHT",
    "PELVIS_TILT_MAX",
    "POSTURE_TASKS",
    "PUSH_LEVEL_TASKS",
    "SEATED_PELVIS_MAX",
    "SIT_DOWN_SECONDS",
    "STAND_UP_SECONDS",
    "ObstacleClearance",
    "chest_height",
    "knee_height",
    "make_goal_primitive",
    "max_reach",
    "min_reach_height",
    "posture_clear",
    "reach_placement",
    "seat_height_range",
]
