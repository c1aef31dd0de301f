"""The reactive worker's live core (no ROS): a strategy with a verified motion per move
(planning/strategy_motion.py) and its executor (planning/strategy_executor.py).

The program is built for real on the paper cell (the pipeline plans and verifies each
move); the executor is driven with a clock of the test's own."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from ltl_human_motion.planning.strategy_executor import StrategyExecutor
from ltl_human_motion.planning.strategy_motion import (
    START,
    build_program,
    load_program,
    save_program,
    strategy_moves,
)
from ltl_human_motion.scene.cell_yaml import resolve_cell
from ltl_human_motion.tasks.reactive import DEMO_SPEC

IN, OUT = {"robot_in(R1)": True}, {"robot_in(R1)": False}


@pytest.fixture(scope="module")
def program():
    from ltl_human_motion.planning import get_library

    cell = resolve_cell("paper_cell")
    return build_program(DEMO_SPEC, "paper_cell", cell, get_library(1.75), seed=0)


def run_until(executor: StrategyExecutor, t0: float, t1: float, dt: float = 0.02
              ) -> list[tuple[float, str, int]]:
    """(time, task, step) at each change of step between t0 and t1."""
    out = []
    t = t0
    while t <= t1:
        status = executor.frame_at(t).status
        if not out or out[-1][2] != status.step:
            out.append((t, status.task, status.step))
        t += dt
    return out


def test_every_move_of_the_strategy_has_a_verified_motion(program):
    moves = strategy_moves(program.worker)
    assert {(m.source, m.task) for m in moves} == set(program.clips)
    assert program.verified
    tasks = {c.task for c in program.clips.values()}
    assert {"grasp(O1)", "walk(R1)", "assemble(R1)", "wait(0.15)"} <= tasks
    for clip in program.clips.values():
        assert clip.positions.ndim == 3 and clip.positions.shape[1:] == (23, 3)
        assert clip.yaw.shape == (len(clip.positions),)
        assert np.all(np.isfinite(clip.positions))
    assert any(m.source == START for m in moves)


def test_a_saved_program_loads_with_the_same_strategy(program, tmp_path):
    path = tmp_path / "s.strategy.npz"
    save_program(program, path)
    loaded = load_program(path)
    assert loaded.strategy_id == program.strategy_id
    assert set(loaded.clips) == set(program.clips)
    for key, clip in program.clips.items():
        np.testing.assert_array_equal(loaded.clips[key].positions, clip.positions)
    path.write_bytes(b"not a strategy")
    with pytest.raises(ValueError, match="not a strategy file"):
        load_program(path)


def test_the_worker_waits_while_the_robot_is_in_r1_and_assembles_when_it_leaves(program):
    ex = StrategyExecutor(program, 100.0, IN)
    steps = run_until(ex, 100.0, 125.0)
    tasks = [task for _, task, _ in steps]
    assert tasks[:2] == ["grasp(O1)", "walk(R1)"]
    assert set(tasks[2:]) == {"wait(0.15)"}, tasks          # at the bench, robot in R1
    assert "assemble(R1)" not in tasks
    before = ex.frame_at(125.0)
    assert ex.set_inputs(OUT, 124.99, 125.0)                 # the wait ends at the event
    after = ex.frame_at(125.0)
    assert after.status.task == "assemble(R1)" and after.status.step_start == 125.0
    assert after.status.reacted_at == 125.0 and after.status.inputs_stamp == 124.99
    # The first frame of the reaction continues the pose the worker was in.
    assert np.max(np.abs(after.positions - before.positions)) < 1e-6
    # A task under way finishes: the robot coming back does not interrupt the assembly.
    assert not ex.set_inputs(IN, 126.0, 126.0)
    assert ex.frame_at(126.5).status.task == "assemble(R1)"


def test_the_executed_run_keeps_the_safety_guarantees(program):
    started = []                                # each move's status as it begins
    ex = StrategyExecutor(program, 0.0, IN, on_step=started.append)
    t, robot_in = 0.0, True
    while t < 150.0:
        if t % 7.0 == 0.0:
            robot_in = not robot_in             # in and out of R1, again and again
            ex.set_inputs({"robot_in(R1)": robot_in}, t, t)
        ex.frame_at(t)
        t = round(t + 0.05, 2)
    tasks = [s.task for s in started]
    assert tasks.count("assemble(R1)") >= 2 and tasks.count("grasp(O1)") >= 2, tasks
    for before, after in itertools.pairwise(started):
        # The inputs a move begins with are those read as the move before it ended.
        if after.inputs["robot_in(R1)"]:
            assert after.task != "assemble(R1)"                # G(robot_in(R1) -> X !assemble)
        if before.task == "grasp(O1)":
            assert after.task == "walk(R1)"                    # G(grasp(O1) -> X walk(R1))
        assert after.step == before.step + 1


def test_junctions_add_no_speed_and_keep_the_bones(program):
    """Across the junctions of a live run (the robot in and out of R1 every 9 s), no
    joint moves faster than inside the verified clips, no bone changes length, and the
    frames played pass the verifier's checks; every junction was checked before it was
    played."""
    from ltl_human_motion.motion.biomechanics import check_biomechanics
    from ltl_human_motion.motion.skeleton import PARENTS
    from ltl_human_motion.scene.predicates import collision

    pairs = np.array([(j, q) for j, q in enumerate(PARENTS) if q >= 0])

    def bones(x: np.ndarray) -> np.ndarray:
        return np.linalg.norm(x[..., pairs[:, 0], :] - x[..., pairs[:, 1], :], axis=-1)

    clip_speed = max(float(np.max(np.linalg.norm(np.diff(c.positions, axis=0), axis=2))) * c.fps
                     for c in program.clips.values() if len(c.positions) > 1)
    reference = bones(next(iter(program.clips.values())).positions[0])
    ex = StrategyExecutor(program, 0.0, IN)
    dt, robot_in = 1 / 120, True
    frames, labels, steps = [ex.frame_at(0.0)], [], []
    for i in range(1, int(120 / dt)):
        t = i * dt
        if i % int(9 / dt) == 0:
            robot_in = not robot_in
            ex.set_inputs({"robot_in(R1)": robot_in}, t, t)
        frames.append(ex.frame_at(t))
    positions = np.array([f.positions for f in frames])
    labels = [f.status.task for f in frames]
    steps = [f.status.step for f in frames]
    junctions = sum(a != b for a, b in itertools.pairwise(steps))
    speed = float(np.max(np.linalg.norm(np.diff(positions, axis=0), axis=2))) / dt
    assert junctions > 10
    assert speed <= clip_speed * 1.05, (speed, clip_speed)
    assert float(np.max(np.abs(bones(positions) - reference))) < 1e-3
    # Every junction played was checked first, and passed.
    assert len(ex.junctions) == max(steps) and ex.junctions_failed == 0
    assert all(j.passed and j.frames > 0 for j in ex.junctions)
    # The run as played, through the verifier's own functions: no collision, no foot
    # below the floor anywhere; around each junction (from the speed window before it to
    # the end of its blend) joint speeds and ranges within the limits of the task.
    cell = resolve_cell("paper_cell")
    assert not collision(positions, cell, stature=program.stature).any()
    assert positions[:, :, 2].min() > cell.floor_z - 0.02
    starts = [i for i in range(1, len(steps)) if steps[i] != steps[i - 1]]
    for i, check in zip(starts, ex.junctions):
        a, b = i - 4, min(i + int(np.ceil(check.blend / dt)) + 4, len(frames))
        window = [labels[i - 1]] * 4 + [labels[i]] * (b - i)
        body = check_biomechanics(positions[a:b], 1 / dt, stature=program.stature,
                                  labels=window, floor_z=cell.floor_z)
        for name in ("joint_speed", "range_of_motion", "self_penetration"):
            assert body[name]["passed"], (check, body[name]["detail"])


def test_a_junction_over_a_limit_is_blended_longer(program):
    """The junction from the grasp into the walk to the bench, with speed limits between
    what its first blend and a blend twice as long need: the executor finds the first
    over the limit before playing it and plays the longer one; with limits no blend meets
    it plays the longest and counts the junction as failed."""
    from dataclasses import replace

    from ltl_human_motion.motion.biomechanics import BiomechanicsLimits, check_biomechanics
    from ltl_human_motion.planning.verify import VerificationOptions

    def walk_junction(options=None) -> StrategyExecutor:
        ex = StrategyExecutor(program, 0.0, OUT, options=options)
        t = 0.0
        while ex.status(t).task != "walk(R1)":
            t += 0.05
        return ex

    ex = walk_junction()
    blend = ex.junctions[-1].blend

    def ratio(k: float) -> float:
        frames = ex.junction_frames(k * blend)
        entry = check_biomechanics(frames, 120.0, stature=program.stature,
                                   labels=["walk(R1)"] * len(frames))["joint_speed"]
        return entry["value"] / entry["limit"]

    r1, r2, r4 = ratio(1.0), ratio(2.0), ratio(4.0)
    assert r1 > r2 > r4                    # a longer blend of the same offset is slower
    base = BiomechanicsLimits()

    def stricter(g: float) -> VerificationOptions:        # every speed limit over g
        return VerificationOptions(limits=replace(
            base, reference_stature=base.reference_stature * g))

    check = walk_junction(stricter(2.0 / (r1 + r2))).junctions[-1]
    assert check.passed and check.blend == pytest.approx(2.0 * blend)
    assert [failed for _, failed in check.tried] == [("joint_speed",), ()]
    strict = walk_junction(stricter(1.05 / r4))
    check = strict.junctions[-1]
    assert not check.passed and check.failed == ("joint_speed",)
    assert len(check.tried) == 3 and check.blend == pytest.approx(4.0 * blend)
    assert strict.junctions_failed == 1


def test_executor_refuses_a_bad_rate(program):
    with pytest.raises(ValueError, match="playback rate"):
        StrategyExecutor(program, 0.0, rate=0.0)




def test_robot_inputs_of_one_joint_state():
    from ltl_human_motion.robot.events import robot_inputs
    from ltl_human_motion.robot.kinematics import pose_from_xyz_rpy, ur_model

    model = ur_model("ur5e").with_tool(0.15, 0.05)
    base = pose_from_xyz_rpy((1.45, -1.3, 0.85), (0.0, 0.0, 2.62))   # config/ur_react_r1.yaml
    r1 = resolve_cell("paper_cell").regions["R1"]
    regions = {"R1": (np.asarray(r1.lo, dtype=float), np.asarray(r1.hi, dtype=float))}
    keys = ("robot_in(R1)", "robot_moving")
    q_in = np.radians([-4.0, -100.0, -100.0, -70.0, 90.0, 0.0])
    q_out = np.radians([-70.0, -90.0, -90.0, -90.0, 90.0, 0.0])
    still, turning = np.zeros(6), np.array([0.0, 0.0, 0.2, 0.0, 0.0, 0.0])
    assert robot_inputs(q_in, still, model, base, regions, keys) == {
        "robot_in(R1)": True, "robot_moving": False}
    assert robot_inputs(q_out, turning, model, base, regions, keys) == {
        "robot_in(R1)": False, "robot_moving": True}
    assert robot_inputs(q_out, turning, model, base, regions, keys, moving_threshold=0.3) == {
        "robot_in(R1)": False, "robot_moving": False}
    # Without joint speeds robot_moving is not reported (the player differences positions).
    assert robot_inputs(q_in, None, model, base, regions, keys) == {"robot_in(R1)": True}
