"""The scenario corpus: labelled (cell, specification) pairs read from a specs file.

The specs file (``scenarios/specs.yaml``) lists, per cell, the Table I tasks feasible in
it (each gives the pair ``F <task>``), tuples ``[P, S, Q, R]`` that instantiate every
Dwyer pattern in every scope (:data:`DWYER_PATTERNS`), realistic multi-step jobs, and
infeasible pairs with the reason. :func:`load_corpus` expands it into :class:`Pair`
objects, each with a family name that the benchmark groups failures by.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ltl_human_motion.errors import CellError

__all__ = [
    "DWYER_PATTERNS", "INFEASIBLE_REASONS", "Pair", "default_specs_path", "load_corpus",
    "task_name",
]

#: The property specification patterns of Dwyer, Avrunin and Corbett (ICSE 1999), in
#: their LTL mappings (patterns catalogue, Kansas State University), over the task
#: atoms P, S (the property) and Q, R (the scope delimiters). Scoped patterns are
#: conjoined with ``F(Q & F R)`` / ``F Q`` / ``F R`` and the property's tasks with
#: ``F P`` (or ``F S``) so that the scope and the tasks occur: otherwise the shortest
#: lasso would satisfy the pattern vacuously and never move. Universality is stated for
#: the property ``P -> X S`` ("every P is immediately followed by S").
DWYER_PATTERNS: dict[str, str] = {
    "absence_global": "F S & G !P",
    "absence_before": "F R & F P & (F R -> (!P U R))",
    "absence_after": "F Q & F P & G(Q -> G !P)",
    "absence_between": "F(Q & F R) & F P & G((Q & !R & F R) -> (!P U R))",
    "existence_global": "F P",
    "existence_before": "F R & (!R W (P & !R))",
    "existence_after": "F Q & (G !Q | F(Q & F P))",
    "existence_between": "F(Q & F R) & G((Q & !R) -> (!R W (P & !R)))",
    "universality_global": "F P & G(P -> X S)",
    "universality_before": "F R & F P & (F R -> ((P -> X S) U R))",
    "universality_after": "F Q & F P & G(Q -> G(P -> X S))",
    "universality_between": "F(Q & F R) & F P & G((Q & !R & F R) -> ((P -> X S) U R))",
    "precedence_global": "F P & (!P W S)",
    "precedence_before": "F R & F P & (F R -> (!P U (S | R)))",
    "precedence_after": "F Q & F P & (G !Q | F(Q & (!P W S)))",
    "precedence_between": "F(Q & F R) & F P & G((Q & !R & F R) -> (!P U (S | R)))",
    "response_global": "F P & G(P -> F S)",
    "response_before": "F R & F P & (F R -> ((P -> (!R U (S & !R))) U R))",
    "response_after": "F Q & F P & G(Q -> G(P -> F S))",
    "response_between": "F(Q & F R) & F P & G((Q & !R & F R) -> ((P -> (!R U (S & !R))) U R))",
}

#: Why a pair is infeasible (the ``reason`` of :class:`~ltl_human_motion.errors.
#: PlanningError` raised by :mod:`ltl_human_motion.planning.feasibility`, or
#: ``unsatisfiable`` for a specification the LTL layer refuses).
INFEASIBLE_REASONS: frozenset[str] = frozenset({
    "reach", "seat_height", "enclosed", "no_floor", "inside_obstacle", "size",
    "unsatisfiable",
})


@dataclass(frozen=True)
class Pair:
    """One labelled (cell, specification) pair of the corpus.

    Attributes
    ----------
    id : str
        Unique, e.g. ``"shelf_heights/single/grasp(O_knee)"``.
    cell : str
        Cell name (a key of the specs file's ``cells``).
    cell_file : str
        Absolute path of the cell YAML.
    spec : str
    expect : {"feasible", "infeasible"}
    family : str
        What the pair exercises: ``single:grasp``, ``dwyer:absence_between``,
        ``job:kitting``, ``infeasible:reach``, ...
    reason : str or None
        For infeasible pairs: one of :data:`INFEASIBLE_REASONS`.
    why : str
        The label's justification in words (infeasible pairs).
    """

    id: str
    cell: str
    cell_file: str
    spec: str
    expect: str
    family: str
    reason: str | None = None
    why: str = ""

    @property
    def feasible(self) -> bool:
        return self.expect == "feasible"


def default_specs_path() -> Path:
    """``scenarios/specs.yaml`` of the source tree."""
    return Path(__file__).resolve().parents[2] / "scenarios" / "specs.yaml"


def task_name(atom: str) -> str:
    """The task of an atom: ``"carry(O1, R1)" -> "carry"``, ``"standUp" -> "standUp"``."""
    return atom.split("(", 1)[0].strip()


def _error(source: str, key: str, message: str) -> CellError:
    return CellError(f"{source}: {key}: {message}")


def _strings(value: Any, source: str, key: str) -> list[str]:
    if not isinstance(value, list) or not all(isinstance(v, str) and v.strip() for v in value):
        raise _error(source, key, f"expected a list of task strings, got {value!r}")
    return [v.strip() for v in value]


def _pattern_pairs(name: str, path: str, entry: Any, source: str, key: str,
                   index: int) -> list[Pair]:
    """The 20 Dwyer pairs of one tuple ``[P, S, Q, R]``, or of ``{tasks: [P, S, Q, R],
    infeasible: {pattern: why}}``, whose listed patterns are labelled ``unsatisfiable``:
    with only the tuple's tasks no physical order of task steps satisfies them (for
    example ``precedence_global`` with S = ``carry(O1, R1)`` and P = ``grasp(O1)``: the
    carry leaves O1 in hand and no task of the specification frees the hand for the
    grasp it demands afterwards)."""
    overrides: Mapping[str, Any] = {}
    if isinstance(entry, Mapping):
        unknown = sorted(set(entry) - {"tasks", "infeasible"})
        if unknown or "tasks" not in entry:
            raise _error(source, key, f"expected {{tasks, infeasible}}, got keys {sorted(entry)}")
        overrides = entry.get("infeasible") or {}
        bad = sorted(set(overrides) - set(DWYER_PATTERNS)) if isinstance(overrides, Mapping) \
            else ["(not a mapping)"]
        if bad or not all(isinstance(w, str) and w.strip() for w in overrides.values()):
            raise _error(source, f"{key}.infeasible",
                         f"expected {{pattern name: why}} over {sorted(DWYER_PATTERNS)}; "
                         f"bad: {bad or 'a why that is not text'}")
        entry = entry["tasks"]
    tasks = _strings(entry, source, key)
    if len(tasks) != 4 or len(set(tasks)) != 4:
        raise _error(source, key, f"expected four different tasks [P, S, Q, R], got {tasks}")
    binding = dict(zip("PSQR", tasks))
    pairs: list[Pair] = []
    for pname, template in DWYER_PATTERNS.items():
        text = "".join(f"({binding[c]})" if c in binding else c for c in template)
        pid = f"{name}/dwyer/{pname}/{index}"
        if pname in overrides:
            pairs.append(Pair(pid, name, path, text, "infeasible", "infeasible:unsatisfiable",
                              "unsatisfiable", str(overrides[pname]).strip()))
        else:
            pairs.append(Pair(pid, name, path, text, "feasible", f"dwyer:{pname}"))
    return pairs


def _cell_pairs(name: str, spec: Mapping[str, Any], root: Path, source: str) -> list[Pair]:
    key = f"cells.{name}"
    if not isinstance(spec, Mapping) or "file" not in spec:
        raise _error(source, key, "expected a mapping with at least 'file'")
    unknown = sorted(set(spec) - {"file", "single", "patterns", "jobs", "infeasible"})
    if unknown:
        raise _error(source, key, f"unknown keys {unknown}")
    cell_file = root / str(spec["file"])
    if not cell_file.is_file():
        raise _error(source, f"{key}.file", f"no such cell file {cell_file}")
    path = str(cell_file)
    pairs: list[Pair] = []
    for atom in _strings(spec.get("single", []), source, f"{key}.single"):
        pairs.append(Pair(f"{name}/single/{atom}", name, path, f"F {atom}", "feasible",
                          f"single:{task_name(atom)}"))
    for i, tup in enumerate(spec.get("patterns", []) or []):
        pairs.extend(_pattern_pairs(name, path, tup, source, f"{key}.patterns[{i}]", i))
    for i, job in enumerate(spec.get("jobs", []) or []):
        jkey = f"{key}.jobs[{i}]"
        if not isinstance(job, Mapping) or not {"name", "spec"} <= set(job):
            raise _error(source, jkey, "expected {name, spec}")
        pairs.append(Pair(f"{name}/job/{job['name']}", name, path, str(job["spec"]),
                          "feasible", f"job:{job['name']}"))
    for i, item in enumerate(spec.get("infeasible", []) or []):
        ikey = f"{key}.infeasible[{i}]"
        if not isinstance(item, Mapping) or not {"spec", "reason"} <= set(item):
            raise _error(source, ikey, "expected {spec, reason, why}")
        reason = str(item["reason"])
        if reason not in INFEASIBLE_REASONS:
            raise _error(source, f"{ikey}.reason", f"expected one of "
                                                   f"{sorted(INFEASIBLE_REASONS)}, got {reason!r}")
        pairs.append(Pair(f"{name}/infeasible/{item['spec']}", name, path, str(item["spec"]),
                          "infeasible", f"infeasible:{reason}", reason,
                          str(item.get("why", ""))))
    return pairs


def load_corpus(path: str | os.PathLike[str] | None = None,
                cells: list[str] | None = None) -> list[Pair]:
    """Expand a specs file into labelled pairs.

    Parameters
    ----------
    path : path, optional
        The specs file (default :func:`default_specs_path`). Cell files are relative to
        the folder above the file's folder (the repository root).
    cells : list of str, optional
        Only these cells (ValueError naming the unknown ones).

    Raises
    ------
    CellError
        Malformed file; the message names the file and the key.
    """
    import yaml
    path = Path(path) if path is not None else default_specs_path()
    source = str(path)
    try:
        data = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise CellError(f"{source}: cannot read the specs file: {exc}") from exc
    if not isinstance(data, Mapping) or not isinstance(data.get("cells"), Mapping):
        raise _error(source, "cells", "expected a mapping of cell name to its pairs")
    root = path.resolve().parent.parent
    known = list(data["cells"])
    if cells is not None:
        missing = sorted(set(cells) - set(known))
        if missing:
            raise ValueError(f"unknown cells {missing}; the corpus has {', '.join(known)}")
    pairs: list[Pair] = []
    for name, spec in data["cells"].items():
        if cells is None or name in cells:
            pairs.extend(_cell_pairs(str(name), spec, root, source))
    ids = [p.id for p in pairs]
    if len(set(ids)) != len(ids):
        dup = sorted({i for i in ids if ids.count(i) > 1})
        raise _error(source, "cells", f"duplicate pairs {dup}")
    return pairs
