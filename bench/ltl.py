"""Benchmark of the LTL layer: translation and sequence synthesis times, automaton sizes.

Times the built-in translator on S1, S2 (with the always-on conjuncts of the paper cell)
and on the formulas of Spot's reference table (55 Dwyer patterns and the paper's two
formulas), and compares state counts with Spot's ``ltl2tgba -B`` from
``shared/data/spot-reference``. Prints a table and writes ``bench/results/ltl.json``.
Medians over ``--repeat`` runs. Not a test: run ``python bench/ltl.py``.
"""

from __future__ import annotations

import argparse
import csv
import json
import platform
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.ltl import (  # noqa: E402
    build_specification,
    degeneralize,
    parse,
    synthesize_sequences,
    translate,
)

PAPER_CELL = {"objects": ["O1", "O2"], "regions": ["R0", "R1"],
              "shorthands": {"assemble": (("R",), "leftHand(R) & rightHand(R)")},
              "final_region": "R1"}


def _reference_dir() -> Path:
    for candidate in (ROOT.parent / "shared" / "data" / "spot-reference",
                      Path("/work/shared/data/spot-reference")):
        if candidate.is_dir():
            return candidate
    raise SystemExit("spot-reference data not found")


def _median_ms(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t0) * 1000.0)
    return statistics.median(times)


def _cell_model_stage(name: str, repeat: int) -> dict:
    """The pipeline's LTL stage for a paper spec in the paper cell: the cell model's
    product search (on-the-fly translation included) against the letter-graph path it
    replaced (translation, then sequences), both for one sequence."""
    from ltl_human_motion.scene.cell_yaml import load_cell
    from ltl_human_motion.tasks import plan_sequences

    cell = load_cell(ROOT / "config" / "paper_cell.yaml")
    spec = build_specification(name, cell)
    seqs, stats = plan_sequences(spec, cell, n=1, backend="builtin")
    new_ms = _median_ms(lambda: plan_sequences(spec, cell, n=1, backend="builtin"), repeat)
    old_ms = _median_ms(lambda: (translate(spec.formula, backend="builtin"),
                                 synthesize_sequences(spec, n=1, seed=0, backend="builtin")),
                        repeat)
    return {"first_sequence": str(seqs[0]), "tasks": [str(t) for t in seqs[0].tasks],
            "estimated_seconds": stats.costs[0], "ltl_stage_ms_median": new_ms,
            "previous_ltl_stage_ms_median": old_ms,
            "previous_first_sequence": str(synthesize_sequences(spec, n=1, seed=0,
                                                                backend="builtin")[0])}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--out", default=str(ROOT / "bench" / "results" / "ltl.json"))
    args = parser.parse_args(argv)
    ref = _reference_dir()
    rows = list(csv.DictReader((ref / "spot-ba-reference.tsv").open(), delimiter="\t"))
    results = []
    print(f"{'name':14s} {'spot BA':>7s} {'ours TGBA':>9s} {'ours BA':>7s} {'ratio':>6s} "
          f"{'ours ms':>8s} {'spot ms':>8s}")
    for row in rows:
        formula = parse(row["formula"], free_atoms=True)
        ms = _median_ms(lambda f=formula: translate(f, backend="builtin"), args.repeat)
        tgba = translate(formula, backend="builtin")
        ba = degeneralize(tgba)
        spot_states = int(row["states"])
        entry = {"name": row["name"], "formula": row["formula"], "spot_ba_states": spot_states,
                 "tgba_states": tgba.num_states, "tgba_sets": tgba.num_sets,
                 "ba_states": ba.num_states, "ba_ratio": ba.num_states / spot_states,
                 "translate_ms_median": ms,
                 "spot_translate_ms_median": float(row["spot_python_translate_ms_median"])}
        results.append(entry)
        print(f"{row['name']:14s} {spot_states:7d} {tgba.num_states:9d} {ba.num_states:7d} "
              f"{entry['ba_ratio']:6.2f} {ms:8.2f} {entry['spot_translate_ms_median']:8.2f}")
    paper = {}
    for name in ("S1", "S2"):
        spec = build_specification(name, PAPER_CELL)
        t_ms = _median_ms(lambda s=spec: translate(s.formula, backend="builtin"), args.repeat)
        aut = translate(spec.formula, backend="builtin")
        seq_ms = {mode: _median_ms(lambda s=spec, m=mode: synthesize_sequences(
            s, n=5, seed=1, mode=m, backend="builtin"), args.repeat)
            for mode in ("random", "coverage", "all")}
        paper[name] = {"spec": spec.text, "full_formula": str(spec.formula),
                       "tgba_states": aut.num_states, "tgba_sets": aut.num_sets,
                       "ba_states": degeneralize(aut).num_states,
                       "translate_ms_median": t_ms, "sequences_ms_median": seq_ms}
        print(f"{name} (+always-on): TGBA {aut.num_states} states/{aut.num_sets} sets, BA "
              f"{paper[name]['ba_states']} states, translate {t_ms:.2f} ms, sequences (n=5) "
              + ", ".join(f"{m} {v:.1f} ms" for m, v in seq_ms.items()))
        paper[name]["cell_model"] = _cell_model_stage(name, args.repeat)
        cm = paper[name]["cell_model"]
        print(f"{name} with the cell model (config/paper_cell.yaml): first sequence "
              f"{cm['first_sequence']} (the search's cost {cm['estimated_seconds']:.1f}), "
              f"LTL stage {cm['ltl_stage_ms_median']:.1f} ms (translation + sequence, n=1) vs "
              f"{cm['previous_ltl_stage_ms_median']:.1f} ms before (translate + sequences)")
    ratios = [r["ba_ratio"] for r in results]
    summary = {
        "formulas": len(results),
        "median_translate_ms": statistics.median(r["translate_ms_median"] for r in results),
        "max_translate_ms": max(r["translate_ms_median"] for r in results),
        "median_ba_ratio": statistics.median(ratios), "max_ba_ratio": max(ratios),
        "within_2x_of_spot": sum(x <= 2.0 for x in ratios),
        "over_2x_of_spot": [r["name"] for r in results if r["ba_ratio"] > 2.0],
        "smaller_than_spot": sum(x < 1.0 for x in ratios),
        "total_ba_states": sum(r["ba_states"] for r in results),
        "total_spot_states": sum(r["spot_ba_states"] for r in results),
    }
    print(json.dumps(summary, indent=2))
    payload = {"machine": {"python": platform.python_version(), "platform": platform.platform(),
                           "processor": platform.processor()},
               "repeat": args.repeat, "summary": summary, "paper": paper, "formulas": results}
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(Path(args.out), json.dumps(payload, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
