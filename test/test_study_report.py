"""The study report says what differs between the layouts (which item moved, by how much,
a top view of both) and why each failed item failed (issue 35, item 5)."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from ltl_human_motion.planning.pipeline import resolve_cell
from ltl_human_motion.scene.cell_yaml import cell_from_yaml
from ltl_human_motion.study.layout import layout_changes, plot_layouts
from ltl_human_motion.study.runner import StudyConfig, run_study

CELLS = ("config/paper_cell.yaml", "config/paper_cell_b.yaml")

BASE = """
name: {name}
start_region: R0
regions:
  R0: {{lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 2.0]}}
  R1: {{lo: [0.9, -1.1, 0.9], hi: [1.1, -0.9, 1.1]}}
objects:
  O1: {{position: {o1}, shape: box, size: [0.1, 0.1, 0.1]}}
{more}obstacles:
  bench:
    parts:
      - {{shape: box, position: [1.2, -1.0, 0.4], size: {bench}}}
"""


def _cell(name: str, o1: str = "[-1.0, -1.0, 0.2]", bench: str = "[0.8, 1.2, 0.8]",
          more: str = ""):
    return cell_from_yaml(BASE.format(name=name, o1=o1, bench=bench, more=more))


def test_the_paper_layouts_differ_by_the_bench_and_r1() -> None:
    a, b = resolve_cell(CELLS[0]), resolve_cell(CELLS[1])
    changes = layout_changes(a, b)
    assert [(c.kind, c.name, c.change) for c in changes] == [
        ("furniture", "workbench", "moved"), ("region", "R1", "moved")]
    for c in changes:
        assert np.allclose(c.shift, [0.0, 0.25, 0.0])
        assert c.describe().endswith("moved 0.25 m (+0.25 m in y)")
    assert layout_changes(a, a) == []


def test_added_removed_resized_and_moved_parts() -> None:
    a = _cell("a")
    b = _cell("b", o1="[-1.0, -0.6, 0.2]", bench="[0.8, 1.0, 0.8]",
              more="  O2: {position: [0, 1, 0.1], shape: box, size: [0.1, 0.1, 0.1]}\n")
    got = {(c.name, c.change): c for c in layout_changes(a, b)}
    assert got.keys() == {("O1", "moved"), ("O2", "added"), ("bench", "resized")}
    assert got[("O1", "moved")].distance == pytest.approx(0.4)
    assert got[("bench", "resized")].describe() == \
        "furniture bench resized from 0.80 x 1.20 x 0.80 m to 0.80 x 1.00 x 0.80 m"
    assert [c.change for c in layout_changes(b, a) if c.name == "O2"] == ["removed"]


def test_top_view_png(tmp_path) -> None:
    a, b = resolve_cell(CELLS[0]), resolve_cell(CELLS[1])
    path = plot_layouts([a, b], ["A", "B"], tmp_path / "layouts.png", layout_changes(a, b))
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """S1 in layouts A and B; a search budget of 100 nodes makes a 1.9 m worker's assembly
    in layout B fail (the bench moved towards the centre line)."""
    out = tmp_path_factory.mktemp("study")
    cfg = StudyConfig(cells=CELLS, spec="S1", variants=2, statures=(1.6, 1.9), out=out,
                      workers=0, max_nodes=100)
    return cfg, run_study(cfg, progress=False)


def test_report_names_the_changes_and_every_failure(study) -> None:
    cfg, _ = study
    saved = json.loads((cfg.out / "study.json").read_text())
    assert [c["text"] for c in saved["layout_changes"]] == [
        "furniture workbench moved 0.25 m (+0.25 m in y)",
        "region R1 moved 0.25 m (+0.25 m in y)"]
    assert saved["report"]["plots"]["layouts"].endswith("layouts.png")
    page = (cfg.out / "study.html").read_text()
    assert "What differs between layouts A and B" in page
    assert "furniture workbench moved 0.25 m (+0.25 m in y)" in page
    assert 'alt="top view of layouts A and B"' in page
    failed = [f for lay in saved["layouts"].values() for f in lay["failed"]["items"]]
    assert failed, "the budget of 100 nodes no longer makes any item fail"
    assert sum(lay["failed"]["count"] for lay in saved["layouts"].values()) == len(failed)
    section = page[page.index("<h2>Failed items</h2>"):]
    rows = re.findall(r"<tr><td>([AB])</td><td>(\d+)</td>", section)
    assert sorted(rows) == sorted((f_layout, str(f["index"]))
                                  for f_layout, lay in saved["layouts"].items()
                                  for f in lay["failed"]["items"])
    for f in failed:
        assert f["message"] and f["message"].replace("'", "&#x27;") in section
