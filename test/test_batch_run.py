"""Batch runs end to end: determinism (1 worker, pool, Dask), crash resume, reader, corruption.

Every run here uses the same small job (9 items of S1/S2, shortest task sequences, two
statures, object and start jitter, 3 items per shard), so all of them must produce the
same manifest (timing aside) and byte-identical shards.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest

from ltl_human_motion.batch import (
    BatchConfigError,
    BatchSummary,
    CorruptDatasetError,
    deterministic_record,
    open_dataset,
    run_batch,
)

pytestmark = pytest.mark.pipeline

ROOT = Path(__file__).resolve().parents[1]
COUNT = 9
SHARD = 3
SEED = 11
SPECS = """
version: 1
specs:
  - {name: S1, spec: S1, weight: 1.0}
  - {name: S2, spec: S2, weight: 1.0}
stature: [1.70, 1.75]
objects:
  O1: [0.05, 0.05, 0.0]
  O2: [0.05, 0.05, 0.0]
regions:
  R0: [0.05, 0.05, 0.0]
sequence_mode: all
options: {max_nodes: 3000}      # deterministic bound on a hopeless search
"""


@pytest.fixture(scope="module")
def specs_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("specs") / "specs.yaml"
    path.write_text(SPECS)
    return path


def _run(specs_file: Path, out: Path, **kw: object) -> BatchSummary:
    return run_batch("paper_cell", specs_file, COUNT, out, seed=SEED, shard_size=SHARD,
                     progress=False, **kw)


def _manifest(out: Path) -> list[dict]:
    lines = (out / "manifest.jsonl").read_text().splitlines()
    return [json.loads(line) for line in lines]


def _comparable(out: Path) -> tuple[list[dict], list[dict]]:
    """Manifest without timing, and the shard list (file, SHA-256, size) of dataset.json."""
    header = json.loads((out / "dataset.json").read_text())
    return [deterministic_record(r) for r in _manifest(out)], header["shards"]


@pytest.fixture(scope="module")
def reference(specs_file: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The dataset from the local process pool with two workers."""
    out = tmp_path_factory.mktemp("pool") / "ds"
    summary = _run(specs_file, out, workers=2)
    assert summary.complete and summary.computed == COUNT and summary.skipped == 0
    return out


def test_pool_dataset_is_complete_and_sorted(reference: Path) -> None:
    records = _manifest(reference)
    assert [r["index"] for r in records] == list(range(COUNT))
    assert {r["spec_name"] for r in records} == {"S1", "S2"}
    assert {r["params"]["stature"] for r in records} == {1.7, 1.75}
    ok = [r for r in records if r["status"] == "ok"]
    assert len(ok) >= COUNT - 2, [r["error"] for r in records]   # planner state, not batch
    for r in ok:
        assert r["verified"] and r["verification"]["collision"]["passed"]
        assert r["sequence"] and r["duration"] > 1.0 and r["n_frames"] > 100
        assert r["shard"] == f"shards/shard-{r['index'] // SHARD:06d}.npz"
    for r in records:
        assert r["timing"]["compute_time"] > 0
        assert r["status"] == "ok" or r["error"]["message"]       # failures say why
    # A complete run leaves only the dataset's own files.
    assert sorted(p.name for p in reference.iterdir()) == ["dataset.json", "manifest.jsonl",
                                                            "shards"]


def test_single_worker_gives_identical_data(reference: Path, specs_file: Path,
                                            tmp_path: Path) -> None:
    summary = _run(specs_file, tmp_path / "ds", workers=0)
    assert summary.complete
    assert _comparable(tmp_path / "ds") == _comparable(reference)


def test_dask_local_cluster_gives_identical_data(reference: Path, specs_file: Path,
                                                 tmp_path: Path) -> None:
    from distributed import LocalCluster

    with LocalCluster(host="127.0.0.1", dashboard_address=None, n_workers=2, processes=True,
                      threads_per_worker=1) as cluster:
        summary = _run(specs_file, tmp_path / "ds", workers=2,
                       scheduler=cluster.scheduler_address)
    assert summary.complete and summary.computed == COUNT
    workers = {r["timing"]["worker"] for r in _manifest(tmp_path / "ds")}
    assert len(workers) == 2                      # both Dask workers took items
    assert _comparable(tmp_path / "ds") == _comparable(reference)


def _done_items(out: Path) -> int:
    staged = len(list((out / "staging").glob("item-*.npz"))) if (out / "staging").is_dir() else 0
    shards = len(list((out / "shards").glob("shard-*.json"))) if (out / "shards").is_dir() else 0
    return staged + SHARD * shards


