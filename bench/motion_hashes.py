"""Fingerprints of the motions the goal models and the planner make, for refactors.

Prints one sha256 per motion: S1 and S2 synthesized in ``config/paper_cell.yaml`` at
statures 1.55, 1.75 and 1.95 m and seeds 0-2 (joint positions (T, J, 3) and root yaw (T,)),
and about 20 goal primitives of every Table I task from ``make_goal_primitive`` (poses
(T, J, 3), root (T, 4) and meta), including reaches under a low board, over and onto
furniture (``support``, ``ceiling``), among obstacles, from the carry stance, kneeling,
sitting and standing up; also ``reach_placement`` and ``posture_clear`` answers. A
refactor that must not change a motion prints the same lines before and after:
``python bench/motion_hashes.py --out before.txt`` and again after, then ``diff``.
Not a test: run ``python bench/motion_hashes.py`` (``--goals-only`` skips S1/S2).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.motion.gait import standing_pose  # noqa: E402
from ltl_human_motion.motion.goals import (  # noqa: E402
    GOAL_TASKS,
    HAND_TASKS,
    make_goal_primitive,
    max_reach,
    posture_clear,
    reach_placement,
)
from ltl_human_motion.motion.skeleton import Skeleton  # noqa: E402

STATURES = (1.55, 1.75, 1.95)
SEEDS = (0, 1, 2)


def digest(*arrays: np.ndarray, extra: str = "") -> str:
    """sha256 of the arrays' shapes and float64 bytes, then ``extra``."""
    h = hashlib.sha256()
    for a in arrays:
        a = np.ascontiguousarray(a, dtype=np.float64)
        h.update(str(a.shape).encode())
        h.update(a.tobytes())
    h.update(extra.encode())
    return h.hexdigest()


def synthesized() -> Iterator[tuple[str, str]]:
    """(name, sha256) of S1 and S2 at every stature and seed."""
    from ltl_human_motion.errors import LtlHumanMotionError
    from ltl_human_motion.planning.pipeline import resolve_cell, synthesize
    cell = resolve_cell(str(ROOT / "config" / "paper_cell.yaml"))
    for spec in ("S1", "S2"):
        for stature in STATURES:
            for seed in SEEDS:
                name = f"{spec} H={stature} seed={seed}"
                try:
                    synth = synthesize(spec, cell, stature=stature, seed=seed)[0]
                except LtlHumanMotionError as exc:
                    yield name, digest(extra=f"error: {exc}")
                    continue
                yield name, digest(synth.motion.positions, synth.root_yaw,
                                   extra=json.dumps(synth.sequence))


def _cases(sk: Skeleton) -> Iterator[tuple[str, str, np.ndarray | None, dict]]:
    """(label, task, target, keyword arguments) of the goal primitives for one stature."""
    H = sk.stature
    stand = standing_pose(sk)[0]
    carry = standing_pose(sk, carry=True)[0]
    for task in GOAL_TASKS:
        if task not in HAND_TASKS:
            continue
        top = max_reach(task, sk)
        for h in (0.03, 0.45, 0.9, 1.2, top - 0.05):
            x, y = reach_placement(task, h, sk)
            yield f"h={h:.3f}", task, np.array([x, y, h]), {}
        x, y = reach_placement(task, 0.55 * H, sk)
        target = np.array([x, y, 0.55 * H])
        yield "carry", task, target, {"start_pose": carry}
        yield "level", task, target, {"path": "level", "start_pose": stand}
        yield "both", task, target, {"hand": "both"}
        yield "left", task, target * [1, -1, 1], {"hand": "l_hand"}
        yield "duration", task, target, {"duration": 6.0}
    for task in ("insert", "extract"):
        for travel in (0.05, 0.2):
            yield f"travel={travel}", task, np.array([0.5, -0.1, 1.0]), {"travel": travel}
        yield "support", task, np.array([0.6, -0.1, 1.06]), {
            "path": "level", "hand": "r_hand", "support": (1.0, 0.0, 0.4, 0.98)}
    for task in ("grasp", "release", "move"):
        yield "over", task, np.array([0.30, -0.18, 0.97 * max_reach(task, sk)]), {
            "hand": "r_hand", "support": (1.0, 0.0, 0.25, 0.90 * max_reach(task, sk)),
            "start_pose": stand}
        yield "compartment", task, np.array([0.70, -0.14, 0.717]), {
            "hand": "r_hand", "board": (0.5665, 0.88, 0.90), "support": (1.0, 0.0, 0.5665, 0.6),
            "start_pose": stand}
        yield "ceiling", task, np.array([0.55, -0.14, 1.0]), {
            "hand": "r_hand", "support": (1.0, 0.0, 0.4, 0.92),
            "ceiling": (1.0, 0.0, 0.4, 1.25, 1.27)}
        for depth, bottom in ((0.17, 0.44), (0.10, 0.6)):
            x, y = reach_placement(task, 0.10, sk, board=(depth, bottom, bottom + 0.02),
                                   start_pose=stand)
            yield f"low board {depth}/{bottom}", task, np.array([x, y, 0.10]), {
                "board": (x - depth, bottom, bottom + 0.02), "start_pose": stand}
        yield "obstacles", task, np.array([0.5, -0.136, 0.84]), {"obstacles": _table(sk)}
        yield "wall", task, np.array([0.45, -0.136, 0.9]), {"obstacles": _wall(sk)}
    for task in ("bend", "stoop", "kneel"):
        yield "plain", task, None, {}
        yield "left", task, None, {"hand": "l_hand"}
        yield "duration", task, None, {"duration": 5.0}
        yield "carry", task, None, {"start_pose": carry}
    yield "reach", "bend", np.array([0.45, -0.15, 0.5]), {}
    yield "reach low", "bend", np.array([0.35, -0.15, 0.4]), {}
    yield "reach", "stoop", np.array([0.45, -0.15, 0.2]), {}
    yield "reach", "kneel", np.array([0.4, -0.15, 0.25]), {}
    yield "reach left", "kneel", np.array([0.4, 0.15, 0.25]), {"hand": "l_hand"}
    lo, hi = 0.20 * H, 0.34 * H
    for z in (lo, 0.26 * H, hi):
        x, _ = reach_placement("sit", z, sk)
        yield f"z={z:.3f}", "sit", np.array([x, 0.0, z]), {}
        yield f"z={z:.3f}", "standUp", np.array([0.0, 0.0, z]), {}
    yield "default", "sit", None, {}
    yield "duration", "sit", None, {"duration": 2.5}
    yield "default", "standUp", None, {}
    yield "duration", "standUp", None, {"duration": 2.5}
    yield "default", "wait", None, {}
    yield "short", "wait", None, {"duration": 0.5}
    for duration in (1.0, 3.0, 4.0):
        yield f"{duration} s", "wait", None, {"duration": duration}
    yield "carry", "wait", None, {"start_pose": carry}


