"""Lift a carried part over the furniture it goes onto, then step in: the preparation of
a move or insert whose part, held in the carry stance, would meet that furniture at
every spot the goal motion reaches the target from.

A carton carried at hip height is lower than a packing table's top. No walk ends where
the hands reach the table's middle (the carton would be in the table), and from the
nearest spot where it is clear the target is out of reach. A person stops there, lifts
the carton over the top and steps in. The spot, the lift and the step are found from
the geometry: the part's exact clearance (:func:`.scene.predicates.object_clearance`)
along the way from the target to the worker, and the least lift that clears it where
the goal motion starts.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from ltl_human_motion.errors import PlanningError
from ltl_human_motion.motion.lift import lift_poses, lifted_stance
from ltl_human_motion.motion.skeleton import JOINT_INDEX
from ltl_human_motion.motion.types import MotionPrimitive
from ltl_human_motion.planning.astar import SearchBudget
from ltl_human_motion.planning.plan_state import PlanContext, StartArms, WorkerState
from ltl_human_motion.planning.standing import ideal_placement
from ltl_human_motion.planning.steps import StepExecutor


class GoalSteps(Protocol):
    """What the lift needs of :class:`.goal_steps.GoalSteps`: the plan's context, state
    and executor, and its walk to a placement."""

    ctx: PlanContext
    state: WorkerState
    executor: StepExecutor

    def approach(self, target: np.ndarray, placement: tuple[float, float], text: str,
                 sector: tuple[float, float] | None = None,
                 budget: SearchBudget | None = None,
                 stand_yaw: float | None = None) -> int: ...

#: Clearance (m) the part keeps from the furniture at the spot the worker lifts it at,
#: and after the lift where the goal motion starts (the pelvis dips as the worker steps
#: in).
LIFT_CLEARANCE = 0.06
#: Clearance (m) of the standing body in the lifted stance where the goal motion starts.
BODY_CLEARANCE = 0.02
#: Distances (m) further back than the goal motion's placement at which it may start
#: (the goal model's placement for a part held low puts the hips at the table's edge).
START_BACKS = tuple(np.round(np.arange(0.0, 0.45, 0.05), 2))
#: Distances (m) beyond the goal motion's placement at which the lift spot is looked for.
SPOT_STEPS = np.arange(0.05, 0.85, 0.05)
#: Lifts tried (m), least first: up to a carton's height above the carry stance.
LIFTS = np.arange(0.02, 0.46, 0.02)
#: Longest step in (m) the standing step model makes.
LONGEST_STEP = 0.6


def _part_clearance(steps: GoalSteps, part: str, root: tuple[float, float, float],
                    stance: np.ndarray, joint: str | None = None,
                    offset: np.ndarray | None = None) -> float:
    """Exact clearance (m) of ``part`` held by ``joint`` at ``offset`` (3,) from it (default:
    as the worker holds it) with the worker standing at ``root`` (x, y, yaw) in ``stance``
    (J, 3)."""
    from ltl_human_motion.scene.predicates import object_clearance
    joint = steps.state.held[part] if joint is None else joint
    offset = steps.state.held_offset(part) if offset is None else offset
    x, y, yaw = root
    c, s = math.cos(yaw), math.sin(yaw)
    rel = stance[JOINT_INDEX[joint]]
    centre = np.array([x + c * rel[0] - s * rel[1], y + s * rel[0] + c * rel[1],
                       steps.ctx.library.standing_height + rel[2]])
    return float(object_clearance(steps.ctx.cell, part, centre + offset,
                                  exact_below=LIFT_CLEARANCE + 0.01))


def _grasp_hold(steps: GoalSteps, part: str, target: np.ndarray,
                placement: tuple[float, float]) -> tuple[str, np.ndarray]:
    """The joint that will hold ``part`` grasped at ``target`` (3,) from ``placement``
    (both hands for a two-handed part, else the hand on the target's side) and the
    part's offset from it (3,), taking the hand to come to the grasp point."""
    from ltl_human_motion.planning.plan_state import holding_joint, object_position
    obj = steps.ctx.cell.object(part)
    hand = "both" if obj.two_handed else ("l_hand" if placement[1] > 0.0 else "r_hand")
    return holding_joint(hand), object_position(steps.ctx.cell, steps.state, part) - target


def _root_at(steps: GoalSteps, target: np.ndarray, placement: tuple[float, float],
             side: float) -> tuple[float, float, float, bool]:
    """Root pose (x, y, yaw) from which the goal motion reaches ``target`` from
    ``placement`` (ahead, left), approached from direction ``side`` (rad from the
    target), and whether the spot is free to stand on."""
    far = 2.0 * math.hypot(*placement) + 1.0
    px, py, yaw, free = ideal_placement(steps.ctx, target, placement,
                                        np.array([target[0] + far * math.cos(side)]),
                                        np.array([target[1] + far * math.sin(side)]), 0.0)
    return float(px[0]), float(py[0]), float(yaw[0]), bool(free[0])


def _lifted_start(steps: GoalSteps, part: str, target: np.ndarray,
                  placement: tuple[float, float], side: float) -> tuple[float, float] | None:
    """Where the goal motion starts after the lift, as the distance (m) further back than
    ``placement`` (up to ``START_BACKS``), and the least lift (m) there: the spot is free
    to stand on, the lifted part keeps ``LIFT_CLEARANCE`` and the standing body in the
    lifted stance ``BODY_CLEARANCE``; None if no such spot and lift."""
    from ltl_human_motion.planning.placement import standing_bodies
    from ltl_human_motion.scene.predicates import body_clearance
    ctx = steps.ctx
    carry = ctx.stance(True)
    d, lat = placement
    for b in START_BACKS:
        root = _root_at(steps, target, (d + float(b), lat), side)
        if not root[3]:
            continue
        for r in LIFTS:
            stance = lifted_stance(carry, float(r))
            if _part_clearance(steps, part, root[:3], stance) <= LIFT_CLEARANCE:
                continue
            body = standing_bodies(stance, ctx.library.standing_height, np.array([root[0]]),
                                   np.array([root[1]]), np.array([root[2]]))
            if float(body_clearance(body, ctx.cell, stature=ctx.stature,
                                    exact_below=BODY_CLEARANCE + 0.01).min()) > BODY_CLEARANCE:
                return float(b), float(r)
            break
    return None


def needs_lift(steps: GoalSteps, part: str, target: np.ndarray,
               placement: tuple[float, float]) -> bool:
    """Whether held ``part``, in the carry stance where the goal motion for ``placement``
    starts (approached from the worker's side of ``target``), meets the furniture."""
    x, y, _ = steps.state.pose
    final = _root_at(steps, target, placement, math.atan2(y - target[1], x - target[0]))
    return _part_clearance(steps, part, final[:3], steps.ctx.stance(True)) <= LIFT_CLEARANCE


def lift_in(steps: GoalSteps, part: str, target: np.ndarray, placement: tuple[float, float],
            text: str, half_width: float, budget: SearchBudget) -> tuple[int, StartArms]:
    """Walk to the nearest spot (from the worker's side of ``target`` (3,)) where held
    ``part`` clears the furniture, lift it the least that clears it where the goal
    motion for ``placement`` starts, and step in there; returns the gait primitives
    walked and the lifted arms the goal motion starts from. Raises PlanningError
    (``blocked``) where the part is clear at the goal motion's start already, no spot
    or lift clears it, or the walk, the lift or the step meets an obstacle."""
    from ltl_human_motion.planning.turns import make_step_primitive
    ctx, state, ex = steps.ctx, steps.state, steps.executor
    carry = ctx.stance(True)
    x, y, _ = state.pose
    side = math.atan2(y - target[1], x - target[0])
    d, lat = placement
    final = _root_at(steps, target, placement, side)

    def refuse(why: str) -> PlanningError:
        return PlanningError(f"task {text}: lifting {part} over the furniture: {why}",
                             task=text, reason="blocked")

    if _part_clearance(steps, part, final[:3], carry) > LIFT_CLEARANCE:
        raise refuse("it is clear without a lift")
    found = _lifted_start(steps, part, target, placement, side)
    if found is None:
        raise refuse(f"no lift up to {LIFTS[-1]:.2f} m clears it where the body stands clear")
    start_back, rise = found
    back = None
    for b in SPOT_STEPS[(SPOT_STEPS > start_back) & (SPOT_STEPS <= start_back + LONGEST_STEP)]:
        spot = _root_at(steps, target, (d + float(b), lat), side)
        if spot[3] and _part_clearance(steps, part, spot[:3], carry) > LIFT_CLEARANCE:
            back = float(b)
            break
    if back is None:
        raise refuse(f"no spot within {LONGEST_STEP:.2f} m keeps it clear")
    walked = steps.approach(target, (d + back, lat), text,
                            sector=(side, half_width), budget=budget)
    lib = ctx.library
    rel = lift_poses(carry, rise, lib.skeleton, lib.fps)
    lift = MotionPrimitive("lift_part", "wait", rel, _still_root(rel, lib), lib.fps,
                           "planner: lift before stepping in")
    if not ex.placed_clear(lift, state.pose):
        raise refuse("the lift meets an obstacle")
    ex.add(lift, state.pose, -1, ctx.overlap)
    lifted = lifted_stance(carry, rise)
    px, py, pyaw, _ = _root_at(steps, target, (d + start_back, lat), side)
    sx, sy, syaw = state.pose
    c, s = math.cos(syaw), math.sin(syaw)
    dx, dy = c * (px - sx) + s * (py - sy), -s * (px - sx) + c * (py - sy)
    dyaw = math.remainder(pyaw - syaw, 2.0 * math.pi)
    step = make_step_primitive(lifted, lib.standing_height, dx, dy, dyaw, lib.skeleton,
                               lib.fps, "carry")
    if not ex.placed_clear(step, state.pose):
        raise refuse("the step in meets an obstacle")
    ex.advance(step)
    state.gait_state = None
    return walked, StartArms(lifted, rise)


def _still_root(rel: np.ndarray, lib) -> np.ndarray:
    """The root track (T, 4) of a motion in place: standing height, no turn."""
    root = np.zeros((len(rel), 4))
    root[:, 2] = lib.standing_height
    return root


def needs_lift_out(steps: GoalSteps, part: str, target: np.ndarray,
                   placement: tuple[float, float]) -> bool:
    """Whether ``part``, grasped at ``target`` (3,) and brought to the carry stance where
    the grasp motion for ``placement`` ends (approached from the worker's side), would
    meet the furniture it rests on (a carton on a stand, higher than the carry stance
    holds its bottom)."""
    x, y, _ = steps.state.pose
    root = _root_at(steps, target, placement, math.atan2(y - target[1], x - target[0]))
    joint, offset = _grasp_hold(steps, part, target, placement)
    return _part_clearance(steps, part, root[:3], steps.ctx.stance(True), joint,
                           offset) <= LIFT_CLEARANCE


def lift_for_grasp(steps: GoalSteps, part: str, target: np.ndarray,
                   placement: tuple[float, float], text: str) -> StartArms:
    """Where the worker stands for the grasp of ``part`` at ``target`` (3,): raise the
    arms from the carry stance by the least lift at which the part, once held, clears
    the furniture it rests on; the grasp motion starts and ends in that stance
    (:func:`settle` takes it back afterwards). Raises PlanningError (``blocked``) if no
    lift up to ``LIFTS`` clears it or the lift meets an obstacle."""
    ctx, state, lib = steps.ctx, steps.state, steps.ctx.library
    carry = ctx.stance(True)
    joint, offset = _grasp_hold(steps, part, target, placement)
    root = state.pose
    rise = next((float(r) for r in LIFTS
                 if _part_clearance(steps, part, root, lifted_stance(carry, float(r)), joint,
                                    offset) > LIFT_CLEARANCE), None)
    if rise is None:
        raise PlanningError(f"task {text}: lifting {part} off the furniture: no lift up to "
                            f"{LIFTS[-1]:.2f} m clears it", task=text, reason="blocked")
    rel = lift_poses(carry, rise, lib.skeleton, lib.fps)
    lift = MotionPrimitive("lift_arms", "wait", rel, _still_root(rel, lib), lib.fps,
                           "planner: arms up to lift a part off")
    if not steps.executor.placed_clear(lift, state.pose):
        raise PlanningError(f"task {text}: lifting {part} off the furniture: raising the "
                            "arms meets an obstacle", task=text, reason="blocked")
    steps.executor.add(lift, state.pose, -1, ctx.overlap)
    return StartArms(lifted_stance(carry, rise), rise)


def settle(steps: GoalSteps, arms: StartArms, label: int, text: str,
           put_down: str | None = None) -> None:
    """After a goal motion that ended in the lifted ``arms`` (a grasp holding its part, a
    move or insert that put ``put_down`` down): lower the arms to the carry stance where
    the worker stands, else step back to the nearest spot (``SPOT_STEPS``) where every
    part still held clears the furniture in the carry stance and lower them there.
    Raises PlanningError (``blocked``) if no step back is clear."""
    from ltl_human_motion.planning.turns import make_step_primitive
    ctx, state, ex, lib = steps.ctx, steps.state, steps.executor, steps.ctx.library
    carry = ctx.stance(True)
    x, y, yaw = state.pose
    c, s = math.cos(yaw), math.sin(yaw)
    held = [name for name in state.held if name != put_down]
    rel = lift_poses(carry, arms.rise, lib.skeleton, lib.fps, lowering=True)
    lower = MotionPrimitive("lower_arms", "wait", rel, _still_root(rel, lib), lib.fps,
                            "planner: arms down after the lifted motion")
    for back in (0.0, *SPOT_STEPS[SPOT_STEPS <= LONGEST_STEP]):
        root = (x - c * float(back), y - s * float(back), yaw)
        if any(_part_clearance(steps, name, root, carry) <= LIFT_CLEARANCE for name in held):
            continue
        step = None if back == 0.0 else make_step_primitive(
            arms.stance, lib.standing_height, -float(back), 0.0, 0.0, lib.skeleton, lib.fps,
            "carry" if held else "walk")
        if step is not None and not ex.placed_clear(step, state.pose, put_down=put_down):
            continue
        pose = state.pose if step is None else ex.hand_over_pose(step, state.pose)
        if not ex.placed_clear(lower, pose, put_down=put_down):
            continue
        if step is not None:
            ex.add(step, state.pose, label, ctx.overlap, pose)
        ex.add(lower, state.pose, label, ctx.overlap)
        state.gait_state = None
        return
    raise PlanningError(f"task {text}: no step back of up to {LONGEST_STEP:.2f} m lets the "
                        "lifted arms down clear of the furniture", task=text, reason="blocked")
