"""Issue 36: input propositions, GR(1) strategies on the cell model (omega + dd), and
``ltl-human-motion react`` on the paper cell with the real pipeline."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.cli import main
from ltl_human_motion.errors import CellError, SpecError
from ltl_human_motion.ltl import build_specification, parse_spec
from ltl_human_motion.ltl.gr1 import split_gr1
from ltl_human_motion.robot.events import robot_events
from ltl_human_motion.scene.cell_yaml import cell_from_yaml, resolve_cell
from ltl_human_motion.tasks.model import CellModel
from ltl_human_motion.tasks.reactive import (
    WAIT_STEP,
    UnrealizableError,
    draw_run,
    joint_satisfies,
    keeps_assumptions,
    random_input_lasso,
    reactive_worker,
    run_strategy,
    timed_run,
)

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "config" / "paper_cell.yaml"
GUARANTEES = "G(robot_in(R1) -> X !assemble(R1)) & G F grasp(O1) & G F assemble(R1)"
REACTIVE = f"(G F !robot_in(R1)) -> ({GUARANTEES})"


@pytest.fixture(scope="module")
def cell():
    return resolve_cell("paper_cell")


@pytest.fixture(scope="module")
def worker(cell):
    return reactive_worker(REACTIVE, cell)


def test_parser_tells_inputs_from_tasks():
    parsed = parse_spec(REACTIVE, PAPER, reactive=True)
    assert [a.key for a in parsed.inputs] == ["robot_in(R1)"]
    assert [a.key for a in parsed.tasks] == ["assemble(R1)", "grasp(O1)"]
    both = parse_spec("G(robot_moving -> X wait(1)) & G(offered(O2) -> X grasp(O2))", PAPER,
                      reactive=True)
    assert [a.key for a in both.inputs] == ["robot_moving", "offered(O2)"]
    assert [a.key for a in both.tasks] == ["wait(1.0)", "grasp(O2)"]


def test_an_input_is_refused_as_a_task_with_its_position():
    with pytest.raises(SpecError) as exc:
        build_specification("grasp(O1) & G F !robot_in(R1)", PAPER)
    assert (exc.value.line, exc.value.column) == (1, 18)
    assert "'robot_in' is an input" in exc.value.message
    cell = {"objects": ["O1"], "regions": ["R1"],
            "shorthands": {"fetch(R)": "robot_in(R) & leftHand(R)"}}
    with pytest.raises(SpecError, match="in the body of a shorthand"):
        parse_spec("F fetch(R1)", cell, reactive=True)
    for bad, what in [("G F robot_in(R9)", "unknown region 'R9'"),
                      ("G F robot_moving(R1)", "takes 0 arguments"),
                      ("G F offered", "takes 1 argument")]:
        with pytest.raises(SpecError, match=what):
            parse_spec(bad, PAPER, reactive=True)


def test_specifications_without_inputs_are_unchanged():
    for text in ("S1", "S2", "grasp(O1) & F (assemble(R1) & X walk(R0))"):
        plain = build_specification(text, PAPER)
        reactive = build_specification(text, PAPER, reactive=True)
        assert (plain.formula, plain.tasks, plain.inputs) == \
            (reactive.formula, reactive.tasks, ())


CELL_WITH_INPUT = """
name: door_cell
start_region: R0
regions:
  R0: {lo: [-0.3, -0.3, 0.0], hi: [0.3, 0.3, 0.1]}
  R1: {lo: [0.9, -1.1, 0.0], hi: [1.1, -0.9, 0.1]}
inputs:
  door_open: /cell/door_open
