"""S1/S2 time of this tree against an earlier commit, on the same machine at the same time.

The machine's speed drifts by tens of percent over minutes (a shared VM), so times from
different sessions do not compare. This benchmark checks out ``--base`` (default: the
commit before the scenario-corpus work, whose S1/S2 times issue 11 says must not grow by
more than 20 %) into a git worktree under ``.build/ab/``, then alternates runs of the two
trees in fresh processes: each run synthesizes S1 and S2 with seeds 0-8, twice, after a
warm-up, and reports the median CPU time per motion. The ratio this tree / base is taken
per pair of neighbouring runs; their median is the result. This tree runs with its
default, the biomechanical checks (and foot locking) on; ``--no-biomechanics`` times it
without them, as the base verifies. Prints a table and writes
``bench/results/paper_specs_ab.json`` (``paper_specs_ab_without_biomechanics.json``).
Not a test: run ``python bench/paper_specs_ab.py``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ltl_human_motion.atomic import atomic_write_text  # noqa: E402

#: The last commit before the work on issue 11 (scenario corpus) began.
DEFAULT_BASE = "a6ece0b^"

_CHILD = r"""
import json, sys, time, statistics
tree, mode = sys.argv[1], sys.argv[2]
sys.path.insert(0, tree)
from ltl_human_motion.planning import pipeline
from ltl_human_motion.planning.pipeline import get_library, resolve_cell, synthesize
kw = {}
if mode != "default":
    from ltl_human_motion.planning.pipeline import SynthesisOptions
    from ltl_human_motion.planning.verify import VerificationOptions
    kw["options"] = SynthesisOptions(verification=VerificationOptions(biomechanics=mode == "on"))
cell, lib = resolve_cell("paper_cell"), get_library()
out = {}
for name in ("S1", "S2"):
    synthesize(name, cell, library=lib, **kw)
    cpu = []
    for rep in range(2):
        for seed in range(9):
            pipeline._SEQUENCE_CACHE.clear()
            t = time.process_time()
            synthesize(name, cell, library=lib, seed=seed, **kw)
            cpu.append(time.process_time() - t)
    out[name] = statistics.median(cpu)
print(json.dumps(out))
"""


def worktree(ref: str) -> Path:
    """A checkout of ``ref`` under ``.build/ab/<sha>`` (made once, then reused)."""
    sha = subprocess.run(["git", "rev-parse", "--short", ref], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout.strip()
    path = ROOT / ".build" / "ab" / sha
    if not (path / "ltl_human_motion").is_dir():
        path.parent.mkdir(parents=True, exist_ok=True)
        subprocess.run(["git", "worktree", "add", "--force", "--detach", str(path), sha],
                       cwd=ROOT, check=True, capture_output=True, text=True)
    return path


def run(tree: Path, mode: str) -> dict[str, float]:
    """Median CPU seconds per S1 and S2 motion of one fresh process on ``tree``, with its
    default verification (``mode`` "default") or the biomechanical checks "on" or
    "off"."""
    res = subprocess.run([sys.executable, "-c", _CHILD, str(tree), mode],
                         check=True, capture_output=True, text=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", default=DEFAULT_BASE, help="git ref to compare against")
    parser.add_argument("--pairs", type=int, default=6)
    parser.add_argument("--no-biomechanics", action="store_true",
                        help="this tree without the biomechanical checks")
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    base = worktree(args.base)
    pairs = []
    for k in range(args.pairs):
        b, h = run(base, "default"), run(ROOT, "off" if args.no_biomechanics else "on")
        pairs.append({"base": b, "head": h})
        print(f"pair {k + 1}: base S1 {b['S1'] * 1e3:.1f} ms, S2 {b['S2'] * 1e3:.1f} ms; "
              f"this tree S1 {h['S1'] * 1e3:.1f} ms, S2 {h['S2'] * 1e3:.1f} ms", flush=True)
    ratio = {n: statistics.median(p["head"][n] / p["base"][n] for p in pairs)
             for n in ("S1", "S2")}
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                          capture_output=True, text=True).stdout.strip()
    report = {"benchmark": "paper_specs_ab", "base": args.base, "base_tree": base.name,
              "head": head, "biomechanics": not args.no_biomechanics, "pairs": pairs,
              "ratio_median": ratio, "limit": 1.2}
    print(f"this tree / {args.base}: S1 {ratio['S1']:.3f}x, S2 {ratio['S2']:.3f}x "
          f"(issue 11 allows 1.2x), "
          f"{'without' if args.no_biomechanics else 'with'} the biomechanical checks")
    out = args.out or ROOT / "bench" / "results" / (
        "paper_specs_ab_without_biomechanics.json" if args.no_biomechanics
        else "paper_specs_ab.json")
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out, json.dumps(report, indent=1))
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
