"""``ltl-human-motion paper``: reproduce the paper's Sec. IV (S1, S2, Fig. 2/3, Tab. II/III)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

NAME = "paper"
HELP = "reproduce the paper's examples S1 and S2: figures, animation and tables"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion paper``."""
    parser.add_argument("--out", type=Path, default=Path("out/paper"),
                        help="output folder (default out/paper)")
    parser.add_argument("--seed", type=int, default=1,
                        help="random seed of the syntheses (default 1)")
    parser.add_argument("--cycles", type=int, default=2,
                        help="assembly cycles per specification (default 2)")
    parser.add_argument("--no-animation", action="store_true", help="skip the GIF animations")


def run(args: argparse.Namespace) -> int:
    """Write the figures and tables; print Tab. III."""
    from ltl_human_motion.reproduce import reproduce_paper

    summary = reproduce_paper(args.out, seed=args.seed, cycles=args.cycles,
                              animation=not args.no_animation,
                              progress=lambda m: print(f"[paper] {m}", file=sys.stderr))
    print(summary["tables"]["tab3"])
    print(f"wrote {len(summary['files'])} files to {args.out}")
    return 0
