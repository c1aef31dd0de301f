"""Benchmark: motion-graph build time versus the number of gait primitives.

Larger primitive sets come from augmenting the real DeepMimic walk loops (shipped with
pybullet): left/right mirroring, small time warps (playback speed 0.85 to 1.15) and, when
needed, body sizes. For each size the graph build is timed: start/end windows, all-pairs
closed-form transition distances (blocked, vectorized), thresholding and the strongly
connected component. Prints a table and writes ``bench/results/motion_graph.json``.

    .venv/bin/python bench/motion_graph.py [--sizes 1000 5000 20000] [--repeats 3]
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

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.motion import deepmimic, gait  # noqa: E402
from ltl_human_motion.motion.automaton import build_transitions, largest_scc, window_positions  # noqa: E402
from ltl_human_motion.motion.library import DEFAULT_LIBRARY_DELTA  # noqa: E402
from ltl_human_motion.motion.skeleton import Skeleton  # noqa: E402
from ltl_human_motion.motion.types import Motion  # noqa: E402


def primitive_pool(n: int, k_comp: int = 5) -> list:
    """At least ``n`` gait primitives from augmented real clips (first n returned)."""
    clips = [deepmimic.motions_dir() / c for c in deepmimic.DEFAULT_GAIT_CLIPS]
    warps = (1.0, 0.94, 1.06, 0.88, 1.12, 0.85, 1.15, 0.91, 1.09)
    statures = (1.75, 1.60, 1.90)
    pool: list = []
    for stature in statures:
        skeleton = Skeleton(stature)
        motions = [deepmimic.load(c, skeleton) for c in clips]
        for warp in warps:
            for path, m in zip(clips, motions):
                warped = Motion(m.positions, m.fps * warp, skeleton, m.name)
                for mirror in (False, True):
                    clip = gait.prepare_loop(warped, f"{path.stem}_w{warp:.2f}_s{stature}",
                                             str(path), mirror=mirror)
                    pool += gait.gait_primitives(clip, skeleton, phase_step=1,
                                                 overlap=k_comp)
                    if len(pool) >= n:
                        return pool[:n]
    raise RuntimeError(f"augmentation gives only {len(pool)} primitives, asked for {n}")


def build_graph(prims: list, delta: float, k_comp: int = 5, dtype=np.float32) -> dict:
    t0 = time.perf_counter()
    ends = window_positions(prims, k_comp, end=True)
    begins = window_positions(prims, k_comp, end=False)
    t1 = time.perf_counter()
    D = build_transitions(ends, begins, delta, dtype=dtype)
    t2 = time.perf_counter()
    carry = np.array([mp.task == "carry" for mp in prims])
    sizes = [largest_scc(D, np.nonzero(carry == flag)[0]).size for flag in (False, True)]
    t3 = time.perf_counter()
    return {"windows_s": t1 - t0, "distances_s": t2 - t1, "scc_s": t3 - t2,
            "total_s": t3 - t0, "edges": int(D.nnz), "scc": sizes}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[1000, 5000, 20000])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--delta", type=float, default=DEFAULT_LIBRARY_DELTA)
    parser.add_argument("--out", type=Path, default=ROOT / "bench" / "results" /
                        "motion_graph.json")
    args = parser.parse_args(argv)
    t0 = time.perf_counter()
    pool = primitive_pool(max(args.sizes))
    t_pool = time.perf_counter() - t0
    rows = []
    print(f"primitive pool: {len(pool)} primitives from augmented DeepMimic loops in "
          f"{t_pool:.1f} s")
    print(f"{'primitives':>10} {'median s':>9} {'min s':>7} {'distances s':>12} "
          f"{'edges':>9} {'SCC walk/carry':>15}")
    for n in args.sizes:
        runs = [build_graph(pool[:n], args.delta) for _ in range(args.repeats)]
        totals = [r["total_s"] for r in runs]
        row = {"primitives": n, "repeats": args.repeats,
               "median_s": statistics.median(totals), "min_s": min(totals),
               "median_distances_s": statistics.median(r["distances_s"] for r in runs),
               "median_windows_s": statistics.median(r["windows_s"] for r in runs),
               "median_scc_s": statistics.median(r["scc_s"] for r in runs),
               "edges": runs[0]["edges"], "scc": runs[0]["scc"], "runs_s": totals}
        rows.append(row)
        print(f"{n:>10} {row['median_s']:>9.2f} {row['min_s']:>7.2f} "
              f"{row['median_distances_s']:>12.2f} {row['edges']:>9} "
              f"{row['scc'][0]:>7}/{row['scc'][1]:<7}")
    if len(rows) >= 2:
        ns = np.array([r["primitives"] for r in rows], float)
        ts = np.array([r["median_s"] for r in rows], float)
        exponent = float(np.polyfit(np.log(ns), np.log(ts), 1)[0])
        print(f"scaling: time ~ N^{exponent:.2f}")
    else:
        exponent = None
    result = {"benchmark": "motion_graph", "delta": args.delta, "k_comp": 5,
              "pool_build_s": t_pool, "rows": rows, "scaling_exponent": exponent,
              "cpus": os.cpu_count(), "python": platform.python_version(),
              "numpy": np.__version__, "machine": platform.machine(),
              "target": "20000 primitives < 60 s on 2 cores"}
    atomic_write_text(args.out, json.dumps(result, indent=2) + "\n")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
