"""Issue 34, item 1: cell and specs files that are not regular files.

A FIFO (or a symlink to one) blocked every loader forever, and a symlink to ``/dev/zero``
or ``/dev/urandom`` was read until memory ran out. Every loader now opens only regular
files, reads at most MAX_YAML_BYTES and names the file and its kind. Real FIFOs, real
device files, the real command line in a process of its own.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ltl_human_motion.batch.specs import BatchConfigError, load_specs
from ltl_human_motion.errors import CellError
from ltl_human_motion.ltl.vocabulary import load_vocabulary
from ltl_human_motion.robot.sim.trajectory import load_robot_config
from ltl_human_motion.scene.cell_yaml import cell_from_yaml, load_cell
from ltl_human_motion.yaml_limits import MAX_YAML_BYTES, TextFileError, read_text_file

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "config" / "specs_example.yaml"


@pytest.fixture()
def special(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """Name -> (path, kind in the message): a FIFO, a symlink to it, two devices."""
    fifo = tmp_path / "c.yaml"
    os.mkfifo(fifo)
    (tmp_path / "link.yaml").symlink_to(fifo)
    (tmp_path / "zero.yaml").symlink_to("/dev/zero")
    (tmp_path / "random.yaml").symlink_to("/dev/urandom")
    (tmp_path / "folder.yaml").mkdir()
    return {"fifo": (fifo, "a FIFO"), "link": (tmp_path / "link.yaml", "a FIFO"),
            "zero": (tmp_path / "zero.yaml", "a character device"),
            "random": (tmp_path / "random.yaml", "a character device"),
            "folder": (tmp_path / "folder.yaml", "a folder")}


@pytest.mark.parametrize("name", ["fifo", "link", "zero", "random", "folder"])
def test_every_loader_refuses_a_file_that_is_not_regular_at_once(
        special: dict[str, tuple[Path, str]], name: str) -> None:
    path, kind = special[name]
    started = time.monotonic()
    with pytest.raises(CellError, match=rf"^cell file {path} is not a regular file \({kind}\)$"):
        load_cell(path)
    with pytest.raises(CellError, match=rf"cell file {path} is not a regular file \({kind}\)"):
        load_vocabulary(path)
    with pytest.raises(BatchConfigError,
                       match=rf"^specs file {path} is not a regular file \({kind}\)$"):
        load_specs(path)
    with pytest.raises(ValueError, match=rf"^robot config {path} is not a regular file"):
        load_robot_config(path)
    assert time.monotonic() - started < 2.0


def test_a_file_beyond_the_byte_limit_is_refused_after_reading_the_limit(
        tmp_path: Path) -> None:
    path = tmp_path / "big.yaml"
    with open(path, "wb") as fh:
        fh.truncate(MAX_YAML_BYTES + 1)            # sparse: no disk used
    with pytest.raises(TextFileError, match="has more than 20,000,000 bytes"):
        read_text_file(path, "cell file")
    assert "start_region" in read_text_file(ROOT / "config" / "paper_cell.yaml", "cell file")


def test_a_mesh_that_is_a_fifo_is_refused_without_reading(special: dict[str, tuple[Path, str]]
                                                         ) -> None:
    fifo, _ = special["fifo"]
    text = (f"start_region: R0\nregions: {{R0: {{lo: [0, 0, 0], hi: [1, 1, 0.1]}}}}\n"
            f"obstacles: {{part: {{mesh: {fifo}}}}}\n")
    with pytest.raises(CellError, match=rf"mesh file {fifo} is not a regular file"):
        cell_from_yaml(text, source="fifo_mesh.yaml")


def test_a_missing_file_still_says_it_cannot_be_read(tmp_path: Path) -> None:
    with pytest.raises(CellError, match=r"nope\.yaml: cannot read cell file: No such file"):
        load_cell(tmp_path / "nope.yaml")


def _cli(args: list[str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "ltl_human_motion", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("args", [
    ["synthesize", "--cell", "{f}", "--spec", "S1", "--out", "o"],
    ["tasks", "--cell", "{f}", "S1"],
    ["batch", "--cell", "{f}", "--specs", str(SPECS), "--count", "2", "--out", "o"],
    ["batch", "--cell", "paper_cell", "--specs", "{f}", "--count", "2", "--out", "o"],
])
@pytest.mark.parametrize("name", ["fifo", "link", "zero"])
def test_the_commands_answer_in_one_line_naming_the_file(
        special: dict[str, tuple[Path, str]], args: list[str], name: str) -> None:
    path, kind = special[name]
    what = "specs file" if "--specs" in args and args[args.index("--specs") + 1] == "{f}" \
        else "cell file"
    proc = _cli([a.replace("{f}", path.name) for a in args], cwd=path.parent)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert lines == [f"ltl-human-motion {args[0]}: error: {what} {path.name} is not a regular "
                     f"file ({kind})"], proc.stderr
    assert not (path.parent / "o").exists()


@pytest.mark.parametrize("name", ["fifo", "zero", "missing"])
def test_bringup_refuses_a_config_that_is_not_a_regular_file(
        special: dict[str, tuple[Path, str]], name: str) -> None:
    pytest.importorskip("rclpy")
    if name == "missing":
        path, cause = special["fifo"][0].parent / "nope.yaml", "does not exist"
    else:
        path, kind = special[name]
        cause = f"is not a regular file ({kind})"
    proc = _cli(["bringup", path.name], cwd=path.parent)
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines() == [
        f"ltl-human-motion bringup: error: bringup configuration {path.name} {cause}"]

