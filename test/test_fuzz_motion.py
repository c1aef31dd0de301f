"""Fuzzing the motion loaders with mutated genuine BVH files (assimp's CMU samples): any
mutation gives a skeleton and frames or a MotionFormatError, never another exception."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from fuzzing import fuzz_settings
from hypothesis import given
from hypothesis import strategies as st

from ltl_human_motion.errors import MotionFormatError
from ltl_human_motion.motion import bvh

BVH_DIR = Path("/usr/share/assimp/models/BVH")
FILES = sorted(BVH_DIR.glob("*.bvh")) if BVH_DIR.is_dir() else []
pytestmark = pytest.mark.skipif(not FILES, reason="assimp's BVH models are not installed")
#: Frames kept of each file, so one example parses in milliseconds.
KEEP_FRAMES = 40


def _short(path: Path) -> list[str]:
    lines = path.read_text(errors="replace").splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Frame Time"))
    lines = lines[:start + 1 + KEEP_FRAMES]
    frames = next(i for i, line in enumerate(lines) if line.startswith("Frames:"))
    lines[frames] = f"Frames: {KEEP_FRAMES}"
    return lines


GENUINE = {p.name: _short(p) for p in FILES}
TOKENS = ["nan", "inf", "-1e308", "1e999", "999999999999", "0", "-", "QQQ", "{", "}",
          "JOINT", "End", "CHANNELS", "CHANNELS 999", "OFFSET", "\x00", "é", ""]


@st.composite
def mutated(draw: st.DrawFn) -> str:
    lines = list(GENUINE[draw(st.sampled_from(sorted(GENUINE)))])
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(lines) - 1))
        kind = draw(st.sampled_from(["replace_token", "drop", "duplicate", "truncate",
                                     "junk"]))
        if kind == "replace_token":
            words = lines[i].split() or [""]
            words[draw(st.integers(0, len(words) - 1))] = draw(st.sampled_from(TOKENS))
            lines[i] = " ".join(words)
        elif kind == "drop":
            del lines[i]
        elif kind == "duplicate":
            lines.insert(i, lines[i])
        elif kind == "truncate":
            lines = lines[:i]
        else:
            lines[i] = draw(st.text(max_size=30))
        if not lines:
            break
    return "\n".join(lines) + "\n"


@fuzz_settings()
@given(mutated())
def test_mutated_bvh_loads_or_gives_a_format_error(tmp_path_factory: pytest.TempPathFactory,
                                                   text: str) -> None:
    path = tmp_path_factory.mktemp("bvh") / "mutated.bvh"
    path.write_text(text, errors="replace")
    try:
        _, data, fps = bvh.load_raw(path)
    except MotionFormatError as exc:
        assert str(path) in str(exc)
        return
    assert data.ndim == 3 and data.shape[-1] == 3 and fps > 0   # positions (T, J, 3)
    assert np.all(np.isfinite(data))


def test_the_genuine_files_load() -> None:
    for name, lines in GENUINE.items():
        path = Path(f"/tmp/lhm-fuzz-{name}")
        path.write_text("\n".join(lines) + "\n")
        try:
            _, data, _ = bvh.load_raw(path)
        finally:
            path.unlink()
        assert data.shape[0] == KEEP_FRAMES
