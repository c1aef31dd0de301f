"""Foot locking of a whole motion (planning.footlock): planted feet stop skating."""

from __future__ import annotations

import numpy as np

from ltl_human_motion.motion.biomechanics import foot_skate
from ltl_human_motion.motion.skeleton import JOINT_INDEX as J
from ltl_human_motion.motion.skeleton import Skeleton
from ltl_human_motion.planning.footlock import lock_feet

FPS = 120.0
SK = Skeleton(1.75)


def _standing(n: int) -> np.ndarray:
    return np.repeat(SK.rest_positions()[None], n, axis=0)


def _bone_error(p: np.ndarray) -> float:
    parents = np.asarray(SK.parents)
    bones = SK.bone_lengths()
    d = np.linalg.norm(p[:, 1:] - p[:, parents[1:]], axis=-1)
    return float(np.abs(d - bones[1:]).max())


def _slide_left_foot(p: np.ndarray, speed: float, yaw_rate: float = 0.0,
                     wobble: float = 0.0) -> np.ndarray:
    """The left leg below the knee slides forward at ``speed`` (and turns about the ankle
    at ``yaw_rate``), the heel and ball flickering ``wobble`` m in height."""
    p = p.copy()
    t = np.arange(len(p)) / FPS
    a, k, toe = J["l_ankle"], J["l_knee"], J["l_toe"]
    for j in (k, a, toe):
        p[:, j, 0] += speed * t
    foot = p[:, toe] - p[:, a]
    c, s = np.cos(yaw_rate * t), np.sin(yaw_rate * t)
    p[:, toe, 0] = p[:, a, 0] + c * foot[:, 0] - s * foot[:, 1]
    p[:, toe, 1] = p[:, a, 1] + s * foot[:, 0] + c * foot[:, 1]
    p[:, a, 2] += wobble * np.sin(2 * np.pi * 7 * t)
    p[:, toe, 2] -= wobble * np.sin(2 * np.pi * 7 * t)
    return p


def test_a_sliding_planted_foot_is_pinned() -> None:
    p = _slide_left_foot(_standing(240), speed=0.03)      # 3 cm slide over 2 s
    before = foot_skate(p, FPS, 1.75)[0]
    out = lock_feet(p, FPS, SK)
    mean, v, g = foot_skate(out, FPS, 1.75)
    assert before[0] > 0.025
    assert mean.max() < 0.005
    assert np.where(g, v, 0.0).max() < 0.15
    # only the left leg below the hip moved; the right foot and the upper body did not
    moved = np.abs(out - p).max(axis=(0, 2)) > 1e-9
    assert set(np.flatnonzero(moved)) <= {J["l_knee"], J["l_ankle"], J["l_toe"]}


def test_a_flat_shuffle_step_is_lifted_and_both_standing_parts_are_pinned() -> None:
    # a stop's last small step: the foot stands 0.5 s, shuffles 6 cm forward at up to
    # 0.5 m/s without rising over the contact height (1.5 cm), and stands again
    p = _standing(300)
    t = np.arange(300) / FPS
    s = np.clip((t - 0.5) / 0.25, 0.0, 1.0)
    shuffle = 0.06 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    for j in (J["l_knee"], J["l_ankle"], J["l_toe"]):
        p[:, j, 0] += shuffle
    for j in (J["l_ankle"], J["l_toe"]):
        p[:, j, 2] += 0.015 * np.sin(np.pi * s)
    mean, v, g = foot_skate(p, FPS, 1.75)
    assert np.where(g, v, 0.0).max() > 0.15            # refused as it is
    out = lock_feet(p, FPS, SK)
    mean, v, g = foot_skate(out, FPS, 1.75)
    assert np.where(g, v, 0.0).max() < 0.15, np.where(g, v, 0.0).max()
    assert mean.max() < 0.03
    # the foot still gets where it went, stands still there, and does not jump (the
    # knee of this straight rest leg may: its IK has no bend to keep)
    ankle = out[:, J["l_ankle"]]
    np.testing.assert_allclose(ankle[-1, :2], p[-1, J["l_ankle"], :2], atol=0.01)
    assert np.linalg.norm(np.diff(ankle[-30:], axis=0), axis=-1).max() < 1e-4
    feet = out[:, [J["l_ankle"], J["l_toe"]]]
    assert np.linalg.norm(np.diff(feet, axis=0), axis=-1).max() * FPS < 1.5


def test_s1_of_a_tall_worker_with_a_flat_shuffle_verifies() -> None:
    # S1 at 1.95 m, seed 4: the right foot's flat shuffle at the end of a stop slid at
    # 0.52 m/s (foot_skate) before the standing part after it was pinned too
    from ltl_human_motion.planning.pipeline import resolve_cell, synthesize
    m = synthesize("S1", resolve_cell("paper_cell"), stature=1.95, seed=4)[0]
    assert m.verification["passed"] and m.verification["foot_skate"]["passed"]
    mean, v, g = foot_skate(m.motion.positions, m.motion.fps, 1.95)
    assert np.where(g, v, 0.0).max() < 0.15 and mean.max() < 0.03


