"""``ltl-human-motion react``: a worker who reacts to the robot (GR(1), docs/reactive.md).

Solves the reactive specification on the cell's worker model, draws seeded random robot
behaviours that keep the assumptions, runs the strategy on each, synthesizes and verifies
each run's motion (once per task sequence: runs with the same tasks get the same motion,
:class:`~ltl_human_motion.planning.reactive.RunMotions`), and checks every joint trace
against the whole specification. Writes
``DIR/react.json``; an unrealizable specification exits with code 2 and the explanation.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from ltl_human_motion.atomic import atomic_write_text
from ltl_human_motion.cli._types import positive as _positive
from ltl_human_motion.cli._types import stature

NAME = "react"
HELP = ("synthesize a reactive worker (GR(1): robot events -> tasks) and verify its "
        "motions on random robot behaviours")


def _speed(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a speed in rad/s, got {text!r}") from None
    if not (np.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"expected a finite speed >= 0 rad/s, got {text}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion react``."""
    parser.add_argument("--cell", required=True,
                        help="cell name (config/<name>.yaml) or path to a cell YAML file")
    parser.add_argument("--spec", required=True,
                        help='reactive specification "assumptions -> guarantees", e.g. '
                             '"(G F !robot_in(R1)) -> (G(robot_in(R1) -> X !assemble(R1)) & '
                             'G F assemble(R1))"')
    parser.add_argument("--traces", type=_positive, default=10,
                        help="random robot behaviours to run (default 10)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--stature", type=stature, default=1.75,
                        help="body height in m, 1.55 to 1.95 (default 1.75)")
    parser.add_argument("--robot", type=Path, default=None,
                        help="robot YAML whose trajectory gives robot_in/robot_moving for a "
                             "third of the traces (default config/ur_pick_place.yaml when the "
                             "specification reads them)")
    parser.add_argument("--moving-threshold", type=_speed, default=0.05, metavar="RAD_S",
                        help="joint speed in rad/s above which robot_moving holds on the "
                             "robot's trajectory (default 0.05)")
    parser.add_argument("--no-motion", action="store_true",
                        help="check the strategy's runs only; plan no motion")
    parser.add_argument("--out", type=Path, default=Path("out/react"),
                        help="output folder for react.json (default out/react)")


def _robot_events(path: Path | None, cell, inputs: tuple[str, ...], threshold: float):
    """The robot's trajectory events, when the specification reads robot_in/robot_moving."""
    from ltl_human_motion.errors import CellError
    from ltl_human_motion.robot.events import robot_events
    if not any(k == "robot_moving" or k.startswith("robot_in(") for k in inputs):
        return None
    if path is None:
        path = Path(__file__).resolve().parents[2] / "config" / "ur_pick_place.yaml"
        if not path.is_file():
            return None
    try:
        return robot_events(path, cell, inputs, threshold)
    except ValueError as exc:
        raise CellError(f"--robot {path}: {exc}") from None


def run(args: argparse.Namespace) -> int:
    """Run ``react``; errors derive from LtlHumanMotionError (printed by the dispatcher)."""
    from ltl_human_motion.errors import CellError
    from ltl_human_motion.scene.cell_yaml import resolve_cell
    from ltl_human_motion.tasks.reactive import (
        TRACE_KINDS,
        UnrealizableError,
        draw_run,
        joint_satisfies,
        reactive_worker,
    )

    cell = resolve_cell(args.cell)
    t0 = time.perf_counter()
    try:
        worker = reactive_worker(args.spec, cell)
    except UnrealizableError as exc:
        print(f"ltl-human-motion react: {exc.message}", file=sys.stderr)
        return 2
    t_solve = time.perf_counter() - t0
    try:
        args.out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CellError(f"cannot create the output folder {args.out}: {exc.strerror}") from None
    library = None
    if not args.no_motion:
        from ltl_human_motion.planning import get_library
        library = get_library(float(args.stature))
    from ltl_human_motion.planning.reactive import RunMotions

    motions = None if library is None else RunMotions(worker, cell, library, int(args.seed),
                                                      float(args.stature))
    robot = _robot_events(args.robot, cell, worker.gr1.inputs, args.moving_threshold)

    records = []
    satisfied = verified = 0
    for i in range(args.traces):
        rng = np.random.default_rng([int(args.seed) & 0xFFFFFFFF, i])
        joint, source = draw_run(worker, rng, TRACE_KINDS[i % len(TRACE_KINDS)], robot)
        ok = joint_satisfies(worker, joint)
        satisfied += ok
        record = {
            "trace": i, "source": source,
            "run": {"prefix": [[sorted(k for k, v in x.items() if v), worker.tasks[t].key]
                               for x, t in zip(joint.prefix_inputs, joint.prefix_tasks)],
                    "cycle": [[sorted(k for k, v in x.items() if v), worker.tasks[t].key]
                              for x, t in zip(joint.cycle_inputs, joint.cycle_tasks)]},
            "spec_satisfied": bool(ok),
        }
        if motions is not None:
            t1 = time.perf_counter()
            m = motions.motion(joint)
            verified += m.verified
            record.update({"verified": m.verified, "motion_checks": m.motion_checks,
                           "observed_satisfies": m.observed_satisfies,
                           "duration": m.duration, "reaction_s": m.reaction,
                           "failed": m.failed, "detail": m.detail,
                           "motion_sha256": m.sha256, "attempts": m.attempts,
                           "motion_reused": m.cached,
                           "seconds": time.perf_counter() - t1})
        records.append(record)
        motion = ""
        if library is not None:
            motion = (f", motion {'verified' if record['verified'] else 'NOT verified'} "
                      f"({record['duration']:.1f} s)")
            if not record["verified"]:
                motion += ": " + ", ".join(record["failed"])
        print(f"trace {i} ({source}): {len(joint.prefix_tasks)}+{len(joint.cycle_tasks)} steps, "
              f"spec {'satisfied' if ok else 'VIOLATED'}{motion}", flush=True)
    result = {"spec": worker.specification.text, "cell": cell.name, "seed": args.seed,
              "realizable": True, "traces": args.traces, "spec_satisfied": satisfied,
              "verified": None if library is None else verified,
              "motions_planned": None if motions is None else motions.planned,
              "inputs": list(worker.gr1.inputs),
              "tasks": [t.key for t in worker.tasks],
              "assumptions": [c.text for c in worker.gr1.assumptions],
              "guarantees": [c.text for c in worker.gr1.guarantees],
              "plant_states": len(worker.plant.moves), "solve_seconds": t_solve,
              "sources": {k: sum(r["source"] == k for r in records) for k in TRACE_KINDS},
              "robot": None if robot is None else str(args.robot or "config/ur_pick_place.yaml"),
              "max_reaction_s": max((r["reaction_s"] for r in records
                                     if r.get("reaction_s") is not None), default=None),
              "records": records}
    atomic_write_text(args.out / "react.json", json.dumps(result, indent=1))
    print(f"realizable: strategy over {len(worker.tasks)} tasks, {len(worker.plant.moves)} "
          f"worker states, solved in {t_solve:.2f} s; {satisfied}/{args.traces} runs satisfy "
          "the specification"
          + ("" if motions is None else f", {verified}/{args.traces} motions verified "
             f"({motions.planned} task sequences planned)")
          + f"; wrote {args.out / 'react.json'}")
    return 0 if satisfied == args.traces else 1
