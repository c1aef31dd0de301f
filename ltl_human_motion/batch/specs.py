"""The batch specs file: which specifications to synthesize and what to vary.

A specs file is YAML (see ``config/specs_example.yaml``)::

    version: 1
    specs:                          # at least one; chosen per item by weight
      - {name: S1, spec: S1, weight: 1.0}
      - name: pick_two
        spec: "S2"                  # LTL text or a name of PAPER_SPECS
        weight: 2.0
        cycles: [1, 2]              # overrides the global cycles for this spec
    cycles: 1                       # int, or a list of ints chosen uniformly
    stature: {min: 1.60, max: 1.90, step: 0.05}   # or a number, or a list of numbers
    objects:                        # object position jitter (offsets in metres)
      O1: [0.10, 0.10, 0.0]         # half-widths: offset ~ U([-0.1, 0.1] x [-0.1, 0.1] x {0})
      O2: {lo: [-0.1, 0.0, 0.0], hi: [0.1, 0.15, 0.0]}   # or an offset box
    regions:                        # region translations, same forms (R0 moves the start)
      R1: [0.05, 0.05, 0.0]
    sequence_mode: random           # task-sequence variations: random | coverage | all
    keep_unverified: false          # keep motions that fail a check (status "unverified")
    options: {max_nodes: 20000}     # SynthesisOptions.from_dict keys
    descriptions:                   # how captions name things (default: by name)
      kit: kit tray                 # objects, regions and obstacles of the cell

Statures are drawn from a grid (``min + k * step``) because every body size needs its
own motion library (built once, ~5 s, then cached on disk). Start poses vary with the
item seed (the pipeline samples a pose inside the start region) and with the jitter of
the start region. Every error names the file and the key, e.g.
``specs.yaml: specs[1].weight: expected a positive number, got -1``.
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ltl_human_motion.errors import LtlHumanMotionError
from ltl_human_motion.yaml_limits import TextFileError, read_text_file

__all__ = [
    "BatchConfigError", "BatchSpecs", "Jitter", "SpecEntry", "load_specs", "specs_from_yaml",
]

SPECS_VERSION = 1
_TOP_KEYS = {"version", "specs", "cycles", "stature", "objects", "regions", "sequence_mode",
             "keep_unverified", "options", "descriptions"}
_SPEC_KEYS = {"name", "spec", "weight", "cycles"}
_MODES = ("random", "coverage", "all")
MAX_STATURE_GRID = 81


class BatchConfigError(LtlHumanMotionError, ValueError):
    """A malformed specs file or batch set-up; the message names the file and the key."""


@dataclass(frozen=True)
class Jitter:
    """A uniform offset box ``[lo, hi]`` (metres, per axis x, y, z)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def to_dict(self) -> dict[str, list[float]]:
        return {"lo": list(self.lo), "hi": list(self.hi)}


@dataclass(frozen=True)
class SpecEntry:
    """One specification of the mix.

    Attributes
    ----------
    name : str
        Short label stored with every item.
    spec : str
        LTL text (or a name of ``PAPER_SPECS``).
    weight : float
        Relative probability of being chosen for an item.
    cycles : tuple of int or None
        Choices of the accepting-cycle repetitions (None: the global choices).
    """

    name: str
    spec: str
    weight: float = 1.0
    cycles: tuple[int, ...] | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "spec": self.spec, "weight": self.weight,
                "cycles": None if self.cycles is None else list(self.cycles)}


@dataclass(frozen=True)
class BatchSpecs:
    """A parsed specs file.

    Attributes
    ----------
    specs : tuple of SpecEntry
    cycles : tuple of int
        Global choices of cycle repetitions.
    statures : tuple of float
        The stature grid, metres.
    objects, regions : dict of str to Jitter
        Offsets applied to object positions and region boxes.
    sequence_mode : str
    keep_unverified : bool
    options : dict
        Keys of :meth:`SynthesisOptions.from_dict`.
    source : str
        File the specs came from (for messages).
    descriptions : dict of str to str
        Noun phrases captions use for objects, regions and obstacles of the cell
        (:mod:`~ltl_human_motion.batch.captions`).
    """

    specs: tuple[SpecEntry, ...]
    cycles: tuple[int, ...] = (1,)
    statures: tuple[float, ...] = (1.75,)
    objects: dict[str, Jitter] = field(default_factory=dict)
    regions: dict[str, Jitter] = field(default_factory=dict)
    sequence_mode: str = "random"
    keep_unverified: bool = False
    options: dict[str, Any] = field(default_factory=dict)
    source: str = "<inline>"
    descriptions: dict[str, str] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """Normalized plain form (no ``source``); the dataset stores it."""
        out = {"version": SPECS_VERSION, "specs": [s.to_dict() for s in self.specs],
               "cycles": list(self.cycles), "statures": list(self.statures),
               "objects": {k: self.objects[k].to_dict() for k in sorted(self.objects)},
               "regions": {k: self.regions[k].to_dict() for k in sorted(self.regions)},
               "sequence_mode": self.sequence_mode, "keep_unverified": self.keep_unverified,
               "options": dict(sorted(self.options.items()))}
        if self.descriptions:               # absent otherwise: older fingerprints hold
            out["descriptions"] = dict(sorted(self.descriptions.items()))
        return out

    def fingerprint(self) -> str:
        """SHA-256 (hex) of the normalized specs."""
        text = json.dumps(self.to_dict(), sort_keys=True)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()


