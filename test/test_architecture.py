"""Layering rules read from the source: the ROS layer imports no CLI (the CLI is the top
layer), the ROS conversions and playback use the core's types instead of probing them,
and the fakes live under test/, not in the package."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.robot.fusion import OccupancySample, fuse_occupancies

PACKAGE = Path(__file__).resolve().parents[1] / "ltl_human_motion"


def _imports(path: Path) -> set[str]:
    """Every module a source file imports, at any depth (lazy imports included)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
    return out


@pytest.mark.parametrize("layer", ["ros", "robot", "scene", "motion", "planning", "ltl",
                                   "kernel", "viz", "batch"])
def test_no_layer_below_the_cli_imports_it(layer: str) -> None:
    offenders = {str(p.relative_to(PACKAGE)): sorted(m for m in _imports(p)
                                                    if m.startswith("ltl_human_motion.cli"))
                 for p in (PACKAGE / layer).rglob("*.py")}
    assert not {k: v for k, v in offenders.items() if v}


def test_the_ltl_layer_reads_names_only_and_imports_no_scene() -> None:
    offenders = {str(p.relative_to(PACKAGE)): sorted(m for m in _imports(p)
                                                    if m.startswith("ltl_human_motion.scene"))
                 for p in (PACKAGE / "ltl").rglob("*.py")}
    assert not {k: v for k, v in offenders.items() if v}


def test_every_layer_takes_the_task_vocabulary_from_one_module() -> None:
    from ltl_human_motion import vocabulary
    from ltl_human_motion.ltl import TASK_SIGNATURES
    from ltl_human_motion.motion.goals import HAND_TASKS
    from ltl_human_motion.scene import TASK_ARGUMENTS
    assert TASK_SIGNATURES is TASK_ARGUMENTS is vocabulary.TASK_ARGUMENTS
    assert HAND_TASKS is vocabulary.HAND_TASKS


@pytest.mark.parametrize("module", ["ros/conversions.py", "ros/playback.py"])
def test_ros_layer_uses_core_types_without_probes(module: str) -> None:
    tree = ast.parse((PACKAGE / module).read_text())
    probes = [n.lineno for n in ast.walk(tree) if isinstance(n, ast.Call)
              and isinstance(n.func, ast.Name) and n.func.id in ("hasattr", "getattr")]
    assert probes == [], f"{module}: hasattr/getattr at lines {probes}"


def test_fakes_are_not_in_the_package() -> None:
    for fake in ("viz/demo.py", "ros/testing.py"):
        assert not (PACKAGE / fake).exists(), fake
    for old in ("ur_sim.py", "rtde_server.py", "sim_state.py", "trajectory.py",
                "port_lock.py", "rtde_protocol.py"):
        assert not (PACKAGE / "robot" / old).exists(), f"robot/{old} belongs in robot/sim/"


def _sample(human: str, x: float, predicted: list[float]) -> OccupancySample:
    seg = np.array([[[x, 0.0, 0.1], [x, 0.0, 1.5]]])
    return OccupancySample(human, 0.0, seg, np.array([0.2]),
                           [(h, seg + np.array([h, 0.0, 0.0]), np.array([0.2])) for h in predicted])


def test_fusion_stacks_humans_and_retimes_predictions_from_the_oldest_stamp() -> None:
    a, b = _sample("a", 1.0, [0.1, 0.2]), _sample("b", 2.0, [0.1])
    fused = fuse_occupancies([(10.0, a), (9.5, b)])
    assert fused.stamp == 9.5                        # the oldest: one silent human is stale
    np.testing.assert_array_equal(fused.segments, np.concatenate([a.segments, b.segments]))
    np.testing.assert_array_equal(fused.radii, [0.2, 0.2])
    assert [h for h, _, _ in fused.predicted] == pytest.approx([0.6, 0.7, 0.1])
    one = fuse_occupancies([(3.0, a)], use_prediction=False)
    assert one.segments is a.segments and one.stamp == 3.0 and one.predicted is None
    assert fuse_occupancies([(3.0, _sample("c", 0.0, []))]).predicted is None
    with pytest.raises(ValueError, match="no human"):
        fuse_occupancies([])


def test_ros2_run_bringup_is_the_cli_with_ros_arguments_dropped() -> None:
    pytest.importorskip("rclpy")
    import subprocess
    import sys

    script = PACKAGE.parent / "nodes" / "bringup"
    proc = subprocess.run([sys.executable, str(script), "--help", "--ros-args", "-r",
                           "__ns:=/probe"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "usage: ltl-human-motion bringup" in proc.stdout


#: The longest function the planner's modules may hold, lines (docstring included).
MAX_FUNCTION_LINES = 80


def _long_functions(path: Path) -> list[str]:
    tree = ast.parse(path.read_text(), str(path))
    return [f"{path.name}:{n.lineno} {n.name} ({n.end_lineno - n.lineno + 1} lines)"
            for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))
            and n.end_lineno - n.lineno + 1 > MAX_FUNCTION_LINES]


def test_no_planning_or_goal_model_function_is_longer_than_80_lines() -> None:
    paths = [*sorted((PACKAGE / "planning").glob("*.py")),
             *sorted((PACKAGE / "motion" / "goals").glob("*.py"))]
    long = [f for p in paths for f in _long_functions(p)]
    assert not long


def test_no_goal_model_module_is_longer_than_500_lines() -> None:
    """The goal models are a package of modules with one job each, not one long module."""
    assert not (PACKAGE / "motion" / "goals.py").exists()
    long = [f"{p.name} ({n} lines)" for p in sorted((PACKAGE / "motion" / "goals").glob("*.py"))
            if (n := len(p.read_text().splitlines())) > 500]
    assert not long


def test_the_planner_parts_set_attributes_only_when_made() -> None:
    """The planner's state travels in its WorkerState, never in attributes a method sets
    on the side (the old ``_back_limit``, ``_wait_seconds``, a temporary ``options``)."""
    offenders = []
    for name in ("planner", "steps", "walk_goals", "goal_steps"):
        path = PACKAGE / "planning" / f"{name}.py"
        for cls in ast.walk(ast.parse(path.read_text(), str(path))):
            if not isinstance(cls, ast.ClassDef):
                continue
            for fn in cls.body:
                if not isinstance(fn, ast.FunctionDef) or fn.name == "__init__":
                    continue
                offenders += [f"{name}.{cls.name}.{fn.name}: self.{t.attr}"
                              for node in ast.walk(fn) if isinstance(node, ast.Assign)
                              for t in node.targets if isinstance(t, ast.Attribute)
                              and isinstance(t.value, ast.Name) and t.value.id == "self"]
    assert not offenders
