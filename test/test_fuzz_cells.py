"""Fuzzing the cell loader: any YAML gives a Cell or a CellError (never another
exception), whatever its structure, numbers or aliases; messages stay short."""

from __future__ import annotations

from pathlib import Path

import yaml
from fuzzing import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from ltl_human_motion.errors import CellError
from ltl_human_motion.scene.cell import Cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml

ROOT = Path(__file__).resolve().parents[1]
PAPER = yaml.safe_load((ROOT / "config" / "paper_cell.yaml").read_text())
#: An error message never grows with the input (values are shortened).
MAX_MESSAGE = 600

NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**30, 10**30),
                    st.sampled_from(["1e999", "-0", "nan", "0x10", "1_000", "", "1e-300"]))
SCALARS = st.one_of(NUMBERS, st.text(max_size=20), st.booleans(), st.none())
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(
    st.lists(inner, max_size=5), st.dictionaries(st.text(max_size=8), inner, max_size=5)),
    max_leaves=30)


def _load(text: str) -> Cell | None:
    try:
        return cell_from_yaml(text)
    except CellError as exc:
        assert len(str(exc)) < MAX_MESSAGE, str(exc)[:200]
        return None


def _mutate(path: list[str | int], value: object) -> dict:
    data = yaml.safe_load(yaml.safe_dump(PAPER))
    node = data
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    return data


PATHS = [["start_region"], ["workspace", "lo"], ["workspace"], ["floor_z"], ["description"],
         ["regions", "R0"], ["regions"], ["objects"], ["obstacles"], ["frame"], ["name"],
         ["shorthands"], ["final_region"]]


@fuzz_settings()
@given(st.sampled_from(PATHS), VALUES)
def test_any_value_at_any_key_loads_or_gives_a_cell_error(path: list, value: object) -> None:
    _load(yaml.safe_dump(_mutate(path, value)))


@fuzz_settings()
@given(st.sampled_from(PATHS), st.lists(NUMBERS, min_size=0, max_size=4))
def test_numbers_in_coordinates_load_or_give_a_cell_error(path: list, numbers: list) -> None:
    _load(yaml.safe_dump(_mutate(path, numbers)))


@fuzz_settings()
@given(st.integers(1, 12), st.integers(1, 12), st.sampled_from(["description", "name",
                                                                "objects", "floor_z"]))
def test_alias_towers_are_refused_or_small(levels: int, width: int, key: str) -> None:
    lines = ["a0: &a0 [x, x]"]
    for i in range(1, levels):
        lines.append(f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * width)}]")
    text = "\n".join(lines) + f"\n{key}: *a{levels - 1}\n"
    assert _load(text) is None                     # unknown keys a0.. at the least


@fuzz_settings()
@given(st.text(max_size=400))
def test_arbitrary_text_loads_or_gives_a_cell_error(text: str) -> None:
    _load(text)


@fuzz_settings()
@given(st.integers(1, 3000), st.sampled_from(["[", "{a: ", "- ", "  "]))
def test_deep_structures_give_a_cell_error(depth: int, opener: str) -> None:
    if opener in ("- ", "  "):
        text = "".join(" " * (2 * i) + "- x:\n" for i in range(depth))
    else:
        text = "description: " + opener * depth
    _load(text)
