"""Offline SSM: the live controller's decisions, in simulated time.

The reference is the live :class:`CoexistenceController` itself, stepped on a simulated
clock against the simulated controller's state (:class:`SimulatedUR`) in this process;
the offline run must make the same decision at every step.
"""

from __future__ import annotations

import numpy as np
import pytest

from ltl_human_motion.kernel.segments import min_signed_distance
from ltl_human_motion.robot.coexistence import CoexistenceController
from ltl_human_motion.robot.kinematics import pose_from_xyz_rpy, robot_capsules, ur_model
from ltl_human_motion.robot.offline_ssm import CONTROL_RATE, batched_separations, run_offline_ssm
from ltl_human_motion.robot.separation import signed_distances
from ltl_human_motion.robot.sim.state import SimulatedUR
from ltl_human_motion.robot.sim.trajectory import load_robot_config
from ltl_human_motion.robot.ssm import SSMParameters
from ltl_human_motion.scene.occupancy import capsules_from_positions

#: Offline against live, m and slider units.
AGREEMENT = 1e-6


@pytest.fixture(scope="module")
def robot():
    cfg = load_robot_config("config/ur_pick_place.yaml")
    model = ur_model(cfg["model"]).with_tool(cfg["tool_length"], cfg["tool_radius"])
    return cfg["trajectory"], model, pose_from_xyz_rpy(cfg["base_xyz"], cfg["base_rpy"])


@pytest.fixture(scope="module")
def s1():
    from ltl_human_motion.planning import synthesize

    return synthesize("S1", "paper_cell", variants=1, seed=1)[0]


def test_batched_kernel_equals_live_kernel(robot, s1):
    traj, model, base = robot
    rng = np.random.default_rng(3)
    hseg, hrad = capsules_from_positions(s1.positions, 1.75)
    frames = rng.integers(0, s1.n_frames, 200)
    q = traj.positions(rng.uniform(0, traj.cycle_time, 200))
    rseg, rrad = robot_capsules(q, model, base)
    got = batched_separations(hseg[frames], hrad, rseg, rrad)
    want = [signed_distances(hseg[f], hrad, r, rrad).min() for f, r in zip(frames, rseg)]
    assert np.allclose(got, want, atol=1e-9, rtol=0)
    # Random capsules, parallel and degenerate (point) segments included.
    P = rng.normal(size=(300, 5, 2, 3))
    Q = rng.normal(size=(300, 4, 2, 3))
    P[:100, 0, 1] = P[:100, 0, 0] + 0.5 * (Q[:100, 0, 1] - Q[:100, 0, 0])   # parallel
    Q[100:150, 1, 1] = Q[100:150, 1, 0]                                   # points
    pr, qr = rng.uniform(0, 0.1, 5), rng.uniform(0, 0.1, 4)
    got = batched_separations(P, pr, Q, qr)
    want = [signed_distances(a, pr, b, qr).min() for a, b in zip(P, Q)]
    assert np.allclose(got, want, atol=1e-9, rtol=0)
    # Bit for bit the live loop's one-query function (same pair kernel, same order).
    assert got.tolist() == [min_signed_distance(a, pr, b, qr) for a, b in zip(P, Q)]
    with pytest.raises(ValueError, match="batched capsules"):
        batched_separations(P[0], pr, Q[0], qr)


class _Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


class _Receive:
    """The simulated controller's state read as ``RTDEReceiveInterface`` would."""

    def __init__(self, sim: SimulatedUR, clock: _Clock) -> None:
        self.sim, self.clock = sim, clock

    def getActualQ(self) -> list[float]:
        return [float(v) for v in self.sim.q]

    def getTimestamp(self) -> float:
        return self.clock.now

    def isConnected(self) -> bool:
        return True

    def reconnect(self) -> bool:
        return True

    def disconnect(self) -> None:
        pass


class _IO:
    def __init__(self, sim: SimulatedUR) -> None:
        self.sim = sim

    def setSpeedSlider(self, speed: float) -> bool:
        return self.sim.set_speed_slider(speed)

    def reconnect(self) -> bool:
        return True

    def disconnect(self) -> None:
        pass


def _live_reference(s1, robot, horizon: float, step: float = 0.1):
    """The live controller stepped at 125 Hz on a simulated clock."""
    traj, model, base = robot
    clock = _Clock()
    sim = SimulatedUR(model, traj, clock=clock, base=base)
    ctl = CoexistenceController(lambda: _Receive(sim, clock), lambda: _IO(sim), model, base,
                                clock=clock)
    hseg, hrad = capsules_from_positions(s1.positions, 1.75)
    T = s1.n_frames
    n = round(s1.duration * CONTROL_RATE)
    horizons = step * np.arange(1, int(np.floor(horizon / step + 1e-9)) + 1)
    out = []
    for k in range(n):
        clock.now = k / CONTROL_RATE
        sim.step(clock.now)
        f = min(int(np.rint(clock.now * s1.fps)), T - 1)
        pred = [(h, hseg[min(f + int(np.rint(h * s1.fps)), T - 1)], hrad) for h in horizons]
        ctl.update_occupancy(hseg[f], hrad, clock.now, pred or None)
        out.append(ctl.step())
    return out, sim