def test_killed_run_resumes_without_loss_or_duplicates(reference: Path, specs_file: Path,
                                                       tmp_path: Path) -> None:
    out = tmp_path / "ds"
    env = dict(os.environ, PYTHONPATH=f"{ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}")
    cmd = [sys.executable, "-m", "ltl_human_motion", "batch", "--cell", "paper_cell",
           "--specs", str(specs_file), "--count", str(COUNT), "--out", str(out),
           "--seed", str(SEED), "--shard-size", str(SHARD), "--workers", "2", "--no-progress"]
    proc = subprocess.Popen(cmd, env=env, start_new_session=True, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    deadline = time.monotonic() + 120
    try:
        while _done_items(out) < 2:
            assert proc.poll() is None, proc.stderr.read().decode()
            assert time.monotonic() < deadline, "the batch run made no progress"
            time.sleep(0.02)
        workers = psutil.Process(proc.pid).children(recursive=True)
        proc.send_signal(signal.SIGKILL)                # the driver only
        proc.wait()
        done_at_kill = _done_items(out)
        _, alive = psutil.wait_procs(workers, timeout=15)
        assert not alive, "pool workers outlived the killed driver"
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)         # clean up whatever is left
        proc.wait()
    assert 2 <= done_at_kill < COUNT
    assert not (out / "manifest.jsonl").exists()
    with pytest.raises(CorruptDatasetError, match="unfinished"):
        open_dataset(out)

    summary = _run(specs_file, out, workers=2)
    assert summary.complete
    assert summary.skipped >= 2
    assert summary.skipped + summary.computed == COUNT
    assert _comparable(out) == _comparable(reference)
    assert not (out / "staging").exists() and not (out / ".lock").exists()
    # Started once more, the finished dataset is left as it is.
    again = _run(specs_file, out, workers=2)
    assert again.skipped == COUNT and again.computed == 0
    assert _comparable(out) == _comparable(reference)


def test_reader_yields_arrays_matching_the_manifest(reference: Path) -> None:
    ds = open_dataset(reference)
    stored = [r["index"] for r in ds.records if r["status"] == "ok"]
    assert len(ds) == len(stored) and len(ds.failed()) == COUNT - len(stored)
    assert repr(ds).endswith(f"{len(stored)} verified, 0 unverified, "
                             f"{len(ds.failed())} failed; {len(ds)} stored)")
    items = list(ds.items(verified_only=True))
    assert [it.index for it in items] == stored
    for it in items:
        T = it.record["n_frames"]
        assert it.positions.shape == (T, len(ds.joint_names), 3)
        assert it.positions.dtype == np.float32
        assert it.root_yaw.shape == (T,) and it.task_index.shape == (T,)
        assert set(it.objects) == {"O1", "O2"} and it.objects["O1"].shape == (T, 3)
        assert it.task_index.max() == len(it.record["sequence"]) - 1
        assert it.fps == 120.0
        # Object O1 starts where the item's offset put it.
        start = np.array([-1.0, -1.0, 0.2]) + np.array(it.record["params"]["objects"]["O1"])
        np.testing.assert_allclose(it.objects["O1"][0], start, atol=1e-6)
    ds.verify()


