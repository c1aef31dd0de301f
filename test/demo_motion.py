"""A synthetic :class:`SynthesizedMotion` built from the rest pose (pure numpy).

Useful for demos, for testing plots, exports and predicates without a motion library:
the worker walks from the start region to a spot in front of a region (legs and arms
swinging rigidly), turns to face it and reaches into it with one or both hands (the
analytic two-bone IK of :mod:`ltl_human_motion.motion.ik` keeps every bone length). It
is *not* a planned motion: it walks in a straight line and ignores obstacles.
"""

from __future__ import annotations

import itertools

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_axis_angle, matrix_from_yaw
from ltl_human_motion.motion.ik import two_bone_ik
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import Motion
from ltl_human_motion.planning.result import SynthesizedMotion, TaskSegment
from ltl_human_motion.scene.cell import Cell

__all__ = ["demo_synthesized_motion", "reach_pose", "standing_spot"]

_Y = np.array([0.0, 1.0, 0.0])
_LEG = {"l": [JOINT_INDEX[n] for n in ("l_knee", "l_ankle", "l_toe")],
        "r": [JOINT_INDEX[n] for n in ("r_knee", "r_ankle", "r_toe")]}


def _smoothstep(u: np.ndarray) -> np.ndarray:
    u = np.clip(u, 0.0, 1.0)
    return u * u * (3.0 - 2.0 * u)


def standing_spot(cell: Cell, target: np.ndarray, distance: float = 0.4) -> tuple[float, float,
                                                                                  float]:
    """Floor pose ``(x, y, yaw)`` at ``distance`` from ``target`` (3,) facing it, chosen
    among 16 headings as the one farthest from obstacle footprints."""
    yaws = np.arange(16) * (2.0 * np.pi / 16)
    spots = np.asarray(target)[:2] - distance * np.stack([np.cos(yaws), np.sin(yaws)], -1)
    best = int(np.argmax(cell.floor_clearance(spots)))
    return float(spots[best, 0]), float(spots[best, 1]), float(yaws[best])


def reach_pose(pose: np.ndarray, side: str, target: np.ndarray) -> np.ndarray:
    """Move one arm of ``pose`` (J, 3) so its hand goes towards ``target`` (3,).

    Two-bone IK (:func:`~ltl_human_motion.motion.ik.two_bone_ik`: shoulder-elbow,
    elbow-hand) with the elbow pointing down and outwards; bone lengths are kept, an
    unreachable target is approached as far as the arm goes.
    """
    out = np.array(pose, dtype=np.float64)
    s, e, w, h = (JOINT_INDEX[f"{side}_{n}"] for n in ("shoulder", "elbow", "wrist", "hand"))
    l1 = float(np.linalg.norm(pose[e] - pose[s]))
    l_ew = np.linalg.norm(pose[w] - pose[e])
    l2 = float(np.linalg.norm(pose[h] - pose[e]))
    # Elbow pole: down and away from the body's mid-line (along shoulder - chest).
    lateral = pose[s] - pose[JOINT_INDEX["chest"]]
    pole = np.array([0.0, 0.0, -1.0]) + 0.5 * lateral / max(np.linalg.norm(lateral), 1e-9)
    elbow, hand = two_bone_ik(pose[s], target, l1, l2, pole, max_stretch=1.0 - 1e-6)
    fore = (hand - elbow) / np.linalg.norm(hand - elbow)
    out[e], out[w], out[h] = elbow, elbow + l_ew * fore, elbow + l2 * fore
    return out


