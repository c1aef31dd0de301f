"""How often S1 and S2 verify in the paper cell across body sizes and seeds.

Synthesizes each paper specification for every stature in ``--statures`` and every seed
in ``range(--seeds)`` (verification on), counts verified motions and lists failures with
their reason, and reports the median time per motion. Prints a summary and writes
``bench/results/statures.json``. Not a test: run ``python bench/statures.py``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402
from ltl_human_motion.errors import LtlHumanMotionError  # noqa: E402
from ltl_human_motion.ltl.spec import PAPER_SPECS  # noqa: E402
from ltl_human_motion.planning.pipeline import (  # noqa: E402
    SynthesisOptions,
    get_library,
    resolve_cell,
    synthesize,
)
from ltl_human_motion.planning.verify import VerificationOptions  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from paper_specs import machine  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--statures", type=float, nargs="+",
                        default=[1.55, 1.65, 1.75, 1.85, 1.95])
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--no-biomechanics", action="store_true",
                        help="verify without the biomechanical checks (on by default) and "
                             "their motion work")
    parser.add_argument("--out", default=None,
                        help="default bench/results/statures.json, with --no-biomechanics "
                             "bench/results/statures_without_biomechanics.json")
    args = parser.parse_args(argv)
    out = args.out or str(ROOT / "bench" / "results" / (
        "statures_without_biomechanics.json" if args.no_biomechanics else "statures.json"))
    options = SynthesisOptions(verification=VerificationOptions(
        biomechanics=not args.no_biomechanics))
    cell = resolve_cell("paper_cell")
    runs, failures, times = 0, [], []
    for name in ("S1", "S2"):
        for stature in args.statures:
            get_library(stature)                       # built or loaded, not timed
            for seed in range(args.seeds):
                runs += 1
                t0 = time.perf_counter()
                try:
                    synthesize(PAPER_SPECS[name], cell, stature=stature, seed=seed,
                               options=options)
                except LtlHumanMotionError as exc:
                    failures.append({"spec": name, "stature": stature, "seed": seed,
                                     "error": str(exc)})
                times.append(time.perf_counter() - t0)
    result = {"benchmark": "statures", "machine": machine(), "statures": args.statures,
              "biomechanics": not args.no_biomechanics,
              "seeds": args.seeds, "runs": runs, "verified": runs - len(failures),
              "median_time_s": statistics.median(times), "failures": failures}
    atomic_write_text(out, json.dumps(result, indent=1) + "\n")
    print(f"verified {result['verified']} of {runs} (S1, S2 x statures {args.statures} x "
          f"{args.seeds} seeds"
          f"{', without the biomechanical checks' if args.no_biomechanics else ''}), "
          f"median {1000 * result['median_time_s']:.0f} ms per motion")
    for f in failures:
        print(f"  {f['spec']} stature {f['stature']} seed {f['seed']}: {f['error']}")
    print(f"written to {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
