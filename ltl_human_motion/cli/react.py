"""``ltl-human-motion react``: a worker who reacts to the robot (GR(1), docs/reactive.md).

Solves the reactive specification on the cell's worker model, draws seeded random robot
behaviours that keep the assumptions, runs the strategy on each, synthesizes and verifies
each run's motion, and checks every joint trace against the whole specification. Writes
``DIR/react.json``; an unrealizable specification exits with code 2 and the explanation.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ltl_human_motion.cli._types import positive as _positive
from ltl_human_motion.cli._types import stature

NAME = "react"
HELP = ("synthesize a reactive worker (GR(1): robot events -> tasks) and verify its "
        "motions on random robot behaviours")


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
    parser.add_argument("--no-motion", action="store_true",
                        help="check the strategy's runs only; plan no motion")
    parser.add_argument("--out", type=Path, default=Path("out/react"),
                        help="output folder for react.json (default out/react)")


def _write_json(path: Path, data: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".react-", suffix=".json")
    try:
        with os.fdopen(fd, "w") as f:
            json.dump(data, f, indent=1)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def run(args: argparse.Namespace) -> int:
    """Run ``react``; errors derive from LtlHumanMotionError (printed by the dispatcher)."""
    from ltl_human_motion.errors import CellError
    from ltl_human_motion.scene.cell_yaml import resolve_cell
    from ltl_human_motion.tasks.reactive import (
        UnrealizableError,
        joint_satisfies,
        random_input_lasso,
        reactive_worker,
        run_strategy,
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
    from ltl_human_motion.planning.reactive import motion_of_run

    records = []
    satisfied = verified = 0
    for i in range(args.traces):
        rng = np.random.default_rng([int(args.seed) & 0xFFFFFFFF, i])
        prefix, cycle = random_input_lasso(worker, rng)
        joint = run_strategy(worker, prefix, cycle)
        ok = joint_satisfies(worker, joint)
        satisfied += ok
        record = {
            "trace": i,
            "inputs": {"prefix": [sorted(k for k, v in x.items() if v) for x in prefix],
                       "cycle": [sorted(k for k, v in x.items() if v) for x in cycle]},
            "run": {"prefix": [[sorted(k for k, v in x.items() if v), worker.tasks[t].key]
                               for x, t in zip(joint.prefix_inputs, joint.prefix_tasks)],
                    "cycle": [[sorted(k for k, v in x.items() if v), worker.tasks[t].key]
                              for x, t in zip(joint.cycle_inputs, joint.cycle_tasks)]},
            "spec_satisfied": bool(ok),
        }
        if library is not None:
            t1 = time.perf_counter()
            m = motion_of_run(worker, joint, cell, library, seed=int(args.seed) * 100003 + i,
                              stature=float(args.stature))
            verified += m.verified
            record.update({"verified": m.verified, "motion_checks": m.motion_checks,
                           "observed_satisfies": m.observed_satisfies,
                           "duration": m.duration, "failed": m.failed, "detail": m.detail,
                           "seconds": time.perf_counter() - t1})
        records.append(record)
        motion = ""
        if library is not None:
            motion = (f", motion {'verified' if record['verified'] else 'NOT verified'} "
                      f"({record['duration']:.1f} s)")
            if not record["verified"]:
                motion += ": " + ", ".join(record["failed"])
        print(f"trace {i}: {len(joint.prefix_tasks)}+{len(joint.cycle_tasks)} steps, "
              f"spec {'satisfied' if ok else 'VIOLATED'}{motion}", flush=True)
    result = {"spec": worker.specification.text, "cell": cell.name, "seed": args.seed,
              "realizable": True, "traces": args.traces, "spec_satisfied": satisfied,
              "verified": None if library is None else verified,
              "inputs": list(worker.gr1.inputs),
              "tasks": [t.key for t in worker.tasks],
              "assumptions": [c.text for c in worker.gr1.assumptions],
              "guarantees": [c.text for c in worker.gr1.guarantees],
              "plant_states": len(worker.plant.moves), "solve_seconds": t_solve,
              "records": records}
    _write_json(args.out / "react.json", result)
    print(f"realizable: strategy over {len(worker.tasks)} tasks, {len(worker.plant.moves)} "
          f"worker states, solved in {t_solve:.2f} s; {satisfied}/{args.traces} runs satisfy "
          "the specification"
          + ("" if library is None else f", {verified}/{args.traces} motions verified")
          + f"; wrote {args.out / 'react.json'}")
    return 0 if satisfied == args.traces else 1
