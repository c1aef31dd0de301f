"""How often synthesis works in many cells: the scenario corpus and generated cells.

Runs every labelled (cell, specification) pair of ``scenarios/specs.yaml`` for each
stature in ``--statures`` and each seed in ``range(--seeds)``, plus ``--generated``
cells of the seeded random generator (:mod:`ltl_human_motion.scenarios.generator`),
on a process pool of at most 2 workers, each pair with a time limit. Each worker first
synthesizes a few warm-up pairs at each stature (:data:`WARM_UP`: the motion libraries
and the compiled kernels are loaded once, not in the first pairs' times; on a fresh
clone the kernels compile then). Prints and writes ``bench/results/scenarios.json``:

* the verified rate on feasible pairs and the correct-refusal rate on infeasible ones;
* failures by family (planning: which task and why; verification: which check);
* median and maximum time per pair;
* a short table per cell;
* the unseen-style family (:mod:`ltl_human_motion.scenarios.unseen`: machine chambers,
  boards, desks, conveyors, aisles, two-handed parts at three statures, labelled from
  geometry) in its own section: per family the verified and refusal rates, CPU time per
  run (median, max, runs over 2 s) and the failures grouped by cause (the first words
  of the refusal or verification message, :func:`~ltl_human_motion.scenarios.run.
  failure_cause`).

Not a test: run ``python bench/scenarios.py`` (``--quick`` for a short look,
``--cells shelf_heights bins``, ``--limit 50``; ``--no-biomechanics`` verifies without
the biomechanical checks, which are on by default; ``--family unseen`` only the unseen
family, ``--unseen-cells 0`` without it).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
from collections import Counter, defaultdict
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.scenarios.corpus import default_specs_path, load_corpus  # noqa: E402
from ltl_human_motion.scenarios.run import (  # noqa: E402
    failure_cause,
    judge,
    prepare_cell,
    run_pair,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paper_specs import machine  # noqa: E402

#: At most two workers: the machine has two cores, shared with other jobs.
MAX_WORKERS = 2
#: Random cells of the generator in a default run (each with its own stature and about
#: 12 labelled pairs): enough to see a family that 10 cells of one seed miss.
GENERATED_CELLS = 30
#: Seconds a pair may take before it counts as a timeout (the target is 2 s per pair;
#: the limit only keeps a hopeless search from stalling the benchmark).
DEFAULT_TIMEOUT = 10.0
#: Cells of each unseen-style family in a default run (each at the three statures with
#: about 8 labelled pairs: some 270 runs).
UNSEEN_CELLS = 2


def _job(item: dict) -> dict:
    """Run one (pair, stature, seed) in a worker; returns the item with its outcome."""
    cell = item["cell_yaml"] if item.get("cell_yaml") else item["cell_file"]
    outcome = run_pair(item["spec"], cell, item["stature"], item["seed"], item["timeout"],
                       biomechanics=item.get("biomechanics", True))
    ok, family = judge(item["expect"], item.get("reason"), outcome)
    out = {k: v for k, v in item.items() if k != "cell_yaml"}
    out.update(outcome=outcome.as_dict(), ok=ok, family=family,
               cause=None if ok else failure_cause(outcome.message, family))
    return out


#: Pairs each worker synthesizes at each stature before it takes any job: the motion
#: library of the stature is built and every compiled kernel loaded (or compiled, on a
#: fresh clone: tens of seconds) once, not within the first pairs' times. A walk, a grasp
#: beside crates and a cart (the posture search's obstacle clearances) and an assembly.
WARM_UP = (("config/paper_cell.yaml", "S1"),
           ("scenarios/cells/cluttered.yaml", "F grasp(O2)"))


def _warm_up(statures: list[float], biomechanics: bool) -> None:
    """Pool initializer: :data:`WARM_UP` at each of ``statures`` (their outcomes are not
    counted)."""
    for stature in statures:
        for cell, spec in WARM_UP:
            run_pair(spec, str(ROOT / cell), stature, 0, 60.0, biomechanics=biomechanics)


def _prepare(item: dict) -> tuple[str, float]:
    """Build a cell's planner fields in a worker (once per layout); (cell, seconds)."""
    return item["cell"], prepare_cell(item["cell_yaml"] or item["cell_file"])


