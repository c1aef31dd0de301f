"""``ltl-human-motion synthesize``: verified motions for a specification in a cell."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from ltl_human_motion.cli._types import stature
from ltl_human_motion.cli.render import (
    PictureOptions,
    add_picture_arguments,
    picture_options,
    write_gif,
    write_sheet,
)

NAME = "synthesize"
HELP = "synthesize verified full-body motions for an LTL specification in a cell"

FORMATS = ("npz", "json", "csv", "bvh")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``ltl-human-motion synthesize``."""
    parser.add_argument("--cell", required=True,
                        help="cell name (config/<name>.yaml) or path to a cell YAML file")
    parser.add_argument("--spec", required=True,
                        help='LTL specification, e.g. "grasp(O1) & F assemble(R1)", or S1/S2')
    parser.add_argument("--variants", type=int, default=1, help="number of motions (default 1)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument("--cycles", type=int, default=1,
                        help="passes through the accepting cycle (default 1)")
    parser.add_argument("--stature", type=stature, default=1.75,
                        help="body height in m, 1.55 to 1.95 (default 1.75)")
    parser.add_argument("--mode", choices=("all", "coverage", "random"), default="all",
                        help="how task-sequence variations are chosen (default all: "
                             "shortest first)")
    parser.add_argument("--format", dest="formats", action="append", choices=FORMATS,
                        help="output formats (repeatable; default npz and json)")
    parser.add_argument("--no-verify", action="store_true",
                        help="return motions even if a verification check fails")
    parser.add_argument("--no-biomechanics", action="store_true",
                        help="verify without the biomechanical checks (joint speed limits, "
                             "range of motion, self-penetration, balance, foot skate)")
    parser.add_argument("--out", type=Path, default=Path("out/motions"),
                        help="output folder (default out/motions)")
    parser.add_argument("--render", action="store_true",
                        help="also draw each motion: motion_NNN.gif (animation) and "
                             "motion_NNN.png (snapshots titled with the tasks) in --out")
    add_picture_arguments(parser, "; with --render")


def _render(synth, cell: str, stem: Path, pictures: PictureOptions) -> list[str]:
    from ltl_human_motion.scene.cell_yaml import resolve_cell
    the_cell = resolve_cell(cell)
    gif, png = stem.with_suffix(".gif"), stem.with_suffix(".png")
    write_gif(synth, the_cell, gif, pictures)
    write_sheet(synth, the_cell, png, pictures)
    return [str(gif), str(png)]


def run(args: argparse.Namespace) -> int:
    """Synthesize, write each motion, print one line per motion and a JSON summary."""
    from ltl_human_motion.planning import exports
    from ltl_human_motion.planning.pipeline import SynthesisOptions, synthesize
    from ltl_human_motion.planning.verify import VerificationOptions

    if args.variants < 1 or args.cycles < 1:
        print("ltl-human-motion synthesize: error: --variants and --cycles must be >= 1",
              file=sys.stderr)
        return 2
    if args.out.suffix.lower() in (".npz", ".json", ".csv", ".bvh") or args.out.is_file():
        print(f"ltl-human-motion synthesize: error: --out {args.out}: give a folder; the "
              f"motions are written into it as motion_000.npz, motion_000.json, ... (e.g. "
              f"--out {args.out.with_suffix('')})", file=sys.stderr)
        return 2
    pictures = picture_options(args)
    if isinstance(pictures, str):
        print(f"ltl-human-motion synthesize: error: {pictures}", file=sys.stderr)
        return 2
    options = SynthesisOptions(
        sequence_mode=args.mode, verify=not args.no_verify,
        verification=VerificationOptions(biomechanics=not args.no_biomechanics))
    motions = synthesize(args.spec, args.cell, variants=args.variants, seed=args.seed,
                         cycles=args.cycles, stature=args.stature, options=options)
    savers = {"npz": exports.save_npz, "json": exports.save_json, "csv": exports.save_csv,
              "bvh": exports.save_bvh}
    summary = []
    for i, synth in enumerate(motions):
        stem = args.out / f"motion_{i:03d}"
        written = []
        for fmt in args.formats or ["npz", "json"]:
            path = stem.with_suffix(f".{fmt}")
            savers[fmt](synth, path)
            written.append(str(path))
        if args.render:
            written += _render(synth, args.cell, stem, pictures)
        checks = {k: v["passed"] for k, v in synth.verification.items() if isinstance(v, dict)}
        st = synth.stats
        stages = st.planning_time + st.blending_time + st.verification_time
        loading = (f"; the first motion of a process also builds what the others reuse "
                   f"(compiled kernels, gait index, the cell's fields), "
                   f"{(st.total_time - stages) * 1000:.0f} ms"
                   if i == 0 and st.total_time - stages > 0.2 else "")
        before = (f"\n  (made in another order of the tasks: {st.orders_failed} failed "
                  f"before it, the first: {(st.first_failure or '')[:200]})"
                  if st.orders_failed else "")
        print(f"motion {i}: {' ; '.join(synth.sequence)}  ({synth.motion.duration:.1f} s of "
              f"motion in {st.total_time * 1000:.0f} ms: planning "
              f"{st.planning_time * 1000:.0f} ms, blending {st.blending_time * 1000:.0f} "
              f"ms, verification {st.verification_time * 1000:.0f} ms{loading}; verified: "
              f"{'yes' if all(checks.values()) else 'NO'}){before}")
        summary.append({"files": written, "sequence": synth.sequence,
                        "duration": synth.motion.duration, "verification": checks,
                        "stats": {k: v for k, v in synth.stats.to_dict().items()
                                  if isinstance(v, (int, float, str))}})
    print(json.dumps({"motions": summary}, indent=1))
    return 0
