"""Issue 17's reproducers for bad input: each gives a clean, specific error (no traceback).

Specifications nested 200-900 deep, translation beyond the named limits or the time
budget, and cells that are not UTF-8, nest deeply, hold an alias bomb, name a region by a
mapping, or are absurdly large or detailed.
"""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from ltl_human_motion.deadline import BudgetExhaustedError, Deadline, active, checkpoint
from ltl_human_motion.errors import CellError, SpecError
from ltl_human_motion.ltl import parse
from ltl_human_motion.ltl.limits import MAX_NESTING, nesting_depth
from ltl_human_motion.ltl.translate_builtin import translate_builtin
from ltl_human_motion.scene.cell_yaml import cell_from_yaml, load_cell
from ltl_human_motion.yaml_limits import MAX_YAML_EXPANDED_NODES

ROOT = Path(__file__).resolve().parents[1]
PAPER_CELL = (ROOT / "config" / "paper_cell.yaml").read_text()


# ------------------------------------------------------------------ specifications
@pytest.mark.parametrize("depth", [200, 500, 900])
@pytest.mark.parametrize("pattern", ["implies", "not", "parens", "next", "until"])
def test_deeply_nested_specs_give_a_clean_spec_error(depth: int, pattern: str) -> None:
    text = {"implies": "p -> " * depth + "p",
            "not": "!" * depth + "p",
            "parens": "!(" * depth + "p" + ")" * depth,
            "next": "X " * depth + "p",
            "until": "p U (" * depth + "q" + ")" * depth}[pattern]
    with pytest.raises(SpecError, match="MAX_NESTING"):
        parse(text, free_atoms=True)


def test_nesting_just_below_the_limit_is_accepted() -> None:
    f = parse("!" * (MAX_NESTING - 2) + "p", free_atoms=True)
    assert nesting_depth(f) == MAX_NESTING - 1


def test_parser_messages_read_as_english() -> None:
    with pytest.raises(SpecError) as info:
        parse("grasp(O1) &")
    assert "unexpected end of the specification" in str(info.value)
    assert "unexpected the end" not in str(info.value)
    with pytest.raises(SpecError) as info:
        parse("(grasp(O1)")
    assert "before the end of the specification" in str(info.value)


def test_translation_stops_when_the_budget_is_spent() -> None:
    t = [0.0]
    deadline = Deadline(5.0, clock=lambda: t[0])
    formula = parse("G F p & G F q & (p U q)", free_atoms=True)
    t[0] = 6.0
    with active(deadline), pytest.raises(BudgetExhaustedError,
                                         match="time budget of 5 s exhausted in translation"):
        translate_builtin(formula)
    translate_builtin(formula)                          # no budget outside the block


def test_a_cancelled_deadline_stops_at_the_next_checkpoint() -> None:
    deadline = Deadline(None)
    with active(deadline):
        checkpoint("planning")
        deadline.cancel("cancelled: shutting down")
        with pytest.raises(BudgetExhaustedError, match="shutting down during planning"):
            checkpoint("planning")
    with pytest.raises(ValueError, match="a time budget"):
        Deadline(-1.0)


# ------------------------------------------------------------------ cells
def test_a_cell_file_that_is_not_utf8_is_a_cell_error(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes(PAPER_CELL.replace("paper", "caf\xe9").encode("latin-1") + b"\xff")
    with pytest.raises(CellError, match="not UTF-8"):
        load_cell(path)


def test_deeply_nested_yaml_is_a_cell_error() -> None:
    with pytest.raises(CellError, match="MAX_YAML_DEPTH"):
        cell_from_yaml("description: " + "[" * 5000 + "]" * 5000)
    with pytest.raises(CellError, match=r"MAX_YAML_DEPTH|invalid YAML"):
        cell_from_yaml("a:\n  " + "[" * 100_000)


def test_a_yaml_alias_bomb_is_refused_and_never_printed() -> None:
    lines = ["a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]"]
    for i in range(1, 10):
        lines.append(f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]")
    text = "\n".join(lines) + "\ndescription: *a9\n"
    assert len(text) < 2500                              # 10^10 leaves
    started = time.monotonic()
    with pytest.raises(CellError) as info:
        cell_from_yaml(text)
    assert "MAX_YAML_EXPANDED_NODES" in str(info.value)
    assert f"{MAX_YAML_EXPANDED_NODES:,}" in str(info.value)
    assert len(str(info.value)) < 300
    assert time.monotonic() - started < 60.0          # refused, never expanded


def test_a_long_wrong_value_is_shortened_in_the_message() -> None:
    text = PAPER_CELL + "\ndescription: [" + ", ".join(["x"] * 5000) + "]\n"
    with pytest.raises(CellError, match="description") as info:
        cell_from_yaml(text)
    assert len(str(info.value)) < 300


@pytest.mark.parametrize("value", ["{R0: 1}", "[R0]", "1", "R99"])
def test_start_region_that_is_not_a_region_name(value: str) -> None:
    text = PAPER_CELL.replace("start_region: R0", f"start_region: {value}")
    assert text != PAPER_CELL
    with pytest.raises(CellError, match="start_region: unknown region"):
        cell_from_yaml(text)


def test_huge_coordinates_and_workspaces_are_refused() -> None:
    with pytest.raises(CellError, match="MAX_CELL_COORDINATE"):
        cell_from_yaml(PAPER_CELL + "\nfloor_z: 1e300\n")
    with pytest.raises(CellError, match="MAX_WORKSPACE_EXTENT"):
        cell_from_yaml(PAPER_CELL + "\nworkspace: {lo: [-500, -500, 0], hi: [500, 500, 3]}\n")


def test_ten_thousand_tiny_obstacles_are_refused_with_advice() -> None:
    obstacles = "\n".join(f"  t{i}: {{shape: box, center: [{i % 100 * 0.05:.2f}, "
                          f"{i // 100 * 0.05:.2f}, 0.5], size: [0.01, 0.01, 0.01]}}"
                          for i in range(10_000))
    text = ("workspace: {lo: [-6, -6, 0], hi: [6, 6, 3]}\nstart_region: R0\n"
            "regions:\n  R0: {shape: box, center: [-4, -4, 0.5], size: [1, 1, 1]}\n"
            "obstacles:\n" + obstacles)
    with pytest.raises(CellError, match="MAX_CELL_ENTRIES") as info:
        cell_from_yaml(text)                      # before any clearance map is built
    assert "merge neighbouring obstacles" in str(info.value)


# ------------------------------------------------------------------ motion files
BVH_DIR = Path("/usr/share/assimp/models/BVH")
GENUINE_BVH = BVH_DIR / "01_01.bvh"


def _mutated_bvh(tmp_path: Path, header: str, value: str) -> Path:
    lines = GENUINE_BVH.read_text().splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith(header))
    lines[i] = f"{header} {value}"
    path = tmp_path / "mutated.bvh"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.skipif(not GENUINE_BVH.is_file(), reason="assimp's BVH models are not installed")
