"""Run the simulated UR controller, in the foreground or in its own process.

The real ``ur_rtde`` client blocks while holding the GIL in its constructors, so a server in
the same Python process deadlocks with it: :func:`start_ur_sim_process` therefore starts
the controller in a separate (spawned) process and talks to it through a pipe.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing as mp
import signal
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ltl_human_motion.robot.kinematics import pose_from_xyz_rpy, ur_model
from ltl_human_motion.robot.sim.server import ControllerServer
from ltl_human_motion.robot.sim.state import SimulatedUR
from ltl_human_motion.robot.sim.trajectory import load_robot_config

__all__ = ["URSimConfig", "URSimHandle", "build_controller", "run_ur_sim",
           "start_ur_sim_process"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class URSimConfig:
    """Settings of one simulated controller.

    Attributes
    ----------
    model : str
        ``ur3e``, ``ur5e``, ``ur10e`` or ``ur16e``; overrides the trajectory file's model
        when not None.
    trajectory : str or None
        Robot/trajectory YAML (``config/ur_pick_place.yaml``); None = built-in cycle.
    host : str
        Bind address (loopback by default).
    rtde_port, dashboard_port : int
        30004 and 29999 like the real controller (``ur_rtde`` always uses 30004);
        ``dashboard_port=-1`` disables the dashboard server.
    rate : float
        Controller rate (Hz).
    initial_speed_slider : float
    """

    model: str | None = None
    trajectory: str | None = None
    host: str = "127.0.0.1"
    rtde_port: int = 30004
    dashboard_port: int = 29999
    rate: float = 500.0
    initial_speed_slider: float = 1.0


def build_controller(config: URSimConfig) -> ControllerServer:
    """Create (and bind) the simulated controller described by ``config``."""
    cfg: dict[str, Any] = load_robot_config(config.trajectory)
    model = ur_model(config.model or cfg["model"])
    if cfg["tool_length"] is not None:
        model = model.with_tool(cfg["tool_length"], cfg["tool_radius"])
    sim = SimulatedUR(model, cfg["trajectory"],
                      base=pose_from_xyz_rpy(cfg["base_xyz"], cfg["base_rpy"]))
    if not sim.set_speed_slider(config.initial_speed_slider):
        raise ValueError(f"initial speed slider must be finite, got {config.initial_speed_slider}")
    dash = None if config.dashboard_port < 0 else config.dashboard_port
    return ControllerServer(sim, config.host, config.rtde_port, dash, config.rate)


def run_ur_sim(config: URSimConfig,
               on_ready: Callable[[ControllerServer], None] | None = None) -> int:
    """Serve in the foreground until Ctrl-C or SIGTERM; returns an exit code.

    ``on_ready(server)`` is called once the ports listen (e.g. to print them).
    """
    server = build_controller(config)
    log.info("simulated %s: RTDE on %s:%d, dashboard on %s", server.sim.model.name, config.host,
             server.rtde_port, server.dashboard_port)
    if on_ready is not None:
        on_ready(server)
    previous = signal.signal(signal.SIGTERM, lambda *_: server.stop())
    try:
        server.serve_forever()
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
        server.close()
    return 0


def _child_main(config: URSimConfig, conn: Any) -> None:
    """Entry of the controller process: bind, report readiness, serve pipe commands."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent decides when we stop
    try:
        server = build_controller(config)
    except Exception as exc:  # report any start-up failure to the parent
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
        conn.close()
        return
    signal.signal(signal.SIGTERM, lambda *_: server.stop())

    def on_command() -> None:
        try:
            request = conn.recv()
        except (EOFError, OSError):
            server.stop()  # the parent is gone
            return
        op, arg = request
        sim = server.sim
        if op == "stop":
            server.stop()
            reply: Any = True
        elif op == "status":
            reply = sim.status()
        elif op == "protective_stop":
            sim.protective_stop(str(arg or "requested"))
            reply = True
        elif op == "unlock":
            reply = sim.unlock_protective_stop()
        elif op == "slider":
            reply = sim.set_speed_slider(float(arg))
        elif op == "dashboard":
            reply = server.dashboard_command(str(arg))
        else:
            reply = f"unknown request {op!r}"
        with contextlib.suppress(OSError):
            conn.send(reply)

    server.add_reader(conn, on_command)
    conn.send(("ready", {"rtde_port": server.rtde_port,
                         "dashboard_port": server.dashboard_port}))
    try:
        server.serve_forever()
    finally:
        server.close()


