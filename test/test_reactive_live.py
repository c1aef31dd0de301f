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
    joint moves faster than inside the verified clips, and no bone changes length."""
    from ltl_human_motion.motion.skeleton import PARENTS

    pairs = np.array([(j, q) for j, q in enumerate(PARENTS) if q >= 0])

    def bones(x: np.ndarray) -> np.ndarray:
        return np.linalg.norm(x[pairs[:, 0]] - x[pairs[:, 1]], axis=-1)

    clip_speed = max(float(np.max(np.linalg.norm(np.diff(c.positions, axis=0), axis=2))) * c.fps
                     for c in program.clips.values() if len(c.positions) > 1)
    reference = bones(next(iter(program.clips.values())).positions[0])
    ex = StrategyExecutor(program, 0.0, IN)
    dt, robot_in = 1 / 120, True
    prev = ex.frame_at(0.0).positions
    speed = stretch = 0.0
    junctions = 0
    step = 0
    for i in range(1, int(120 / dt)):
        t = i * dt
        if i % int(9 / dt) == 0:
            robot_in = not robot_in
            ex.set_inputs({"robot_in(R1)": robot_in}, t, t)
        frame = ex.frame_at(t)
        junctions += frame.status.step != step
        step = frame.status.step
        speed = max(speed, float(np.max(np.linalg.norm(frame.positions - prev, axis=1))) / dt)
        stretch = max(stretch, float(np.max(np.abs(bones(frame.positions) - reference))))
        prev = frame.positions
    assert junctions > 10
    assert speed <= clip_speed * 1.05, (speed, clip_speed)
    assert stretch < 0.01, stretch


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
