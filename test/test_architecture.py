"""Layering rules read from the source: every import goes down the layer order of
docs/ARCHITECTURE.md (lazy imports inside functions included), the ROS conversions and
playback use the core's types instead of probing them, and the fakes live under test/,
not in the package."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.robot.fusion import OccupancySample, fuse_occupancies

PACKAGE = Path(__file__).resolve().parents[1] / "ltl_human_motion"
ARCHITECTURE = PACKAGE.parent / "docs" / "ARCHITECTURE.md"

#: Top-level names that are not listed in the layers: the entry point of ``python -m``
#: is the CLI's, and the interfaces colcon generates are the ROS layer's.
_LAYER_OF = {"__main__": "cli", "msg": "ros", "srv": "ros"}


def _imports(path: Path) -> set[str]:
    """Every module a source file imports, at any depth (lazy imports included); a name
    imported from the package itself (``from ltl_human_motion import x``) counts as the
    module ``ltl_human_motion.x``, and so does a compiled-loop module loaded by name
    (``compiled_module("ltl_human_motion.x._numba")``)."""
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                and node.func.id == "compiled_module" and node.args
                and isinstance(node.args[0], ast.Constant)):
            out.add(node.args[0].value)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path}:{node.lineno}: relative import"
            if node.module == PACKAGE.name:
                out.update(f"{PACKAGE.name}.{a.name}" for a in node.names)
            elif node.module:
                out.add(node.module)
    return out


def _layer_order() -> list[str]:
    """The package's top-level modules and sub-packages, ground first, as the code block
    under "## Layers" in docs/ARCHITECTURE.md lists them (two spaces in: sub-packages of
    a layer stand deeper)."""
    text = ARCHITECTURE.read_text()
    block = text.split("## Layers", 1)[1].split("```")[1]
    return [m.group(1) for m in re.finditer(r"^  (\w+)(?:/|\.py)\s", block, re.MULTILINE)]


def _layer(module: str) -> str | None:
    """The layer of a dotted module name inside the package (None: outside it, or a name
    of the package's own ``__init__`` such as ``__version__``, which every layer may read)."""
    parts = module.split(".")
    if parts[0] != PACKAGE.name or len(parts) < 2:
        return None
    top = parts[1]
    if top in _LAYER_OF:
        return _LAYER_OF[top]
    return top if (PACKAGE / top).is_dir() or (PACKAGE / f"{top}.py").is_file() else None


def test_the_layer_list_names_every_module_of_the_package_once() -> None:
    order = _layer_order()
    assert len(order) == len(set(order)), order
    assert order[0] == "errors" and order[-1] == "cli"
    tops = {p.stem if p.is_file() else p.name for p in PACKAGE.iterdir()
            if (p.suffix == ".py" and p.stem != "__init__") or (p / "__init__.py").exists()}
    assert {_LAYER_OF.get(t, t) for t in tops} == set(order)


def test_every_import_goes_down_the_layers() -> None:
    """Lazy imports count: a function that imports a higher layer ties the layers as much
    as a module-level import does."""
    rank = {name: i for i, name in enumerate(_layer_order())}
    upward = set()
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE)
        top = rel.parts[0].removesuffix(".py")
        if top == "__init__":
            continue
        own = _LAYER_OF.get(top, top)
        for module in _imports(path):
            layer = _layer(module)
            if layer is not None and rank[layer] > rank[own]:
                upward.add((rel.as_posix(), module))
    assert not upward, f"imports up the layers of docs/ARCHITECTURE.md: {sorted(upward)}"


def test_every_layer_takes_the_task_vocabulary_from_one_module() -> None:
    from ltl_human_motion import vocabulary
    from ltl_human_motion.ltl import TASK_SIGNATURES
    from ltl_human_motion.motion.goals import HAND_TASKS
    from ltl_human_motion.scene import TASK_ARGUMENTS
    assert TASK_SIGNATURES is TASK_ARGUMENTS is vocabulary.TASK_ARGUMENTS
    assert HAND_TASKS is vocabulary.HAND_TASKS


@pytest.mark.parametrize("module", ["ros/conversions.py", "planning/playback.py"])
def test_ros_layer_uses_core_types_without_probes(module: str) -> None:
    tree = ast.parse((PACKAGE / module).read_text())
    probes = [n.lineno for n in ast.walk(tree) if isinstance(n, ast.Call)
              and isinstance(n.func, ast.Name) and n.func.id in ("hasattr", "getattr")]
    assert probes == [], f"{module}: hasattr/getattr at lines {probes}"


#: Modules of ros/ that import nothing of ROS: the nodes' support (the HumanOccupancy wire
#: format, message definitions for the recorder, the arm's TF frames, the stream thread's
#: schedule). Plain Python the core could use belongs in the core; what launch files read
#: before a context, in ros/launch_support/.
_ROS_SUPPORT = {"__init__.py", "msgdefs.py", "occupancy_cdr.py", "ur_frames.py",
                "wall_schedule.py"}


def _imports_ros(path: Path) -> bool:
    """Whether a module imports ROS: rclpy, launch, a message package, our interfaces or
    another module of ros/."""
    roots = {"rclpy", "rcl_interfaces", "builtin_interfaces", "launch", "launch_ros",
             "tf2_ros"}
    ours = (f"{PACKAGE.name}.msg", f"{PACKAGE.name}.srv", f"{PACKAGE.name}.ros")
    return any(m.split(".")[0] in roots or m.split(".")[0].endswith("_msgs")
               or m in ours or m.startswith(tuple(f"{o}." for o in ours))
               for m in _imports(path))


def test_ros_keeps_nodes_conversions_and_their_support() -> None:
    plain = {p.name for p in (PACKAGE / "ros").glob("*.py") if not _imports_ros(p)}
    assert plain == _ROS_SUPPORT, (
        f"ros/ modules that import nothing of ROS: {sorted(plain - _ROS_SUPPORT)} new, "
        f"{sorted(_ROS_SUPPORT - plain)} gone (core code goes to the core, launch support to "
        "ros/launch_support/)")
    for path in sorted((PACKAGE / "ros" / "launch_support").glob("*.py")):
        rclpy = sorted(m for m in _imports(path) if m.split(".")[0] == "rclpy")
        assert not rclpy, f"{path.name} imports {rclpy}: launch support runs before a context"


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


def test_only_the_worker_state_moves_the_worker() -> None:
    """The worker's pose changes only through WorkerState (start_at, place, restore): the
    planner's parts place segments and pass poses as arguments, never writing ``pose``."""
    writers = []
    for path in sorted((PACKAGE / "planning").glob("*.py")):
        if path.name == "plan_state.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            targets = node.targets if isinstance(node, ast.Assign) else \
                [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
            names = [e for t in targets for e in (t.elts if isinstance(t, ast.Tuple) else [t])]
            writers += [f"{path.name}:{node.lineno}" for e in names
                        if isinstance(e, ast.Attribute) and e.attr == "pose"]
    assert not writers
