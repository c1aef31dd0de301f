"""The fast paths of planning and motion against the straightforward computations they
replace: the same values, bit for bit, so synthesis gives the same motions."""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.motion import goals
from ltl_human_motion.motion.retarget import enforce_bone_lengths
from ltl_human_motion.motion.skeleton import JOINT_NAMES, PARENTS, Skeleton
from ltl_human_motion.motion.types import MotionPrimitive, world_positions, yaw_matrix
from ltl_human_motion.planning.gait_index import sample_bodies, sample_body
from ltl_human_motion.planning.navigation import (
    ClearanceMap,
    FloorGrid,
    NavigationField,
    ObstacleField,
    _trilinear,
    floor_grid,
)
from ltl_human_motion.planning.turns import _turned
from ltl_human_motion.scene import cell_by_name
from ltl_human_motion.scene.occupancy import capsules_from_positions


@pytest.fixture(scope="module")
def paper():
    return cell_by_name("paper_cell")


@pytest.mark.parametrize("compiled", [True, False])
def test_clearance_map_interpolates_as_scipy_does(paper, compiled, monkeypatch) -> None:
    from scipy.interpolate import RegularGridInterpolator

    from ltl_human_motion.planning import navigation
    if not compiled:
        monkeypatch.setattr(navigation, "_compiled_loops", lambda: None)
    elif navigation._compiled_loops() is None:
        pytest.skip("numba is not in use")
    cm = ClearanceMap(paper, resolution=0.07)
    ref = RegularGridInterpolator((cm._xs, cm._ys), cm._values.copy(), bounds_error=False,
                                  fill_value=-1.0)
    rng = np.random.default_rng(0)
    pts = np.concatenate([rng.uniform(-3.3, 3.3, (20000, 2)),
                          np.stack(np.meshgrid(cm._xs, cm._ys), -1).reshape(-1, 2),
                          [[3.0, 3.0], [-3.0, -3.0], [3.0 + 1e-12, 0.0], [np.nan, 0.0],
                           [0.0, np.inf], [-np.inf, 0.0]]])
    inside = np.all((pts >= cm.lo) & (pts <= cm.hi), axis=-1)
    got = cm(pts)
    np.testing.assert_array_equal(got, np.where(inside, ref(pts), -1.0))
    # Bit for bit (signed zeros too), and in the shape of the points.
    assert got.tobytes() == np.where(inside, ref(pts), -1.0).tobytes()
    assert cm(pts[:6].reshape(2, 3, 2)).shape == (2, 3)
    assert cm(np.zeros((0, 2))).shape == (0,)


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("shape", [(2, 2, 2), (3, 5, 4), (17, 9, 6)])
def test_trilinear_matches_map_coordinates(shape, compiled, monkeypatch) -> None:
    from scipy.ndimage import map_coordinates

    from ltl_human_motion.planning import navigation
    if not compiled:
        monkeypatch.setattr(navigation, "_compiled_loops", lambda: None)
    elif navigation._compiled_loops() is None:
        pytest.skip("numba is not in use")
    rng = np.random.default_rng(1)
    grid = rng.uniform(0.0, 2.0, shape)
    n = np.array(shape)
    u = np.concatenate([rng.uniform(-5, n + 5, (20000, 3)),
                        np.round(rng.uniform(-2, n + 2, (5000, 3)) * 2) / 2])
    got = _trilinear(grid, u)
    assert got.tobytes() == map_coordinates(grid, u.T, order=1, mode="nearest").tobytes()


def _field_on_path(cell, compiled: bool, monkeypatch) -> ObstacleField:
    """The obstacle field of ``cell``, read by the compiled loops or (``compiled``
    False) by numpy; skips where numba is not in use."""
    from ltl_human_motion.planning import navigation
    if not compiled:
        monkeypatch.setattr(navigation, "_compiled_loops", lambda: None)
    elif navigation._compiled_loops() is None:
        pytest.skip("numba is not in use")
    return ObstacleField(cell)


def _scattered_poses(rng: np.random.Generator, m: int, s: int, jitter: float) -> np.ndarray:
    """Rest poses placed over the paper cell's floor, (m, s, J, 3), jittered per sample."""
    rest = Skeleton().rest_positions()
    where = rng.uniform([-2.5, -2.5, 0.0], [2.5, 2.5, 0.0], (m, 1, 1, 3))
    return rest[None, None] + where + rng.normal(scale=jitter, size=(m, s, *rest.shape))