def _spread(pairs: list, limit: int) -> list:
    """At most ``limit`` pairs, taken round-robin over the families (deterministic)."""
    if limit <= 0 or limit >= len(pairs):
        return pairs
    by_family: dict[str, dict[str, list]] = defaultdict(lambda: defaultdict(list))
    for p in pairs:
        by_family[p.family][p.cell].append(p)
    queues = []
    for k, per_cell in enumerate(by_family.values()):  # interleave the cells of a family,
        lists = list(per_cell.values())                # each family from another cell on
        lists = lists[k % len(lists):] + lists[:k % len(lists)]
        queues.append([q[i] for i in range(max(map(len, lists))) for q in lists if i < len(q)])
    chosen: list = []
    while len(chosen) < limit:
        for q in queues:
            if q and len(chosen) < limit:
                chosen.append(q.pop(0))
    return chosen


def _items(args) -> list[dict]:
    pairs = [] if args.no_corpus else _spread(load_corpus(args.specs, args.cells), args.limit)
    items = []
    for p in pairs:
        for stature in args.statures:
            for seed in range(args.seeds):
                items.append({"source": "corpus", "id": p.id, "cell": p.cell,
                              "cell_file": p.cell_file, "spec": p.spec, "expect": p.expect,
                              "reason": p.reason, "family_label": p.family,
                              "stature": stature, "seed": seed, "timeout": args.timeout,
                              "biomechanics": not args.no_biomechanics})
    if args.generated > 0:
        from ltl_human_motion.scenarios.generator import generate_scenarios
        for scen in generate_scenarios(args.generated, seed=args.generator_seed):
            for gp in scen.pairs:
                items.append({"source": "generated", "id": f"{scen.name}/{gp.spec}",
                              "cell": scen.name, "cell_file": None, "cell_yaml": scen.yaml,
                              "spec": gp.spec, "expect": gp.expect, "reason": gp.reason,
                              "family_label": gp.family, "stature": scen.stature,
                              "seed": 0, "timeout": args.timeout,
                              "biomechanics": not args.no_biomechanics})
    if args.unseen_cells > 0:
        items.extend(_unseen_items(args))
    return items


def _unseen_items(args) -> list[dict]:
    """The unseen-style family's runs: every labelled pair of every cell at each stature
    (the labels differ by stature) and each seed in ``range(--unseen-seeds)``."""
    from ltl_human_motion.scenarios.unseen import FAMILIES, generate_unseen
    families = tuple(args.unseen_families or FAMILIES)
    unknown = sorted(set(families) - set(FAMILIES))
    if unknown:
        raise ValueError(f"unknown unseen families {unknown}; expected {', '.join(FAMILIES)}")
    items = []
    for scen in generate_unseen(args.unseen_cells, seed=args.generator_seed,
                                families=families, statures=tuple(args.statures)):
        for gp in scen.pairs:
            for seed in range(args.unseen_seeds):
                items.append({"source": "unseen", "id": f"{scen.name}/{gp.spec}",
                              "cell": scen.name, "cell_file": None, "cell_yaml": scen.yaml,
                              "spec": gp.spec, "expect": gp.expect, "reason": gp.reason,
                              "why": gp.why, "family_label": gp.kind,
                              "unseen_family": scen.family, "stature": scen.stature,
                              "seed": seed, "timeout": args.timeout,
                              "biomechanics": not args.no_biomechanics})
    return items


def _commit() -> str | None:
    """The source tree's git commit, if it is a git checkout."""
    import subprocess
    try:
        return subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def _rate(num: int, den: int) -> float | None:
    return None if den == 0 else num / den


