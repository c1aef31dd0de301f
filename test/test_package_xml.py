"""package.xml declares what the package imports (issue 38 item 3), with rosdep keys.

Every third-party module imported anywhere under ``ltl_human_motion/`` maps to a rosdep
key (:data:`MODULE_KEYS`) that package.xml declares as ``depend``/``exec_depend``, and
every declared runtime key is imported (or is one of :data:`NOT_IMPORTED`). Keys that
rosdistro's database lacks are defined in the package's ``rosdep.yaml`` as the pip
package that requirements.txt pins.
"""

from __future__ import annotations

import ast
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "ltl_human_motion"

#: Imported top-level module -> its rosdep key (ROS packages by their own name).
MODULE_KEYS: dict[str, str] = {
    "rclpy": "rclpy", "rcl_interfaces": "rcl_interfaces",
    "builtin_interfaces": "builtin_interfaces", "std_msgs": "std_msgs",
    "geometry_msgs": "geometry_msgs", "sensor_msgs": "sensor_msgs",
    "visualization_msgs": "visualization_msgs", "tf2_msgs": "tf2_msgs",
    "hri_msgs": "hri_msgs", "diagnostic_msgs": "diagnostic_msgs",
    "lifecycle_msgs": "lifecycle_msgs",
    "ament_index_python": "ament_index_python", "launch": "launch",
    "launch_ros": "launch_ros", "pinocchio": "pinocchio",
    "numpy": "python3-numpy", "scipy": "python3-scipy", "yaml": "python3-yaml",
    "matplotlib": "python3-matplotlib", "mpl_toolkits": "python3-matplotlib",
    "networkx": "python3-networkx", "numba": "python3-numba", "PIL": "python3-pil",
    "tqdm": "python3-tqdm",
    # rosdistro's pip keys
    "trimesh": "python3-trimesh-pip", "fcl": "python-fcl-pip",
    "pybullet_data": "python3-pybullet-pip", "qpsolvers": "python3-qpsolvers-pip",
    # this package's rosdep.yaml
    "pink": "python3-pin-pink-pip", "mcap": "python3-mcap-pip",
    "rtde_io": "python3-ur-rtde-pip", "rtde_receive": "python3-ur-rtde-pip",
    "rtde_control": "python3-ur-rtde-pip", "distributed": "python3-distributed-pip",
    "omega": "python3-omega-pip",
}
#: Imported modules deliberately not declared, with the reason.
UNDECLARED: dict[str, str] = {
    "spot": "Spot's bindings are not on PyPI nor in rosdep; the Spot LTL backend is "
            "optional (MissingDependencyError names how to install it)",
}
#: Declared runtime keys that no module imports, with the reason.
NOT_IMPORTED: dict[str, str] = {
    "rosidl_default_runtime": "the generated msg/srv modules need it",
    "ros2launch": "'ros2 launch' of launch/*.launch.py",
    "python3-daqp-pip": "qpsolvers loads the daqp solver by name",
}
#: rosdistro's rosdep keys used here (rosdep/python.yaml, checked 2026-08).
UPSTREAM_KEYS = {"python3-numpy", "python3-scipy", "python3-yaml", "python3-matplotlib",
                 "python3-networkx", "python3-numba", "python3-pil", "python3-tqdm",
                 "python3-trimesh-pip", "python-fcl-pip", "python3-pybullet-pip",
                 "python3-qpsolvers-pip", "python3-pytest", "mcap-ros2-support"}


def imported_modules() -> dict[str, set[str]]:
    """Top-level third-party modules imported by the package -> files importing them."""
    out: dict[str, set[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 \
                and node.module else []
            for name in names:
                top = name.split(".")[0]
                if top not in sys.stdlib_module_names and top != "ltl_human_motion":
                    out.setdefault(top, set()).add(str(path.relative_to(ROOT)))
    return out


def declared(*tags: str) -> set[str]:
    root = ET.parse(ROOT / "package.xml").getroot()
    return {e.text.strip() for tag in tags for e in root.iter(tag)}


def test_every_import_is_declared_with_its_rosdep_key() -> None:
    modules = imported_modules()
    unmapped = {m: sorted(f) for m, f in modules.items()
                if m not in MODULE_KEYS and m not in UNDECLARED}
    assert not unmapped, f"imports without a rosdep key in this test: {unmapped}"
    runtime = declared("depend", "exec_depend")
    missing = {MODULE_KEYS[m]: sorted(f) for m, f in modules.items()
               if m in MODULE_KEYS and MODULE_KEYS[m] not in runtime}
    assert not missing, f"package.xml lacks: {missing}"


def test_every_declared_key_is_used() -> None:
    used = {MODULE_KEYS[m] for m in imported_modules() if m in MODULE_KEYS}
    unused = declared("depend", "exec_depend") - used - set(NOT_IMPORTED)
    assert not unused, f"package.xml declares keys nothing imports: {sorted(unused)}"


def test_keys_rosdep_lacks_are_defined_and_pinned() -> None:
    """Every non-ROS key is rosdistro's or this package's rosdep.yaml's, and each pip
    package rosdep.yaml installs is pinned in requirements.txt."""
    local = yaml.safe_load((ROOT / "rosdep.yaml").read_text())
    ros_packages = {k for k in MODULE_KEYS.values() if not k.startswith("python")} \
        | {"rosidl_default_runtime", "ros2launch", "ament_cmake", "ament_cmake_python",
           "rosidl_default_generators"}
    keys = declared("depend", "exec_depend", "test_depend", "buildtool_depend")
    unknown = keys - ros_packages - UPSTREAM_KEYS - set(local)
    assert not unknown, f"keys neither rosdistro's nor in rosdep.yaml: {sorted(unknown)}"
    assert set(local) <= keys, "rosdep.yaml defines keys package.xml does not use"
    pinned = {line.split("==")[0].strip().lower().replace("_", "-")
              for line in (ROOT / "requirements.txt").read_text().splitlines()
              if "==" in line and not line.startswith("#")}
    for key, platforms in local.items():
        for platform, rule in platforms.items():
            for package in rule["pip"]["packages"]:
                assert package.lower().replace("_", "-") in pinned, (key, platform, package)