class URSimHandle:
    """A simulated controller running in its own process.

    Attributes
    ----------
    host : str
    rtde_port : int
    dashboard_port : int or None
    process : multiprocessing.Process
    """

    def __init__(self, process: Any, conn: Any, host: str, ports: dict[str, Any]) -> None:
        self.process = process
        self._conn = conn
        self.host = host
        self.rtde_port = int(ports["rtde_port"])
        self.dashboard_port = ports["dashboard_port"]

    @property
    def pid(self) -> int:
        """Process id of the controller."""
        return int(self.process.pid)

    def is_alive(self) -> bool:
        """True while the controller process runs."""
        return bool(self.process.is_alive())

    def _request(self, op: str, arg: Any = None, timeout: float = 5.0) -> Any:
        if not self.is_alive():
            raise RuntimeError("the simulated controller process is not running")
        self._conn.send((op, arg))
        if not self._conn.poll(timeout):
            raise TimeoutError(f"simulated controller did not answer {op!r} in {timeout} s")
        return self._conn.recv()

    def status(self) -> dict[str, Any]:
        """State snapshot (q, speed slider, safety mode, cycle times, ...)."""
        return dict(self._request("status"))

    def protective_stop(self, reason: str = "requested") -> None:
        """Trigger a protective stop (as a collision would on a real arm)."""
        self._request("protective_stop", reason)

    def unlock_protective_stop(self) -> bool:
        """Release a protective stop; False if there was none."""
        return bool(self._request("unlock"))

    def dashboard(self, command: str) -> str | None:
        """Answer of the dashboard server to ``command`` (without a TCP connection)."""
        return self._request("dashboard", command)

    def stop(self, timeout: float = 5.0) -> None:
        """Stop the controller gracefully (kill it if it does not exit in ``timeout``)."""
        if self.is_alive():
            with contextlib.suppress(OSError, EOFError, TimeoutError, RuntimeError):
                self._request("stop", timeout=timeout)
            self.process.join(timeout)
        if self.is_alive():
            self.kill()
        self._conn.close()

    def kill(self) -> None:
        """SIGKILL the controller, as a crash or power loss would (sockets reset)."""
        if self.is_alive():
            self.process.kill()
        self.process.join(5.0)

    def __enter__(self) -> URSimHandle:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def start_ur_sim_process(model: str | None = None, trajectory: str | Path | None = None,
                         host: str = "127.0.0.1", rtde_port: int = 30004,
                         dashboard_port: int = 29999, rate: float = 500.0,
                         initial_speed_slider: float = 1.0,
                         ready_timeout: float = 20.0) -> URSimHandle:
    """Start a simulated controller in a new process; return when its ports listen.

    Parameters
    ----------
    model, trajectory, host, rtde_port, dashboard_port, rate, initial_speed_slider
        See :class:`URSimConfig`.
    ready_timeout : float
        Seconds to wait for the process to bind its ports.

    Returns
    -------
    URSimHandle
        Call ``.stop()`` (or use it as a context manager) when done.

    Raises
    ------
    OSError
        If a port cannot be bound (e.g. another controller already listens on it).
    """
    config = URSimConfig(model, None if trajectory is None else str(trajectory), host,
                         rtde_port, dashboard_port, rate, initial_speed_slider)
    ctx = mp.get_context("spawn")
    parent, child = ctx.Pipe()
    process = ctx.Process(target=_child_main, args=(config, child), daemon=True,
                          name=f"ur-sim-{rtde_port}")
    process.start()
    child.close()
    deadline = time.monotonic() + ready_timeout
    while not parent.poll(0.05):
        if not process.is_alive() or time.monotonic() > deadline:
            process.kill()
            process.join(2.0)
            raise RuntimeError("the simulated controller process did not start")
    status, info = parent.recv()
    if status != "ready":
        process.join(5.0)
        parent.close()
        raise OSError(f"simulated controller failed to start on {host}: {info}")
    return URSimHandle(process, parent, host, info)