def summarize(results: list[dict]) -> dict:
    """Rates, times, failures by family and per-cell rows of a list of job results."""
    def block(rows: list[dict]) -> dict:
        feas = [r for r in rows if r["expect"] == "feasible"]
        infeas = [r for r in rows if r["expect"] != "feasible"]
        times = [r["outcome"]["seconds"] for r in rows]
        cpu = [r["outcome"].get("cpu_seconds", 0.0) for r in rows]
        fam: dict[str, dict] = {}
        for r in rows:
            if r["ok"]:
                continue
            f = fam.setdefault(r["family"], {"count": 0, "examples": []})
            f["count"] += 1
            if len(f["examples"]) < 3:
                f["examples"].append({"id": r["id"], "stature": r["stature"],
                                      "seed": r["seed"],
                                      "message": r["outcome"]["message"][:300]})
        return {
            "runs": len(rows),
            "feasible_runs": len(feas),
            "verified": sum(r["ok"] for r in feas),
            "verified_rate": _rate(sum(r["ok"] for r in feas), len(feas)),
            "infeasible_runs": len(infeas),
            "refused_correctly": sum(r["ok"] for r in infeas),
            "refusal_rate": _rate(sum(r["ok"] for r in infeas), len(infeas)),
            "median_time_s": statistics.median(times) if times else None,
            "max_time_s": max(times) if times else None,
            "over_2s": sum(t > 2.0 for t in times),
            "median_cpu_s": statistics.median(cpu) if cpu else None,
            "max_cpu_s": max(cpu) if cpu else None,
            "over_2s_cpu": sum(t > 2.0 for t in cpu),
            "slowest": [{"id": r["id"], "stature": r["stature"], "seed": r["seed"],
                         "seconds": round(r["outcome"]["seconds"], 3), "ok": r["ok"]}
                        for r in sorted(rows, key=lambda r: -r["outcome"]["seconds"])
                        if r["outcome"]["seconds"] > 2.0],
            "failures_by_family": dict(sorted(fam.items(), key=lambda kv: -kv[1]["count"])),
        }

    corpus = [r for r in results if r["source"] == "corpus"]
    generated = [r for r in results if r["source"] == "generated"]
    cells = {}
    for name in sorted({r["cell"] for r in corpus}):
        rows = [r for r in corpus if r["cell"] == name]
        b = block(rows)
        cells[name] = {k: b[k] for k in ("runs", "feasible_runs", "verified", "infeasible_runs",
                                         "refused_correctly", "median_time_s", "max_time_s")}
        cells[name]["top_failures"] = Counter(r["family"] for r in rows if not r["ok"]
                                              ).most_common(3)
    pair_families = {}
    for name in sorted({r["family_label"] for r in corpus}):
        rows = [r for r in corpus if r["family_label"] == name]
        pair_families[name] = {"runs": len(rows), "ok": sum(r["ok"] for r in rows)}
    unseen = [r for r in results if r["source"] == "unseen"]
    return {"corpus": block(corpus), "generated": block(generated), "cells": cells,
            "pair_families": pair_families, "unseen": block(unseen),
            **_unseen_summary(unseen, block)}


def _causes(rows: list[dict], limit: int = 12) -> list[dict]:
    """The failures of ``rows`` grouped by cause, most frequent first, with an example."""
    groups: dict[str, list[dict]] = defaultdict(list)
    for r in rows:
        if not r["ok"]:
            groups[r.get("cause") or r["family"]].append(r)
    return [{"cause": cause, "count": len(g), "families": dict(Counter(
                r.get("unseen_family", r["source"]) for r in g).most_common()),
             "example": {"id": g[0]["id"], "stature": g[0]["stature"],
                         "message": g[0]["outcome"]["message"][:300]}}
            for cause, g in sorted(groups.items(), key=lambda kv: -len(kv[1]))[:limit]]


def _unseen_summary(rows: list[dict], block) -> dict:
    """Per unseen family: the block's rates and times, and the failures by cause."""
    if not rows:
        return {}
    keys = ("runs", "feasible_runs", "verified", "verified_rate", "infeasible_runs",
            "refused_correctly", "refusal_rate", "median_time_s", "max_time_s", "over_2s",
            "median_cpu_s", "max_cpu_s", "over_2s_cpu")
    families = {}
    for name in sorted({r["unseen_family"] for r in rows}):
        sub = [r for r in rows if r["unseen_family"] == name]
        b = block(sub)
        families[name] = {**{k: b[k] for k in keys}, "by_stature": {
            str(h): {"feasible_runs": sum(r["expect"] == "feasible" for r in sub
                                          if r["stature"] == h),
                     "verified": sum(r["ok"] for r in sub if r["stature"] == h
                                     and r["expect"] == "feasible")}
            for h in sorted({r["stature"] for r in sub})},
            "failures_by_cause": _causes(sub)}
    return {"unseen_families": families, "unseen_failures_by_cause": _causes(rows, 25)}


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100 * x:.1f} %"


def _print_unseen(summary: dict) -> None:
    """The unseen family's section: a row per family, then the causes of failures."""
    fams = summary.get("unseen_families") or {}
    if not fams:
        return
    print(f"\n{'unseen family':14s} {'verified':>14s} {'refused':>10s} {'cpu med':>8s} "
          f"{'cpu max':>8s} {'>2 s':>5s}  top cause")
    for name, f in fams.items():
        top = f["failures_by_cause"][0] if f["failures_by_cause"] else None
        verified = f"{f['verified']}/{f['feasible_runs']} {_pct(f['verified_rate'])}"
        refused = f"{f['refused_correctly']}/{f['infeasible_runs']}"
        print(f"{name:14s} {verified:>14s} {refused:>10s} {f['median_cpu_s']:8.2f} "
              f"{f['max_cpu_s']:8.2f} {f['over_2s_cpu']:5d}  "
              + (f"{top['count']} x {top['cause']}" if top else ""))
    print("  failures by cause (families):")
    for c in summary["unseen_failures_by_cause"]:
        fam = ", ".join(f"{k} {v}" for k, v in c["families"].items())
        print(f"    {c['count']:4d}  {c['cause'][:70]:70s} ({fam})")


