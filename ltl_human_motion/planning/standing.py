"""Placement geometry: where the worker stands for a goal task and how it faces.

Pure functions of the cell, the stature and the worker's pose: the standing offset of
a target in the root frame (from the goal models' reach), the ideal root pose for a
target seen from a floor point, a low board over a target and how the goal primitive
takes it, where a held part can be let go, the palm target of a grasp on a board, and
how far an extract pulls. The walk goals (:mod:`.walk_goals`) and the goal steps
(:mod:`.goal_steps`) use them.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.motion.goals import LEVEL_PATH_TASKS, LOW_BOARD_HEIGHT
from ltl_human_motion.planning.plan_state import PlanContext, Pose

Board = tuple[float, float, float, np.ndarray]

#: Height of the hand where a held part is let go, as a fraction of the stature (waist
#: height: 0.75 m for a 1.75 m worker, the planner's value since the first release).
RELEASE_HEIGHT = 0.75 / 1.75

#: Places a part is let go at, (metres ahead of the root, turn from the heading in
#: radians), tried in order: straight ahead at a forearm's length, then to either side
#: and nearer the body when furniture stands in front.
RELEASE_PLACES: tuple[tuple[float, float], ...] = (
    (0.45, 0.0), (0.45, math.pi / 4), (0.45, -math.pi / 4), (0.4, math.pi / 2),
    (0.4, -math.pi / 2), (0.3, 0.0))

#: A board over a hand target lower than this fraction of the stature (the head of a
#: worker stooping to the target passes under or at it: 1.05 m at 1.75 m, a rack's
#: waist board over its knee board) is approached square to its edge, and the reach
#: keeps every body capsule out from under it, as for a low board (:func:`low_board`
#: with ``below``; the goal model's ``board``).
SQUARE_BOARD_HEIGHT = 0.6

#: Half length of a low board's front edge either side of the target that the reach
#: under it keeps clear of, metres (about a shoulder width: the arm and the head).
BOARD_EDGE_SPAN = 0.25

#: Tops of furniture a released part is set down on: up to this fraction of the stature
#: (1.2 m at 1.75 m, about chest height: higher tops are shelves out of a natural
#: put-down).
RELEASE_SURFACE_MAX = 1.2 / 1.75

#: Gap between a part set down and the surface under it when it is let go, metres (the
#: cells' parts rest 1 cm above their tables).
RELEASE_GAP = 0.01

#: Raising a grasp's palm target off the part's support (:func:`palm_clear_of_support`):
#: step and the gap kept to the support (the planner's goal checks need
#: ``steps.PLACED_MARGIN``; blends move the palm a few mm), and how deep the palm
#: sphere stays in the part (grasp holds when it enters), metres.
PALM_RISE_STEP = 0.005
PALM_SUPPORT_GAP = 0.01
PALM_IN_PART = 0.01

#: How far beyond its container an extract pulls the part, metres.
PULL_MARGIN = 0.03
#: The shortest and longest extract pull, metres: the extract model's 8 cm, and a
#: forearm's length the hand pulls without a step.
PULL_RANGE = (0.08, 0.3)



def low_board(cell, target: np.ndarray, stature: float, below: float = LOW_BOARD_HEIGHT
              ) -> Board | None:
    """The lowest obstacle part over ``target`` (3,) with its underside above it and
    below ``below`` of the stature (default ``LOW_BOARD_HEIGHT``: a board the reach
    crouches under): (depth of the target behind the part's nearest edge, underside,
    top in metres, the edge's outward normal (2,)); None if there is none."""
    highest = below * stature
    best = None
    xy = np.asarray(target[:2], dtype=np.float64)
    probe = xy + np.array([[0.0, 0.0], [1e-3, 0.0], [0.0, 1e-3]])
    for ob in cell.obstacles:
        for part in ob.parts:
            lo, hi = part.aabb()
            if not (float(target[2]) < float(lo[2]) <= highest
                    and (best is None or float(lo[2]) < best[1])):
                continue
            sd = part.footprint().signed_distance(probe)
            if sd[0] <= 0.0:
                grad = sd[1:] - sd[0]
                normal = grad / max(float(np.linalg.norm(grad)), 1e-12)
                best = (-float(sd[0]), float(lo[2]), float(hi[2]), normal)
    return best


def board_local(cell, target: np.ndarray, local: np.ndarray, yaw: float, stature: float
                ) -> tuple[float, float, float] | None:
    """The low board over ``target`` (world (3,); ``local``: it in the start frame of the
    goal primitive, whose heading is ``yaw``) as the goal primitive takes it: (edge x,
    underside, top), the edge's nearest x within ``BOARD_EDGE_SPAN`` either side of the
    target; None if there is no low board."""
    low = low_board(cell, target, stature, below=SQUARE_BOARD_HEIGHT)
    if low is None:
        return None
    return _edge_local(low[0], low[3], local, yaw), low[1], low[2]


#: Metres below which the posture search's clearances are exact (above, the bounding
#: boxes' gap: a lower bound). The search only asks whether a posture keeps
#: ``motion.goals._OBSTACLE_CLEARANCE`` (1 cm): any bound above that answers the same,
#: and the exact capsule-box distances of every pair within 25 cm took most of its time
#: beside shelves.
POSTURE_EXACT_BELOW = 0.05


def posture_clearance(ctx: PlanContext, pose: Pose
                      ) -> Callable[[np.ndarray, tuple[str, ...]], np.ndarray]:
    """The obstacles of the cell around a worker standing at ``pose`` (x, y, yaw) as the
    goal models' posture search takes them (``motion.goals.ObstacleClearance``):
    ``clearance(poses, parts)``, the smallest clearance (m) of the capsules ``parts`` of
    start-frame poses (C, J, 3) to any obstacle part, (C,): exact below
    ``POSTURE_EXACT_BELOW``, a lower bound above it."""
    from ltl_human_motion.scene.geometry import point_bounds
    from ltl_human_motion.scene.occupancy import capsules_from_positions
    cell, stature = ctx.cell, ctx.stature
    x, y, yaw = (float(v) for v in pose)
    rot = np.array([[math.cos(yaw), -math.sin(yaw), 0.0],
                    [math.sin(yaw), math.cos(yaw), 0.0], [0.0, 0.0, 1.0]])
    shift = np.array([x, y, 0.0])

    def clearance(poses: np.ndarray, parts: tuple[str, ...]) -> np.ndarray:
        world = np.asarray(poses, dtype=np.float64) @ rot.T + shift
        seg, rad = capsules_from_positions(world, stature, parts)
        return cell.part_set.body_clearance(seg, rad, POSTURE_EXACT_BELOW,
                                            bounds=point_bounds(world))

    return clearance


def standing_offset(ctx: PlanContext, kind: str, target: np.ndarray, task: str,
                    hand: str | None = None, carry_stance: bool = True,
                    full_tilt: bool = True) -> tuple[float, float]:
    """Where ``target`` (3,) should be in the standing root's frame for goal task
    ``kind``: (ahead, left), metres (for ``hand``, if given: the left hand reaches a
    target on the left). Raises PlanningError (``unreachable``) for a height no goal
    model reaches. Under a low board the reach is planned from the stance the goal
    primitive starts from: the carry stance (``carry_stance``: the planner raises the
    arms first, or they hold a part), else arms down;
    ``full_tilt`` as :func:`.motion.goals.reach_placement`'s."""
    from ltl_human_motion.motion import goals
    low = low_board(ctx.cell, target, ctx.stature, below=SQUARE_BOARD_HEIGHT) \
        if kind in LEVEL_PATH_TASKS else None
    try:
        d, lat = goals.reach_placement(kind, float(target[2]), ctx.library.skeleton,
                                       hand=hand or "auto",
                                       board=None if low is None else low[:3],
                                       start_pose=None if low is None else ctx.stance(carry_stance),
                                       full_tilt=full_tilt)
        return float(d), float(lat)
    except ValueError as exc:
        raise PlanningError(f"task {task}: the target at height {target[2]:.2f} m is "
                            f"unreachable: {exc}", task=task, reason="unreachable") from None


@functools.lru_cache(maxsize=16)
def _back_steps(limit: float) -> np.ndarray:
    """Distances (8,) a worker may stand further back than the ideal spot, 0 to ``limit``."""
    steps = np.linspace(0.0, limit, 8)
    steps.flags.writeable = False
    return steps


def ideal_placement(ctx: PlanContext, target: np.ndarray, placement: tuple[float, float],
                    x: np.ndarray, y: np.ndarray, back_limit: float, room: bool = False,
                    walk_map: Callable[[np.ndarray], np.ndarray] | None = None,
                    stand_yaw: float | None = None) -> tuple[np.ndarray, ...]:
    """Root pose (x*, y*, yaw*) from which the goal primitive reaches ``target``, facing
    it from the side of (x, y) (with ``stand_yaw``: facing that way, rad, wherever (x, y)
    is; square to a low board's edge), and whether that spot is free.

    ``placement``: the target in the standing root's frame (:func:`standing_offset`).
    Where the ideal spot is too close to an obstacle (a bench in front), the worker
    stands up to ``back_limit`` further back. Arrays shaped like ``x``. With ``room``,
    also the floor clearance at (x, y) itself on ``walk_map`` (default the walking map).
    """
    d, lat = placement
    if stand_yaw is None:
        yaw = np.arctan2(target[1] - y, target[0] - x) - np.arctan2(lat, d)
    else:
        yaw = np.full(np.shape(x), float(stand_yaw))
    c, s = np.cos(yaw), np.sin(yaw)
    back = _back_steps(float(back_limit))
    px = target[0] - (c[..., None] * (d + back) - s[..., None] * lat)
    py = target[1] - (s[..., None] * (d + back) + c[..., None] * lat)
    pts = np.stack([px, py], axis=-1).reshape(-1, 2)
    free = ctx.stand_map(pts).reshape(px.shape) > ctx.stand_room
    k = np.argmax(free, axis=-1)
    rows = (np.arange(k.size), k.ravel())                   # the first free step back
    out = (px.reshape(-1, len(back))[rows].reshape(k.shape),
           py.reshape(-1, len(back))[rows].reshape(k.shape), yaw, free.any(axis=-1))
    if not room:
        return out
    walk_map = ctx.clearance if walk_map is None else walk_map
    return (*out, walk_map(np.stack([x, y], axis=-1).reshape(-1, 2)).reshape(np.shape(x)))


def _edge_local(depth: float, normal: np.ndarray, local: np.ndarray, yaw: float) -> float:
    """The x (start frame of a goal primitive whose heading is ``yaw``; ``local``: the
    target in it, (3,)) of the nearest edge of a part the target lies ``depth`` metres
    behind, with outward ``normal`` (2,) (world), within ``BOARD_EDGE_SPAN`` either side
    of the target."""
    c, s = math.cos(-yaw), math.sin(-yaw)
    n = np.array([c * normal[0] - s * normal[1], s * normal[0] + c * normal[1]])
    return float(local[0]) + depth * float(n[0]) - BOARD_EDGE_SPAN * abs(float(n[1]))


#: Metres a part's bounding box is widened by before its footprint is asked whether it
#: holds a point (rounding only: the box holds every point of the footprint).
_BOX_SLACK = 1e-9


def _parts_over(cell, target: np.ndarray, local: np.ndarray, yaw: float):
    """The obstacle parts whose footprint holds the floor point of ``target`` (world
    (3,); ``local``: it in the start frame of a goal primitive whose heading is ``yaw``),
    each as ``(lo (3,), hi (3,), inward (2,), offset)``: its bounds, and the half space
    beyond its nearest edge in the start frame (``inward @ xy >= offset``)."""
    xy = np.asarray(target[:2], dtype=np.float64)
    probe = xy + np.array([[0.0, 0.0], [1e-3, 0.0], [0.0, 1e-3]])
    c, s = math.cos(-yaw), math.sin(-yaw)
    parts = cell.part_set                       # every obstacle's parts, in their order
    # A footprint that holds the point has a bounding box that holds it.
    boxed = np.all((parts.lo[:, :2] - _BOX_SLACK <= xy) & (xy <= parts.hi[:, :2] + _BOX_SLACK),
                   axis=1)
    for k in np.flatnonzero(boxed):
        sd = parts.parts[k].footprint().signed_distance(probe)
        if sd[0] > 0.0:
            continue
        grad = (sd[1:] - sd[0]) / max(float(np.linalg.norm(sd[1:] - sd[0])), 1e-12)
        inward = -np.array([c * grad[0] - s * grad[1], s * grad[0] + c * grad[1]])
        # The edge lies -sd metres from the target along the outward normal.
        offset = float(inward @ np.asarray(local[:2], dtype=np.float64)) + float(sd[0])
        yield parts.lo[k], parts.hi[k], inward, offset


def support_local(cell, target: np.ndarray, local: np.ndarray, yaw: float
                  ) -> tuple[float, float, float, float] | None:
    """The furniture under ``target`` (world (3,); ``local``: it in the start frame of
    the goal primitive, whose heading is ``yaw``) as the goal primitive keeps the trunk
    and legs out of it: the obstacle part under the target (its footprint holds the
    target's floor point, its top is no higher than the target) whose nearest edge is
    nearest the worker, as the half space beyond that edge, (nx, ny, offset, top) (see
    :func:`~ltl_human_motion.motion.goals.make_goal_primitive`); None if there is none."""
    best = None
    for _, hi, inward, offset in _parts_over(cell, target, local, yaw):
        top = float(hi[2])
        if top > float(target[2]):
            continue
        if best is None or (offset, -top) < (best[2], -best[3]):
            best = (float(inward[0]), float(inward[1]), offset, top)
    return best


def ceiling_local(cell, target: np.ndarray, local: np.ndarray, yaw: float
                  ) -> tuple[float, float, float, float, float] | None:
    """The board over ``target`` (world (3,); ``local``: it in the start frame of the
    goal primitive, whose heading is ``yaw``) as the goal primitive keeps the body out of
    it: the lowest obstacle part above the target (its footprint holds the target's
    floor point, its underside is higher than the target) as the slab beyond its nearest
    edge, (nx, ny, offset, bottom, top) (see
    :func:`~ltl_human_motion.motion.goals.make_goal_primitive`); None if there is none."""
    best = None
    for lo, hi, inward, offset in _parts_over(cell, target, local, yaw):
        if float(lo[2]) <= float(target[2]) or (best is not None and float(lo[2]) >= best[3]):
            continue
        best = (float(inward[0]), float(inward[1]), offset, float(lo[2]), float(hi[2]))
    return best


def palm_clear_of_support(cell, stature: float, point: np.ndarray, part) -> np.ndarray:
    """The palm target (3,) for a grasp at ``point`` (3,) of ``part`` (its shape where it
    rests): the grasp point, raised by up to the palm's radius where the palm sphere
    there would touch the support (a flat part on a board), so that the grasp holds
    while the palm still enters the part."""
    if not cell.obstacles:
        return point
    from ltl_human_motion.motion.capsules import BODY_PARTS, capsule_radii
    radius = float(capsule_radii(stature)[BODY_PARTS.index("r_palm")])
    for rise in np.arange(0.0, radius, PALM_RISE_STEP):
        palm = point + np.array([0.0, 0.0, rise])
        clear = float(cell.part_set.capsule_clearance(np.stack([palm, palm])[None],
                                                      radius)[0])
        if clear > PALM_SUPPORT_GAP:
            inside = float(part.signed_distance(palm[None])[0])
            return palm if inside <= radius - PALM_IN_PART else point
    return point


def surface_below(cell, xy: np.ndarray, highest: float) -> float | None:
    """Height of the highest obstacle top under the floor point ``xy`` (2,) that is no
    higher than ``highest``, metres; None if none."""
    tops = [float(part.aabb()[1][2]) for ob in cell.obstacles for part in ob.parts
            if float(part.aabb()[1][2]) <= highest
            and float(part.footprint().signed_distance(xy[None])[0]) <= 0.0]
    return max(tops) if tops else None


def release_targets(cell, pose: Pose, stature: float, part_height: float,
                    offset: np.ndarray) -> list[np.ndarray]:
    """Where a hand may let a held part go, palm positions (3,), in order: ahead of the
    worker standing at ``pose``, then turned to either side, then nearer
    (``RELEASE_PLACES``). Over a table or bench the part (``part_height`` tall, held at
    ``offset`` (3,) from the palm) is set down on its top; elsewhere it is let go at
    ``RELEASE_HEIGHT`` of the stature."""
    x, y, yaw = pose
    half = 0.5 * part_height
    out = []
    for dist, turn in RELEASE_PLACES:
        c, s = math.cos(yaw + turn), math.sin(yaw + turn)
        palm = np.array([x + dist * c, y + dist * s, RELEASE_HEIGHT * stature])
        top = surface_below(cell, palm[:2], RELEASE_SURFACE_MAX * stature)
        if top is not None:
            palm[2] = max(palm[2], top + half + RELEASE_GAP - float(offset[2]))
        out.append(palm)
    return out


def pull_length(container_box: tuple[np.ndarray, np.ndarray],
                part_box: tuple[np.ndarray, np.ndarray]) -> float:
    """How far an extract pulls a part (m) out of its container horizontally, from the
    axis-aligned boxes (lo (3,), hi (3,)) of both where they are: the container's half
    extent beyond the part's centre plus the part's half size and ``PULL_MARGIN``, at
    least the model's 8 cm, at most 0.3 m."""
    lo, hi = container_box
    plo, phi = part_box
    centre = 0.5 * (plo + phi)
    out = min(float(np.min(np.r_[hi[:2] - centre[:2], centre[:2] - lo[:2]])),
              0.5 * float(np.max(hi[:2] - lo[:2])))
    need = out + 0.5 * float(np.max(phi[:2] - plo[:2])) + PULL_MARGIN
    return float(np.clip(need, *PULL_RANGE))
