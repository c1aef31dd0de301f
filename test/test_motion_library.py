"""The default motion library: gait primitives from real clips, graph, planner arrays, cache."""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np
import pytest
from scipy.sparse.csgraph import connected_components

from ltl_human_motion.motion import deepmimic, gait
from ltl_human_motion.motion.automaton import transition_distances, window_positions
from ltl_human_motion.motion.library import (
    DEFAULT_LIBRARY_DELTA,
    MotionLibrary,
    cache_dir,
    library_key,
    load_library,
)
from ltl_human_motion.motion.skeleton import JOINT_INDEX, Skeleton
from ltl_human_motion.motion.types import world_positions


@pytest.fixture(scope="module")
def cache(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("motion_cache")


@pytest.fixture(scope="module")
def lib(cache: Path) -> MotionLibrary:
    return load_library(cache_dir=cache)


def test_gait_primitives_come_from_real_clips(lib: MotionLibrary) -> None:
    sources = {mp.source.split(" ")[0].split(":")[0] for mp in lib.primitives}
    clip_dir = str(deepmimic.motions_dir())
    assert sources and all(s.startswith(clip_dir) for s in sources)
    assert {Path(s).name for s in sources} == {Path(c).name for c in
                                               deepmimic.DEFAULT_GAIT_CLIPS}
    names = [mp.name for mp in lib.primitives]
    assert any(n.endswith("_m_p000") for n in names)          # mirrored copies
    loops = [mp for mp in lib.primitives if mp.meta["kind"] == "loop"]
    assert all(mp.n_frames == gait.PRIMITIVE_FRAMES + lib.overlap for mp in loops)
    assert all(mp.fps == gait.LIBRARY_FPS == lib.fps for mp in lib.primitives)
    np.testing.assert_allclose(lib.durations[lib.kinds == "loop"],
                               gait.PRIMITIVE_FRAMES / gait.LIBRARY_FPS)
    assert {mp.task for mp in lib.primitives} == {"walk", "carry"}
    assert lib.starts.size > 0 and lib.stops.size > 0
    assert lib.start_indices(carry=False).size and lib.start_indices(carry=True).size


def test_graph_is_strongly_connected_per_gait(lib: MotionLibrary) -> None:
    T = lib.automaton.transitions
    for carry in (False, True):
        idx = np.nonzero((lib.kinds == "loop") & (lib.is_carry == carry))[0]
        n, _ = connected_components(T[idx][:, idx], directed=True, connection="strong")
        assert n == 1
        assert idx.size == lib.stats["scc"]["carry" if carry else "walk"]
    # never switch between walk and carry, never enter a start, never leave a stop
    coo = T.tocoo()
    assert np.all(lib.is_carry[coo.row] == lib.is_carry[coo.col])
    assert not np.any(lib.kinds[coo.col] == "start")
    assert not np.any(lib.kinds[coo.row] == "stop")
    assert np.all(coo.data < lib.delta)
    # every start leads into the loops, every stop is reachable from them
    for s in lib.starts:
        assert np.any(lib.kinds[lib.gait_successors(s)] == "loop")
    Tt = T.T.tocsr()
    for s in lib.stops:
        assert np.any(lib.kinds[Tt.indices[Tt.indptr[s]:Tt.indptr[s + 1]]] == "loop")


def test_edges_match_recomputed_distances(lib: MotionLibrary) -> None:
    rng = np.random.default_rng(0)
    rows = rng.choice(lib.n_primitives, size=20, replace=False)
    prims = lib.primitives
    ends = window_positions([prims[i] for i in rows], lib.automaton.k_comp, end=True)
    starts = window_positions(prims, lib.automaton.k_comp, end=False)
    D = transition_distances(ends, starts, lib.stature)
    for r, i in enumerate(rows):
        expect = np.nonzero(D[r] < lib.delta)[0]
        expect = [j for j in expect if j != i and lib.kinds[j] != "start"
                  and lib.kinds[i] != "stop" and lib.is_carry[i] == lib.is_carry[j]]
        assert lib.gait_successors(i).tolist() == sorted(expect)


def test_natural_successor_is_seamless(lib: MotionLibrary) -> None:
    mp = lib.primitive(lib.automaton.index("walk_0walk_forward_p000"))
    nxt = lib.automaton.index("walk_0walk_forward_p020")
    assert nxt in lib.gait_successors(lib.automaton.index(mp.name)).tolist()
    assert lib.automaton.distance(lib.automaton.index(mp.name), nxt) < 1e-6
    # placed at displacement[i], the successor's first frames coincide with the last ones
    i = lib.automaton.index(mp.name)
    dx, dy, dyaw = lib.displacement[i]
    a = world_positions(mp)[-lib.overlap:]
    b = world_positions(lib.primitive(nxt), dx, dy, dyaw)[:lib.overlap]
    assert np.abs(a - b).max() < 1e-6


def test_planner_arrays(lib: MotionLibrary) -> None:
    n = lib.n_primitives
    assert lib.displacement.shape == (n, 3) and lib.end_displacement.shape == (n, 3)
    assert lib.root_paths.shape[0] == n and lib.root_paths.shape[2] == 2
    for i in (0, n // 2, n - 1):
        mp = lib.primitive(i)
        k = mp.n_frames - lib.overlap
        np.testing.assert_allclose(lib.displacement[i], mp.root[k, [0, 1, 3]])
        np.testing.assert_allclose(lib.end_displacement[i], mp.root[-1, [0, 1, 3]])
        np.testing.assert_allclose(lib.root_paths[i, 0], 0.0, atol=1e-12)
        np.testing.assert_allclose(lib.root_paths[i, -1], mp.root[k, :2])
    # walking speed of the loops is human: 0.8 to 1.8 m/s
    loops = lib.kinds == "loop"
    speed = np.linalg.norm(lib.displacement[loops, :2], axis=1) / lib.durations[loops]
    assert 0.8 < np.median(speed) < 1.8
    assert lib.indptr.shape == (n + 1,) and lib.indices.dtype.kind == "i"


def test_start_and_stop_primitives_meet_the_standing_pose(lib: MotionLibrary) -> None:
    stand, h = gait.standing_pose(lib.skeleton)
    carry_stand, _ = gait.standing_pose(lib.skeleton, carry=True)
    np.testing.assert_allclose(lib.standing_pose, stand)
    assert lib.standing_height == pytest.approx(h)
    for s in lib.starts:
        mp = lib.primitive(s)
        want = carry_stand if lib.is_carry[s] else stand
        assert np.abs(mp.poses[0] - want).max() < 0.02
        assert mp.root[0, 2] == pytest.approx(h, abs=0.02)
    for s in lib.stops:
        mp = lib.primitive(s)
        want = carry_stand if lib.is_carry[s] else stand
        assert np.abs(mp.poses[-1] - want).max() < 0.02
        # it comes to rest: the last frames barely move
        w = world_positions(mp)
        assert np.abs(np.diff(w[-3:], axis=0)).max() < 1e-3


def test_carry_holds_the_hands_in_front_of_the_chest(lib: MotionLibrary) -> None:
    carry = np.nonzero((lib.kinds == "loop") & lib.is_carry)[0]
    for i in carry[:: max(1, carry.size // 10)]:
        p = lib.primitive(i).poses
        chest = p[:, JOINT_INDEX["chest"]]
        for hand in ("l_hand", "r_hand"):
            rel = p[:, JOINT_INDEX[hand]] - chest
            assert np.all(rel[:, 0] > 0.15)                       # in front
            assert np.all(np.abs(rel[:, 2]) < 0.3)                # at chest height


def test_quality_report_passes(lib: MotionLibrary) -> None:
    q = lib.quality
    assert q["ok"] and q["gait"]["failed"] == [] and q["goal"]["failed"] == []
    assert q["gait"]["count"] == lib.n_primitives
    assert set(q["goal"]["by_task"]) >= {"grasp", "assemble", "sit", "kneel", "wait"}


def test_cache_reuse_and_key(lib: MotionLibrary, cache: Path) -> None:
    t0 = time.perf_counter()
    again = load_library(cache_dir=cache)
    assert time.perf_counter() - t0 < 1.0
    assert again.key == lib.key and again.n_primitives == lib.n_primitives
    assert again.automaton.n_transitions == lib.automaton.n_transitions
    np.testing.assert_array_equal(again.primitive(5).poses, lib.primitive(5).poses)
    files = [deepmimic.motions_dir() / c for c in deepmimic.DEFAULT_GAIT_CLIPS]
    k = library_key(1.75, files, DEFAULT_LIBRARY_DELTA, 5, 4, True)
    assert k == lib.key
    assert library_key(1.6, files, DEFAULT_LIBRARY_DELTA, 5, 4, True) != k
    assert library_key(1.75, files, 0.15, 5, 4, True) != k


def test_corrupt_cache_is_rebuilt(tmp_path: Path) -> None:
    first = load_library(stature=1.6, cache_dir=tmp_path, delta=0.15)
    (entry,) = list(tmp_path.glob("library-*.npz"))
    entry.write_bytes(entry.read_bytes()[:1000])
    second = load_library(stature=1.6, cache_dir=tmp_path, delta=0.15)
    assert second.n_primitives == first.n_primitives
    assert second.skeleton.stature == 1.6
    np.testing.assert_allclose(second.skeleton.bone_lengths(),
                               Skeleton(1.6).bone_lengths())
    # the rebuilt entry is valid again
    third = load_library(stature=1.6, cache_dir=tmp_path, delta=0.15)
    assert third.automaton.n_transitions == second.automaton.n_transitions


def test_cache_dir_from_environment(monkeypatch, tmp_path: Path) -> None:
    monkeypatch.setenv("LTL_HUMAN_MOTION_CACHE", str(tmp_path / "c"))
    assert cache_dir() == tmp_path / "c"
    monkeypatch.delenv("LTL_HUMAN_MOTION_CACHE")
    assert cache_dir() == Path(os.path.expanduser("~")) / ".cache" / "ltl_human_motion"


def test_user_source_folder_adds_primitives(tmp_path: Path) -> None:
    from ltl_human_motion.motion import bvh
    src = Path("/usr/share/assimp/models/BVH/01_03.bvh")
    if not src.is_file():
        pytest.skip("Debian assimp-testmodels not installed")
    folder = tmp_path / "mocap"
    folder.mkdir()
    m = bvh.load(src)
    bvh.save(type(m)(m.positions[:360], m.fps, m.skeleton, "part"), folder / "part.bvh",
             translations=True)
    lib = load_library(source=folder, include_default=False, use_cache=False)
    assert lib.stats["candidates"] > 0
    assert all("part.bvh" in mp.source for mp in lib.primitives)


def test_bad_arguments() -> None:
    with pytest.raises(ValueError, match="stature must be between"):
        load_library(stature=2.3, use_cache=False)
    with pytest.raises(ValueError, match="delta must be positive"):
        load_library(delta=-1, use_cache=False)
    with pytest.raises(ValueError, match="does not exist"):
        load_library(source="/nonexistent/folder", use_cache=False)


def test_goal_from_library(lib: MotionLibrary) -> None:
    g = lib.goal("grasp", np.array([0.4, -0.15, 0.9]))
    assert g.fps == lib.fps and g.task == "grasp"
    np.testing.assert_allclose(g.poses[0], lib.standing_pose, atol=1e-9)
