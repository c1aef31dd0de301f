"""The placo side of ``bench/ik_libraries.py``: one goal-motion program solved with placo's
whole-body kinematics solver, run in a separate interpreter that has placo installed
(placo bundles its own pinocchio build, so it never shares a process with the project's).

Imports only numpy, placo and the pinocchio and coal placo brings; reads a problem written
by ``bench/ik_libraries.py`` (an ``.npz``) and writes the tracked joint positions.

    <placo python> bench/ik_libraries_placo.py PROBLEM.npz OUT.npz

The program mirrors the project's (``motion/goals/optimizer.py``) with placo's own parts:
position tasks on the acting palms and wrists, a frame task on the pelvis, a centre-of-mass
task (x, y), joint tasks pulling towards the reference's angles (weights per anatomical
joint as the project's posture term, rising after the last hold), the toes fixed (hard
frame tasks), the clavicles and the neck's base on the reference's angles (hard joint
task), joint ranges and speeds (placo's joint and velocity limits), the verifier's joint
speed limits (placo's joint-space half-spaces, rebuilt every step from the joints'
Jacobians; they bound the revolute joints' share, placo leaves the floating base out of
them), and clearance by placo's collision constraint: coal distances between the worker
URDF's capsule geometry (cylinder and two spheres per capsule) and the obstacle boxes,
added to placo's collision model as fixed geometry, and the part in hand as a box on the
hand from the frame it is lifted. Weights are the project's squared (pink's costs multiply
the residual, placo's weights its square).
"""

from __future__ import annotations

import sys
import time

import numpy as np

#: The worker's root as six joints under placo's (masked) floating base: x, y, z, then
#: yaw, pitch, roll (R = Rz Ry Rx), so that placo's joint speed limits and joint-space
#: half-spaces, which leave the floating base out, bound the root's motion too.
ROOT_JOINTS = (("bench_x", "prismatic", "1 0 0"), ("bench_y", "prismatic", "0 1 0"),
               ("bench_z", "prismatic", "0 0 1"), ("bench_yaw", "revolute", "0 0 1"),
               ("bench_pitch", "revolute", "0 1 0"), ("bench_roll", "revolute", "1 0 0"))


def rooted_urdf(urdf: str, root_link: str) -> str:
    """``urdf`` with its root link ``root_link`` hung from :data:`ROOT_JOINTS`."""
    inertial = ('<inertial><mass value="0.001"/><inertia ixx="1e-6" ixy="0" ixz="0" '
                'iyy="1e-6" iyz="0" izz="1e-6"/></inertial>')
    parts, parent = ['<link name="bench_world">' + inertial + '</link>'], "bench_world"
    for k, (name, kind, axis) in enumerate(ROOT_JOINTS):
        child = root_link if k == len(ROOT_JOINTS) - 1 else f"{name}_link"
        if child != root_link:
            parts.append(f'<link name="{child}">{inertial}</link>')
        parts.append(f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
                     f'<child link="{child}"/><origin xyz="0 0 0" rpy="0 0 0"/>'
                     f'<axis xyz="{axis}"/><limit lower="-20" upper="20" effort="1" '
                     f'velocity="1"/></joint>')
        parent = child
    head, tail = urdf.split(">", 2)[0:2], urdf.split(">", 2)[2]
    return ">".join(head) + ">" + "\n".join(parts) + tail


def root_coordinates(q_root: np.ndarray) -> np.ndarray:
    """:data:`ROOT_JOINTS` coordinates (T, 6) of root poses (T, 7: xyz, quaternion xyzw),
    the angles unwrapped over time."""
    x, y, z, w = q_root[:, 3], q_root[:, 4], q_root[:, 5], q_root[:, 6]
    yaw = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    pitch = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    roll = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    return np.column_stack([q_root[:, :3], np.unwrap(yaw), np.unwrap(pitch), np.unwrap(roll)])


def _load(path: str) -> dict:
    with np.load(path, allow_pickle=False) as data:
        return {k: (data[k] if data[k].dtype.kind != "U" else
                    (str(data[k]) if data[k].ndim == 0 else list(map(str, data[k]))))
                for k in data.files}


