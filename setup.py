"""pip / setuptools entry for plain-Python use of ltl_human_motion.

ROS users build the package with colcon (package.xml + CMakeLists.txt), which also
generates the msg/srv interfaces. ``pip install .`` installs the core, the CLI and the
node entry points; the ROS nodes additionally need rclpy and the generated interfaces.
"""

from setuptools import find_packages, setup

package_name = "ltl_human_motion"

setup(
    name=package_name,
    version="0.1.0",
    description="Verified human motion synthesis from LTL task specifications (ROS 2)",
    license="BSD-3-Clause",
    python_requires=">=3.10",
    packages=find_packages(include=[package_name, f"{package_name}.*"]),
    package_data={f"{package_name}.ros": ["fastdds_profiles.xml"]},
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{package_name}"]),
        (f"share/{package_name}", ["package.xml"]),
    ],
    install_requires=["numpy>=1.24", "scipy>=1.10", "PyYAML>=6", "trimesh>=4",
                      "pin>=3.0", "pin-pink>=3.4", "qpsolvers[daqp]>=4.0"],
    extras_require={
        "collision": ["python-fcl>=0.7"],
        "fast": ["numba>=0.60"],
        "viz": ["matplotlib>=3.7", "imageio>=2.30", "pillow>=10"],
        "data": ["pybullet>=3.2"],
        "robot": ["ur-rtde>=1.5"],
        "batch": ["dask[distributed]>=2024.1", "tqdm>=4.60"],
        "record": ["mcap>=1.1", "mcap-ros2-support>=0.5"],
    },
    entry_points={
        "console_scripts": [
            "ltl-human-motion = ltl_human_motion.cli:run",
            "synthesis_node = ltl_human_motion.ros.entry_points:synthesis_node",
            "skeleton_publisher = ltl_human_motion.ros.entry_points:skeleton_publisher",
            "occupancy_node = ltl_human_motion.ros.entry_points:occupancy_node",
            "ergonomics_node = ltl_human_motion.ros.entry_points:ergonomics_node",
            "coexistence_node = ltl_human_motion.ros.entry_points:coexistence_node",
            "reactive_player = ltl_human_motion.ros.entry_points:reactive_player",
        ],
    },
)
