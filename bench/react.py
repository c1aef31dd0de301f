"""Reactive worker (issue 36): the done-when run and the synthesis target.

1. ``ltl-human-motion react`` on the paper cell with :data:`SPEC`
   (``(G F !robot_in(R1)) -> (G(robot_in(R1) -> X !assemble(R1)) & G F grasp(O1) &
   G F assemble(R1))``) over ``--traces`` robot behaviours (default 200; steps, timed
   and the UR trajectory in turn): runs satisfying the specification, motions verified,
   the longest wait step. The same guarantees without the assumption must be refused
   as unrealizable.
2. Synthesis of a specification with 6 inputs and 12 tasks on the paper cell (with a
   declared ``door_open`` input): realizability and the strategy, target <= 1 s.
3. ``--strategy-traces`` (default 10,000) robot behaviours on the paper specification,
   strategy only (no motion): runs satisfying the whole specification, target 100 %.
4. ``--motion-traces`` (default 10,000) robot behaviours on the demo's specification
   (:data:`~ltl_human_motion.tasks.reactive.DEMO_SPEC`) with motions: runs satisfying
   the specification (target 100 %) and verified motions (target >= 99 %), within
   ``--budget`` seconds (default 1800): the traces run in that time are reported as run,
   the target is not changed. A run's motion is its task sequence's, planned and
   verified once (:class:`~ltl_human_motion.planning.reactive.RunMotions`); each run's
   observed letters with its own inputs are checked against the whole specification, and
   ``--recheck`` sequences are planned again from scratch and must give the same bytes.

``--only PART`` (repeatable) runs some parts and keeps the others' saved results.

Prints the numbers and writes ``bench/results/react.json`` (the per-trace report goes to
``out/bench_react/react.json``). Not a test: run ``python bench/react.py``.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.cli import main  # noqa: E402
from ltl_human_motion.robot.events import robot_events  # noqa: E402
from ltl_human_motion.scene.cell_yaml import cell_from_yaml, resolve_cell  # noqa: E402
from ltl_human_motion.tasks.reactive import (  # noqa: E402
    DEMO_SPEC,
    TRACE_KINDS,
    draw_run,
    joint_satisfies,
    reactive_worker,
)

GUARANTEES = "G(robot_in(R1) -> X !assemble(R1)) & G F grasp(O1) & G F assemble(R1)"
SPEC = f"(G F !robot_in(R1)) -> ({GUARANTEES})"

#: Six inputs (five built in, one declared by the cell) and twelve tasks.
LARGE_ASSUMPTIONS = ["G F !robot_in(R1)", "G F !robot_in(R0)", "G F !robot_moving",
                     "G F offered(O1)", "G F offered(O2)", "G F !door_open"]
LARGE_GUARANTEES = [
    "G(robot_in(R1) -> X !(assemble(R1) | leftHand(R1)))",
    "G(robot_in(R0) -> X !(move(O1, R0) | move(O2, R0)))",
    "G(robot_moving -> X !(carry(O1, R1) | carry(O2, R1)))",
    "G(door_open -> X !(walk(R0) | walk(R1)))",
    "G(offered(O1) -> X !release(O1))", "G(offered(O2) -> X !release(O2))",
    "G F grasp(O1)", "G F grasp(O2)", "G F assemble(R1)"]


def done_when(traces: int, seed: int) -> dict:
    out = ROOT / "out" / "bench_react"
    t0 = time.perf_counter()
    code = main(["react", "--cell", "config/paper_cell.yaml", "--spec", SPEC, "--traces",
                 str(traces), "--seed", str(seed), "--out", str(out)])
    wall = time.perf_counter() - t0
    report = json.loads((out / "react.json").read_text())
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        refused = main(["react", "--cell", "config/paper_cell.yaml", "--spec", GUARANTEES,
                        "--traces", "5", "--out", str(out / "unrealizable")])
    seconds = [r["seconds"] for r in report["records"]]
    return {"spec": SPEC, "exit_code": code, "traces": report["traces"],
            "spec_satisfied": report["spec_satisfied"], "verified": report["verified"],
            "realizable": report["realizable"], "sources": report["sources"],
            "motions_planned": report["motions_planned"],
            "max_reaction_s": report["max_reaction_s"], "solve_seconds": report["solve_seconds"],
            "motion_seconds_median": statistics.median(seconds),
            "planned_motion_seconds_median": statistics.median(
                r["seconds"] for r in report["records"] if not r["motion_reused"]),
            "wall_seconds": wall,
            "not_verified": [{"trace": r["trace"], "failed": r["failed"]}
                             for r in report["records"] if not r["verified"]],
            "without_assumption": {"exit_code": refused, "message": err.getvalue().strip()}}


def large_synthesis(repeats: int) -> dict:
    text = (ROOT / "config" / "paper_cell.yaml").read_text() \
        + "\ninputs:\n  door_open: /cell/door_open\n"
    cell = cell_from_yaml(text, source="paper_cell + door_open", base_dir=ROOT / "config")
    spec = f"({' & '.join(LARGE_ASSUMPTIONS)}) -> ({' & '.join(LARGE_GUARANTEES)})"
    times, worker = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        worker = reactive_worker(spec, cell)
        times.append(time.perf_counter() - t0)
    return {"spec": spec, "inputs": len(worker.gr1.inputs),
            "tasks": len(worker.specification.tasks), "worker_states": len(worker.plant.moves),
            "seconds": times, "median_seconds": statistics.median(times), "target_seconds": 1.0}


def strategy_only(traces: int, seed: int) -> dict:
    import numpy as np

    cell = resolve_cell("paper_cell")
    worker = reactive_worker(SPEC, cell)
    robot = robot_events(ROOT / "config" / "ur_pick_place.yaml", cell, worker.gr1.inputs)
    t0 = time.perf_counter()
    satisfied, lengths, sources = 0, [], dict.fromkeys(TRACE_KINDS, 0)
    for i in range(traces):
        rng = np.random.default_rng([seed, i])
        run, source = draw_run(worker, rng, TRACE_KINDS[i % len(TRACE_KINDS)], robot)
        satisfied += joint_satisfies(worker, run)
        sources[source] += 1
        lengths.append(len(run.prefix_tasks) + len(run.cycle_tasks))
    return {"traces": traces, "spec_satisfied": satisfied, "sources": sources,
            "steps_median": statistics.median(lengths), "steps_max": max(lengths),
            "seconds": time.perf_counter() - t0}


def motion_target(traces: int, seed: int, budget: float, recheck: int) -> dict:
    """``traces`` robot behaviours on :data:`DEMO_SPEC` with motions, until ``budget`` s.

    Each run's motion is its task sequence's (:class:`RunMotions`: planned and verified
    once per sequence, the same bytes for every run with it); every run's observed
    letters, joined with its own inputs, are checked against the whole specification.
    ``recheck`` sequences are planned again without the cache and must hash the same.
    """
    import numpy as np

    from ltl_human_motion.planning import get_library
    from ltl_human_motion.planning.reactive import RunMotions

    cell = resolve_cell("paper_cell")
    worker = reactive_worker(DEMO_SPEC, cell)
    robot = robot_events(ROOT / "config" / "ur_pick_place.yaml", cell, worker.gr1.inputs)
    library = get_library(1.75)
    motions = RunMotions(worker, cell, library, seed, 1.75)
    t0 = time.perf_counter()
    run = satisfied = verified = reused = 0
    t_draw = t_motion = 0.0
    failed: dict[str, int] = {}
    sequences: dict[tuple, dict] = {}
    for i in range(traces):
        if time.perf_counter() - t0 > budget:
            break
        t1 = time.perf_counter()
        rng = np.random.default_rng([seed, 1_000_000 + i])
        joint, _ = draw_run(worker, rng, TRACE_KINDS[i % len(TRACE_KINDS)], robot)
        satisfied += joint_satisfies(worker, joint)
        t2 = time.perf_counter()
        m = motions.motion(joint)
        t_motion += time.perf_counter() - t2
        t_draw += t2 - t1
        verified += m.verified
        reused += m.cached
        for name in m.failed:
            failed[name] = failed.get(name, 0) + 1
        seq = sequences.setdefault((joint.prefix_tasks, joint.cycle_tasks), {
            "tasks": len(joint.prefix_tasks) + len(joint.cycle_tasks), "runs": 0,
            "sha256": m.sha256, "attempts": m.attempts, "motion_checks": m.motion_checks,
            "failed": [k for k in m.failed if k != "reactive_ltl"], "detail": m.detail,
            "rejected_draws": list(motions.sequence_motion(
                joint.prefix_tasks, joint.cycle_tasks)[0].rejected)})
        seq["runs"] += 1
        run += 1
    seconds = time.perf_counter() - t0
    retried = [dict(v, prefix=[worker.tasks[k].key for k in p],
                    cycle=[worker.tasks[k].key for k in c])
               for (p, c), v in sequences.items() if v["attempts"] > 1 or not v["motion_checks"]]
    # Reuse is only honest where the motion is the same bytes: plan some sequences again
    # (a fresh cache) and compare their hashes.
    fresh = RunMotions(worker, cell, library, seed, 1.75, cache_size=1)
    picked = sorted(sequences, key=lambda k: -sequences[k]["runs"])[:recheck]
    same = sum(fresh.sequence_motion(*k)[0].sha256 == sequences[k]["sha256"] for k in picked)
    lengths = [v["tasks"] for v in sequences.values()]
    return {"spec": DEMO_SPEC, "target_traces": traces, "traces_run": run,
            "spec_satisfied": satisfied, "verified": verified,
            "verified_fraction": verified / run if run else None, "failed_checks": failed,
            "task_sequences": len(sequences), "motions_planned": motions.planned,
            "draws_planned": motions.draws, "runs_reusing_a_motion": reused,
            "sequence_tasks_median": statistics.median(lengths) if lengths else None,
            "sequence_tasks_max": max(lengths, default=None),
            "sequences_verified": sum(v["motion_checks"] for v in sequences.values()),
            "sequences_retried_or_failed": retried,
            "recheck": {"sequences": len(picked), "byte_identical": same},
            "draw_and_check_seconds": t_draw, "motion_seconds": t_motion,
            "budget_seconds": budget, "seconds": seconds, "complete": run == traces}


def main_bench() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--traces", type=int, default=200)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--strategy-traces", type=int, default=10000)
    parser.add_argument("--motion-traces", type=int, default=10000)
    parser.add_argument("--budget", type=float, default=1800.0,
                        help="seconds for the --motion-traces run (default 1800)")
    parser.add_argument("--recheck", type=int, default=20,
                        help="task sequences planned again to check their motion's bytes")
    parser.add_argument("--only", choices=("done_when", "synthesis", "strategy", "motion"),
                        action="append", help="run only these parts (default all); the "
                        "others keep their saved results")
    args = parser.parse_args()
    path = ROOT / "bench" / "results" / "react.json"
    parts = {"done_when": ("done_when", lambda: done_when(args.traces, args.seed)),
             "synthesis": ("synthesis_6_inputs_12_tasks",
                           lambda: large_synthesis(args.repeats)),
             "strategy": ("strategy_only",
                          lambda: strategy_only(args.strategy_traces, args.seed)),
             "motion": ("motion_10k", lambda: motion_target(
                 args.motion_traces, args.seed, args.budget, args.recheck))}
    only = args.only or list(parts)
    result = json.loads(path.read_text()) if args.only and path.is_file() else {}
    loads = {"cpus": os.cpu_count(), "load_before": os.getloadavg()}
    for name in only:
        key, run = parts[name]
        result[key] = run()
        result[key]["load_after"] = os.getloadavg()
    kept = result.get("machine", {})
    result["machine"] = {**loads, "load_after": os.getloadavg(), "parts_run": only}
    if len(only) < len(parts) and kept:
        # The machine of the parts kept from the saved results.
        result["machine"]["kept_parts_machine"] = kept.get("kept_parts_machine", kept)
    d, s = result.get("done_when"), result.get("synthesis_6_inputs_12_tasks")
    o, m = result.get("strategy_only"), result.get("motion_10k")
    if d and "done_when" in only:
        print(f"paper cell: {d['spec_satisfied']}/{d['traces']} satisfied, {d['verified']}/"
              f"{d['traces']} verified, longest wait step {d['max_reaction_s']:.3f} s, "
              f"{d['wall_seconds']:.0f} s; without the assumption exit "
              f"{d['without_assumption']['exit_code']}")
    if s and "synthesis" in only:
        print(f"synthesis, {s['inputs']} inputs and {s['tasks']} tasks ({s['worker_states']} "
              f"worker states): median {s['median_seconds']:.3f} s (target <= 1 s)")
    if o and "strategy" in only:
        print(f"strategy only: {o['spec_satisfied']}/{o['traces']} runs satisfy the "
              f"specification ({o['seconds']:.0f} s)")
    if m and "motion" in only:
        print(f"demo specification with motions: {m['traces_run']}/{m['target_traces']} traces "
              f"run in {m['seconds']:.0f} s (budget {m['budget_seconds']:.0f} s), "
              f"{m['spec_satisfied']}/{m['traces_run']} satisfy the specification, "
              f"{m['verified']}/{m['traces_run']} motions verified (target >= 99 %); "
              f"{m['task_sequences']} task sequences, {m['motions_planned']} motions planned "
              f"({m['draws_planned']} draws), {m['recheck']['byte_identical']}/"
              f"{m['recheck']['sequences']} re-planned byte-identical"
              + ("" if m["complete"] else "; the target's count was not reached in the budget"))
    print(f"load: {loads['load_before']} before, {result['machine']['load_after']} after")
    atomic_write_text(path, json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main_bench())
