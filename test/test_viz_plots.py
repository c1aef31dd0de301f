"""Offscreen plots: hand trajectory (Fig. 3), snapshots (Fig. 2), cell overview."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from demo_motion import demo_synthesized_motion
from PIL import Image

from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.scene import cell_by_name
from ltl_human_motion.viz import (
    plot_cell,
    plot_hand_trajectory,
    render_snapshots,
)

BONE_RGB = np.array([0x1F, 0x3B, 0x73])


@pytest.fixture(scope="module")
def paper():
    return cell_by_name("paper_cell")


@pytest.fixture(scope="module")
def motions(paper):
    return [demo_synthesized_motion(paper, fps=20.0),
            demo_synthesized_motion(cell_by_name("obstacle_cell"), fps=20.0, hands="right")]


def _pixels(path) -> np.ndarray:
    with Image.open(path) as im:
        return np.asarray(im.convert("RGB")).astype(int)


def _near(img: np.ndarray, rgb: np.ndarray, tol: int = 30) -> np.ndarray:
    return np.all(np.abs(img - rgb) <= tol, axis=-1)


def test_hand_trajectory_one_panel_per_motion(motions, tmp_path):
    one, two = tmp_path / "one.png", tmp_path / "two.png"
    plot_hand_trajectory(motions[0], one)
    plot_hand_trajectory(motions, two, titles=["S1", "S2"])
    a, b = _pixels(one), _pixels(two)
    assert b.shape[1] > 1.8 * a.shape[1]                       # two panels side by side
    # x (red), y (green), z (blue) lines and the shaded task span are drawn.
    for rgb in ((0xD6, 0x27, 0x28), (0x2C, 0xA0, 0x2C), (0x1F, 0x77, 0xB4), (0x74, 0xC4, 0x76)):
        assert _near(a, np.array(rgb), 25).sum() > 50
    with pytest.raises(ValueError, match="2 titles for 1 motions"):
        plot_hand_trajectory(motions[0], one, titles=["a", "b"])
    with pytest.raises(ValueError, match="at least one motion"):
        plot_hand_trajectory([], one)
    with pytest.raises(ValueError, match="unknown joint"):
        plot_hand_trajectory(motions[0], one, joint="tail")


def test_snapshots_show_worker_in_every_panel(motions, paper, tmp_path):
    path = tmp_path / "snap.png"
    synth = motions[0]
    times = [0.0, synth.duration / 2, synth.duration]
    render_snapshots(synth, paper, times, path, ncols=3, capsules=False, body="stick")
    img = _pixels(path)
    h, w, _ = img.shape
    assert w > 2 * h
    for k in range(3):
        panel = img[:, k * w // 3:(k + 1) * w // 3]
        assert _near(panel, BONE_RGB, 25).sum() > 30           # the bones
    # The stick figure with capsules shows as translucent blue in every panel.
    render_snapshots(synth, paper, times, path, ncols=3, body="stick")
    img = _pixels(path)
    for k in range(3):
        panel = img[:, k * w // 3:(k + 1) * w // 3]
        blue = (panel[..., 2] - panel[..., 0] > 60) & (panel[..., 2] > 150)
        assert blue.sum() > 300
    # The default is the shaded body: shirt, trousers and skin in every panel.
    render_snapshots(synth, paper, times, path, ncols=3)
    img = _pixels(path)
    for k in range(3):
        panel = img[:, k * w // 3:(k + 1) * w // 3]
        shirt = (panel[..., 2] - panel[..., 0] > 50) & (panel[..., 2] > 80)
        skin = (panel[..., 0] - panel[..., 2] > 40) & (panel[..., 0] > 150) & (
            panel[..., 1] > 100)
        assert shirt.sum() > 150 and skin.sum() > 10
    assert [p.name for p in tmp_path.iterdir()] == ["snap.png"]
    with pytest.raises(ValueError, match="at least one time"):
        render_snapshots(synth, paper, [], path)
    with pytest.raises(ValueError, match="body must be one of"):
        render_snapshots(synth, paper, times, path, body="ghost")


def test_plot_cell_in_several_formats(paper, tmp_path):
    plot_cell(paper, tmp_path / "cell.png")
    plot_cell(cell_by_name("obstacle_cell"), tmp_path / "cell.svg")
    img = _pixels(tmp_path / "cell.png")
    assert img.std() > 10
    # The workbench's brown and the drill press's green appear.
    assert _near(img, np.array([0x8B, 0x45, 0x13]), 40).sum() > 100
    assert _near(img, np.array([0x22, 0x8B, 0x22]), 40).sum() > 100
    assert (tmp_path / "cell.svg").read_text().lstrip().startswith("<?xml")


def test_missing_matplotlib_names_the_package(motions, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(MissingDependencyError, match="pip install matplotlib"):
        plot_hand_trajectory(motions[0], tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()
