"""How our motions compare with real motion capture (issue 13's realism report).

Ours: S1 and S2 synthesized in the paper cell for ``--statures`` and ``--seeds`` with
the biomechanical checks and their motion work on (offset blending, foot locking;
verification off, so that a motion a check refuses is still measured; the verified flag
and the whole-motion MOJO foot skate, limit 0.03 m/s, are recorded). Real: the DeepMimic
walking clips that ship with pybullet (as the gait library prepares them, and raw), the
CMU BVH takes of Debian's assimp-testmodels (``/usr/share/assimp/models/BVH``) and any
``--source`` folder of BVH / ASF+AMC / DeepMimic files. For every metric of
:mod:`ltl_human_motion.motion.realism` it prints ours vs real (median and 95th
percentile) with the 1-Wasserstein distance between the two distributions, and writes
``bench/results/realism.json``.
Not a test: run ``python bench/realism.py``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.errors import LtlHumanMotionError  # noqa: E402
from ltl_human_motion.motion.realism import (  # noqa: E402
    METRICS,
    compare,
    motion_samples,
    real_clip_samples,
    real_sources,
)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paper_specs import machine  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--statures", type=float, nargs="+", default=[1.65, 1.75, 1.85])
    parser.add_argument("--seeds", type=int, default=1)
    parser.add_argument("--source", action="append", default=[],
                        help="a folder or file of the user's own mocap (repeatable)")
    parser.add_argument("--out", default=str(ROOT / "bench" / "results" / "realism.json"))
    args = parser.parse_args(argv)
    from ltl_human_motion.ltl.spec import PAPER_SPECS
    from ltl_human_motion.motion.biomechanics import foot_skate
    from ltl_human_motion.planning.pipeline import SynthesisOptions, resolve_cell, synthesize
    from ltl_human_motion.planning.verify import VerificationOptions

    cell = resolve_cell("paper_cell")
    ours, items = [], []
    for name in ("S1", "S2"):
        for stature in args.statures:
            for seed in range(args.seeds):
                try:
                    synth = synthesize(PAPER_SPECS[name], cell, stature=stature, seed=seed,
                                       options=SynthesisOptions(
                                           verify=False, verification=VerificationOptions(
                                               biomechanics=True)))[0]
                except LtlHumanMotionError as exc:
                    items.append({"spec": name, "stature": stature, "seed": seed,
                                  "error": str(exc)})
                    continue
                ours.append(motion_samples(synth.positions, synth.fps, stature, cell.floor_z))
                rep = synth.verification
                skate = float(foot_skate(synth.positions, synth.fps, stature,
                                         cell.floor_z)[0].max())
                items.append({"spec": name, "stature": stature, "seed": seed,
                              "verified": bool(rep["passed"]), "foot_skate_mean": skate,
                              "failed": [k for k, v in rep.items()
                                         if isinstance(v, dict) and not v["passed"]]})
    real, sources = [], []
    for kind, path in real_sources(args.source):
        try:
            real.append(real_clip_samples(kind, path, 1.75))
            sources.append({"kind": kind, "path": str(path)})
        except (LtlHumanMotionError, ValueError, OSError) as exc:
            sources.append({"kind": kind, "path": str(path), "error": str(exc)})
    table = compare(ours, real)
    by_kind = {k: compare(ours, [s for s, src in zip(real, [x for x in sources
                                                            if "error" not in x])
                                 if src["kind"] == k])
               for k in sorted({s["kind"] for s in sources if "error" not in s})}
    result = {"benchmark": "realism", "machine": machine(), "statures": args.statures,
              "seeds": args.seeds, "ours": items, "real_sources": sources,
              "metrics": table, "by_source": by_kind}
    atomic_write_text(args.out, json.dumps(result, indent=1) + "\n")
    print(f"ours: {len(ours)} motions (S1, S2 x statures {args.statures} x {args.seeds} "
          f"seeds); real: {sum('error' not in s for s in sources)} clips")
    print(f"{'metric':<13}{'unit':<11}{'ours median':>12}{'ours p95':>10}"
          f"{'real median':>12}{'real p95':>10}{'W1 dist':>10}")

    def fmt(x: float | None) -> str:
        return "-" if x is None else f"{x:.3g}"
    for m in METRICS:
        r = table[m]
        print(f"{m:<13}{r['unit']:<11}{fmt(r['ours']['median']):>12}{fmt(r['ours']['p95']):>10}"
              f"{fmt(r['real']['median']):>12}{fmt(r['real']['p95']):>10}"
              f"{fmt(r['wasserstein']):>10}")
    skates = [it["foot_skate_mean"] for it in items if "foot_skate_mean" in it]
    if skates:
        print(f"whole-motion foot skate (MOJO mean, worse foot): median "
              f"{np.median(skates):.4f}, max {max(skates):.4f} m/s over {len(skates)} "
              f"motions (limit 0.03 m/s)")
    print(f"written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