# --------------------------------------------------------------------------- parsing

class _Checker:
    def __init__(self, source: str) -> None:
        self.source = source

    def error(self, key: str, message: str) -> BatchConfigError:
        return BatchConfigError(f"{self.source}: {key}: {message}")

    def number(self, value: Any, key: str, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) \
                or not math.isfinite(float(value)) or (positive and not value > 0):
            kind = "a positive number" if positive else "a finite number"
            raise self.error(key, f"expected {kind}, got {value!r}")
        return float(value)

    def int_choices(self, value: Any, key: str) -> tuple[int, ...]:
        items = value if isinstance(value, list) else [value]
        if not items:
            raise self.error(key, "expected an integer >= 1 or a non-empty list of them")
        out = []
        for i, v in enumerate(items):
            if isinstance(v, bool) or not isinstance(v, int) or v < 1:
                where = key if not isinstance(value, list) else f"{key}[{i}]"
                raise self.error(where, f"expected an integer >= 1, got {v!r}")
            out.append(int(v))
        return tuple(out)

    def vec3(self, value: Any, key: str) -> tuple[float, float, float]:
        if not isinstance(value, list) or len(value) != 3:
            raise self.error(key, f"expected 3 numbers [x, y, z], got {value!r}")
        return tuple(self.number(v, f"{key}[{i}]") for i, v in enumerate(value))  # type: ignore

    def jitter(self, value: Any, key: str) -> Jitter:
        if isinstance(value, list):
            half = self.vec3(value, key)
            if any(h < 0 for h in half):
                raise self.error(key, f"half-widths must be >= 0, got {list(half)}")
            return Jitter(tuple(-h for h in half), half)  # type: ignore[arg-type]
        if isinstance(value, Mapping):
            extra = sorted(set(value) - {"lo", "hi"})
            if extra or "lo" not in value or "hi" not in value:
                raise self.error(key, f"expected {{lo: [x, y, z], hi: [x, y, z]}}, got keys "
                                      f"{sorted(value)}")
            lo, hi = self.vec3(value["lo"], f"{key}.lo"), self.vec3(value["hi"], f"{key}.hi")
            if any(a > b for a, b in zip(lo, hi)):
                raise self.error(key, f"lo {list(lo)} must not exceed hi {list(hi)}")
            return Jitter(lo, hi)
        raise self.error(key, "expected half-widths [x, y, z] or {lo: [...], hi: [...]}, got "
                              f"{value!r}")

    def statures(self, value: Any, key: str = "stature") -> tuple[float, ...]:
        from ltl_human_motion.motion.library import MAX_LIBRARY_STATURE, MIN_LIBRARY_STATURE
        if isinstance(value, Mapping):
            extra = sorted(set(value) - {"min", "max", "step"})
            if extra or "min" not in value or "max" not in value:
                raise self.error(key, "expected {min: m, max: m, step: m}, got keys "
                                      f"{sorted(value)}")
            lo = self.number(value["min"], f"{key}.min")
            hi = self.number(value["max"], f"{key}.max")
            step = self.number(value.get("step", 0.05), f"{key}.step", positive=True)
            if hi < lo:
                raise self.error(key, f"max {hi} is below min {lo}")
            n = math.floor((hi - lo) / step + 1e-9) + 1
            if n > MAX_STATURE_GRID:
                raise self.error(f"{key}.step", f"{n} statures in the grid (at most "
                                                f"{MAX_STATURE_GRID}); each needs a library")
            grid = [round(lo + k * step, 3) for k in range(n)]
        else:
            items = value if isinstance(value, list) else [value]
            if not items:
                raise self.error(key, "expected a number, a list or {min, max, step}")
            grid = [round(self.number(v, f"{key}[{i}]" if isinstance(value, list) else key), 3)
                    for i, v in enumerate(items)]
        for s in grid:
            if not MIN_LIBRARY_STATURE <= s <= MAX_LIBRARY_STATURE:
                raise self.error(key, f"stature {s} m is outside [{MIN_LIBRARY_STATURE}, "
                                      f"{MAX_LIBRARY_STATURE}]")
        return tuple(sorted(set(grid)))


