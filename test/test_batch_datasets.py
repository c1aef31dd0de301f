"""Datasets ML teams train on (issue 37): captions, per-frame labels, the documented
layout read with plain numpy and json, the BVH and window exports.

One real dataset of the shipped mixed kitting specs (config/specs_kitting.yaml) is made
in this process and read back every way docs/datasets.md describes.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.batch import BatchConfigError, open_dataset, run_batch, specs_from_yaml
from ltl_human_motion.batch.captions import (
    MANIPULATE,
    PHASES,
    REACH,
    WALK,
    CellNames,
    GoalStep,
    captions,
)

pytestmark = pytest.mark.pipeline

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "datasets.md"
SPECS = ROOT / "config" / "specs_kitting.yaml"
COUNT = 4


@pytest.fixture(scope="module")
def dataset(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("kitting") / "ds"
    summary = run_batch("kitting_cell", SPECS, COUNT, out, seed=0, workers=0, shard_size=3,
                        progress=False)
    assert summary.complete and summary.counts["ok"] >= COUNT - 1, summary
    return out


def _doc_block(heading: str) -> str:
    """The first ```python block after ``heading`` in docs/datasets.md."""
    text = DOC.read_text()
    start = text.index(heading)
    m = re.compile(r"```python\n(.*?)```", re.S).search(text, start)
    assert m is not None, heading
    return m.group(1)


def test_a_complete_run_leaves_only_the_dataset_files(dataset: Path) -> None:
    assert sorted(p.name for p in dataset.iterdir()) == ["dataset.json", "manifest.jsonl",
                                                         "shards"]
    ds = open_dataset(dataset)
    counts = ds.counts()
    assert repr(ds) == (f"MotionDataset({str(dataset)!r}, {COUNT} items: {counts['ok']} "
                        f"verified, {counts['unverified']} unverified, {counts['failed']} "
                        f"failed; {len(ds)} stored)")
    assert len(ds) == counts["ok"] + counts["unverified"]
    assert len(ds.failed()) == counts["failed"] == COUNT - len(ds)


def test_every_item_has_captions_labels_and_its_ltl(dataset: Path) -> None:
    ds = open_dataset(dataset)
    header = json.loads((dataset / "dataset.json").read_text())
    assert header["phases"] == list(PHASES) and header["version"] == 2
    assert len(header["joint_parents"]) == len(header["joint_names"])
    specs = {s["name"]: s["spec"] for s in header["specs"]["specs"]}
    for item in ds.items():
        r = item.record
        assert item.ltl == specs[r["spec_name"]]
        caps = item.captions
        assert len(caps) == 4 and len(set(caps)) >= 2, caps
        assert caps[0].startswith("The worker ") and caps[0].endswith(".")
        hands = {s["hand"] for s in r["steps"] if s["hand"] in ("l_hand", "r_hand")}
        for hand in hands:
            assert f"{'left' if hand == 'l_hand' else 'right'} hand" in caps[0], caps[0]
        for task in r["sequence"]:
            part = re.match(r"\w+\((P\d)", task)
            if part:
                assert part.group(1) in caps[0], (task, caps[0])
        if any(t.startswith("insert") for t in r["sequence"]):
            assert "kit tray" in caps[0]                  # the specs file's description
        T = r["n_frames"]
        assert item.task_label.shape == (T,) and item.task_label.dtype == np.int16
        assert item.phase.shape == (T,) and item.phase.dtype == np.int8
        assert set(np.unique(item.phase)) <= set(range(len(PHASES)))
        # Goal frames of a task are labelled with that task; labels never go back.
        inside = item.task_index >= 0
        np.testing.assert_array_equal(item.task_label[inside], item.task_index[inside])
        labelled = item.task_label[item.task_label >= 0]
        assert np.all(np.diff(labelled) >= 0) and labelled.max() == len(r["sequence"]) - 1
        assert np.count_nonzero(item.phase == WALK) > r["fps"]        # it walks
        for step in r["steps"]:
            a, b = step["goal"]
            assert np.all(item.phase[a:b] != WALK)
            if step["hand"] in ("l_hand", "r_hand", "both"):
                assert item.phase[a] == REACH and item.phase[step["contact"]] == MANIPULATE
            if step["lift"] is not None:
                assert np.all(item.phase[step["contact"]:step["lift"]] == MANIPULATE)


def test_captions_are_seeded_and_name_what_the_cell_describes() -> None:
    from ltl_human_motion.scene.cell_yaml import cell_by_name

    cell = cell_by_name("kitting_cell")
    steps = [GoalStep(0, "grasp(P1)", "grasp", "r_hand", (100, 300), 180, 220),
             GoalStep(1, "insert(P1, kit)", "insert", "r_hand", (900, 1100), 1000)]
    phase = np.full(1200, WALK, dtype=np.int8)
    plain = CellNames.from_cell(cell)
    named = CellNames.from_cell(cell, {"kit": "kit tray", "P1": "the gear"})
    seq = ["grasp(P1)", "insert(P1, kit)"]
    first = captions(seq, steps, named, seed=7, n=5, phase=phase)
    assert first == captions(seq, steps, named, seed=7, n=5, phase=phase)
    assert first != captions(seq, steps, named, seed=8, n=5, phase=phase)
    assert first[0] == ("The worker walks to the left table, picks up the gear with the "
                        "right hand, carries it to the kit tray and puts it in.")
    assert "P1" in captions(seq, steps, plain, seed=7, n=1, phase=phase)[0]


def test_specs_descriptions_are_checked_against_the_cell(tmp_path: Path) -> None:
    specs = specs_from_yaml("specs: [{name: a, spec: 'F grasp(P1)'}]\n"
                            "descriptions: {P11: a gear}\n", "s.yaml")
    with pytest.raises(BatchConfigError, match=r"s.yaml: descriptions.P11: .*no such"):
        run_batch("kitting_cell", specs, 1, tmp_path / "x", workers=0, progress=False)
    with pytest.raises(BatchConfigError, match=r"descriptions.P1: expected a non-empty"):
        specs_from_yaml("specs: [S1]\ndescriptions: {P1: ''}\n", "s.yaml")


def test_plain_numpy_reading_and_training_loop_run_as_documented(dataset: Path) -> None:
    """The doc's two blocks, run with the package made unimportable."""
    code = ("import sys\nsys.modules['ltl_human_motion'] = None\n"
            + _doc_block("## Reading it with numpy and json only")
            + _doc_block("## A training loop"))
    assert "ltl_human_motion" not in code.split("\n", 2)[2]
    run = subprocess.run([sys.executable, "-c", code, str(dataset)], capture_output=True,
                         text=True, timeout=300, cwd=dataset.parent)
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    ds = open_dataset(dataset)
    assert f"{len(ds)} stored of {COUNT} items;" in run.stdout
    first = next(ds.items())
    assert lines[0].startswith(f"{first.index} {first.ltl} ") and first.captions[0] in lines[0]
    losses = [float(m.group(1)) for m in re.finditer(r"loss (\d+\.\d+)", run.stdout)]
    assert len(losses) == 5 and losses[-1] < np.log(len(PHASES))   # better than chance


def test_exports_bvh_and_windows(dataset: Path, tmp_path: Path) -> None:
    from ltl_human_motion.batch.export import WindowSpec, export_bvh, export_windows
    from ltl_human_motion.motion import bvh

    ds = open_dataset(dataset)
    files = export_bvh(dataset, tmp_path / "bvh")
    assert [f.name for f in files] == [f"item-{i.index:010d}.bvh" for i in ds.items()]
    lines = [json.loads(x) for x in (tmp_path / "bvh" / "items.jsonl").read_text().splitlines()]
    first = next(ds.items())
    assert lines[0]["captions"] == first.captions and lines[0]["ltl"] == first.ltl
    loaded = bvh.load(files[0])
    assert loaded.n_frames == first.record["n_frames"]
    np.testing.assert_allclose(loaded.positions[:, 0], first.positions[:, 0], atol=2e-3)

    spec = WindowSpec(length=32, stride=16, step=4)
    n = export_windows(dataset, tmp_path / "w.npz", spec)
    with np.load(tmp_path / "w.npz") as z:
        assert z["positions"].shape == (n, 32, 23, 3) and z["positions"].dtype == np.float32
        assert z["task_label"].shape == z["phase"].shape == (n, 32)
        assert z["captions"].shape == (n, 4) and float(z["fps"]) == 30.0
        assert list(z["phases"]) == list(PHASES)
        expected = sum((len(it.positions[::4]) - 32) // 16 + 1 for it in ds.items())
        assert n == expected
        k = int(np.flatnonzero(z["item_index"] == first.index)[1])
        a = int(z["start_frame"][k])
        np.testing.assert_array_equal(z["positions"][k], first.positions[a:a + 128:4])
        np.testing.assert_array_equal(z["phase"][k], first.phase[a:a + 128:4])
        assert z["captions"][k][0] == first.captions[0] and z["ltl"][k] == first.ltl
    with pytest.raises(ValueError, match="window length"):
        WindowSpec(length=0)


def test_cli_exports_after_a_complete_run(dataset: Path, tmp_path: Path) -> None:
    from ltl_human_motion.cli import main

    out = tmp_path / "ds"
    import shutil
    shutil.copytree(dataset, out)                     # complete: the run only finalizes
    rc = main(["batch", "--cell", "kitting_cell", "--specs", str(SPECS), "--count",
               str(COUNT), "--out", str(out), "--shard-size", "3", "--workers", "0",
               "--no-progress", "--export-windows", str(tmp_path / "w.npz"), "--window",
               "16", "16", "8", "--export-bvh", str(tmp_path / "bvh")])
    assert rc == 0
    assert (tmp_path / "w.npz").is_file() and len(list((tmp_path / "bvh").glob("*.bvh"))) \
        == len(open_dataset(out))
    assert sorted(p.name for p in out.iterdir()) == ["dataset.json", "manifest.jsonl",
                                                     "shards"]


_FRESH = """
import json, sys
from ltl_human_motion.batch import ItemParams, cell_for_item, load_specs
from ltl_human_motion.batch.worker import BatchJob, _arrays, motion_sha256
from ltl_human_motion.planning.pipeline import synthesize
from ltl_human_motion.scene.cell_yaml import cell_by_name
r = json.loads(sys.argv[1])
specs = load_specs(sys.argv[2])
p = r["params"]
item = ItemParams(index=r["index"], spec_name=r["spec_name"], spec=r["spec"], seed=r["seed"],
                  cycles=p["cycles"], stature=p["stature"],
                  object_offsets={k: tuple(v) for k, v in p["objects"].items()},
                  region_offsets={k: tuple(v) for k, v in p["regions"].items()})
options = BatchJob(cell_yaml="", options=dict(specs.options),
                   sequence_mode=specs.sequence_mode).synthesis_options()
synth = synthesize(item.spec, cell_for_item(cell_by_name("kitting_cell"), item),
                   seed=item.seed, cycles=item.cycles, stature=item.stature,
                   options=options)[0]
print(json.dumps({"sha": motion_sha256(_arrays(synth, "float32")),
                  "passed": bool(synth.verification["passed"])}))
"""


def test_items_of_a_worker_equal_fresh_single_item_syntheses(dataset: Path) -> None:
    """Items made one after another in one worker (its per-spec, per-cell and
    per-stature caches warm) are byte-identical to each item synthesized alone in a new
    process."""
    ds = open_dataset(dataset)
    for r in ds.records[1:]:                    # item 0 ran with cold caches
        run = subprocess.run([sys.executable, "-c", _FRESH, json.dumps(r), str(SPECS)],
                             capture_output=True, text=True, timeout=300)
        assert run.returncode == 0, run.stderr
        fresh = json.loads(run.stdout.strip().splitlines()[-1])
        assert fresh["passed"] == r["verified"], r["index"]
        if r["status"] == "ok":
            assert fresh["sha"] == r["motion_sha256"], r["index"]
