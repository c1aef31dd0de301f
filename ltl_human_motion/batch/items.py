"""Items of a batch: parameters derived deterministically from (global seed, item index).

Item ``i`` of a run with global seed ``s`` draws from ``np.random.default_rng([s, i])`` in
a fixed order: the specification (by weight), the cycle count, the stature (from the
grid), one offset per jittered object (sorted by name, x, y, z), one per jittered region
(sorted by name), and finally the synthesis seed. Offsets are rounded to 0.1 mm so the
manifest holds the exact values used. Nothing depends on which worker runs the item, or
when.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ltl_human_motion.batch.specs import BatchConfigError, BatchSpecs

if TYPE_CHECKING:
    from ltl_human_motion.scene.cell import Cell

__all__ = ["ItemParams", "cell_for_item", "derive_item", "validate_against_cell"]

_SEED_BOUND = 2**31 - 1
_OFFSET_DECIMALS = 4


@dataclass(frozen=True)
class ItemParams:
    """Everything that defines one item.

    Attributes
    ----------
    index : int
        Position in the dataset, 0-based.
    spec_name, spec : str
        Label and LTL text of the chosen specification.
    seed : int
        Seed passed to :func:`~ltl_human_motion.planning.pipeline.synthesize`.
    cycles : int
    stature : float
        Metres.
    object_offsets, region_offsets : dict of str to tuple of 3 floats
        Translations (metres) applied to the cell before synthesis.
    """

    index: int
    spec_name: str
    spec: str
    seed: int
    cycles: int = 1
    stature: float = 1.75
    object_offsets: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    region_offsets: dict[str, tuple[float, float, float]] = field(default_factory=dict)

    def params_dict(self) -> dict[str, Any]:
        """The varied parameters in plain form (manifest ``params``)."""
        return {"cycles": self.cycles, "stature": self.stature,
                "objects": {k: list(v) for k, v in sorted(self.object_offsets.items())},
                "regions": {k: list(v) for k, v in sorted(self.region_offsets.items())}}


def _check_index(seed: int, index: int) -> None:
    for name, v in (("seed", seed), ("index", index)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise ValueError(f"{name} must be an integer >= 0, got {v!r}")


def derive_item(specs: BatchSpecs, seed: int, index: int) -> ItemParams:
    """The parameters of item ``index`` of a run with global seed ``seed``.

    Parameters
    ----------
    specs : BatchSpecs
    seed : int
        Global seed, >= 0.
    index : int
        Item index, >= 0.

    Returns
    -------
    ItemParams
    """
    _check_index(seed, index)
    rng = np.random.default_rng([int(seed), int(index)])
    weights = np.array([s.weight for s in specs.specs], dtype=np.float64)
    cumulative = np.cumsum(weights / weights.sum())
    k = int(np.searchsorted(cumulative, rng.random(), side="right"))
    entry = specs.specs[min(k, len(specs.specs) - 1)]
    cycle_choices = entry.cycles if entry.cycles is not None else specs.cycles
    cycles = cycle_choices[int(rng.integers(len(cycle_choices)))]
    stature = specs.statures[int(rng.integers(len(specs.statures)))]

    def offsets(section: dict) -> dict[str, tuple[float, float, float]]:
        out = {}
        for name in sorted(section):
            jit = section[name]
            v = rng.uniform(np.asarray(jit.lo), np.asarray(jit.hi))
            out[name] = tuple(float(round(x, _OFFSET_DECIMALS)) + 0.0 for x in v)
        return out

    objects = offsets(specs.objects)
    regions = offsets(specs.regions)
    item_seed = int(rng.integers(0, _SEED_BOUND))
    return ItemParams(index=int(index), spec_name=entry.name, spec=entry.spec, seed=item_seed,
                      cycles=int(cycles), stature=float(stature), object_offsets=objects,
                      region_offsets=regions)


def validate_against_cell(specs: BatchSpecs, cell: Cell) -> None:
    """Check that jittered names exist in ``cell`` and every spec builds there.

    Raises
    ------
    BatchConfigError
        Unknown object/region or an invalid specification (names the key).
    """
    from ltl_human_motion.errors import LtlHumanMotionError
    from ltl_human_motion.ltl.spec import build_specification

    for section, known in (("objects", cell.objects), ("regions", cell.regions)):
        for name in getattr(specs, section):
            if name not in known:
                raise BatchConfigError(f"{specs.source}: {section}.{name}: cell {cell.name!r} "
                                       f"has no such {section[:-1]}; known: "
                                       f"{', '.join(sorted(known)) or '(none)'}")
    named = {*cell.objects, *cell.regions, *(o.name for o in cell.obstacles)}
    for name in specs.descriptions:
        if name not in named:
            raise BatchConfigError(f"{specs.source}: descriptions.{name}: cell {cell.name!r} "
                                   "has no such object, region or obstacle; known: "
                                   f"{', '.join(sorted(named))}")
    for i, entry in enumerate(specs.specs):
        try:
            build_specification(entry.spec, cell)
        except (LtlHumanMotionError, ValueError) as exc:
            raise BatchConfigError(f"{specs.source}: specs[{i}].spec: {exc}") from exc


def cell_for_item(cell: Cell, item: ItemParams) -> Cell:
    """``cell`` with the item's object and region offsets applied (a new Cell).

    The start and final regions follow their jittered regions. Without offsets the
    cell itself is returned.
    """
    if not item.object_offsets and not item.region_offsets:
        return cell
    objects = dict(cell.objects)
    for name, off in item.object_offsets.items():
        obj = objects[name]
        delta = np.asarray(off, dtype=np.float64)
        objects[name] = dataclasses.replace(obj, position=obj.position + delta,
                                            shape=obj.shape.translated(delta))
    regions = dict(cell.regions)
    for name, off in item.region_offsets.items():
        reg = regions[name]
        regions[name] = dataclasses.replace(reg, shape=reg.shape.translated(
            np.asarray(off, dtype=np.float64)))
    start = regions[cell.start_region.name]
    final = None if cell.final_region is None else regions[cell.final_region.name]
    return dataclasses.replace(cell, objects=objects, regions=regions, start_region=start,
                               final_region=final)
