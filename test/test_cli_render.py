"""Pictures of one's own motion: ``synthesize --render``, ``render``, and lines that no
longer cross the worker (issue 35)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from ltl_human_motion.cli import main
from ltl_human_motion.planning.exports import load_npz, save_npz
from ltl_human_motion.scene import cell_by_name
from ltl_human_motion.scene.occupancy import capsules_from_positions
from ltl_human_motion.viz._common import (
    cell_bounds,
    draw_static_cell,
    new_figure,
    object_supports,
    setup_axes3d,
)
from ltl_human_motion.viz.lines import camera_position, chop

pytestmark = pytest.mark.pipeline


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``synthesize --render`` of a short motion, small pictures."""
    out = tmp_path_factory.mktemp("synth")
    code = main(["synthesize", "--spec", "F grasp(O1)", "--cell", "paper_cell", "--out",
                 str(out), "--render", "--size", "320x240", "--fps", "4"])
    assert code == 0
    return out


def _sheet_shape(n_panels: int, panel: tuple[int, int]) -> tuple[int, int]:
    cols = min(3, n_panels)
    return cols * panel[0], math.ceil(n_panels / cols) * panel[1]


def test_synthesize_render_writes_a_gif_and_a_sheet(made: Path, capsys) -> None:
    synth = load_npz(made / "motion_000.npz")
    with Image.open(made / "motion_000.gif") as gif:
        assert gif.size == (320, 240)
        assert gif.n_frames == int(np.floor(synth.duration * 4)) + 1
    with Image.open(made / "motion_000.png") as png:
        # the start and the middle of each task
        assert png.size == _sheet_shape(1 + len(synth.timeline), (320, 240))
        px = np.asarray(png.convert("RGB")).astype(int)
    shirt = (px[..., 2] - px[..., 0] > 50) & (px[..., 2] > 80)
    assert shirt.sum() > 200                                   # the worker is drawn


def test_render_command_reads_what_synthesize_wrote(made: Path, tmp_path: Path,
                                                     capsys) -> None:
    synth = load_npz(made / "motion_000.npz")
    gif = tmp_path / "pics" / "m.gif"
    assert main(["render", str(made / "motion_000.npz"), "--out", str(gif), "--size",
                 "200x150", "--fps", "2"]) == 0
    printed = capsys.readouterr().out
    n = int(np.floor(synth.duration * 2)) + 1
    assert f"wrote {gif} ({n} frames at 2 Hz, 200x150" in printed
    assert "in paper_cell" in printed
    with Image.open(gif) as im:
        assert im.size == (200, 150) and im.n_frames == n
    png = tmp_path / "m.png"
    assert main(["render", str(made / "motion_000.json"), "--out", str(png), "--size",
                 "200x180", "--cell", "paper_cell"]) == 0
    with Image.open(png) as im:
        assert im.size == _sheet_shape(1 + len(synth.timeline), (200, 180))


@pytest.mark.parametrize("args, message", [
    (["missing.npz", "--out", "x.png"], "missing.npz: no such file"),
    (["junk.npz", "--out", "x.png"], "junk.npz: not an npz archive"),
    (["motion_000.npz", "--out", "x.jpg"], "the file must end in .gif, .png, .svg, .pdf"),
    (["motion_000.npz", "--out", "x.gif", "--fps", "0"], "--fps must be in (0, 120] Hz"),
    (["renamed.npz", "--out", "x.png"], "does not say which cell it was made in; pass --cell"),
])
def test_render_errors_are_clear(made: Path, tmp_path: Path, monkeypatch, capsys,
                                 args: list[str], message: str) -> None:
    monkeypatch.chdir(tmp_path)
    (tmp_path / "junk.npz").write_text("not a motion")
    (tmp_path / "motion_000.npz").write_bytes((made / "motion_000.npz").read_bytes())
    synth = load_npz(made / "motion_000.npz")
    save_npz(dataclasses.replace(synth, motion=dataclasses.replace(synth.motion,
                                                                   name="my motion")),
             tmp_path / "renamed.npz")
    assert main(["render", *args]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "x.gif").exists()


@pytest.mark.parametrize("size", ["10x10", "800", "axb", "5000x300"])
def test_bad_size_is_refused_by_the_parser(size: str, capsys) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["render", "m.npz", "--out", "x.gif", "--size", size])
    assert exc.value.code == 2
    assert "argument --size" in capsys.readouterr().err


def test_synthesize_summary_lists_the_pictures(made: Path) -> None:
    assert (made / "motion_000.gif").stat().st_size > 1000
    assert json.loads((made / "motion_000.json").read_text())["sequence"][0] == "grasp(O1)"