def demo_synthesized_motion(cell: Cell | None = None, region: str | None = None,
                            fps: float = 30.0, stature: float = 1.75, hands: str = "both",
                            speed: float = 1.0, reach_time: float = 1.5,
                            hold_time: float = 1.0) -> SynthesizedMotion:
    """Walk from the start region to ``region`` and reach into it.

    Parameters
    ----------
    cell : Cell, optional
        Default: a free floor with the target 2 m ahead at 1 m height.
    region : str, optional
        Region to reach into (default: the cell's final region).
    fps, stature : float
    hands : {"both", "right", "left"}
        ``"both"`` labels the task ``assemble(R)`` (if the cell has that shorthand).
    speed : float
        Walking speed, m/s.
    reach_time, hold_time : float
        Seconds to reach and to hold the hand(s) in the region.

    Returns
    -------
    SynthesizedMotion
        Walking frames have ``task_index`` -1; the reach is task 0.
    """
    if hands not in ("both", "right", "left"):
        raise ValueError(f"hands must be 'both', 'right' or 'left', got {hands!r}")
    skel = Skeleton(stature=stature)
    rest = skel.rest_positions()
    if cell is not None:
        reg = cell.region(region) if region else (cell.final_region or
                                                  next(iter(cell.regions.values())))
        target = reg.center
        start = cell.start_region.center[:2]
        x1, y1, yaw1 = standing_spot(cell, target)
        name = reg.name
    else:
        target, start, (x1, y1, yaw1), name = np.array([2.0, 0.0, 1.0]), np.zeros(2), \
            (1.5, 0.0, 0.0), "R1"
    # Walk start -> a point 0.6 m behind the spot -> the spot (the last leg faces the
    # region); turn on the spot before each leg.
    spot = np.array([x1, y1])
    facing = np.array([np.cos(yaw1), np.sin(yaw1)])
    waypoints = [start, spot - 0.6 * facing, spot]
    n_turn = max(round(0.5 * fps), 2)
    n_reach = max(round(reach_time * fps), 2)
    n_hold = max(round(hold_time * fps), 1)
    xy_list: list[np.ndarray] = []
    yaw_list: list[float] = []
    swing_list: list[float] = []
    heading = float(np.arctan2(*(waypoints[1] - start)[::-1]))
    stride_freq = speed / 0.7                    # steps of ~0.7 m
    for a_pt, b_pt in itertools.pairwise(waypoints):
        leg = b_pt - a_pt
        dist = float(np.linalg.norm(leg))
        if dist < 1e-6:
            continue
        new_heading = float(np.arctan2(leg[1], leg[0]))
        diff = (new_heading - heading + np.pi) % (2 * np.pi) - np.pi
        for k in range(n_turn):
            xy_list.append(a_pt)
            yaw_list.append(heading + diff * float(_smoothstep(np.array(k / (n_turn - 1)))))
            swing_list.append(0.0)
        heading = new_heading
        n = max(round(dist / speed * fps), 2)
        for k in range(n):
            u = k / (n - 1)
            xy_list.append(a_pt + leg * u)
            yaw_list.append(heading)
            swing_list.append(np.radians(22.0) * np.sin(2 * np.pi * stride_freq * k / fps)
                              * np.sin(np.pi * u) ** 2)
    n_walk = len(xy_list)
    T = n_walk + n_reach + n_hold
    xy = np.array(xy_list + [spot] * (n_reach + n_hold))
    yaw = np.array(yaw_list + [heading] * (n_reach + n_hold))
    yaw1 = heading
    frames = np.zeros((T, len(rest), 3))
    for t in range(T):
        pose = rest.copy()
        swing = swing_list[t] if t < n_walk else 0.0
        if swing:
            for side, sign in (("l", 1.0), ("r", -1.0)):
                hip = rest[JOINT_INDEX[f"{side}_hip"]]
                idx = _LEG[side]
                pose[idx] = (rest[idx] - hip) @ matrix_from_axis_angle(_Y, -sign * swing).T + hip
                sh = rest[JOINT_INDEX[f"{side}_shoulder"]]
                arm = [JOINT_INDEX[f"{side}_{n}"] for n in ("elbow", "wrist", "hand")]
                pose[arm] = (rest[arm] - sh) @ matrix_from_axis_angle(_Y, sign * 0.4 * swing).T + sh
        frames[t] = pose @ matrix_from_yaw(yaw[t]).T + np.array([xy[t, 0], xy[t, 1], 0.0])
    # Reaching: world-frame IK towards target points inside the region.
    sides = {"both": ("l", "r"), "right": ("r",), "left": ("l",)}[hands]
    lateral = matrix_from_yaw(yaw1) @ np.array([0.0, 1.0, 0.0])
    for t in range(n_walk, T):
        u = min((t - n_walk) / (n_reach - 1), 1.0)
        for side in sides:
            offset = 0.01 * lateral * (1.0 if side == "l" else -1.0) if len(sides) == 2 else 0
            start_hand = frames[n_walk - 1, JOINT_INDEX[f"{side}_hand"]]
            # Lift first, then move over: the hands clear a bench below the region.
            lift = _smoothstep(np.array(2.0 * u))
            over = _smoothstep(np.array((u - 0.3) / 0.7))
            delta = target + offset - start_hand
            goal = start_hand + np.array([over * delta[0], over * delta[1], lift * delta[2]])
            # Aim the middle of the hand (wrist-palm capsule), not the palm centre.
            aim, base = goal.copy(), frames[t].copy()
            w, h = JOINT_INDEX[f"{side}_wrist"], JOINT_INDEX[f"{side}_hand"]
            for _ in range(4):
                pose = reach_pose(base, side, aim)
                aim = aim + goal - (pose[w] + pose[h]) / 2.0
            frames[t] = pose
    if hands == "both" and cell is not None and "assemble" in cell.shorthands:
        task = f"assemble({name})"
    else:
        task = f"{'leftHand' if hands == 'left' else 'rightHand'}({name})"
    task_index = np.full(T, -1, dtype=np.int64)
    task_index[n_walk:] = 0
    objects = {} if cell is None else {n: np.repeat(o.position[None], T, axis=0)
                                       for n, o in cell.objects.items()}
    motion = Motion(frames, fps, skel, name="demo")
    return SynthesizedMotion(
        motion=motion, root_yaw=yaw, task_index=task_index,
        timeline=[TaskSegment(task, n_walk, T, "demo_reach", target)],
        objects=objects, spec=f"F {task}", sequence=[task], seed=0,
        verification={})