@pytest.mark.parametrize("header, value, message", [
    ("Frames:", "999999999999", "announces 999999999999 frames"),
    ("Frame Time:", "1e-300", "MIN_FRAME_TIME"),
    ("Frame Time:", "1e300", "MAX_FRAME_TIME"),
])
def test_absurd_bvh_headers_are_format_errors(tmp_path: Path, header: str, value: str,
                                              message: str) -> None:
    from ltl_human_motion.errors import MotionFormatError
    from ltl_human_motion.motion import bvh

    with pytest.raises(MotionFormatError, match=message):
        bvh.load_raw(_mutated_bvh(tmp_path, header, value))


def test_a_bad_asf_axis_order_is_a_format_error(tmp_path: Path) -> None:
    from test_motion_loaders import _write_asf

    from ltl_human_motion.errors import MotionFormatError
    from ltl_human_motion.motion import asfamc

    asf = tmp_path / "t.asf"
    _write_asf(asf)
    asf.write_text(asf.read_text().replace("axis 0 0 0 XYZ", "axis 0 0 0 QQQ", 1))
    with pytest.raises(MotionFormatError, match="permutation of XYZ"):
        asfamc.parse_asf(asf)


def test_amc_files_in_a_source_folder_are_paired_with_their_asf(tmp_path: Path) -> None:
    from test_motion_loaders import _write_amc, _write_asf

    from ltl_human_motion.motion.library import _source_files, asf_for, load_motion

    _write_asf(tmp_path / "07.asf")
    _write_amc(tmp_path / "07_01.amc", [{}, {"lfemur": [30, 0, 0]}, {}])
    assert _source_files(tmp_path) == [tmp_path / "07_01.amc"]
    assert asf_for(tmp_path / "07_01.amc") == tmp_path / "07.asf"
    assert load_motion(tmp_path / "07_01.amc").n_frames == 3


# ------------------------------------------------------------------ library cache
def test_a_damaged_library_cache_is_refused_on_load(tmp_path: Path) -> None:
    import numpy as np

    from ltl_human_motion.motion import library as lib_mod
    from ltl_human_motion.planning.pipeline import get_library

    key = get_library().key
    cached = lib_mod.cache_dir() / f"library-{key}.npz"
    assert cached.is_file()
    with np.load(cached) as z:
        arrays = dict(z)
    for name, damage in (("poses", lambda a: np.where(np.arange(a.size).reshape(a.shape) == 7,
                                                      np.nan, a)),
                         ("indices", lambda a: a + 10_000_000)):
        bad = dict(arrays)
        bad[name] = damage(arrays[name])
        path = tmp_path / f"library-{key}.npz"
        np.savez(path, **bad)
        with pytest.raises(ValueError, match=r"NaN|indices outside"):
            lib_mod._load(path, key)


# ------------------------------------------------------------------ batch start-up
def test_a_batch_folder_killed_during_start_up_resumes(tmp_path: Path) -> None:
    """What a SIGKILL between making the folders and writing dataset.json left: the rerun
    resumes it instead of refusing "exists, is not empty and is not a dataset"."""
    from ltl_human_motion.batch.store import DatasetStore

    out = tmp_path / "out"
    for sub in ("staging", "shards"):
        (out / sub).mkdir(parents=True)
    (out / ".lock").touch()
    (out / "staging" / ".item-0.npz.tmp").write_bytes(b"half")
    store = DatasetStore(out, {"fingerprint": "f" * 64, "count": 2, "shard_size": 1})
    assert store.header_path.is_file()
    (out / "shards" / "stray.txt").write_text("not ours")
    (out / "dataset.json").unlink()
    with pytest.raises(Exception, match="is not a dataset"):
        DatasetStore(tmp_path / "out", {"fingerprint": "f" * 64, "count": 2, "shard_size": 1})


def test_synthesize_honours_its_time_budget_without_ros() -> None:
    """``SynthesisOptions(max_seconds=)`` makes synthesize itself stop at its first check
    (the deadline wraps the public function), naming the stage."""
    from ltl_human_motion.planning.pipeline import SynthesisOptions, synthesize
    options = SynthesisOptions.from_dict({"max_seconds": 1e-4})
    with pytest.raises(BudgetExhaustedError, match=r"time budget of 0\.0001 s exhausted in "):
        synthesize("S2", "paper_cell", seed=11, options=options)