@pytest.mark.parametrize("compiled", [False, True])
def test_obstacle_field_clear_matches_reading_every_capsule(paper, compiled, monkeypatch
                                                            ) -> None:
    """Both paths (the compiled loop stops at a candidate's first failing sample) give
    what reading every capsule's ends and middle gives."""
    field = _field_on_path(paper, compiled, monkeypatch)
    poses = _scattered_poses(np.random.default_rng(2), 60, 4, 0.02)
    for relative in (False, True):
        got = field.clear(poses, 1.75, relative=relative)
        seg, rad = capsules_from_positions(poses, 1.75)
        pts = np.concatenate([seg, seg.mean(axis=-2, keepdims=True)], axis=-2)
        gap = (field.distance(pts) - (rad[:, None] + 0.01 + field.res * 0.4)).min(axis=-1)
        allowed = np.minimum(gap[:, :1], 0.0) - 0.005 if relative else 0.0
        np.testing.assert_array_equal(got, np.all(gap >= allowed, axis=(1, 2)))
    assert got.any() and not got.all()


@pytest.mark.parametrize("compiled", [False, True])
def test_clear_samples_equals_clear_of_the_selection(paper, compiled, monkeypatch) -> None:
    """The search's one-call test of some candidates at some samples (with the bounding
    box pre-tests in the compiled loop, of the candidate and of each capsule) answers as
    :meth:`ObstacleField.clear` of the selected poses, for the whole body and for the
    arms with the sweep margin."""
    from ltl_human_motion.motion.capsules import part_indices
    from ltl_human_motion.planning.steps import SWEEP_MARGIN, SWEEP_PARTS
    field = _field_on_path(paper, compiled, monkeypatch)
    rng = np.random.default_rng(5)
    poses = _scattered_poses(rng, 80, 9, 0.03)
    cand = np.sort(rng.choice(80, 50, replace=False))
    arms = part_indices(SWEEP_PARTS)
    answers = []
    for samples in (np.arange(0, 9, 2), np.r_[0, 1:9:2]):
        for relative in (False, True):
            for margin, parts in ((0.01, None), (SWEEP_MARGIN * field.res, arms)):
                got = field.clear_samples(poses, cand, samples, 1.75, margin=margin,
                                          relative=relative, parts=parts)
                want = field.clear(poses[cand][:, samples], 1.75, margin=margin,
                                   relative=relative, parts=parts)
                np.testing.assert_array_equal(got, want)
                answers.append(got)
    answers = np.concatenate(answers)
    assert answers.any() and not answers.all()


def test_fields_on_a_shared_grid_equal_fields_built_alone(paper) -> None:
    cm = ClearanceMap(paper)
    lo, hi = paper.workspace_lo[:2], paper.workspace_hi[:2]
    grid = floor_grid(cm, lo, hi, 0.25, 0.1)
    assert floor_grid(cm, lo, hi, 0.25, 0.1) is grid
    assert isinstance(grid, FloorGrid)

    def goal(xy: np.ndarray) -> np.ndarray:
        return np.hypot(xy[:, 0] + 1.0, xy[:, 1] + 1.0) < 0.5

    alone = NavigationField(lo, hi, lambda xy: cm(xy) > 0.25, goal, 0.1)
    shared = NavigationField.on_grid(grid, goal)
    np.testing.assert_array_equal(shared.dist, alone.dist)
    np.testing.assert_array_equal(shared.descent, alone.descent)
    assert shared.reachable_from(0.0, 0.0)


def _primitive(rng: np.random.Generator, n: int) -> MotionPrimitive:
    poses = Skeleton().rest_positions()[None] + rng.normal(scale=0.05, size=(n, 23, 3))
    root = np.cumsum(rng.normal(scale=0.01, size=(n, 4)), axis=0)
    return MotionPrimitive("p", "walk", poses, root, 120.0, "test")


def test_world_positions_of_some_frames_and_of_many_primitives() -> None:
    rng = np.random.default_rng(3)
    prims = [_primitive(rng, n) for n in (7, 12, 12, 40)]
    mp = prims[-1]
    full = world_positions(mp, 0.3, -0.2, 1.1)
    ref = np.einsum("tij,tkj->tki", yaw_matrix(1.1 + mp.root[:, 3]), mp.poses)
    np.testing.assert_allclose(full[..., 2], ref[..., 2] + mp.root[:, None, 2])
    np.testing.assert_array_equal(world_positions(mp, 0.3, -0.2, 1.1, frames=[0, 5, 39]),
                                  full[[0, 5, 39]])
    np.testing.assert_array_equal(sample_bodies(prims),
                                  np.stack([sample_body(p) for p in prims]))


