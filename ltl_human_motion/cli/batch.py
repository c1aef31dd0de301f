"""``ltl-human-motion batch``: a dataset of many verified motions (local pool or Dask)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

NAME = "batch"
HELP = ("generate a dataset of verified motions from a specs file, on a local process pool "
        "or a Dask cluster; a killed run started again finishes the rest")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion batch``."""
    parser.add_argument("--cell", required=True,
                        help="cell name (config/<name>.yaml) or path to a cell YAML file")
    parser.add_argument("--specs", required=True, type=Path,
                        help="specs YAML: specs with weights, stature grid, object/region "
                             "jitter, cycles (see config/specs_example.yaml)")
    parser.add_argument("--count", required=True, type=int, help="number of items")
    parser.add_argument("--out", required=True, type=Path,
                        help="dataset folder (an interrupted run in it is resumed)")
    parser.add_argument("--seed", type=int, default=0,
                        help="global seed; item i depends only on (seed, i) (default 0)")
    parser.add_argument("--workers", type=int, default=None,
                        help="worker processes (default: CPU count; 0 = this process); "
                             "with --scheduler local the number of Dask workers")
    parser.add_argument("--scheduler", default=None,
                        help="Dask scheduler address (tcp://host:8786), or 'local' for a "
                             "LocalCluster on 127.0.0.1")
    parser.add_argument("--shard-size", type=int, default=100,
                        help="items per shard file (default 100)")
    parser.add_argument("--dtype", choices=("float32", "float64"), default="float32",
                        help="storage type of positions and tracks (default float32)")
    parser.add_argument("--no-progress", action="store_true", help="hide the progress bar")
    parser.add_argument("--export-bvh", type=Path, default=None, metavar="DIR",
                        help="when complete, also write one BVH per stored motion and "
                             "items.jsonl (captions) to DIR (docs/datasets.md)")
    parser.add_argument("--export-windows", type=Path, default=None, metavar="FILE.npz",
                        help="when complete, also write fixed-length windows (positions, "
                             "captions, labels) to one npz (docs/datasets.md)")
    parser.add_argument("--window", type=int, nargs=3, default=(64, 32, 4),
                        metavar=("LENGTH", "STRIDE", "STEP"),
                        help="windows of --export-windows: frames per window, frames "
                             "between starts, keep every STEP-th frame (default 64 32 4: "
                             "2.1 s at 30 fps)")


def run(args: argparse.Namespace) -> int:
    """Run the batch, print a JSON summary; exit 0 when the dataset is complete, else 1."""
    from ltl_human_motion.batch.runner import run_batch
    from ltl_human_motion.errors import LtlHumanMotionError

    for name in ("count", "shard_size"):
        if getattr(args, name) < 1:
            print(f"ltl-human-motion batch: error: --{name.replace('_', '-')} must be >= 1",
                  file=sys.stderr)
            return 2
    if min(args.window) < 1:
        print("ltl-human-motion batch: error: --window values must be >= 1", file=sys.stderr)
        return 2
    if args.workers is not None and args.workers < 0:
        print("ltl-human-motion batch: error: --workers must be >= 0", file=sys.stderr)
        return 2
    try:
        summary = run_batch(args.cell, args.specs, args.count, args.out, seed=args.seed,
                            workers=args.workers, scheduler=args.scheduler,
                            shard_size=args.shard_size, dtype=args.dtype,
                            progress=not args.no_progress)
    except LtlHumanMotionError:
        raise                                   # printed by the dispatcher
    except ValueError as exc:
        print(f"ltl-human-motion batch: error: {exc}", file=sys.stderr)
        return 2
    result = summary.to_dict()
    if summary.complete:
        try:
            result.update(_exports(args))
        except (ValueError, OSError) as exc:
            print(f"ltl-human-motion batch: error: export: {exc}", file=sys.stderr)
            return 2
    print(json.dumps(result, indent=1))
    if not summary.complete:
        print(f"ltl-human-motion batch: {len(summary.lost)} items were lost with their "
              "workers; run the same command again to finish", file=sys.stderr)
        return 1
    return 0


def _exports(args: argparse.Namespace) -> dict[str, object]:
    """The exports asked for (``--export-bvh``, ``--export-windows``) of the finished run."""
    from ltl_human_motion.batch.export import WindowSpec, export_bvh, export_windows
    out: dict[str, object] = {}
    if args.export_windows is not None:
        spec = WindowSpec(*(int(v) for v in args.window))
        out["windows"] = {"file": str(args.export_windows),
                          "count": export_windows(args.out, args.export_windows, spec)}
    if args.export_bvh is not None:
        out["bvh"] = {"folder": str(args.export_bvh),
                      "count": len(export_bvh(args.out, args.export_bvh))}
    return out