def test_a_flat_turning_foot_does_not_jump_between_heel_and_ball() -> None:
    # heel and ball within a few mm of the floor, the contact flickering between them,
    # while the motion twists the foot: the pin passes between the joints without a jump
    p = _slide_left_foot(_standing(240), speed=0.01, yaw_rate=0.05, wobble=0.002)
    out = lock_feet(p, FPS, SK)
    mean, v, g = foot_skate(out, FPS, 1.75)
    assert np.where(g, v, 0.0).max() < 0.15, np.where(g, v, 0.0).max()
    assert mean.max() < 0.03
    step = np.linalg.norm(np.diff(out[:, [J["l_ankle"], J["l_toe"]]], axis=0), axis=-1)
    assert step.max() * FPS < 0.3
    assert _bone_error(out) < 1e-6


def test_synthesis_with_foot_locking_pins_the_feet_or_falls_back_when_it_collides(
        monkeypatch) -> None:
    from ltl_human_motion.ltl.spec import PAPER_SPECS
    from ltl_human_motion.planning import pipeline
    from ltl_human_motion.planning.pipeline import SynthesisOptions, resolve_cell, synthesize
    from ltl_human_motion.planning.verify import VerificationOptions

    # with the biomechanical checks (the default) the feet are always locked
    s1 = synthesize(PAPER_SPECS["S1"], resolve_cell("paper_cell"), seed=0)[0]
    assert s1.verification["passed"] and s1.stats.foot_locking is True
    assert foot_skate(s1.motion.positions, s1.motion.fps, 1.75)[0].max() < 0.03
    # without them foot locking is an option, with a fallback
    loose = VerificationOptions(biomechanics=False)
    on = SynthesisOptions(foot_locking=True, verification=loose)
    s1 = synthesize(PAPER_SPECS["S1"], resolve_cell("paper_cell"), seed=0, options=on)[0]
    assert s1.verification["passed"] and s1.stats.foot_locking is True
    off = synthesize(PAPER_SPECS["S1"], resolve_cell("paper_cell"), seed=0,
                     options=SynthesisOptions(verification=loose))[0]
    assert off.stats.foot_locking is False
    # next to the demo cell's table the blend moves a pose into it: its junctions are
    # blended again (junction_repair), and the motion keeps foot locking; without those
    # repairs it is blended again without foot locking, and verified
    spec, demo = "F(grasp(O1) & X release(O1))", resolve_cell("demo_cell")
    m = synthesize(spec, demo, seed=0, options=on)[0]
    assert m.verification["passed"] and m.stats.foot_locking is True
    monkeypatch.setattr(pipeline, "JUNCTION_REPAIRS", 0)
    m = synthesize(spec, demo, seed=0, options=on)[0]
    assert m.verification["passed"] and m.verification["collision"]["passed"]
    assert m.stats.foot_locking is False


def test_compiled_sequential_passes_equal_the_python_loops() -> None:
    """The numba loops of the yaw-lock envelope and the rate limiter give the Python
    loops' numbers exactly."""
    import math

    from ltl_human_motion.kernel.segments import compiled_module
    nb = compiled_module("ltl_human_motion.planning._motion_numba")
    if nb is None:
        import pytest
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(3)
    for n in (1, 2, 50, 700):
        w = rng.random(n) * (rng.random(n) > 0.7)
        ref = w.tolist()
        for t in range(n - 2, -1, -1):
            ref[t] = max(ref[t], ref[t + 1] - 0.05)
        for t in range(1, n):
            ref[t] = max(ref[t], ref[t - 1] - 0.05)
        np.testing.assert_array_equal(nb.decay_envelope(w, 0.05), ref)
        x = np.cumsum(rng.normal(size=(n, 3)) * 0.02, axis=0)
        rows = x.tolist()
        for order, back in ((range(1, n), 1), (range(n - 2, -1, -1), -1)):
            for t in order:
                d = [c - p for c, p in zip(rows[t], rows[t - back])]
                size = math.sqrt(sum(v * v for v in d))
                if size > 0.01:
                    rows[t] = [p + v * (0.01 / size) for p, v in zip(rows[t - back], d)]
        np.testing.assert_array_equal(nb.rate_limited(x, 0.01), np.array(rows))


def test_compiled_pass_kernels_equal_the_numpy_paths() -> None:
    """The numba kernels of the foot's pass by the other leg (segment gaps, the slower
    foot joint's speed) give the numpy paths' numbers bit for bit, signed zeros,
    parallel and point segments included."""
    from ltl_human_motion.kernel.segments import compiled_module
    from ltl_human_motion.planning import footlock
    if compiled_module("ltl_human_motion.planning._motion_numba") is None:
        import pytest
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(5)
    for trial in range(60):
        n = int(rng.integers(1, 400))
        pts = rng.normal(size=(n, 6, 3)) * [1e-3, 0.1, 1.0, 100.0][trial % 4]
        if trial % 3 == 0:
            pts = np.round(pts, 1)                       # exact zeros, signed zeros
        if trial % 5 == 0:                               # collinear, overlapping
            pts[:, 2] = pts[:, 1]
            pts[:, 3] = pts[:, 0] + 2.0 * (pts[:, 1] - pts[:, 0])
        if trial % 7 == 0:                               # point segments
            pts[::3, 1] = pts[::3, 0]
            pts[:, 0, 2] = -0.0
        ends = [pts[:, k] for k in range(4)]
        gap, dist = footlock._segment_gaps(*ends)
        gap_np, dist_np = footlock._segment_gaps_numpy(*ends)
        assert gap.tobytes() == gap_np.tobytes() and dist.tobytes() == dist_np.tobytes()
        speed = footlock._slower_speed(pts[:, 4], pts[:, 5], FPS)
        assert speed.tobytes() == footlock._slower_speed_numpy(pts[:, 4], pts[:, 5],
                                                               FPS).tobytes()


