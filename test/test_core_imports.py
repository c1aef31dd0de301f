"""The core imports and runs in a plain interpreter with no ROS on its path."""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CORE_MODULES = [
    "ltl_human_motion.ltl", "ltl_human_motion.motion", "ltl_human_motion.scene",
    "ltl_human_motion.planning", "ltl_human_motion.viz", "ltl_human_motion.robot",
    "ltl_human_motion.batch", "ltl_human_motion.reproduce", "ltl_human_motion.cli",
    "ltl_human_motion.assess", "ltl_human_motion.study",
]

PROBE = r"""
import importlib, sys
sys.path[:0] = [{root!r}]
sys.path.append({site!r})
ROS = ("rclpy", "rcl", "rmw", "rosidl", "std_msgs", "geometry_msgs", "sensor_msgs",
       "visualization_msgs", "builtin_interfaces", "tf2_msgs", "rosgraph_msgs",
       "ros_wheels_bootstrapper", "mcap_ros2")

class NoRos:
    def find_spec(self, name, path=None, target=None):
        top = name.split(".")[0]
        if top.startswith(ROS) or name in ("ltl_human_motion.msg", "ltl_human_motion.srv",
                                            "ltl_human_motion.ros"):
            raise ImportError(f"ROS is not available here: {{name}}")
        return None

sys.meta_path.insert(0, NoRos())
for mod in {modules!r}:
    importlib.import_module(mod)
from ltl_human_motion.planning import synthesize
m = synthesize("S1", "paper_cell", seed=2)[0]
assert m.verification["passed"], m.verification
from ltl_human_motion.cli import build_parser
assert "synthesize" in build_parser().format_help()
loaded = [k for k in sys.modules if k.split(".")[0].startswith(ROS)]
assert not loaded, loaded
print("core ok without ROS:", " ; ".join(m.sequence))
"""


def test_core_imports_and_synthesizes_without_ros(tmp_path: Path) -> None:
    site = sysconfig.get_paths()["purelib"]
    code = PROBE.format(root=str(ROOT), site=site, modules=CORE_MODULES)
    env = {k: v for k, v in os.environ.items()
           if not k.startswith(("AMENT", "ROS", "RMW", "COLCON", "_ROS"))
           and k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "CMAKE_PREFIX_PATH")}
    # -S: no site-packages processing, so no .pth hook re-executes the interpreter for ROS.
    proc = subprocess.run([sys.executable, "-S", "-c", code], env=env, cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "core ok without ROS" in proc.stdout
