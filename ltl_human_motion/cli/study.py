"""``ltl-human-motion study``: ergonomics, cycle time and safety of a cell (or two layouts)
over many verified variants of a task, with an HTML report."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

NAME = "study"
HELP = ("study a cell over many verified variants and statures: REBA/RULA/NIOSH, cycle "
        "time and waste, offline SSM against a robot; JSON, PNG and one HTML page "
        "(--compare A.yaml B.yaml for two layouts side by side)")


def _statures(text: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"statures: expected numbers like 1.6,1.75,1.9, "
                                         f"got {text!r}") from None
    if not values:
        raise argparse.ArgumentTypeError("statures: give at least one")
    return values


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion study``."""
    cells = parser.add_mutually_exclusive_group(required=True)
    cells.add_argument("--cell", help="cell name (config/<name>.yaml) or YAML path")
    cells.add_argument("--compare", nargs=2, metavar=("LAYOUT_A", "LAYOUT_B"),
                       help="two cell YAML files to compare")
    parser.add_argument("--spec", default="S2",
                        help="LTL specification or a paper name (default S2)")
    parser.add_argument("--variants", type=int, default=50,
                        help="variants per stature: each layout gets VARIANTS x "
                             "len(STATURES) motions, each with a stature drawn from the "
                             "grid (default 50)")
    parser.add_argument("--statures", type=_statures, default=[1.6, 1.75, 1.9],
                        help="comma-separated body heights in m (default 1.6,1.75,1.9)")
    parser.add_argument("--robot", default=None, metavar="YAML",
                        help="robot model, base and trajectory for offline SSM (e.g. "
                             "config/ur_pick_place.yaml); default: no robot")
    parser.add_argument("--prediction-horizon", type=float, default=0.0, metavar="S",
                        help="offline SSM with predicted occupancy S seconds ahead "
                             "(default 0: reactive)")
    parser.add_argument("--sequence-mode", choices=("all", "random", "coverage"),
                        default="all",
                        help="task sequences: all = the shortest ones (default), random = "
                             "random walks of the automaton")
    parser.add_argument("--jitter", type=float, default=0.05, metavar="M",
                        help="x/y offsets of the parts' positions per variant, uniform in "
                             "+-M metres (default 0.05)")
    parser.add_argument("--out", type=Path, default=Path("out/study"),
                        help="output folder (default out/study; an interrupted study in it is "
                             "resumed)")
    parser.add_argument("--seed", type=int, default=0, help="global seed (default 0)")
    parser.add_argument("--workers", type=int, default=None,
                        help="worker processes (default: CPU count; 0 = this process)")
    parser.add_argument("--scheduler", default=None,
                        help="Dask scheduler address, or 'local' (127.0.0.1)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")


def run(args: argparse.Namespace) -> int:
    """Run the study; print where the report is and the headline figures."""
    from ltl_human_motion.study.report import METRICS
    from ltl_human_motion.study.runner import StudyConfig, run_study

    cells = list(args.compare) if args.compare else [args.cell]
    if args.variants < 1:
        print("ltl-human-motion study: error: --variants must be >= 1", file=sys.stderr)
        return 2
    try:
        cfg = StudyConfig(cells=cells, spec=args.spec, variants=args.variants,
                          statures=tuple(args.statures), robot=args.robot, out=args.out,
                          seed=args.seed, workers=args.workers, scheduler=args.scheduler,
                          prediction_horizon=args.prediction_horizon,
                          sequence_mode=args.sequence_mode, jitter=args.jitter)
        data = run_study(cfg, progress=not args.no_progress)
    except (ValueError, RuntimeError, OSError) as exc:
        print(f"ltl-human-motion study: error: {exc}", file=sys.stderr)
        return 2
    for label, lay in data["layouts"].items():
        s = lay["summary"]
        line = [f"layout {label}: {len(lay['items'])} motions ({lay['failed']['count']} "
                "failed)"]
        for key in ("cycle_time", "reba_max", "lifting_index", "min_separation"):
            if s[key].get("n"):
                unit = METRICS[key][1]
                line.append(f"{METRICS[key][0]} {s[key]['mean']:.3g}{' ' + unit if unit else ''}")
        print("; ".join(line))
    if data["comparison"]:
        a, b = list(data["layouts"])
        for key, c in data["comparison"].items():
            if c.get("significant"):
                print(f"{b} - {a}: {METRICS[key][0]} {c['diff']:+.3g} "
                      f"(95% CI {c['ci95'][0]:+.3g} .. {c['ci95'][1]:+.3g})")
    print(f"report: {data['report']['html']}")
    return 0
