"""Benchmark of the whole pipeline on the paper's S1 and S2 (Sec. IV, Tab. III).

For each specification: the time of every stage (automaton, task sequence, motion
planning, skeleton/blending, verification), the end-to-end time and the real-time factor
(seconds of motion made per second of computation), as medians over ``--repeat`` runs
with different seeds, the motion library already built (it is cached on disk; its load
time is reported separately). The task-sequence cache is cleared before every run, so
each run pays for the automaton and the sequences. Prints a table and writes
``bench/results/paper_specs.json``.
Not a test: run ``python bench/paper_specs.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.planning import pipeline  # noqa: E402
from ltl_human_motion.planning.pipeline import get_library, resolve_cell, synthesize  # noqa: E402
from ltl_human_motion.reproduce import PAPER_TIMES  # noqa: E402

STAGES = ("automaton_time", "sequence_time", "planning_time", "blending_time",
          "verification_time", "total_time")


def machine() -> dict:
    """What the numbers were measured on."""
    cpu = platform.processor()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
            "system": platform.platform()}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--cycles", type=int, default=1)
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" /
                        "paper_specs.json")
    args = parser.parse_args(argv)
    cell = resolve_cell("paper_cell")
    t0 = time.perf_counter()
    get_library.cache_clear()
    library = get_library()
    library_load = time.perf_counter() - t0
    synthesize("S1", cell, library=library)          # warm caches (clearance maps, index)
    results: dict = {}
    for name in ("S1", "S2"):
        runs = []
        for seed in range(args.repeat):
            pipeline._SEQUENCE_CACHE.clear()        # time the LTL stages too, every run
            t = time.perf_counter()
            synth = synthesize(name, cell, library=library, seed=seed, cycles=args.cycles)[0]
            wall = time.perf_counter() - t
            run = {k: getattr(synth.stats, k) for k in STAGES}
            run.update(wall=wall, duration=synth.motion.duration,
                       nodes=synth.stats.nodes_expanded,
                       verified=bool(synth.verification["passed"]))
            runs.append(run)
        med = {k: statistics.median(r[k] for r in runs) for k in (*STAGES, "wall", "duration")}
        med["real_time_factor"] = statistics.median(r["duration"] / r["wall"] for r in runs)
        med["nodes_expanded"] = statistics.median(r["nodes"] for r in runs)
        results[name] = {"median": med, "runs": runs,
                         "all_verified": all(r["verified"] for r in runs),
                         "paper": PAPER_TIMES[name],
                         "speedup_vs_paper": PAPER_TIMES[name]["total"] / med["wall"]}
    report = {"benchmark": "paper_specs", "machine": machine(), "repeat": args.repeat,
              "cycles": args.cycles, "library_load_s": library_load, "results": results}
    print(f"library load (cached): {library_load:.2f} s")
    print(f"{'stage [s], median':32s} {'S1':>9s} {'S2':>9s}")
    for k in (*STAGES, "wall", "duration", "real_time_factor", "nodes_expanded"):
        print(f"{k:32s} {results['S1']['median'][k]:9.4f} {results['S2']['median'][k]:9.4f}")
    print(f"{'speed-up vs the paper':32s} {results['S1']['speedup_vs_paper']:9.0f} "
          f"{results['S2']['speedup_vs_paper']:9.0f}")
    args.out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(args.out, json.dumps(report, indent=2))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
