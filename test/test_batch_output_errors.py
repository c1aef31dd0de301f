"""Issue 34, item 4: a dataset folder that cannot be written is a one-line CLI error.

``batch --out /proc/x``, a read-only folder and a full disk ended in a traceback
(FileNotFoundError, OSError errno 30, errno 28). Now the command prints one line naming
the folder and the cause, exits 2, and leaves what it wrote intact: after space is freed
the same command finishes, with shards byte-identical to an uninterrupted run. Real
files: a read-only tmpfs and a 200 kB tmpfs (root only; skipped otherwise).
"""

from __future__ import annotations

import contextlib
import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from ltl_human_motion.batch import deterministic_record

pytestmark = pytest.mark.pipeline

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "config" / "specs_example.yaml"
COUNT = 6
SHARD = 2


def _batch(out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ltl_human_motion", "batch", "--cell",
                           "paper_cell", "--specs", str(SPECS), "--count", str(COUNT),
                           "--shard-size", str(SHARD), "--out", str(out), "--no-progress",
                           *extra], capture_output=True, text=True, timeout=600)


@contextlib.contextmanager
def _tmpfs(path: Path, options: str) -> Iterator[Path]:
    path.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    mounted = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(path)],
                             capture_output=True, text=True)
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {mounted.stderr.strip()}")
    try:
        yield path
    finally:
        subprocess.run(["umount", "-l", str(path)], check=False)


def _one_line_error(proc: subprocess.CompletedProcess[str], folder: Path, cause: str) -> None:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"ltl-human-motion batch: error: cannot write the dataset "
                               f"to {folder} ({cause})"), lines[0]
    assert "Traceback" not in proc.stderr


def test_a_folder_that_cannot_be_made_is_named() -> None:
    _one_line_error(_batch(Path("/proc/x")), Path("/proc/x"), "No such file or directory")


def test_a_read_only_folder_is_named(tmp_path: Path) -> None:
    with _tmpfs(tmp_path / "ro", "ro,size=100k") as ro:
        proc = _batch(ro / "ds")
        _one_line_error(proc, ro / "ds", "Read-only file system")
        assert "choose a folder you can write to" in proc.stderr


def _shards(out: Path) -> tuple[list[dict], list[dict]]:
    header = json.loads((out / "dataset.json").read_text())
    manifest = [json.loads(line) for line in (out / "manifest.jsonl").read_text().splitlines()]
    return [deterministic_record(r) for r in manifest], header["shards"]


@pytest.mark.parametrize("workers", ["0", "1"])
def test_a_full_disk_stops_cleanly_and_a_rerun_finishes(tmp_path: Path, workers: str) -> None:
    reference = tmp_path / "reference"
    assert _batch(reference, "--workers", workers).returncode == 0
    with _tmpfs(tmp_path / "small", "size=200k") as small:
        out = small / "ds"
        proc = _batch(out, "--workers", workers)
        _one_line_error(proc, out, "No space left on device")
        assert "run the same command again to finish" in proc.stderr
        assert not list(out.rglob(".*.tmp"))                 # no half-written file
        assert not (out / "manifest.jsonl").exists()
        subprocess.run(["mount", "-o", "remount,size=64m", str(small)], check=True)
        again = _batch(out, "--workers", workers)
        assert again.returncode == 0, again.stderr
        summary = json.loads(again.stdout)
        assert summary["complete"]
        assert _shards(out) == _shards(reference)