# ------------------------------------------------------------------ what hides a line

def _axes(cell, lo, hi):
    fig = new_figure(6.0, 4.5, 80)
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    setup_axes3d(ax, lo, hi)
    return fig, ax


def test_camera_position_is_where_every_ray_meets() -> None:
    from mpl_toolkits.mplot3d import proj3d
    cell = cell_by_name("paper_cell")
    lo, hi = cell_bounds(cell)
    _, ax = _axes(cell, lo, hi)
    eye = camera_position(ax)
    m = ax.get_proj()
    for p in ([0.0, 0.0, 0.0], [1.2, -1.0, 0.85], [-1.5, 1.2, 1.7]):
        p = np.array(p)
        on_ray = [p + t * (eye - p) for t in (0.0, 0.3, 0.6, 0.9)]
        xy = np.array([proj3d.proj_transform(*q, m)[:2] for q in on_ray])
        assert np.allclose(xy, xy[0], atol=1e-9)
    assert eye[2] > hi[2]                                      # looking down (elev 20)


def _clearance(points: np.ndarray, seg: np.ndarray, rad: np.ndarray) -> float:
    """Smallest distance (m) of points (P, 3) to the capsules' surfaces (< 0: inside)."""
    a, b = seg[:, 0], seg[:, 1]
    ab = b - a
    t = np.clip(np.einsum("pkj,kj->pk", points[:, None] - a[None], ab)
                / np.maximum(np.einsum("kj,kj->k", ab, ab), 1e-12)[None], 0.0, 1.0)
    closest = a[None] + t[..., None] * ab[None]
    return float((np.linalg.norm(points[:, None] - closest, axis=-1) - rad[None]).min())


def test_the_worker_hides_the_floor_grid_behind_it() -> None:
    """A worker standing on the grid: every drawn piece has a clear view of the camera
    (checked by marching along its ray), and the pieces behind the worker are gone."""
    from demo_motion import demo_synthesized_motion
    cell = cell_by_name("paper_cell")
    synth = demo_synthesized_motion(cell, fps=30.0)
    pose = synth.positions[0]
    lo, hi = cell_bounds(cell, synth.positions[:, 0])
    _, ax = _axes(cell, lo, hi)
    lines = draw_static_cell(ax, cell, lo, hi, grid=0.25)
    seg, rad = capsules_from_positions(pose, synth.motion.skeleton.stature)
    lines.update((seg, rad), None)
    eye = camera_position(ax)
    grid = lines.groups[1]
    visible = grid.visible
    drawn = np.asarray(grid.artist.get_data_3d()).T
    runs = 1 + np.isnan(drawn[:, 0]).sum()
    assert len(drawn) - (runs - 1) == visible.sum() + runs    # exactly the visible pieces
    mids = 0.5 * (grid.pieces[:, 0] + grid.pieces[:, 1])
    reach = 4.0 / np.linalg.norm(eye - mids, axis=1)           # march 4 m towards the eye
    steps = np.linspace(0.0, 1.0, 2001)[1:, None]
    near = (np.linalg.norm(mids[:, :2] - pose[0, :2], axis=1) < 2.5) & ~grid.static_hidden
    checked = 0
    for mid, shown, r in zip(mids[near], visible[near], reach[near]):
        margin = _clearance(mid + steps * r * (eye - mid), seg, rad)
        if abs(margin) > 0.003:                                # not grazing a capsule
            assert shown == (margin > 0), f"piece at {mid}: drawn {shown}, clearance {margin}"
            checked += 1
    assert checked > 100
    assert (~visible[near]).sum() >= 10                        # the body hid some grid


def test_floating_objects_get_a_drawn_support() -> None:
    kit = cell_by_name("kitting_cell")
    supports = object_supports(kit)
    assert len(supports) == 1                                  # the parts lie on tables
    lo, hi = supports[0]
    assert lo[2] == pytest.approx(0.0) and hi[2] == pytest.approx(0.94 - 0.04)
    assert lo[0] < 0.0 < hi[0] and lo[1] < -1.85 < hi[1]
    paper = object_supports(cell_by_name("paper_cell"))      # O1, O2 on small trays
    assert sorted(round(h[2], 3) for _, h in paper) == [0.15, 0.25]


def test_chop_keeps_the_segments_in_order() -> None:
    pieces, owner = chop(np.array([[[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 0, 0.01]]]), 0.3)
    assert owner.tolist() == [0, 0, 0, 0, 1]
    assert np.allclose(pieces[0, 0], 0) and np.allclose(pieces[3, 1], [1, 0, 0])
    assert np.allclose(pieces[:3, 1], pieces[1:4, 0])
