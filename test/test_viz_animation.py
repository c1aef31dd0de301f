"""GIF animation: offscreen, frame count follows the requested rate, reasonably fast."""

from __future__ import annotations

import sys
import time

import numpy as np
import pytest
from demo_motion import demo_synthesized_motion
from PIL import Image

from ltl_human_motion.errors import MissingDependencyError
from ltl_human_motion.scene import cell_by_name
from ltl_human_motion.viz import render_animation


@pytest.fixture(scope="module")
def paper():
    return cell_by_name("paper_cell")


@pytest.fixture(scope="module")
def synth(paper):
    return demo_synthesized_motion(paper, fps=30.0)


def test_gif_frames_follow_the_rate(synth, paper, tmp_path):
    path = tmp_path / "a.gif"
    t0 = time.perf_counter()
    n = render_animation(synth, paper, path, fps=10.0, body="stick")
    elapsed = time.perf_counter() - t0
    assert n == int(np.floor(synth.duration * 10.0)) + 1
    with Image.open(path) as im:
        assert im.n_frames == n
        assert im.info["duration"] == 100
        im.seek(0)
        first = np.asarray(im.convert("RGB")).astype(int)
        im.seek(n - 1)
        last = np.asarray(im.convert("RGB")).astype(int)
    assert np.abs(first - last).sum() > 0                     # the worker moved
    assert elapsed / n < 0.25                                 # seconds per frame


def test_gif_shows_a_shaded_body_by_default(synth, paper, tmp_path):
    path = tmp_path / "body.gif"
    n = render_animation(synth, paper, path, fps=10.0, max_frames=6)
    assert n == 6
    with Image.open(path) as im:
        for k in range(n):
            im.seek(k)
            px = np.asarray(im.convert("RGB")).astype(int)
            shirt = (px[..., 2] - px[..., 0] > 50) & (px[..., 2] > 80)
            skin = (px[..., 0] - px[..., 2] > 40) & (px[..., 0] > 150) & (px[..., 1] > 100)
            assert shirt.sum() > 100 and skin.sum() > 5


def test_gif_with_capsules_and_frame_cap(synth, paper, tmp_path):
    path = tmp_path / "b.gif"
    n = render_animation(synth, paper, path, fps=15.0, capsules=True, max_frames=12,
                         size=(4.0, 3.0), body="stick")
    assert n == 12
    with Image.open(path) as im:
        assert im.n_frames == 12 and im.size == (320, 240)


def test_bad_arguments_and_missing_pillow(synth, paper, tmp_path, monkeypatch):
    with pytest.raises(ValueError, match="fps must be positive"):
        render_animation(synth, paper, tmp_path / "c.gif", fps=0.0)
    with pytest.raises(ValueError, match="max_frames must be positive"):
        render_animation(synth, paper, tmp_path / "c.gif", max_frames=0)
    monkeypatch.setitem(sys.modules, "PIL", None)
    with pytest.raises(MissingDependencyError, match="pip install pillow"):
        render_animation(synth, paper, tmp_path / "c.gif")
    assert not (tmp_path / "c.gif").exists()


def test_the_camera_turns_to_see_a_machine_tender_in_front_of_the_machine():
    """The default view looks at a worker at a machine's door from behind the machine;
    the chosen azimuth sees every task position (pelvis, head, hands) unhidden."""
    from ltl_human_motion.planning import synthesize
    from ltl_human_motion.scenarios.unseen import build_cell
    from ltl_human_motion.scene.cell_yaml import cell_from_yaml
    from ltl_human_motion.viz.render import VIEW_AZIMUTHS, clear_view_azimuth
    built = build_cell("chamber", 0, 1)
    cell = cell_from_yaml(built.yaml, source=built.name)
    motion = synthesize("F extract(done, vise_a)", cell, stature=1.75)[0]
    azim = clear_view_azimuth(motion, cell)
    assert azim in VIEW_AZIMUTHS and azim != VIEW_AZIMUTHS[0]
    # the worker stands in front of the door: the camera is on the door's side
    door = np.asarray(cell.obstacles[0].aabb()[1])[1]         # the machine's front face (y)
    assert np.sin(np.radians(azim)) > 0.0 and motion.positions[:, 0, 1].max() > door
