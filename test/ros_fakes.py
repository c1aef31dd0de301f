"""Deterministic motions and a scripted synthesizer for testing and benchmarking the ROS
layer without the planning pipeline.

:func:`make_test_motion` builds a :class:`~ltl_human_motion.planning.result.SynthesizedMotion`
by hand: the canonical rest pose walks from the origin towards ``O1`` of the paper cell,
turning on the way, then "grasps" (task 0) and carries ``O1`` with the right hand.
:func:`scripted_synthesize` has the signature of ``planning.synthesize``; it checks the
spec with the real LTL parser (so a bad spec raises the real ``SpecError`` with line and
column), waits ``delay`` seconds to stand in for a long synthesis, and returns test
motions.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ltl_human_motion.kernel.rotations import matrix_from_yaw
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import Motion


def make_test_motion(duration: float = 2.0, fps: float = 60.0, stature: float = 1.75,
                     name: str = "test_motion") -> Any:
    """A hand-made SynthesizedMotion of ``duration`` seconds (walk, then grasp + carry)."""
    from ltl_human_motion.planning.result import SynthesisStats, SynthesizedMotion, TaskSegment

    if not duration > 0 or not fps > 0:
        raise ValueError(f"duration and fps must be positive, got {duration}, {fps}")
    n = round(duration * fps) + 1
    s = np.linspace(0.0, 1.0, n)
    skeleton = Skeleton(stature=stature)
    rest = skeleton.rest_positions()                                  # (J, 3), facing +x
    yaw = -np.pi / 2 * np.minimum(s * 2, 1.0)                         # turn towards -y
    root = np.stack([-0.6 * np.minimum(s * 2, 1.0), -0.6 * np.minimum(s * 2, 1.0),
                     np.zeros(n)], axis=-1)
    body = np.einsum("tij,kj->tki", matrix_from_yaw(yaw), rest)            # (T, J, 3)
    positions = body + root[:, None, :]
    half = n // 2
    task_index = np.full(n, -1, dtype=np.int64)
    task_index[half:] = 0
    hand = positions[:, JOINT_INDEX["r_hand"]]
    o1 = np.tile(np.array([-1.0, -1.0, 0.2]), (n, 1))
    o1[half:] = hand[half:]
    return SynthesizedMotion(
        motion=Motion(positions, fps, skeleton, name), root_yaw=yaw, task_index=task_index,
        timeline=[TaskSegment("grasp(O1)", half, n, "test_grasp")],
        objects={"O1": o1, "O2": np.tile(np.array([-1.5, 1.2, 0.3]), (n, 1))},
        spec="grasp(O1)", sequence=["grasp(O1)"], seed=0,
        stats=SynthesisStats(total_time=0.01, planning_time=0.005, nodes_expanded=7))


def scripted_synthesize(spec: str, cell: Any, library: Any = None, variants: int = 1,
                        seed: int = 0, cycles: int = 1, stature: float = 1.75,
                        options: Any = None, *, delay: float = 0.0,
                        duration: float = 2.0) -> list:
    """Stand-in for ``planning.synthesize``: real spec check, fixed motions."""
    from ltl_human_motion.ltl import parse
    from ltl_human_motion.ltl.spec import resolve_spec_text

    parse(resolve_spec_text(spec), cell)
    if delay > 0:
        time.sleep(delay)
    return [make_test_motion(duration=duration, stature=stature, name=f"variant_{v}")
            for v in range(max(int(variants), 1))]


#: A bringup file that starts only the synthesis node (for service tests).
SYNTHESIS_ONLY_BRINGUP = """\
bringup:
  ros__parameters:
    nodes: [synthesis_node]
    humans: ["1"]
synthesis_node:
  ros__parameters:
    default_cell: paper_cell
    max_concurrent: 4
"""