def test_turned_points_equal_the_matrix_products() -> None:
    rng = np.random.default_rng(4)
    yaw, pts = rng.uniform(-4, 4, 50), rng.normal(size=(50, 23, 3))
    np.testing.assert_array_equal(_turned(yaw, pts),
                                  np.einsum("tij,tkj->tki", yaw_matrix(yaw), pts))
    np.testing.assert_array_equal(_turned(yaw, pts, inverse=True),
                                  np.einsum("tji,tkj->tki", yaw_matrix(yaw), pts))


def test_enforce_bone_lengths_equals_the_joint_by_joint_walk() -> None:
    from ltl_human_motion.motion.retarget import _CHEST_RIGID, _PELVIS_RIGID, frame_from_axes
    sk = Skeleton(1.8)
    rng = np.random.default_rng(5)
    pos = sk.rest_positions()[None] + rng.normal(scale=0.03, size=(40, 23, 3))
    pos[3, 8] = pos[3, 7]                                  # a degenerate source bone
    rest, lengths = sk.rest_positions(), sk.bone_lengths()
    ix = {n: i for i, n in enumerate(JOINT_NAMES)}
    r_pelvis = frame_from_axes(pos[:, ix["l_hip"]] - pos[:, ix["r_hip"]],
                               pos[:, ix["chest"]] - pos[:, ix["pelvis"]])
    r_chest = frame_from_axes(pos[:, ix["l_shoulder"]] - pos[:, ix["r_shoulder"]],
                              pos[:, ix["neck"]] - pos[:, ix["chest"]])
    ref = np.zeros_like(pos)
    ref[:, 0] = pos[:, 0]
    for j in range(1, 23):
        p = PARENTS[j]
        if JOINT_NAMES[j] in _PELVIS_RIGID:
            ref[:, j] = ref[:, p] + r_pelvis @ (rest[j] - rest[p])
        elif JOINT_NAMES[j] in _CHEST_RIGID:
            ref[:, j] = ref[:, p] + r_chest @ (rest[j] - rest[p])
        else:
            vec = pos[:, j] - pos[:, p]
            norm = np.linalg.norm(vec, axis=-1, keepdims=True)
            rest_dir = (rest[j] - rest[p]) / np.linalg.norm(rest[j] - rest[p])
            direction = np.where(norm > 1e-9, vec / np.maximum(norm, 1e-12), rest_dir)
            ref[:, j] = ref[:, p] + lengths[j] * direction
    np.testing.assert_array_equal(enforce_bone_lengths(pos, sk), ref)


def test_posture_grid_is_cached_per_start_pose_with_the_same_values() -> None:
    sk = Skeleton()
    st = goals._Start(sk, None)
    targets = np.array([[0.45, 0.1, 0.9], [0.45, -0.1, 0.9]])
    goals._GRID_CACHE.clear()
    first = goals._grid(sk, st, targets, (0, 1))
    assert len(goals._GRID_CACHE) == 1
    again = goals._grid(sk, goals._Start(sk, None), targets, (0, 1))
    assert len(goals._GRID_CACHE) == 1
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a, b)
    assert np.isfinite(first[3]).any()
    cost = first[3]
    P, D = first[0], first[1]
    # The cost of the best posture: flexion and drop terms plus the reach term.
    i = int(np.argmin(cost))
    tr = goals._trunk(sk, st.pelvis + np.array([first[2][i], 0.0, -D[i]]), P[i:i + 1])
    d = [np.linalg.norm(targets[k] - tr[0, goals._J[f"{s}_shoulder"]])
         for k, s in enumerate("lr")]
    arm = goals._arm_length(sk)
    expect = P[i] ** 2 + (D[i] / (0.14 * sk.stature)) ** 2 + sum(
        0.5 * (x / arm - 0.8) ** 2 for x in d)
    assert cost[i] == pytest.approx(expect, rel=1e-12)


