"""The simulated UR controller against the REAL ur_rtde client (pip ur-rtde), on loopback.

ur_rtde always connects to TCP 30004, so these tests run one controller process at a time
on 127.0.0.1:30004; they wait until no other simulator holds the port (test/robot_sim.py).
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import struct
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from ltl_human_motion.robot import URSimHandle, start_ur_sim_process, tcp_pose
from ltl_human_motion.robot.sim import rtde_protocol as rp

rtde_receive = pytest.importorskip("rtde_receive")
rtde_io = pytest.importorskip("rtde_io")
dashboard_client = pytest.importorskip("dashboard_client")

REPO = Path(__file__).resolve().parents[1]
HOST = "127.0.0.1"


def wait_for(predicate, timeout: float = 3.0, period: float = 0.01) -> bool:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(period)
    return bool(predicate())


@pytest.fixture
def io(sim: URSimHandle) -> Iterator[object]:
    # Disconnected while the controller still runs: ur_rtde 1.6.5 aborts the process when
    # an RTDEIOInterface with a broken connection is destroyed.
    client = rtde_io.RTDEIOInterface(HOST)
    yield client
    client.setSpeedSlider(1.0)
    client.disconnect()


class RawClient:
    """A bare RTDE client on a socket, for malformed and out-of-order packets."""

    def __init__(self, port: int = 30004) -> None:
        self.sock = socket.create_connection((HOST, port), timeout=2.0)
        self.reader = rp.PacketReader(max_size=65535)
        self.pending: list[rp.Packet] = []

    def send(self, kind: int, payload: bytes = b"") -> None:
        self.sock.sendall(rp.encode_packet(kind, payload))

    def recv(self, kind: int | None = None, timeout: float = 2.0) -> rp.Packet:
        deadline = time.monotonic() + timeout
        while True:
            for i, p in enumerate(self.pending):
                if kind is None or p.kind == kind:
                    return self.pending.pop(i)
            self.sock.settimeout(max(0.01, deadline - time.monotonic()))
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("closed by the controller")
            self.pending.extend(self.reader.feed(data))

    def close(self) -> None:
        self.sock.close()


def test_receive_interface_reads_the_state(sim: URSimHandle, receive: object) -> None:
    assert receive.isConnected()
    assert wait_for(lambda: receive.getTimestamp() > 0)
    q = np.array(receive.getActualQ())
    pose = np.array(receive.getActualTCPPose())
    assert q.shape == (6,) and pose.shape == (6,)
    assert pose == pytest.approx(tcp_pose(q, "ur5e"), abs=1e-9)
    assert receive.getRobotMode() == 7
    assert receive.getSafetyMode() == 1
    assert receive.getSpeedScaling() == pytest.approx(1.0)
    # The arm moves: the trajectory runs.
    time.sleep(0.2)
    assert not np.allclose(receive.getActualQ(), q)
    status = sim.status()
    assert status["model"] == "ur5e" and status["nominal_cycle_time"] == pytest.approx(6.2)


def test_speed_slider_changes_speed_scaling(sim: URSimHandle, receive: object,
                                            io: object) -> None:
    assert io.setSpeedSlider(0.3)
    assert wait_for(lambda: abs(receive.getSpeedScaling() - 0.3) < 1e-9)
    assert receive.getTargetSpeedFraction() == pytest.approx(0.3)
    assert sim.status()["speed_slider"] == pytest.approx(0.3)
    # The trajectory time advances at 30 % of wall time.
    t0 = receive.getOutputDoubleRegister(13)
    w0 = receive.getTimestamp()
    time.sleep(0.5)
    rate = (receive.getOutputDoubleRegister(13) - t0) / (receive.getTimestamp() - w0)
    assert rate == pytest.approx(0.3, abs=0.02)
    assert io.setSpeedSlider(1.0)
    assert wait_for(lambda: receive.getSpeedScaling() == pytest.approx(1.0))


def test_protective_stop_halts_and_dashboard_unlocks(sim: URSimHandle,
                                                     receive: object) -> None:
    sim.protective_stop("test")
    assert wait_for(lambda: receive.getSafetyMode() == 3)
    assert receive.isProtectiveStopped()
    assert receive.getSpeedScaling() == 0.0
    q = receive.getActualQ()
    time.sleep(0.2)
    assert receive.getActualQ() == pytest.approx(q, abs=1e-12)
    dash = dashboard_client.DashboardClient(HOST)
    dash.connect()
    try:
        assert "PROTECTIVE_STOP" in dash.safetystatus()
        dash.unlockProtectiveStop()
    finally:
        dash.disconnect()
    assert wait_for(lambda: receive.getSafetyMode() == 1)
    time.sleep(0.1)
    assert receive.getActualQ() != pytest.approx(q, abs=1e-6)


def test_malformed_and_out_of_order_packets(sim: URSimHandle, receive: object) -> None:
    raw = RawClient()
    try:
        # START before any setup: refused, connection kept.
        raw.send(rp.RTDE_CONTROL_PACKAGE_START)
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_START).payload == b"\x00"
        # Protocol version with a wrong payload size: refused with a text message.
        raw.send(rp.RTDE_REQUEST_PROTOCOL_VERSION, b"\x02")
        assert raw.recv(rp.RTDE_REQUEST_PROTOCOL_VERSION).payload == b"\x00"
        assert raw.recv(rp.RTDE_TEXT_MESSAGE)
        raw.send(rp.RTDE_REQUEST_PROTOCOL_VERSION, struct.pack(">H", 2))
        assert raw.recv(rp.RTDE_REQUEST_PROTOCOL_VERSION).payload == b"\x01"
        # Unknown command byte and a data package for an unknown recipe: text messages.
        raw.send(ord("Z"), b"junk")
        assert b"unknown" in raw.recv(rp.RTDE_TEXT_MESSAGE).payload
        raw.send(rp.RTDE_DATA_PACKAGE, b"\x09\x00\x00")
        assert b"recipe" in raw.recv(rp.RTDE_TEXT_MESSAGE).payload
        raw.send(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS, b"\x00\x01")   # no frequency
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS).payload == b"\x00"
        assert raw.recv(rp.RTDE_TEXT_MESSAGE)
        raw.send(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS, b"\xff\xfe,speed_slider_mask")
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS).payload.startswith(
            b"\x00NOT_FOUND,")
        # Unknown variables are NOT_FOUND, like the real controller, and get recipe id 0.
        raw.send(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS,
                 struct.pack(">d", 125.0) + b"actual_q,no_such_variable")
        reply = raw.recv(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS).payload
        assert reply == b"\x00VECTOR6D,NOT_FOUND"
        # A valid recipe streams; an input data package of the wrong size is refused.
        raw.send(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS,
                 struct.pack(">d", 125.0) + b"timestamp,speed_scaling")
        reply = raw.recv(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS).payload
        assert reply[1:] == b"DOUBLE,DOUBLE"
        raw.send(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS, b"input_double_register_30")
        in_id = raw.recv(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS).payload[0]
        assert in_id >= 1
        raw.send(rp.RTDE_DATA_PACKAGE, bytes([in_id]) + b"\x00")
        assert b"bytes" in raw.recv(rp.RTDE_TEXT_MESSAGE).payload
        raw.send(rp.RTDE_CONTROL_PACKAGE_START)
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_START).payload == b"\x01"
        data = raw.recv(rp.RTDE_DATA_PACKAGE).payload
        assert len(data) == 1 + 16 and data[0] == reply[0]
        # PAUSE stops the stream; START resumes it.
        raw.send(rp.RTDE_CONTROL_PACKAGE_PAUSE)
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_PAUSE).payload == b"\x01"
        raw.pending.clear()
        time.sleep(0.05)
        raw.pending.clear()
        with pytest.raises(TimeoutError):
            raw.recv(rp.RTDE_DATA_PACKAGE, timeout=0.1)
        raw.send(rp.RTDE_CONTROL_PACKAGE_START)
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_START).payload == b"\x01"
        assert raw.recv(rp.RTDE_DATA_PACKAGE).payload[0] == reply[0]
    finally:
        raw.close()
    # A broken header (size < 3) cannot be resynchronised: that client is dropped...
    bad = RawClient()
    bad.sock.sendall(b"\x00\x01V")
    with pytest.raises((ConnectionError, OSError)):
        while True:
            bad.recv()
    bad.close()
    # ... and random garbage from another one changes nothing for the real client.
    junk = socket.create_connection((HOST, 30004), timeout=2.0)
    junk.sendall(np.random.default_rng(3).bytes(5000))
    junk.close()
    stamp = receive.getTimestamp()
    assert wait_for(lambda: receive.getTimestamp() > stamp)
    assert receive.isConnected() and sim.is_alive()


def test_speed_slider_at_zero_then_changed_is_a_protective_stop(sim: URSimHandle,
                                                                 receive: object,
                                                                 io: object) -> None:
    # Why SSM never commands 0: the next slider change after 0 stops the arm.
    assert io.setSpeedSlider(0.0)
    assert wait_for(lambda: receive.getTargetSpeedFraction() == 0.0)
    assert receive.getSafetyMode() == 1
    assert io.setSpeedSlider(0.5)
    assert wait_for(lambda: receive.getSafetyMode() == 3)
    assert sim.unlock_protective_stop()
    assert wait_for(lambda: receive.getSafetyMode() == 1)


def test_second_writer_of_an_input_is_in_use(sim: URSimHandle, io: object) -> None:
    raw = RawClient()
    try:
        raw.send(rp.RTDE_REQUEST_PROTOCOL_VERSION, struct.pack(">H", 2))
        raw.recv(rp.RTDE_REQUEST_PROTOCOL_VERSION)
        raw.send(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS, b"speed_slider_mask,speed_slider_fraction")
        assert raw.recv(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS).payload == b"\x00IN_USE,IN_USE"
    finally:
        raw.close()


def test_second_controller_on_a_busy_port_fails_clearly(sim: URSimHandle) -> None:
    with pytest.raises(OSError, match="failed to start"):
        start_ur_sim_process(host=HOST, dashboard_port=-1)
    assert sim.is_alive()


def test_dashboard_sim_status_over_tcp(sim: URSimHandle) -> None:
    with socket.create_connection((HOST, 29999), timeout=2.0) as s:
        f = s.makefile("rwb")
        assert f.readline().startswith(b"Connected: Universal Robots Dashboard Server")
        f.write(b"robotmode\nsim status\nnonsense\n")
        f.flush()
        assert f.readline().strip() == b"Robotmode: RUNNING"
        status = json.loads(f.readline())
        assert status["safety_mode"] == 1
        assert f.readline().startswith(b"could not understand")


def test_cli_runs_the_controller_until_interrupted(tmp_path: Path) -> None:
    with socket.socket() as probe:
        probe.bind((HOST, 0))
        port = probe.getsockname()[1]
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    log = (tmp_path / "ur-sim.log").open("wb")     # a file: a full pipe would block exit
    proc = subprocess.Popen([sys.executable, "-m", "ltl_human_motion", "ur-sim", "--model",
                             "ur10e", "--trajectory", str(REPO / "config" / "ur_pick_place.yaml"),
                             "--rtde-port", str(port), "--dashboard-port", "-1"],
                            env=env, stdout=log, stderr=subprocess.STDOUT)
    try:
        raw = None
        for _ in range(200):
            with contextlib.suppress(OSError):
                raw = RawClient(port)
                break
            time.sleep(0.05)
        assert raw is not None, (tmp_path / "ur-sim.log").read_text(errors="replace")
        raw.send(rp.RTDE_REQUEST_PROTOCOL_VERSION, struct.pack(">H", 2))
        assert raw.recv(rp.RTDE_REQUEST_PROTOCOL_VERSION).payload == b"\x01"
        raw.send(rp.RTDE_GET_URCONTROL_VERSION)
        assert struct.unpack(">IIII", raw.recv(rp.RTDE_GET_URCONTROL_VERSION).payload)[0] == 5
        raw.close()
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0, (tmp_path / "ur-sim.log").read_text(errors="replace")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        log.close()