def _box_clearance(lo: np.ndarray, hi: np.ndarray, stature: float):
    """An ``ObstacleClearance`` of one box (start frame)."""
    from ltl_human_motion.scene.clearance import PartSet
    from ltl_human_motion.scene.occupancy import capsules_from_positions
    from ltl_human_motion.scene.shapes import Box
    box = PartSet([Box.from_bounds(lo, hi)])

    def clearance(poses: np.ndarray, parts: tuple[str, ...]) -> np.ndarray:
        seg, rad = capsules_from_positions(poses, stature, parts)
        return box.body_clearance(seg, rad)
    return clearance


def _table(sk: Skeleton):
    return _box_clearance(np.array([0.28, -0.6, 0.0]), np.array([0.88, 0.6, 0.75]), sk.stature)


def _wall(sk: Skeleton):
    return _box_clearance(np.array([-0.3, -1.0, 0.0]), np.array([1.0, 1.0, 2.5]), sk.stature)


def goal_primitives() -> Iterator[tuple[str, str]]:
    """(name, sha256) of the goal primitives, placements and posture checks."""
    for stature in STATURES:
        sk = Skeleton(stature)
        for n, (label, task, target, kw) in enumerate(_cases(sk)):
            name = f"goal H={stature} {task} {label}"
            try:
                mp = make_goal_primitive(task, target, sk, rng=np.random.default_rng(n), **kw)
            except ValueError as exc:
                yield name, digest(extra=f"error: {exc}")
                continue
            yield name, digest(mp.poses, mp.root,
                               extra=json.dumps(mp.meta, sort_keys=True, default=str))
        for task in GOAL_TASKS:
            for h in (0.1, 0.8, 1.4):
                try:
                    answer = str(reach_placement(task, h, sk, hand="auto"))
                except ValueError as exc:
                    answer = f"error: {exc}"
                yield f"placement H={stature} {task} h={h}", digest(extra=answer)
        for task in ("grasp", "insert", "assemble"):
            target = np.array([0.5, -0.136, 0.84])
            for label, obstacles in (("table", _table(sk)), ("wall", _wall(sk))):
                yield (f"posture_clear H={stature} {task} {label}",
                       digest(extra=str(posture_clear(task, target, sk, obstacles))))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--goals-only", action="store_true", help="skip S1 and S2")
    parser.add_argument("--out", type=Path, default=None, help="also write the lines here")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    lines = []
    parts = [goal_primitives()] + ([] if args.goals_only else [synthesized()])
    for part in parts:
        for name, sha in part:
            lines.append(f"{sha}  {name}")
            print(lines[-1], flush=True)
    total = hashlib.sha256("\n".join(lines).encode()).hexdigest()
    print(f"{len(lines)} motions and answers, all: {total} "
          f"({time.perf_counter() - t0:.0f} s)")
    if args.out is not None:
        atomic_write_text(args.out, "\n".join(lines) + f"\nall {total}\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