def _print(summary: dict, wall: float) -> None:
    for name in ("corpus", "generated", "unseen"):
        b = summary[name]
        if not b["runs"]:
            continue
        print(f"\n{name}: {b['runs']} runs; verified {b['verified']} of {b['feasible_runs']} "
              f"feasible ({_pct(b['verified_rate'])}); refused correctly "
              f"{b['refused_correctly']} of {b['infeasible_runs']} infeasible "
              f"({_pct(b['refusal_rate'])}); time per pair median "
              f"{b['median_time_s']:.2f} s, max {b['max_time_s']:.2f} s, "
              f"{b['over_2s']} over 2 s")
        if b["slowest"]:
            print("  slowest (over 2 s): " + ", ".join(
                f"{r['id']} {r['stature']} m {r['seconds']:.1f} s" for r in b["slowest"][:8]))
        if b["failures_by_family"]:
            print("  failures by family:")
            for fam, f in b["failures_by_family"].items():
                ex = f["examples"][0]
                print(f"    {f['count']:4d}  {fam:42s} e.g. {ex['id']} "
                      f"({ex['stature']} m): {ex['message'][:110]}")
    if summary["cells"]:
        print(f"\n{'cell':18s} {'verified':>12s} {'refused':>9s} {'median s':>9s} "
              f"{'max s':>7s}  top failure")
        for name, c in summary["cells"].items():
            top = c["top_failures"][0][0] if c["top_failures"] else ""
            print(f"{name:18s} {c['verified']:5d}/{c['feasible_runs']:<6d} "
                  f"{c['refused_correctly']:3d}/{c['infeasible_runs']:<5d} "
                  f"{c['median_time_s']:9.2f} {c['max_time_s']:7.2f}  {top}")
    _print_unseen(summary)
    print(f"\nwall time {wall:.0f} s (measured under load on a shared 2-core machine)")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--specs", type=Path, default=default_specs_path())
    parser.add_argument("--cells", nargs="+", default=None, help="only these corpus cells")
    parser.add_argument("--no-corpus", action="store_true",
                        help="only the generated cells (see --generated)")
    parser.add_argument("--limit", type=int, default=0,
                        help="at most this many corpus pairs, spread over the families")
    parser.add_argument("--statures", type=float, nargs="+", default=[1.55, 1.75, 1.95])
    parser.add_argument("--seeds", type=int, default=2)
    parser.add_argument("--generated", type=int, default=GENERATED_CELLS,
                        help="random cells of the generator (each with its pairs)")
    parser.add_argument("--generator-seed", type=int, default=0)
    parser.add_argument("--family", choices=("all", "corpus", "generated", "unseen"),
                        default="all", help="run only this part (default all three)")
    parser.add_argument("--unseen-cells", type=int, default=UNSEEN_CELLS,
                        help="cells of each unseen-style family (0: none)")
    parser.add_argument("--unseen-families", nargs="+", default=None,
                        help="only these unseen families (chamber boards desk conveyor "
                             "aisle twohanded)")
    parser.add_argument("--unseen-seeds", type=int, default=1,
                        help="synthesis seeds per unseen pair and stature")
    parser.add_argument("--timeout", type=float, default=DEFAULT_TIMEOUT,
                        help="seconds per pair")
    parser.add_argument("--workers", type=int, default=MAX_WORKERS)
    parser.add_argument("--no-biomechanics", action="store_true",
                        help="verify without the biomechanical checks (and their motion "
                             "work: foot locking), as before they were on by default")
    parser.add_argument("--quick", action="store_true",
                        help="one stature (1.75 m), one seed, 60 pairs, 3 generated cells")
    parser.add_argument("--out", type=Path, default=None,
                        help="default bench/results/scenarios.json, with --no-biomechanics "
                             "bench/results/scenarios_without_biomechanics.json")
    parser.add_argument("--runs-out", type=Path, default=None,
                        help="also write every run's outcome (id, stature, seed, seconds, "
                             "ok, family) to this JSON file, to compare two trees run by run")
    args = parser.parse_args(argv)
    args.out = args.out or ROOT / "bench" / "results" / (
        "scenarios_without_biomechanics.json" if args.no_biomechanics
        else "scenarios.json" if args.family == "all" else f"scenarios_{args.family}.json")
    if args.quick:
        args.statures, args.seeds = [1.75], 1
        args.limit = args.limit or 60
        args.generated = min(args.generated, 3)
        args.unseen_cells = min(args.unseen_cells, 1)
    if args.family != "all":
        args.no_corpus = args.no_corpus or args.family != "corpus"
        args.generated = args.generated if args.family == "generated" else 0
        args.unseen_cells = args.unseen_cells if args.family == "unseen" else 0
    workers = max(1, min(args.workers, MAX_WORKERS))
    try:
        items = _items(args)
    except (OSError, ValueError) as exc:      # unknown cell, unreadable or broken specs
        parser.error(str(exc))
    for out in (args.out, args.runs_out):      # a bad output folder: before the run
        try:
            if out is not None:
                out.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            parser.error(f"cannot write {out}: {exc.strerror}: {exc.filename}")
    print(f"{len(items)} runs on {workers} worker(s), {args.timeout:.0f} s limit per pair")
    t0 = time.perf_counter()
    results: list[dict] = []
    statures = sorted({it["stature"] for it in items})
    with ProcessPoolExecutor(max_workers=workers, initializer=_warm_up,
                             initargs=(statures, not args.no_biomechanics)) as pool:
        # Each worker warms up first (_warm_up), and the planner's obstacle fields of a
        # new layout are built once and cached on disk; that time is measured here,
        # apart from the time per pair.
        cells = {it["cell"]: {"cell": it["cell"], "cell_yaml": it.get("cell_yaml"),
                              "cell_file": it["cell_file"]} for it in items}
        preparation = dict(pool.map(_prepare, cells.values()))
        ready = time.perf_counter() - t0
        slow = {k: round(v, 2) for k, v in preparation.items() if v > 2.0}
        print(f"workers warmed up and cell fields ready in {ready:.0f} s"
              + (f"; built over 2 s: {slow}" if slow else ""))
        futures = [pool.submit(_job, it) for it in items]
        for k, fut in enumerate(as_completed(futures), 1):
            results.append(fut.result())
            if k % 50 == 0 or k == len(futures):
                bad = sum(not r["ok"] for r in results)
                print(f"  {k}/{len(futures)} done, {bad} not ok, "
                      f"{time.perf_counter() - t0:.0f} s", flush=True)
    wall = time.perf_counter() - t0
    results.sort(key=lambda r: (r["source"], r["id"], r["stature"], r["seed"]))
    summary = summarize(results)
    report = {"benchmark": "scenarios", "machine": machine(), "commit": _commit(),
              "load_average": list(os.getloadavg()), "statures": args.statures,
              "seeds": args.seeds, "timeout_s": args.timeout, "workers": workers,
              "biomechanics": not args.no_biomechanics,
              "wall_time_s": wall, "specs": str(args.specs.relative_to(ROOT))
              if args.specs.resolve().is_relative_to(ROOT) else str(args.specs),
              "cells_selected": args.cells, "limit": args.limit,
              "generated_cells": args.generated, "generator_seed": args.generator_seed,
              "family": args.family, "unseen_cells": args.unseen_cells,
              "unseen_seeds": args.unseen_seeds,
              "workers_ready_s": round(ready, 1),
              "cell_preparation_s": {k: round(v, 3) for k, v in sorted(preparation.items())},
              **summary,
              "failures": [{"id": r["id"], "source": r["source"], "stature": r["stature"],
                            "seed": r["seed"], "family": r["family"],
                            "seconds": round(r["outcome"]["seconds"], 3),
                            "cpu_seconds": round(r["outcome"].get("cpu_seconds", 0.0), 3),
                            "cause": r.get("cause"),
                            **({"unseen_family": r["unseen_family"], "expect": r["expect"],
                                "why": r.get("why", "")} if r["source"] == "unseen" else {}),
                            "message": r["outcome"]["message"][:240]}
                           for r in results if not r["ok"]]}
    atomic_write_text(args.out, json.dumps(report, indent=1) + "\n")
    if args.runs_out is not None:
        atomic_write_text(args.runs_out, json.dumps(
            [{"id": r["id"], "source": r["source"], "stature": r["stature"], "seed": r["seed"],
              "seconds": round(r["outcome"]["seconds"], 3), "ok": r["ok"],
              "family": r["family"]} for r in results], indent=0) + "\n")
    _print(summary, wall)
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