def _concatenate_parts(segments):
    """Reference: concatenation part by part, each overlap blended into the previous part."""
    from ltl_human_motion.planning.blend import blend_weights, wrap_angle
    pos, yaw = [segments[0].positions], [np.unwrap(segments[0].root_yaw)]
    lab = [np.full(len(segments[0].root_yaw), segments[0].label)]
    for seg in segments[1:]:
        nf = min(int(seg.blend_in), len(yaw[-1]), len(seg.root_yaw))
        yaw_in = np.unwrap(seg.root_yaw)
        ref = yaw[-1][-nf] if nf else yaw[-1][-1]
        yaw_in = yaw_in + 2.0 * np.pi * np.round((ref - yaw_in[0]) / (2.0 * np.pi))
        if nf:
            w = blend_weights(nf)
            mixed = w[:, None, None] * pos[-1][-nf:] + (1.0 - w[:, None, None]) * seg.positions[:nf]
            mixed_yaw = yaw[-1][-nf:] + (1.0 - w) * wrap_angle(yaw_in[:nf] - yaw[-1][-nf:])
            pos[-1] = np.concatenate([pos[-1][:-nf], mixed])
            yaw[-1] = np.concatenate([yaw[-1][:-nf], mixed_yaw])
            lab[-1] = np.concatenate([lab[-1][:-nf], np.where(w >= 0.5, lab[-1][-nf:],
                                                              seg.label)])
        pos.append(seg.positions[nf:])
        yaw.append(yaw_in[nf:])
        lab.append(np.full(len(yaw_in) - nf, seg.label))
    return np.concatenate(pos), np.concatenate(yaw), np.concatenate(lab)


def test_concatenate_into_one_buffer_equals_part_by_part() -> None:
    from ltl_human_motion.planning.blend import PlacedSegment, concatenate
    rng = np.random.default_rng(6)
    segments = [PlacedSegment(rng.normal(size=(n, 23, 3)), rng.uniform(-7, 7, n), label,
                              blend, f"s{label}")
                for label, (n, blend) in enumerate([(9, 0), (8, 6), (12, 6), (5, 4), (10, 8),
                                                    (20, 0), (12, 10)])]
    positions, yaw, labels, spans = concatenate(segments)
    ref = _concatenate_parts(segments)
    np.testing.assert_array_equal(positions, ref[0])
    np.testing.assert_array_equal(yaw, ref[1])
    np.testing.assert_array_equal(labels, ref[2])
    assert spans[0] == (0, 9) and spans[-1][1] == len(positions)


def test_fields_with_a_key_are_reused_between_planners(paper) -> None:
    from ltl_human_motion.planning.pipeline import get_library
    from ltl_human_motion.planning.planner import SequencePlanner
    lib = get_library(1.75)
    a = SequencePlanner(paper, lib, np.random.default_rng(0))
    b = SequencePlanner(paper, lib, np.random.default_rng(1))

    def goal(xy: np.ndarray, clearance=None) -> np.ndarray:
        return np.hypot(xy[:, 0] - 1.0, xy[:, 1] + 1.0) < 0.6

    first = a.goals.field(goal, ("test", 1.0, -1.0, 0.6))
    assert b.goals.field(goal, ("test", 1.0, -1.0, 0.6)) is first
    fresh = b.goals.field(goal)
    assert fresh is not first
    np.testing.assert_array_equal(fresh.dist, first.dist)
    assert not first.dist.flags.writeable and not first.descent.flags.writeable


def test_compiled_field_distances_equal_the_numpy_path(paper, monkeypatch) -> None:
    """The obstacle field's compiled distances (points near and off its grid) equal the
    numpy path's, bit for bit; its compiled test of a part in hand read at points on its
    box (which skips the points far from every obstacle and stops at the first that
    fails) answers as the numpy path, which reads every point."""
    from ltl_human_motion.planning import navigation
    if navigation._compiled_loops() is None:
        pytest.skip("numba is not in use")
    field = ObstacleField(paper)
    rng = np.random.default_rng(5)
    centres = rng.uniform(field.lo - 0.3, field.lo + field.res * field.shape + 0.3, (40, 7, 3))
    side = np.linspace(-0.3, 0.3, 13)
    box = np.stack(np.meshgrid(side, side, side, indexing="ij"), axis=-1).reshape(-1, 3)
    offsets = box[np.any(np.abs(box) > 0.29, axis=1)]
    near = field.part_lo[rng.integers(len(field.part_lo), size=400)]
    held = near[:, None] + rng.normal(scale=0.3, size=(400, 5, 3))
    standing = rng.random(400) < 0.5
    thresholds = (0.02, 0.1)

    def answers() -> tuple[np.ndarray, ...]:
        return (field.distance(centres),
                *(field.points_clear(held, offsets, t, standing) for t in thresholds))

    compiled = answers()
    monkeypatch.setattr(navigation, "_compiled_loops", lambda: None)
    numpy = answers()
    assert compiled[0].shape == (40, 7)
    for got, want in zip(compiled, numpy):
        np.testing.assert_array_equal(got, want)
    assert (compiled[0] < 0.05).any() and (compiled[0] >= field.far).any()
    for ok in compiled[1:]:
        assert ok.any() and not ok.all()
        assert (ok & standing).any() and (~ok & standing).any()