def test_compiled_stance_loop_equals_the_numpy_path() -> None:
    """The compiled stance loop (anchor, pin, trim to the lock limits, standing shuffle,
    release ramps) gives the Python path's displacements, weights and stances bit for
    bit, on feet that slide, turn, flicker and shuffle."""
    from ltl_human_motion.kernel.segments import compiled_module
    from ltl_human_motion.planning import footlock
    from ltl_human_motion.planning.footlock import _contact_joint, _keep_heading, _runs, _stance
    if compiled_module("ltl_human_motion.planning._motion_numba") is None:
        import pytest
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(2)
    rest = SK.rest_positions()
    rest_h = np.array([rest[J["l_ankle"], 2], rest[J["l_toe"], 2]])
    checked = 0
    for trial in range(40):
        p = _slide_left_foot(_standing(360), speed=[0.0, 0.1, 0.3, 0.6][trial % 4],
                             yaw_rate=[0.0, 0.5, 2.0][trial % 3], wobble=0.004 * (trial % 2))
        p = p + rng.normal(size=p.shape) * [0.0, 0.0005, 0.002][trial % 3]
        p[120:150, [J["l_ankle"], J["l_toe"]], 2] += 0.05 * (trial % 5 == 0)  # a lifted step
        joints = np.stack([p[:, J["l_ankle"]], p[:, J["l_toe"]]], 1)
        h = joints[:, :, 2] - rest_h
        v = np.zeros((len(p), 2))
        v[1:] = np.linalg.norm(np.diff(joints[:, :, :2], axis=0), axis=-1) * FPS
        v[0] = v[1]
        contact = _contact_joint(h)
        T = np.arange(len(p))
        hc, vc = h[T, contact], v[T, contact]
        stance = _stance(hc, vc)
        held = _keep_heading(joints, h, stance, FPS)
        n_rel = max(1, round(footlock.RELEASE * FPS))
        ramp = footlock.min_jerk(np.arange(1, n_rel + 1) / (n_rel + 1))
        s_np = stance.copy()
        d_np, w_np = footlock._lock_stances_numpy(held, joints, h, hc, vc, contact, s_np, FPS,
                                                  n_rel, ramp, _runs(stance))
        s_nb = stance.copy()
        d_nb, w_nb = footlock._lock_stances(held, joints, h, hc, vc, contact, s_nb, FPS, n_rel)
        assert d_nb.tobytes() == d_np.tobytes() and w_nb.tobytes() == w_np.tobytes()
        assert np.array_equal(s_nb, s_np)
        checked += int(np.any(w_np > 0))
    assert checked > 30


def test_compiled_leg_solve_equals_the_numpy_path(monkeypatch) -> None:
    """The compiled leg re-solve (targets out of reach raise the heel, rate-limited
    corrections, the knee's pole, two-bone IK) gives the numpy path's joints bit for bit."""
    from ltl_human_motion.kernel.segments import compiled_module
    from ltl_human_motion.planning import footlock
    if compiled_module("ltl_human_motion.planning._motion_numba") is None:
        import pytest
        pytest.skip("numba kernels not in use")
    rng = np.random.default_rng(6)
    bones = SK.bone_lengths()
    cases = []
    for trial in range(24):
        p = _slide_left_foot(_standing(240), speed=0.3, yaw_rate=0.5 * (trial % 3))
        p = p + rng.normal(size=p.shape) * [0.0, 0.001, 0.01][trial % 3]
        s = "lr"[trial % 2]
        ank, toe = p[:, J[f"{s}_ankle"]], p[:, J[f"{s}_toe"]]
        shift = rng.normal(size=(len(p), 3)) * [0.0, 0.01, 0.05, 0.2][trial % 4]
        shift[rng.random(len(p)) < 0.3] = 0.0               # frames left where they are
        if trial % 5 == 0:
            shift[:, 2] -= 0.3                               # out of the leg's reach
        cases.append((p, s, ank + shift, toe + shift))
    got = [footlock._solve_leg(p, s, bones, a, t, FPS) for p, s, a, t in cases]
    monkeypatch.setattr(footlock, "_compiled", lambda: None)
    for (p, s, a, t), joints in zip(cases, got):
        ref = footlock._solve_leg(p, s, bones, a, t, FPS)
        assert all(x.tobytes() == y.tobytes() for x, y in zip(joints, ref))
