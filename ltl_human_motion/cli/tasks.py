"""``ltl-human-motion tasks``: task sequences (or the automaton) of an LTL specification."""

from __future__ import annotations

import argparse
import json

from ltl_human_motion.cli._types import positive as _positive
from ltl_human_motion.ltl import (
    BACKENDS,
    MODES,
    PAPER_SPECS,
    Automaton,
    HoaError,
    automaton_from_hoa,
    build_specification,
    dot_from_automaton,
    hoa_from_automaton,
    synthesize_sequences,
    task_automaton,
)
from ltl_human_motion.ltl.automaton import degeneralize
from ltl_human_motion.ltl.formula import And, Globally
from ltl_human_motion.ltl.spec import Specification
from ltl_human_motion.tasks import has_geometry, plan_sequences
from ltl_human_motion.tasks.model import TIME_CALIBRATION, CellModel, estimated_duration
from ltl_human_motion.yaml_limits import TextFileError, read_text_file

NAME = "tasks"
HELP = "print task sequences (or the Büchi automaton) satisfying an LTL specification"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add the options of ``tasks``."""
    parser.add_argument("spec", help="LTL specification, e.g. \"grasp(O1) & G F walk(R1)\", "
                        f"or a paper specification name ({', '.join(PAPER_SPECS)})")
    parser.add_argument("--cell", help="cell name (config/<name>.yaml, e.g. paper_cell) or "
                        "YAML file naming objects, regions, shorthands and the final region")
    parser.add_argument("-n", type=_positive, default=None,
                        help="number of sequences (default 5; coverage/all: the full set)")
    parser.add_argument("--seed", type=int, default=0, help="seed of --mode random (default 0)")
    parser.add_argument("--mode", choices=MODES, default="random",
                        help="variations: seeded random walks (default), transition "
                        "coverage, or all distinct sequences by length")
    parser.add_argument("--cycles", type=_positive, default=1,
                        help="passes through the accepting cycle (default 1)")
    parser.add_argument("--min-steps", type=int, default=0,
                        help="repeat the cycle until a sequence has this many steps "
                        "(default 0: once)")
    parser.add_argument("--max-length", type=_positive, default=None,
                        help="bound on prefix+cycle length for --mode all")
    parser.add_argument("--backend", choices=BACKENDS, default="auto",
                        help="LTL translator (default auto: Spot if installed, else built-in)")
    parser.add_argument("--hoa", metavar="FILE",
                        help="take the automaton from a HOA file (e.g. from Spot's ltl2tgba) "
                        "instead of translating; sequences are still checked against the spec")
    parser.add_argument("--automaton", choices=("hoa", "dot"),
                        help="print the automaton instead of sequences")
    parser.add_argument("--state-based", action="store_true",
                        help="with --automaton: a state-based Büchi automaton (as ltl2tgba -B)")
    parser.add_argument("--json", action="store_true", help="print sequences as JSON")


def run(args: argparse.Namespace) -> int:
    """Run ``tasks``; errors derive from LtlHumanMotionError (printed by the dispatcher)."""
    cell = args.cell
    if cell is not None:
        try:
            from ltl_human_motion.scene.cell import Cell  # noqa: F401 (the scene layer)
            from ltl_human_motion.scene.cell_yaml import resolve_cell
            cell = resolve_cell(cell)
        except ImportError:   # without the scene module a YAML file still names things
            pass
    spec = build_specification(args.spec, cell)
    given = _read_hoa(args.hoa) if args.hoa else None
    if args.automaton:
        aut = given if given is not None else task_automaton(spec, args.backend)
        if args.state_based:
            aut = degeneralize(aut)
        text = hoa_from_automaton(aut) if args.automaton == "hoa" else dot_from_automaton(aut)
        print(text, end="")
        return 0
    n = args.n if args.n is not None else (5 if args.mode == "random" else None)
    costs: list[float] = []
    lengths: list[float | None] = []
    if given is None and has_geometry(cell):
        # the cell model: cost-optimal, physically possible sequences first
        seqs, stats = plan_sequences(spec, cell, n=n, seed=args.seed, mode=args.mode,
                                     cycles=args.cycles, min_steps=args.min_steps,
                                     backend=args.backend)
        costs = stats.costs
        model = CellModel.from_cell(cell)
        lengths = [estimated_duration(model, s.tasks) for s in seqs]
    else:
        seqs = synthesize_sequences(spec, n=n, seed=args.seed, mode=args.mode,
                                    cycles=args.cycles, min_steps=args.min_steps,
                                    backend=args.backend, max_length=args.max_length,
                                    automaton=given)
    if args.json:
        print(json.dumps({"spec": spec.text, "formula": str(spec.formula), "sequences": [
            {"prefix": list(map(str, s.prefix)), "cycle": list(map(str, s.cycle)),
             "repetitions": s.repetitions, "tasks": list(map(str, s.tasks)),
             **({"estimated_seconds": _round(lengths[i]), "search_cost": round(costs[i], 3)}
                if i < len(costs) else {})}
            for i, s in enumerate(seqs)]}, indent=2))
        return 0
    print(f"# specification: {spec.text}")
    for line in always_on_lines(spec):
        print(f"# always on: {line}")
    if lengths:
        print(f"# estimated time of the motion: {TIME_CALIBRATION.describe()}")
    for i, seq in enumerate(seqs, 1):
        print(f"{i}: {' -> '.join(map(str, seq.tasks))}")
        if i - 1 < len(costs) and lengths[i - 1] is not None:
            print(f"   estimated time of the motion {lengths[i - 1]:.0f} s (the search's "
                  f"cost {costs[i - 1]:.1f})")
        print(f"   prefix [{', '.join(map(str, seq.prefix))}] cycle "
              f"[{', '.join(map(str, seq.cycle))}] x{seq.repetitions}")
    return 0


def _round(value: float | None) -> float | None:
    return None if value is None else round(value, 2)


#: Up to this many exclusivity clauses are printed in full; more are summarised.
MAX_PRINTED_CLAUSES = 6


def always_on_lines(spec: Specification) -> list[str]:
    """One line per always-on conjunct the specification adds to the user's formula; a long
    exclusivity conjunct (``G(!(p & q) & ...)``, one clause per pair of tasks that no
    single task makes true together) is summarised by its number of pairs (``--json`` and
    ``--automaton`` keep the whole formula)."""
    lines = []
    for label, formula in spec.always_on:
        clauses = formula.arg.args if isinstance(formula, Globally) and \
            isinstance(formula.arg, And) else ()
        if label.startswith("exclusivity") and len(clauses) > MAX_PRINTED_CLAUSES:
            lines.append(f"{label}: G !(p & q) for {len(clauses)} pairs of tasks, e.g. "
                         f"{' & '.join(map(str, clauses[:2]))}")
        else:
            lines.append(f"{label}: {formula}")
    return lines


def _read_hoa(path: str) -> Automaton:
    try:
        text = read_text_file(path, "HOA file")
    except TextFileError as exc:
        raise HoaError(str(exc)) from None
    return automaton_from_hoa(text)