@pytest.mark.parametrize("horizon", [0.0, 0.5])
def test_offline_makes_the_live_controllers_decisions(s1, robot, horizon):
    traj, model, base = robot
    live, sim = _live_reference(s1, robot, horizon)
    off = run_offline_ssm(s1.positions, s1.fps, traj, model, base,
                          prediction_horizon=horizon)
    assert len(off.slider) == len(live)
    # The same decisions; the numbers agree to 1 um (measured: 3e-8 m of separation and
    # 3e-8 of slider apart since the geometry-kernel and rotation merge; the simulated
    # controller also sums its clock differences).
    assert np.allclose(off.slider, [d.slider for d in live], atol=AGREEMENT, rtol=0)
    assert list(off.mode) == [d.mode for d in live]
    known = np.isfinite(off.separation)
    live_sep = np.array([d.separation for d in live])
    assert np.allclose(off.separation[known], live_sep[known], atol=AGREEMENT)
    assert off.metrics["min_separation"] == pytest.approx(np.min(live_sep), abs=AGREEMENT)
    # Skipped steps are the far ones: their real separation exceeds S_p + margin.
    sp = SSMParameters().protective_distance
    assert np.all(live_sep[~known] > sp + SSMParameters().margin)
    # tau before the last step (the simulated controller has not applied its command).
    assert off.trajectory_time[-2] == pytest.approx(sim.trajectory_time, abs=AGREEMENT)
    m = off.metrics
    assert m["min_separation"] < sp and m["violations"] and m["time_min_speed"] > 1.0
    assert m["effective_cycle_time"] > traj.cycle_time
    assert m["frames_below_sp"] and max(m["frames_below_sp"]) < s1.n_frames


@pytest.fixture
def numpy_steps(monkeypatch):
    """Run the offline SSM's numpy step loop instead of the compiled one."""
    from ltl_human_motion.robot import offline_ssm

    monkeypatch.setattr(offline_ssm, "_compiled_steps", lambda: None)


@pytest.mark.parametrize("horizon, start", [(0.0, 0.0), (0.5, 0.0), (0.3, 2.9)])
def test_compiled_and_numpy_step_loops_agree(s1, robot, horizon, start, request):
    from ltl_human_motion.robot import offline_ssm

    if offline_ssm._compiled_steps() is None:
        pytest.skip("numba is not in use")
    traj, model, base = robot
    args = (s1.positions, s1.fps, traj, model, base)
    kw = {"prediction_horizon": horizon, "trajectory_start": start}
    fast = run_offline_ssm(*args, **kw)
    request.getfixturevalue("numpy_steps")
    slow = run_offline_ssm(*args, **kw)
    # The same decisions and skipped steps; the numbers apart by rounding only (the
    # compiled DH chain sums its products in another order than BLAS).
    assert list(fast.mode) == list(slow.mode)
    assert np.array_equal(np.isnan(fast.separation), np.isnan(slow.separation))
    known = np.isfinite(slow.separation)
    assert np.allclose(fast.separation[known], slow.separation[known], atol=1e-9, rtol=0)
    assert np.allclose(fast.slider, slow.slider, atol=1e-9, rtol=0)
    assert np.allclose(fast.trajectory_time, slow.trajectory_time, atol=1e-9, rtol=0)
    for key in ("min_separation", "time_min_speed", "time_reduced_speed", "time_below_sp",
                "throughput_ratio"):
        assert fast.metrics[key] == pytest.approx(slow.metrics[key], abs=1e-9)
    assert fast.metrics["frames_below_sp"] == slow.metrics["frames_below_sp"]
    assert len(fast.metrics["violations"]) == len(slow.metrics["violations"])


def test_compiled_slider_is_the_python_one():
    from ltl_human_motion.robot import offline_ssm
    from ltl_human_motion.robot.ssm import slider_from_separation

    nb = offline_ssm._compiled_steps()
    if nb is None:
        pytest.skip("numba is not in use")
    params = SSMParameters(min_slider=0.05, max_slider=0.9)
    sp, margin = params.protective_distance, params.margin
    rng = np.random.default_rng(5)
    values = [sp, sp + margin, np.nextafter(sp, 0), np.nextafter(sp + margin, 9), -1.0,
              np.nan, np.inf, -np.inf, *rng.uniform(sp - 0.2, sp + margin + 0.2, 500)]
    for v in values:
        assert nb.slider(float(v), sp, margin, params.min_slider, params.max_slider) \
            == slider_from_separation(float(v), params)


def test_offline_input_errors(robot):
    traj, model, base = robot
    with pytest.raises(ValueError, match="shape"):
        run_offline_ssm(np.zeros((10, 22, 3)), 120.0, traj, model, base)
    with pytest.raises(ValueError, match="fps"):
        run_offline_ssm(np.zeros((10, 23, 3)), 0.0, traj, model, base)
    with pytest.raises(ValueError, match="base"):
        run_offline_ssm(np.zeros((10, 23, 3)), 120.0, traj, model, np.full((4, 4), np.nan))