class _Program:
    """placo's solver over the worker, its obstacles and its tasks for problem ``p``."""

    def __init__(self, p: dict) -> None:
        import coal
        import pinocchio as pin
        import placo
        self.p = p
        robot = placo.RobotWrapper("", placo.Flags.ignore_collisions,
                                   rooted_urdf(str(p["urdf"]), str(p["pelvis_link"])))
        self.robot = robot
        model, geom = robot.model, robot.collision_model
        body = list(range(geom.ngeoms))
        obstacles = []
        for i, b in enumerate(p["boxes"]):
            c, s = np.cos(b[6]), np.sin(b[6])
            rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            obstacles.append(geom.addGeometryObject(pin.GeometryObject(
                f"obs_{i}", 0, 0, pin.SE3(rot, np.asarray(b[:3], float)), coal.Box(*b[3:6]))))
        geom.removeAllCollisionPairs()
        for o in obstacles:
            for k in body:
                geom.addCollisionPair(pin.CollisionPair(k, o))
        self.obstacles = obstacles
        self.held = None
        if int(p["held_joint"]) >= 0:
            frame = model.frames[model.getFrameId(str(p["held_link"]))]
            self.held = (frame, geom)
        names = list(p["joint_names"])
        for n, lo, hi in zip(names, p["range_lo"], p["range_hi"], strict=True):
            robot.set_joint_limits(n, float(lo), float(hi))
            robot.set_velocity_limit(n, float(p["joint_speed"]))
        for n, _, _ in ROOT_JOINTS:
            robot.set_velocity_limit(n, float(p["root_speed"]))
        self.root = root_coordinates(p["q_root"])
        s = placo.KinematicsSolver(robot)
        s.mask_fbase(True)
        s.enable_joint_limits(True)
        s.enable_velocity_limits(True)
        s.dt = float(p["dt"])
        self.solver = s
        self.points = []
        for frame, w in zip(p["tracked_links"], p["tracked_weights"], strict=True):
            t = s.add_position_task(frame, np.zeros(3))
            t.configure(frame, "soft", float(w) ** 2)
            self.points.append(t)
        w = float(p["pelvis_weight"]) ** 2
        self.pelvis = s.add_frame_task(str(p["pelvis_link"]), np.eye(4))
        self.pelvis.configure("pelvis", "soft", w, w)
        self.com = s.add_com_task(np.zeros(3))
        self.com.mask.set_axises("xy")
        self.com.configure("com", "soft", float(p["com_weight"]) ** 2)
        self.feet = []
        for frame in p["feet_links"]:
            t = s.add_frame_task(frame, np.eye(4))
            t.configure(frame, "hard", 1.0, 1.0)
            self.feet.append(t)
        gains = np.asarray(p["posture_gains"])
        self.groups = [(s.add_joints_task(), np.flatnonzero(gains == g), float(g))
                       for g in np.unique(gains)]
        self.rigid = (s.add_joints_task(), np.asarray(p["rigid"], dtype=int))
        self.rigid[0].configure("rigid", "hard")
        self.collisions = s.add_avoid_self_collisions_constraint()
        self.collisions.self_collisions_margin = float(p["margin"])
        self.collisions.self_collisions_trigger = float(p["influence"])
        self.collisions.configure("collisions", "hard")
        nq = model.nq
        self.speed = s.add_joint_space_half_spaces_constraint(np.zeros((0, nq)), np.zeros(0))
        self.speed.configure("speed", "hard")
        s.add_regularization_task(float(p["damping"]))

    def carry(self) -> None:
        """From now on the part in hand is a box on the hand, kept clear of the obstacles,
        at its offset from the hand joint (start-frame axes) as the hand is turned now."""
        import coal
        import pinocchio as pin
        p, robot = self.p, self.robot
        frame, geom = self.held
        turn = robot.get_T_world_frame(str(p["held_link"]))[:3, :3].T
        local = pin.SE3(turn @ p["held_rot"], turn @ np.asarray(p["held_centre"], float))
        k = geom.addGeometryObject(pin.GeometryObject(
            "held", frame.parentJoint, frame.placement * local,
            coal.Box(*(2.0 * np.asarray(p["held_half"], float)))))
        for o in self.obstacles:
            geom.addCollisionPair(pin.CollisionPair(k, o))

    def set_frame(self, t: int, posture_base: float, ramp: float, feet: list[np.ndarray],
                  seconds: float) -> None:
        """Point every task at the reference's frame ``t``; the toes' poses ``feet``; the
        joints' speed rows for a step of ``seconds``."""
        p, robot = self.p, self.robot
        ref, names, qref = p["reference"][t], list(p["joint_names"]), p["q_angles"][t]
        for task, j in zip(self.points, p["tracked_index"], strict=True):
            task.target_world = ref[int(j)]
        pelvis = np.eye(4)
        pelvis[:3, :3], pelvis[:3, 3] = p["root_rot"][t], p["root_pos"][t]
        self.pelvis.T_world_frame = pelvis
        self.com.target_world = p["com"][t]
        for task, T in zip(self.feet, feet, strict=True):
            task.T_world_frame = T
        for task, idx, g in self.groups:
            task.set_joints({names[i]: float(qref[i]) for i in idx})
            w = posture_base * g
            w = w + ramp * (float(p["return_weight"]) - w)
            task.configure(f"posture_{g}", "soft", w ** 2)
        task, idx = self.rigid
        task.set_joints({names[i]: float(qref[i]) for i in idx})
        J = np.vstack([robot.frame_jacobian(f, "local_world_aligned")[:3]
                       for f in p["joint_links"]])                         # (3J, nv)
        A = np.zeros((len(J), robot.model.nq))
        A[:, 7:] = J[:, 6:]             # the six root joints and the revolute ones
        bound = np.repeat(np.asarray(p["speed_limits"]), 3) * seconds / np.sqrt(2.0)
        q = robot.state.q[7:]
        self.speed.A = np.vstack([A, -A])
        self.speed.b = np.concatenate([bound + A[:, 7:] @ q, bound - A[:, 7:] @ q])