def test_corrupt_shard_is_detected_and_named(reference: Path, tmp_path: Path) -> None:
    copy = tmp_path / "ds"
    shutil.copytree(reference, copy)
    stored = open_dataset(copy).stored_records()
    name = stored[-1]["shard"]                            # a shard that holds motions
    intact = [r for r in stored if r["shard"] != name]
    shard = copy / name
    data = bytearray(shard.read_bytes())
    data[len(data) // 2] ^= 0xFF                          # one flipped byte in the arrays
    shard.write_bytes(bytes(data))
    ds = open_dataset(copy)
    if intact:                                            # other shards still read
        assert ds.item(intact[0]).index == intact[0]["index"]
    pattern = re.escape(Path(name).name)
    with pytest.raises(CorruptDatasetError, match=pattern + ": corrupt shard"):
        list(ds.items())
    with pytest.raises(CorruptDatasetError, match=pattern):
        ds.verify()
    shard.unlink()
    with pytest.raises(CorruptDatasetError, match=pattern + ": cannot read shard"):
        list(open_dataset(copy).items())
    (copy / "manifest.jsonl").write_text("{not json\n")
    with pytest.raises(CorruptDatasetError, match=r"manifest\.jsonl: line 1"):
        open_dataset(copy)


def test_failed_items_are_listed_with_reasons(tmp_path: Path) -> None:
    specs = tmp_path / "fail.yaml"
    specs.write_text("specs: [S2]\nsequence_mode: all\noptions: {max_nodes: 1}\n")
    summary = run_batch("paper_cell", specs, 3, tmp_path / "ds", workers=0, progress=False)
    assert summary.complete and summary.counts == {"ok": 0, "unverified": 0, "failed": 3}
    ds = open_dataset(tmp_path / "ds")
    assert len(ds) == 0 and list(ds.items()) == []
    for r in ds.failed():
        assert r["error"]["type"] == "PlanningError"
        assert "search budget ran out" in r["error"]["message"]
        assert r["shard"] is None and r["motion_sha256"] is None


def test_a_different_job_does_not_touch_an_existing_dataset(reference: Path,
                                                            specs_file: Path) -> None:
    before = (reference / "manifest.jsonl").read_bytes()
    with pytest.raises(BatchConfigError, match=r"holds a different dataset.*seed"):
        run_batch("paper_cell", specs_file, COUNT, reference, seed=SEED + 1,
                  shard_size=SHARD, progress=False, workers=0)
    assert (reference / "manifest.jsonl").read_bytes() == before


def test_cli_reports_bad_arguments(specs_file: Path, tmp_path: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    from ltl_human_motion.cli import main

    assert main(["batch", "--cell", "paper_cell", "--specs", str(specs_file), "--count", "0",
                 "--out", str(tmp_path / "x")]) == 2
    assert "--count must be >= 1" in capsys.readouterr().err
    bad = tmp_path / "bad.yaml"
    bad.write_text("specs: [{spec: S1, weight: 0}]\n")
    assert main(["batch", "--cell", "paper_cell", "--specs", str(bad), "--count", "1",
                 "--out", str(tmp_path / "y")]) == 2
    assert "bad.yaml: specs[0].weight: expected a positive number" in capsys.readouterr().err


def test_unverified_motions_are_kept_on_request_and_filtered(tmp_path: Path) -> None:
    specs = tmp_path / "strict.yaml"
    specs.write_text("specs: [S1]\nsequence_mode: all\nkeep_unverified: true\n"
                     "options: {max_joint_speed: 0.5}\n")    # no walk is that slow
    summary = run_batch("paper_cell", specs, 2, tmp_path / "ds", workers=0, progress=False)
    assert summary.counts == {"ok": 0, "unverified": 2, "failed": 0}
    ds = open_dataset(tmp_path / "ds")
    assert list(ds.items()) == []                        # verified only, by default
    kept = list(ds.items(verified_only=False))
    assert [it.index for it in kept] == [0, 1]
    for it in kept:
        assert not it.verified
        assert it.record["error"]["check"] == "smoothness"
        assert not it.record["verification"]["smoothness"]["passed"]
        assert it.record["verification"]["collision"]["passed"]
        assert it.positions.shape[0] == it.record["n_frames"]


def test_two_runs_cannot_write_one_folder(reference: Path, specs_file: Path) -> None:
    from ltl_human_motion.batch import DatasetStore

    header = json.loads((reference / "dataset.json").read_text())
    holder = DatasetStore(reference, header)           # as if another run were active
    try:
        with pytest.raises(BatchConfigError, match="another batch run is writing"):
            _run(specs_file, reference, workers=0)
    finally:
        holder.close()
    assert _run(specs_file, reference, workers=0).skipped == COUNT


def test_an_item_is_reproducible_from_its_manifest_record(reference: Path) -> None:
    from ltl_human_motion.batch import ItemParams, cell_for_item
    from ltl_human_motion.batch.worker import BatchJob
    from ltl_human_motion.planning.pipeline import synthesize
    from ltl_human_motion.scene.cell_yaml import cell_by_name

    item = next(iter(open_dataset(reference).items()))
    r = item.record
    params = ItemParams(index=r["index"], spec_name=r["spec_name"], spec=r["spec"],
                        seed=r["seed"], cycles=r["params"]["cycles"],
                        stature=r["params"]["stature"],
                        object_offsets={k: tuple(v) for k, v in r["params"]["objects"].items()},
                        region_offsets={k: tuple(v) for k, v in r["params"]["regions"].items()})
    options = BatchJob(cell_yaml="", options={"max_nodes": 3000},
                       sequence_mode="all").synthesis_options()
    synth = synthesize(r["spec"], cell_for_item(cell_by_name("paper_cell"), params),
                       seed=r["seed"], cycles=params.cycles, stature=params.stature,
                       options=options)[0]
    assert synth.sequence == r["sequence"]
    np.testing.assert_array_equal(synth.positions.astype(np.float32), item.positions)
    np.testing.assert_array_equal(synth.task_index, item.task_index)


def test_workers_keep_freed_memory() -> None:
    """glibc on Linux takes the heap settings (in a fresh process: they are global)."""
    import platform

    if not sys.platform.startswith("linux") or platform.libc_ver()[0] != "glibc":
        pytest.skip("glibc only")
    code = ("from ltl_human_motion.batch.memory import keep_freed_memory\n"
            "assert keep_freed_memory() and keep_freed_memory()\n"
            "import numpy as np\n"
            "for _ in range(3): np.ones((3000, 23, 3)).sum()\n")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
