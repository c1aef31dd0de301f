"""``ltl-human-motion library``: build or inspect the motion library.

Builds (or loads from the cache) the gait library for one body size, prints its size and
the motion automaton's statistics, writes the JSON quality report and, optionally, a plot
of the gait graph (root paths of the primitives and the out-degree distribution).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

NAME = "library"
HELP = "build or inspect the motion library (gait graph, goal primitives, quality report)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    from ltl_human_motion.motion.library import DEFAULT_LIBRARY_DELTA

    parser.add_argument("--stature", type=float, default=1.75,
                        help="body height in metres, 1.55 to 1.95 (default 1.75)")
    parser.add_argument("--source", action="append", default=None, metavar="PATH",
                        help="extra motion file or folder (BVH, DeepMimic, npz) of walking; "
                             "repeatable, e.g. a CMU BVH database")
    parser.add_argument("--no-default", action="store_true",
                        help="do not use the DeepMimic walk loops shipped with pybullet")
    parser.add_argument("--delta", type=float, default=DEFAULT_LIBRARY_DELTA,
                        help=f"transition threshold on d_ij (default {DEFAULT_LIBRARY_DELTA})")
    parser.add_argument("--k-comp", type=int, default=5,
                        help="transition window / blend overlap in frames (default 5)")
    parser.add_argument("--cache-dir", type=Path, default=None,
                        help="cache folder (default $LTL_HUMAN_MOTION_CACHE or "
                             "~/.cache/ltl_human_motion)")
    parser.add_argument("--no-cache", action="store_true", help="build without the cache")
    parser.add_argument("--report", type=Path, default=None, metavar="JSON",
                        help="write the quality report and library summary here")
    parser.add_argument("--details", action="store_true",
                        help="include per-primitive metrics in the report")
    parser.add_argument("--plot", type=Path, default=None, metavar="PNG",
                        help="plot the gait graph (needs matplotlib)")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.add_argument("--progress", action="store_true", help="always show progress bars")


def _plot(lib, path: Path) -> None:
    from ltl_human_motion.errors import MissingDependencyError
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - matplotlib is installed here
        raise MissingDependencyError("plotting needs matplotlib: pip install matplotlib") \
            from exc
    import numpy as np

    from ltl_human_motion.atomic import atomic_path

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 5))
    colors = {"loop": "tab:blue", "start": "tab:green", "stop": "tab:red"}
    for i in range(lib.n_primitives):
        p = lib.root_paths[i]
        ax1.plot(p[:, 0], p[:, 1], lw=0.6, alpha=0.5,
                 color="tab:orange" if lib.is_carry[i] and lib.kinds[i] == "loop"
                 else colors.get(str(lib.kinds[i]), "k"))
    ax1.set_aspect("equal")
    ax1.set_xlabel("x [m]")
    ax1.set_ylabel("y [m]")
    ax1.set_title(f"root paths of {lib.n_primitives} gait primitives\n(blue walk, orange "
                  f"carry, green start, red stop)")
    deg = np.diff(lib.indptr)
    ax2.hist(deg, bins=40)
    ax2.set_xlabel("successors per primitive")
    ax2.set_ylabel("primitives")
    ax2.set_title(f"{lib.automaton.n_transitions} transitions, delta = {lib.delta:g}")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=90, format=path.suffix.lstrip(".") or "png")
    plt.close(fig)


def _realism(lib, source) -> dict:
    """Gait primitives (every 8th) vs the real clips installed here and ``source``:
    :func:`~ltl_human_motion.motion.realism.compare` per metric."""
    from ltl_human_motion.motion.realism import (
        compare,
        motion_samples,
        real_clip_samples,
        real_sources,
    )
    from ltl_human_motion.motion.types import world_positions
    ours = [motion_samples(world_positions(mp), mp.fps, lib.stature)
            for mp in lib.primitives[::8]]
    extra = [] if source is None else ([source] if isinstance(source, str) else list(source))
    real, used = [], []
    for kind, path in real_sources(extra):
        try:
            real.append(real_clip_samples(kind, path, lib.stature))
            used.append(path)
        except (ValueError, OSError):
            continue
    return {"ours": f"{len(ours)} gait primitives", "real": used,
            "metrics": compare(ours, real)}


def run(args: argparse.Namespace) -> int:
    from ltl_human_motion.atomic import atomic_write_text
    from ltl_human_motion.errors import LtlHumanMotionError
    from ltl_human_motion.motion.library import load_library
    from ltl_human_motion.motion.quality import check_primitives, goal_sample

    try:
        lib = load_library(stature=args.stature, source=args.source, delta=args.delta,
                           cache_dir=args.cache_dir, k_comp=args.k_comp,
                           include_default=not args.no_default, use_cache=not args.no_cache,
                           progress=True if args.progress else None)
    except LtlHumanMotionError:
        raise
    except ValueError as exc:          # bad option values: one clear line, no traceback
        print(f"ltl-human-motion library: error: {exc}", file=sys.stderr)
        return 2
    summary = lib.summary()
    quality = dict(lib.quality)
    if args.details or not quality:
        quality = {"gait": check_primitives(lib.primitives, lib.skeleton, kind="gait",
                                            details=args.details),
                   "goal": check_primitives(goal_sample(lib.skeleton), lib.skeleton,
                                            kind="goal", details=args.details)}
        quality["ok"] = bool(quality["gait"]["ok"] and quality["goal"]["ok"])
    report = {"summary": summary, "quality": quality}
    if args.report is not None:
        report["realism"] = _realism(lib, args.source)
        atomic_write_text(args.report, json.dumps(report, indent=2, default=float) + "\n")
    if args.plot is not None:
        _plot(lib, args.plot)
    if args.json:
        print(json.dumps(summary, indent=2, default=float))
    else:
        scc = summary.get("scc", {})
        print(f"motion library  stature {lib.stature:.2f} m  key {lib.key}")
        print(f"  gait primitives  {summary['primitives']:6d}  (walk {summary['walk']}, "
              f"carry {summary['carry']}; loop {summary['loop']}, start {summary['start']}, "
              f"stop {summary['stop']})")
        print(f"  transitions      {summary['edges']:6d}  (delta {lib.delta:g}, k_comp "
              f"{lib.automaton.k_comp}; largest SCC walk {scc.get('walk', 0)}, "
              f"carry {scc.get('carry', 0)})")
        for kind in ("gait", "goal"):
            q = quality.get(kind, {})
            if q:
                _print_quality(kind, q)
        if args.report is not None:
            print(f"  realism          ours ({report['realism']['ours']}) vs "
                  f"{len(report['realism']['real'])} real clips: median ours / real, "
                  f"1-Wasserstein distance")
            for name, r in report["realism"]["metrics"].items():
                o, q, w = r["ours"]["median"], r["real"]["median"], r["wasserstein"]
                if o is not None and q is not None:
                    print(f"    {name:<12} {o:9.3g} / {q:<9.3g} {r['unit']:<10} W1 {w:.3g}")
            print(f"  report           {args.report}")
        if args.plot is not None:
            print(f"  plot             {args.plot}")
    if not quality.get("ok", True):
        print("library: some primitives fail the quality checks (see the report)",
              file=sys.stderr)
        return 1
    return 0


def _print_quality(kind: str, q: dict) -> None:
    """One kind's quality line: how many primitives keep the per-primitive limits, and the
    worst value of each check beside its limit."""
    from dataclasses import asdict

    from ltl_human_motion.motion.biomechanics import BiomechanicsLimits
    from ltl_human_motion.motion.quality import QualityThresholds
    t = {**asdict(QualityThresholds()), **q.get("thresholds", {})}
    w = q["worst"]
    print(f"  quality {kind:5s}    {q['passed']:4d}/{q['count']:<4d} primitives within the "
          f"per-primitive limits; worst (limit): bone {w['bone_length']:.1e} m "
          f"({t['bone_length']:.0e}), floor {w['floor']:+.3f} m (>= {-t['floor_tolerance']:+.3f}),"
          f" speed {w['joint_speed']:.2f} m/s ({t['joint_speed']:.1f})")
    print(f"                   foot skate {w['foot_skate']:.2f} m/s ({t['foot_skate']:.2f}: a "
          f"primitive alone; a synthesized motion's feet are pinned and its skate held to "
          f"{BiomechanicsLimits().skate_mean:.2f} m/s)")