def _set_q(robot, p: dict, root: np.ndarray, t: int) -> None:
    """The reference's configuration at frame ``t`` (root coordinates ``root`` (T, 6),
    joint angles)."""
    q = robot.state.q.copy()
    q[:7] = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    robot.state.q = q
    for (n, _, _), v in zip(ROOT_JOINTS, root[t], strict=True):
        robot.set_joint(n, float(v))
    for n, v in zip(p["joint_names"], p["q_angles"][t], strict=True):
        robot.set_joint(n, float(v))
    robot.update_kinematics()


def _positions(robot, p: dict) -> np.ndarray:
    return np.array([robot.get_T_world_frame(f)[:3, 3] for f in p["joint_links"]])


def track(p: dict) -> dict:
    """Run the program of problem ``p``: joint positions (T, J, 3), CPU and wall ms, the
    CPU ms of the model's setup, QP steps placo found no solution for."""
    import pinocchio as pin
    t0, w0 = time.process_time(), time.perf_counter()
    prog = _Program(p)
    robot = prog.robot
    setup = time.process_time() - t0
    ref = p["reference"]
    first, last_near, release = int(p["first"]), int(p["last_near"]), int(p["release"])
    fps, stride = float(p["fps"]), int(p["stride"])
    held_from = int(p["held_from"]) if prog.held is not None else len(ref)
    feet = {}
    for t in [*range(first, len(ref), stride), len(ref) - 1]:
        _set_q(robot, p, prog.root, t)
        feet[t] = [robot.get_T_world_frame(f) for f in p["feet_links"]]
    _set_q(robot, p, prog.root, first)
    out = ref.copy()
    failed, t, carrying = 0, first, False
    q_prev = robot.state.q.copy()
    while t < len(ref) - 1:
        step = min(stride, len(ref) - 1 - t)
        t += step
        if t >= held_from and not carrying:
            prog.carry()
            carrying = True
        prog.solver.dt = step / fps
        ramp = min(max((t - release) / (float(p["return_seconds"]) * fps), 0.0), 1.0)
        target = t if t in feet else max(k for k in feet if k <= t)
        prog.set_frame(t, float(p["posture_weight"]), ramp, feet[target], step / fps)
        try:
            prog.solver.solve(True)
        except Exception:          # placo raises where the hard rows have no solution
            failed += 1
            robot.state.q = q_prev.copy()
        robot.update_kinematics()
        q = robot.state.q.copy()
        for k in range(1, step):
            robot.state.q = pin.interpolate(robot.model, q_prev, q, k / step)
            robot.update_kinematics()
            out[t - step + k] = _positions(robot, p)
        robot.state.q = q
        robot.update_kinematics()
        out[t] = _positions(robot, p)
        q_prev = q
        if t > last_near and np.abs(out[t] - ref[t]).max() < 5e-4:
            out[t:] = ref[t:]
            break
    return {"positions": out, "setup_ms": 1e3 * setup, "ms": 1e3 * (time.process_time() - t0),
            "wall_ms": 1e3 * (time.perf_counter() - w0), "failed_steps": failed}


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    from pathlib import Path
    p = _load(argv[1])
    runs = [track(p) for _ in range(int(p["repeats"]))]
    tmp = Path(argv[2]).with_suffix(".part.npz")
    np.savez(tmp, positions=runs[-1]["positions"], ms=np.array([r["ms"] for r in runs]),
             setup_ms=np.array([r["setup_ms"] for r in runs]),
             wall_ms=np.array([r["wall_ms"] for r in runs]),
             failed_steps=np.array(runs[-1]["failed_steps"]), boxes=np.array(len(p["boxes"])))
    tmp.replace(argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