def specs_from_yaml(text: str, source: str = "<inline>") -> BatchSpecs:
    """Parse a specs file from YAML text.

    Parameters
    ----------
    text : str
    source : str
        Name used in error messages.

    Raises
    ------
    BatchConfigError
        Malformed file; the message names ``source`` and the key.
    """
    import yaml

    chk = _Checker(source)
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise BatchConfigError(f"{source}: not valid YAML: {exc}") from exc
    if not isinstance(data, Mapping):
        raise BatchConfigError(f"{source}: expected a mapping with a 'specs' list at the top")
    unknown = sorted(set(data) - _TOP_KEYS)
    if unknown:
        raise chk.error(unknown[0], f"unknown key; expected some of {sorted(_TOP_KEYS)}")
    version = data.get("version", SPECS_VERSION)
    if version != SPECS_VERSION:
        raise chk.error("version", f"expected {SPECS_VERSION}, got {version!r}")
    raw_specs = data.get("specs")
    if not isinstance(raw_specs, list) or not raw_specs:
        raise chk.error("specs", "expected a non-empty list of {name, spec, weight, cycles}")
    entries = []
    names: set[str] = set()
    for i, raw in enumerate(raw_specs):
        key = f"specs[{i}]"
        if isinstance(raw, str):
            raw = {"spec": raw}
        if not isinstance(raw, Mapping):
            raise chk.error(key, f"expected a mapping or an LTL string, got {raw!r}")
        extra = sorted(set(raw) - _SPEC_KEYS)
        if extra:
            raise chk.error(f"{key}.{extra[0]}", f"unknown key; expected some of "
                                                  f"{sorted(_SPEC_KEYS)}")
        spec = raw.get("spec")
        if not isinstance(spec, str) or not spec.strip():
            raise chk.error(f"{key}.spec", f"expected an LTL formula, got {spec!r}")
        name = raw.get("name", spec.strip())
        if not isinstance(name, str) or not name:
            raise chk.error(f"{key}.name", f"expected a non-empty string, got {name!r}")
        if name in names:
            raise chk.error(f"{key}.name", f"duplicate name {name!r}")
        names.add(name)
        weight = chk.number(raw.get("weight", 1.0), f"{key}.weight", positive=True)
        cycles = (chk.int_choices(raw["cycles"], f"{key}.cycles") if "cycles" in raw
                  else None)
        entries.append(SpecEntry(name, spec.strip(), weight, cycles))
    jitters: dict[str, dict[str, Jitter]] = {}
    for section in ("objects", "regions"):
        raw = data.get(section) or {}
        if not isinstance(raw, Mapping):
            raise chk.error(section, f"expected a mapping name -> jitter, got {raw!r}")
        jitters[section] = {str(k): chk.jitter(v, f"{section}.{k}") for k, v in raw.items()}
    mode = data.get("sequence_mode", "random")
    if mode not in _MODES:
        raise chk.error("sequence_mode", f"expected one of {list(_MODES)}, got {mode!r}")
    keep = data.get("keep_unverified", False)
    if not isinstance(keep, bool):
        raise chk.error("keep_unverified", f"expected true or false, got {keep!r}")
    options = data.get("options") or {}
    if not isinstance(options, Mapping):
        raise chk.error("options", f"expected a mapping, got {options!r}")
    if "verify" in options:
        raise chk.error("options.verify", "not allowed here: every item is verified; use "
                                          "keep_unverified to keep failing motions")
    from ltl_human_motion.planning.pipeline import SynthesisOptions
    try:
        SynthesisOptions.from_dict(dict(options))
    except (ValueError, TypeError) as exc:
        raise chk.error("options", str(exc)) from exc
    descriptions = data.get("descriptions") or {}
    if not isinstance(descriptions, Mapping):
        raise chk.error("descriptions", f"expected a mapping name -> phrase, got "
                                        f"{descriptions!r}")
    for k, v in descriptions.items():
        if not isinstance(v, str) or not v.strip():
            raise chk.error(f"descriptions.{k}", f"expected a non-empty phrase, got {v!r}")
    return BatchSpecs(
        specs=tuple(entries),
        cycles=chk.int_choices(data.get("cycles", 1), "cycles"),
        statures=chk.statures(data.get("stature", 1.75)),
        objects=jitters["objects"], regions=jitters["regions"], sequence_mode=mode,
        keep_unverified=keep, options=dict(options), source=source,
        descriptions={str(k): v.strip() for k, v in descriptions.items()})


def load_specs(path: str | os.PathLike[str]) -> BatchSpecs:
    """Read and check a specs file (see the module docstring for the format)."""
    path = Path(path)
    try:
        text = read_text_file(path, "specs file")
    except TextFileError as exc:
        raise BatchConfigError(str(exc)) from None
    return specs_from_yaml(text, source=str(path))