"""


def test_cell_declares_boolean_inputs_with_topics():
    cell = cell_from_yaml(CELL_WITH_INPUT)
    assert cell.inputs == {"door_open": "/cell/door_open"}
    parsed = parse_spec("(G F door_open) -> G F (door_open & walk(R1))", cell, reactive=True)
    assert [a.key for a in parsed.inputs] == ["door_open"]
    with pytest.raises(SpecError, match="'door_open' is an input"):
        parse_spec("G F door_open", cell)
    for bad, what in [("door_open: cell/door", "absolute name"),
                      ("walk: /cell/walk", "already a task")]:
        with pytest.raises(CellError, match=what):
            cell_from_yaml(CELL_WITH_INPUT.replace("door_open: /cell/door_open", bad))


def test_gr1_form_is_checked():
    def split(text: str):
        parsed = parse_spec(text, PAPER, reactive=True)
        return split_gr1(parsed.formula, parsed.inputs)
    spec = split(REACTIVE)
    assert [c.kind for c in spec.assumptions] == ["liveness"]
    assert [c.kind for c in spec.guarantees] == ["safety", "liveness", "liveness"]
    with pytest.raises(SpecError, match="mentions grasp"):
        split("(G F (grasp(O1) | robot_in(R1))) -> G F assemble(R1)")
    plain = split("grasp(O1) -> walk(R0)")          # no input on the left: a guarantee
    assert (plain.assumptions, [c.kind for c in plain.guarantees]) == ((), ["init"])
    with pytest.raises(SpecError, match="not of GR\\(1\\) form"):
        split("(F G robot_in(R1)) -> G F assemble(R1)")
    with pytest.raises(SpecError, match="not of GR\\(1\\) form"):
        split("G F robot_in(R1) -> G(grasp(O1) U assemble(R1))")


def test_strategy_reacts_to_the_robot_and_keeps_the_whole_spec(worker):
    assert worker.gr1.inputs == ("robot_in(R1)",)
    rng = np.random.default_rng(7)
    model = CellModel.from_cell(resolve_cell("paper_cell"))
    saw_wait_for_robot = False
    for _ in range(20):
        prefix, cycle = random_input_lasso(worker, rng)
        run = run_strategy(worker, prefix, cycle)
        assert joint_satisfies(worker, run)
        inputs = [*run.prefix_inputs, *run.cycle_inputs, *run.cycle_inputs]
        tasks = [worker.tasks[k].key for k in (*run.prefix_tasks, *run.cycle_tasks,
                                               *run.cycle_tasks)]
        for i in range(1, len(tasks)):
            if inputs[i - 1]["robot_in(R1)"]:
                assert tasks[i] != "assemble(R1)"
                saw_wait_for_robot |= tasks[i].startswith("wait")
        state = model.initial_state()
        for t in tasks:                           # every step physically possible
            nxt = model.step(state, worker.tasks[[x.key for x in worker.tasks].index(t)])
            assert nxt is not None, (t, state)
            state = nxt[0]
            assert len(state.held) <= 2
    assert saw_wait_for_robot


def test_a_timed_robot_in_r1_makes_the_worker_wait_then_assemble(worker):
    def events(t: float) -> dict[str, bool]:
        return {"robot_in(R1)": 4.0 <= t < 12.0}
    run, ends = timed_run(worker, events, 12.0)
    assert keeps_assumptions(worker, run) and joint_satisfies(worker, run)
    steps = [(x["robot_in(R1)"], worker.tasks[k].key, t) for x, k, t in
             zip([*run.prefix_inputs, *run.cycle_inputs],
                 [*run.prefix_tasks, *run.cycle_tasks], ends)]
    assert steps[0][:2] == (True, "grasp(O1)")          # the grasp ends at 6.9 s, robot in R1
    waits = [s for s in steps if s[1] == f"wait({WAIT_STEP!r})"]
    assert waits and all(t <= 12.0 + WAIT_STEP + 1e-9 for _, _, t in waits)
    first_assembly = next(i for i, s in enumerate(steps) if s[1] == "assemble(R1)")
    assert not steps[first_assembly - 1][0]             # started after the robot left
    assert steps[first_assembly - 1][2] - 12.0 <= WAIT_STEP + 1e-9


def test_robot_events_from_the_ur_trajectory(cell, worker):
    events = robot_events(ROOT / "config" / "ur_pick_place.yaml", cell,
                          ["robot_in(R1)", "robot_moving"])
    samples = [events.at(t) for t in np.arange(0.0, events.period, 0.1)]
    assert not any(s["robot_in(R1)"] for s in samples)     # it sweeps away from R1
    assert any(s["robot_moving"] for s in samples) and not all(s["robot_moving"]
                                                               for s in samples)
    from dataclasses import replace
    base = {"B": (np.array([1.3, -1.45, 0.85]), np.array([1.6, -1.15, 1.2]))}
    assert all(s["robot_in(B)"] for s in (replace(events, regions=base,
                                                  inputs=("robot_in(B)",)).at(t)
                                          for t in (0.0, 2.0, 4.0)))
    assert events.stopped(1.0)["robot_moving"] is False
    run, source = draw_run(worker, np.random.default_rng(4), "trajectory", events)
    assert source == "trajectory" and joint_satisfies(worker, run)


def test_the_worker_never_holds_a_third_part(cell):
    w = reactive_worker("(G F !robot_in(R1)) -> (G F grasp(O1) & G F grasp(O2) & "
                        "G(robot_in(R1) -> X !assemble(R1)) & G F assemble(R1))", cell)
    rng = np.random.default_rng(3)
    model = CellModel.from_cell(cell)
    for _ in range(10):
        run = run_strategy(w, *random_input_lasso(w, rng))
        assert joint_satisfies(w, run)
        state = model.initial_state()
        for k in (*run.prefix_tasks, *run.cycle_tasks, *run.cycle_tasks):
            state = model.step(state, w.tasks[k])[0]
            assert len(state.held) <= 2


def test_unrealizable_spec_is_explained(cell):
    with pytest.raises(UnrealizableError) as exc:
        reactive_worker(GUARANTEES, cell)
    message = exc.value.message
    assert message.startswith("unrealizable: the robot can defeat")
    assert "'G F assemble(R1)'" in message
    assert "the robot stays in R1 forever" in message
    assert "add an assumption such as G F !robot_in(R1)" in message


def test_among_winning_moves_the_cheapest(cell):
    w = reactive_worker("(G F !robot_in(R1)) -> (G F (grasp(O1) | grasp(O2)) & "
                        "G F assemble(R1) & G(robot_in(R1) -> X !assemble(R1)))", cell)
    model = w.model
    start = model.initial_state()
    cost = {t.key: model.step(start, t)[1] for t in w.tasks if t.name == "grasp"}
    assert cost["grasp(O1)"] < cost["grasp(O2)"]        # O1 lies nearer the start
    rng = np.random.default_rng(5)
    for _ in range(10):
        run = run_strategy(w, *random_input_lasso(w, rng))
        first = (run.prefix_tasks or run.cycle_tasks)[0]
        assert w.tasks[first].key == "grasp(O1)"
        assert joint_satisfies(w, run)


def test_unrealizable_explanations_name_the_robots_counter_strategy(cell):
    with pytest.raises(UnrealizableError) as exc:
        reactive_worker("(G F !robot_in(R1)) -> G F grasp(O1)", cell)
    assert "the worker cannot meet the guarantee 'G F grasp(O1)' whatever the robot does" \
        in exc.value.message
    with pytest.raises(UnrealizableError, match="the robot is in R1 as each assemble\\(R1\\) "
                       "of the worker ends, and is out of R1 otherwise"):
        reactive_worker("(G F !robot_in(R1)) -> G(robot_in(R1) -> !assemble(R1)) & "
                        "G F assemble(R1)", cell)
    with pytest.raises(UnrealizableError, match="the robot keeps offering O1 forever"):
        reactive_worker("(G F offered(O1)) -> G(offered(O1) -> X grasp(O1)) & "
                        "G F assemble(R1)", cell)


def test_react_cli_writes_the_report(tmp_path, capsys):
    out = tmp_path / "react"
    code = main(["react", "--cell", str(PAPER), "--spec", REACTIVE, "--traces", "5",
                 "--seed", "2", "--out", str(out)])
    assert code == 0
    report = json.loads((out / "react.json").read_text())
    assert report["realizable"] is True
    assert report["traces"] == 5 and report["spec_satisfied"] == 5
    assert report["verified"] >= 4
    assert len(report["records"]) == 5
    first = report["records"][0]
    assert first["run"]["cycle"] and "verified" in first and first["duration"] > 0
    assert [r["source"] for r in report["records"]] == ["steps", "timed", "trajectory",
                                                         "steps", "timed"]
    assert report["max_reaction_s"] is None or report["max_reaction_s"] <= 0.3
    assert "5/5 runs satisfy" in capsys.readouterr().out


def test_runs_with_the_same_tasks_share_one_motion_checked_with_their_own_inputs(cell,
                                                                                 worker):
    """Two robot behaviours that make the strategy do the same tasks get the same motion
    (planned and verified once, the same bytes when planned again from scratch); each
    run's observed letters are checked with its own inputs."""
    from ltl_human_motion.planning import get_library
    from ltl_human_motion.planning.reactive import RunMotions
    from ltl_human_motion.tasks.reactive import JointLasso

    rng = np.random.default_rng(3)
    runs: dict[tuple, list] = {}
    while not any(len(v) > 1 and len({str(r.prefix_inputs + r.cycle_inputs) for r in v}) > 1
                  for v in runs.values()):
        run = run_strategy(worker, *random_input_lasso(worker, rng))
        runs.setdefault((run.prefix_tasks, run.cycle_tasks), []).append(run)
    same = next(v for v in runs.values() if len(v) > 1)
    library = get_library(1.75)
    motions = RunMotions(worker, cell, library, seed=5, stature=1.75)
    first, second = motions.motion(same[0]), motions.motion(same[1])
    assert first.verified and second.verified
    assert not first.cached and second.cached and motions.planned == 1
    assert first.sha256 == second.sha256 and len(first.sha256) == 64
    fresh = RunMotions(worker, cell, library, seed=5, stature=1.75).motion(same[1])
    assert fresh.sha256 == first.sha256 and not fresh.cached
    # The same motion with inputs that break the guarantee: the robot in R1 before each
    # assembly is caught on the joint trace, not taken from the cache.
    run = same[0]
    tasks = [*run.prefix_tasks, *run.cycle_tasks]
    inputs = [{"robot_in(R1)": worker.tasks[tasks[(i + 1) % len(tasks)]].key
               == "assemble(R1)"} for i in range(len(tasks))]
    n = len(run.prefix_tasks)
    broken = motions.motion(JointLasso(tuple(inputs[:n]), run.prefix_tasks,
                                       tuple(inputs[n:]), run.cycle_tasks))
    assert broken.cached and broken.motion_checks and not broken.observed_satisfies
    assert not broken.verified and broken.failed == ["reactive_ltl"]


def test_react_cli_refuses_unrealizable_without_traceback(tmp_path, capsys):
    code = main(["react", "--cell", str(PAPER), "--spec", GUARANTEES, "--traces", "5",
                 "--out", str(tmp_path / "r")])
    err = capsys.readouterr().err
    assert code == 2
    assert "unrealizable" in err and "G F !robot_in(R1)" in err
    assert "Traceback" not in err
    assert not (tmp_path / "r" / "react.json").exists()
