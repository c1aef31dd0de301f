"""docs/cells.md documents every key the cell loader accepts, and no other (issue 35).

The keys are read from the loader's source (``scene/cell_yaml.py``): every
``mapping(value, key, allowed)`` call names the keys allowed at one place of the file; the
place follows from the function it is in and the key variable it is given. A new mapping
call fails this test until it is documented and its place is added to ``PLACES``."""

from __future__ import annotations

import ast
import inspect
import re
from pathlib import Path

import pytest

from ltl_human_motion.errors import CellError
from ltl_human_motion.scene import cell_yaml
from ltl_human_motion.scene.cell_yaml import cell_from_yaml

DOC = Path(__file__).resolve().parents[1] / "docs" / "cells.md"

#: (function, key argument) of each mapping call -> the path prefix of its keys in the doc.
PLACES = {
    ("_parse_cell", ""): "",
    ("_parse_cell", "workspace"): "workspace.",
    ("obj", "key"): "objects.<name>.",
    ("obj", "skey"): "objects.<name>.sitting_surface.",
    ("region", "key"): "regions.<name>.",
    ("obstacle", "key"): "obstacles.<name>.",
    ("obstacle", "pkey"): "obstacles.<name>.parts[].",
}


def loader_keys() -> set[str]:
    """Every key path the loader accepts, from its ``mapping`` calls."""
    tree = ast.parse(inspect.getsource(cell_yaml))
    namespace = {**vars(cell_yaml), "self": cell_yaml._Parser}
    keys: set[str] = set()
    calls = 0
    for func in ast.walk(tree):
        if not isinstance(func, ast.FunctionDef):
            continue
        for node in ast.walk(func):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and node.func.attr == "mapping" and len(node.args) >= 3):
                continue
            where = node.args[1]
            label = where.value if isinstance(where, ast.Constant) else ast.unparse(where)
            place = (func.name, label)
            assert place in PLACES, (f"a mapping in cell_yaml.{func.name} with key {label!r}: "
                                     "document its keys in docs/cells.md and add it to PLACES")
            allowed = eval(compile(ast.Expression(node.args[2]), "<allowed>", "eval"),
                           namespace)
            keys |= {PLACES[place] + k for k in allowed}
            calls += 1
    assert calls >= len(PLACES)
    return keys


def doc_keys() -> set[str]:
    """The key paths in the first column of the doc's tables."""
    return set(re.findall(r"^\| `([^`]+)` \|", DOC.read_text(encoding="utf-8"), re.M))


def test_every_accepted_key_is_documented() -> None:
    missing = loader_keys() - doc_keys()
    assert not missing, f"accepted by the loader, not in docs/cells.md: {sorted(missing)}"


def test_every_documented_key_is_accepted() -> None:
    extra = doc_keys() - loader_keys()
    assert not extra, f"in docs/cells.md, refused by the loader: {sorted(extra)}"


def test_annotated_example_loads() -> None:
    examples = re.findall(r"```yaml\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    cell = cell_from_yaml(examples[0], source="docs/cells.md")
    assert set(cell.objects) == {"O1", "crate", "stool"}
    assert cell.objects["crate"].two_handed and not cell.objects["stool"].movable
    assert cell.final_region.name == "R1" and "assemble" in cell.shorthands


@pytest.mark.parametrize("key", ["objects.O1.grasp_point", "regions.R1.centre"])
def test_a_key_the_doc_lacks_is_refused_by_name(key: str) -> None:
    """The test's premise: a key outside the loader's lists is refused, naming it."""
    section, name, bad = key.split(".")
    body = {"objects": "{position: [0, 0, 0.1], shape: box, size: [0.1, 0.1, 0.1], "
                       f"{bad}: 1}}",
            "regions": f"{{lo: [0, 0, 0], hi: [1, 1, 1], {bad}: 1}}"}[section]
    entry = f"  {name}: {body}\n"
    text = ("start_region: R0\nregions:\n  R0: {lo: [-1, -1, 0], hi: [-0.5, -0.5, 1]}\n"
            + (entry if section == "regions" else f"{section}:\n{entry}"))
    with pytest.raises(CellError, match=re.escape(f"{key}: unknown key")):
        cell_from_yaml(text)
