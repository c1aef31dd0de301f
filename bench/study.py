"""Benchmark of a cell-study item: synthesis, verification, ergonomics, offline SSM.

For ``--items`` items of a study of S2 on the paper cell (stature grid 1.6/1.75/1.9 m,
parts jittered by 5 cm, the UR5e of config/ur_pick_place.yaml next to the bench) it runs
the batch worker's ``run_item`` with the study's assessment in this process and reports
medians of:

* the CPU time of a full item and the items per minute per core it allows (target 600);
* the time of each part: planning, blending, verification (from the synthesis stats),
  ergonomics (REBA, RULA, NIOSH), cycle time, offline SSM, and the item without its
  assessment (CPU: the item less those parts, the ceiling of the item rate);
* the offline SSM's speed-up over real time (motion seconds per CPU second, target 100),
  reactive and with 0.5 s of predicted occupancy.

CPU times (``time.process_time``) are used where the machine is shared: they are less
sensitive to other jobs than wall-clock times (the parts from the synthesis stats and
the pool study are wall clock).

Then a small study on a 2-worker process pool gives the wall-clock rate including
worker start-up and the report. Prints a table and writes ``bench/results/study.json``.
Run ``python bench/study.py`` (about a minute on 2 cores).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402

TARGET_PER_CORE = 600.0        # full study items per minute per core (issue 15)
TARGET_SSM_SPEEDUP = 100.0     # offline SSM: motion seconds per computing second
ROBOT = str(ROOT / "config" / "ur_pick_place.yaml")


def _median(xs: list[float]) -> float:
    return float(statistics.median(xs)) if xs else float("nan")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--items", type=int, default=20)
    ap.add_argument("--pool-items", type=int, default=12,
                    help="items per layout of the process-pool study (0: skip it)")
    args = ap.parse_args()

    from ltl_human_motion.assess import assess_motion, cycle_breakdown
    from ltl_human_motion.batch.items import cell_for_item, derive_item
    from ltl_human_motion.batch.runner import make_job
    from ltl_human_motion.batch.worker import (
        ItemAssessment,
        _cell_and_options,
        prepare_worker,
        run_item,
    )
    from ltl_human_motion.planning.pipeline import get_library, synthesize
    from ltl_human_motion.robot.offline_ssm import run_offline_ssm
    from ltl_human_motion.study.item import _robot, assess_item, assess_settings
    from ltl_human_motion.study.runner import StudyConfig, _specs, run_study

    cfg = StudyConfig(cells=["paper_cell"], spec="S2", statures=(1.6, 1.75, 1.9),
                      robot=ROBOT)
    specs = _specs(cfg, ["O1", "O2"])
    settings = assess_settings(ROBOT)
    job, _ = make_job("paper_cell", specs)
    from dataclasses import replace
    job = replace(job, assess=ItemAssessment(assess_item, settings),
                  statures=(1.6, 1.75, 1.9))
    prepare_worker(job)
    run_item(job, derive_item(specs, 0, 10_000))         # warm-up (caches, imports)

    cpu, wall, parts = [], [], {k: [] for k in ("planning_time", "blending_time",
                                                "verification_time", "assess_time")}
    studied, failed = [], []
    for i in range(args.items):
        c0, t0 = time.process_time(), time.perf_counter()
        res = run_item(job, derive_item(specs, 0, i))
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - t0)
        (studied if "study" in res.record else failed).append(i)
        for k in parts:
            if k in res.timing:
                parts[k].append(res.timing[k])
    # The assessment's parts, on the same items' motions.
    base_cell, options = _cell_and_options(job)
    traj, model, base = _robot(json.dumps(settings["robot"], sort_keys=True))
    ergo_t, cyc_t, ssm_t, ssm_pred_t, speedup, speedup_pred = ([] for _ in range(6))
    for i in studied:
        item = derive_item(specs, 0, i)
        cell = cell_for_item(base_cell, item)
        synth = synthesize(item.spec, cell, library=get_library(item.stature,
                                                                options.library_source),
                           variants=1, seed=item.seed, stature=item.stature,
                           options=options)[0]
        t0 = time.process_time()
        assess_motion(synth, {n: o.mass for n, o in cell.objects.items()})
        ergo_t.append(time.process_time() - t0)
        t0 = time.process_time()
        cycle_breakdown(synth)
        cyc_t.append(time.process_time() - t0)
        t0 = time.process_time()
        run_offline_ssm(synth.positions, synth.fps, traj, model, base, stature=item.stature)
        ssm_t.append(time.process_time() - t0)
        speedup.append(synth.duration / ssm_t[-1])
        t0 = time.process_time()
        run_offline_ssm(synth.positions, synth.fps, traj, model, base, stature=item.stature,
                        prediction_horizon=0.5)
        ssm_pred_t.append(time.process_time() - t0)
        speedup_pred.append(synth.duration / ssm_pred_t[-1])

    pool = None
    if args.pool_items > 0:
        with tempfile.TemporaryDirectory() as tmp:
            scfg = StudyConfig(cells=["config/paper_cell.yaml", "config/paper_cell_b.yaml"],
                               spec="S2", variants=max(args.pool_items // 3, 1),
                               statures=(1.6, 1.75, 1.9), robot=ROBOT, out=Path(tmp),
                               workers=2)
            t0 = time.perf_counter()
            data = run_study(scfg, progress=False)
            elapsed = time.perf_counter() - t0
            n = sum(b["computed"] for b in data["batches"])
            pool = {"items": n, "workers": 2, "elapsed_s": elapsed,
                    "items_per_minute": 60.0 * n / elapsed,
                    "items_per_minute_per_core": 60.0 * n / elapsed / 2,
                    "note": "wall clock: worker start-up per layout, report included"}

    # The item without its assessment (synthesis, verification, packing): per item, the
    # full item's CPU time less its parts measured above; the ceiling of the item rate.
    rest = [cpu[i] - e - c - m for i, e, c, m in zip(studied, ergo_t, cyc_t, ssm_t)]
    per_core = 60.0 / _median(cpu)
    result = {
        "machine": {"platform": platform.platform(), "python": platform.python_version(),
                    "cpus": os.cpu_count(), "load_average": list(os.getloadavg())},
        "items": args.items, "items_failed": failed,
        "item_cpu_s_median": _median(cpu), "item_wall_s_median": _median(wall),
        "items_per_minute_per_core": per_core, "target_per_core": TARGET_PER_CORE,
        "parts_s_median": {k: _median(v) for k, v in parts.items()},
        "synthesis_cpu_s_median": _median(rest),
        "items_per_minute_per_core_synthesis_only": 60.0 / _median(rest),
        "ergonomics_s_median": _median(ergo_t), "cycle_s_median": _median(cyc_t),
        "offline_ssm_s_median": _median(ssm_t),
        "offline_ssm_predictive_s_median": _median(ssm_pred_t),
        "offline_ssm_speedup_median": _median(speedup),
        "offline_ssm_predictive_speedup_median": _median(speedup_pred),
        "target_ssm_speedup": TARGET_SSM_SPEEDUP,
        "pool_study": pool,
    }
    print(f"study item (S2, paper cell, UR5e), {args.items} items ({len(failed)} failed: "
          f"timed all the same, their parts left out), load {os.getloadavg()[0]:.1f}:")
    print(f"  full item: {result['item_cpu_s_median'] * 1e3:.0f} ms CPU -> "
          f"{per_core:.0f} items/min/core (target {TARGET_PER_CORE:.0f})")
    for k, v in result["parts_s_median"].items():
        print(f"    {k}: {v * 1e3:.1f} ms (wall)")
    print(f"    without the assessment (synthesis, verification, packing): "
          f"{result['synthesis_cpu_s_median'] * 1e3:.0f} ms CPU (at most "
          f"{result['items_per_minute_per_core_synthesis_only']:.0f} items/min/core)")
    print(f"    ergonomics {result['ergonomics_s_median'] * 1e3:.1f} ms, cycle "
          f"{result['cycle_s_median'] * 1e3:.1f} ms, offline SSM "
          f"{result['offline_ssm_s_median'] * 1e3:.1f} ms (predictive "
          f"{result['offline_ssm_predictive_s_median'] * 1e3:.1f} ms), CPU")
    print(f"  offline SSM speed-up over real time: {result['offline_ssm_speedup_median']:.0f}x"
          f" reactive, {result['offline_ssm_predictive_speedup_median']:.0f}x predictive "
          f"(target {TARGET_SSM_SPEEDUP:.0f}x)")
    if pool:
        print(f"  study on 2 workers: {pool['items']} items in {pool['elapsed_s']:.1f} s = "
              f"{pool['items_per_minute']:.0f}/min ({pool['items_per_minute_per_core']:.0f}"
              f"/min/core, start-up and report included)")
    out = ROOT / "bench" / "results" / "study.json"
    atomic_write_text(out, json.dumps(result, indent=2) + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
