"""RTDE (TCP 30004) and dashboard (TCP 29999) servers of the simulated UR controller.

One thread, one ``selectors`` loop: it accepts clients, parses their packets, ticks the
:class:`~ltl_human_motion.robot.sim.state.SimulatedUR` at the controller rate and streams
data packages at each output recipe's frequency. Sockets are non-blocking; a client that
stops reading loses data packages (never blocks the loop). A client sending garbage is
answered with an RTDE text message, or disconnected when its stream cannot be resynchronised;
the controller keeps running either way.

Simulator extras on the output registers (readable with ``getOutputIntRegister`` /
``getOutputDoubleRegister`` of ur_rtde): ``output_int_register_12`` = completed cycles,
``output_double_register_12`` = last cycle time (s), ``output_double_register_13`` =
trajectory time (s), ``output_double_register_14`` = nominal cycle time (s).
"""

from __future__ import annotations

import contextlib
import json
import logging
import selectors
import socket
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from ltl_human_motion.robot.sim import rtde_protocol as rp
from ltl_human_motion.robot.sim.state import (
    RUNTIME_PLAYING,
    SAFETY_NORMAL,
    SAFETY_PROTECTIVE_STOP,
    SimulatedUR,
)

__all__ = ["ControllerServer", "listen_socket"]

log = logging.getLogger(__name__)

_MAX_BACKLOG = 64 * 1024      # skip data packages beyond this unsent backlog
_MAX_UNREAD = 1024 * 1024     # drop a client that leaves this much unread
_SAFETY_NAMES = {1: "NORMAL", 2: "REDUCED", 3: "PROTECTIVE_STOP", 4: "RECOVERY",
                 5: "SAFEGUARD_STOP", 6: "SYSTEM_EMERGENCY_STOP", 7: "ROBOT_EMERGENCY_STOP",
                 8: "VIOLATION", 9: "FAULT"}
_ROBOT_MODE_NAMES = {3: "POWER_OFF", 5: "IDLE", 7: "RUNNING"}
_STATIC_OUTPUTS: dict[str, object] = {
    "joint_temperatures": (32.0,) * 6, "actual_main_voltage": 48.0,
    "actual_robot_voltage": 48.0, "actual_robot_current": 0.6,
    "actual_joint_voltage": (47.5,) * 6, "actual_execution_time": 0.3,
    "payload": 1.0, "payload_cog": (0.0, 0.0, 0.05), "actual_tool_accelerometer": (0.0, 0.0, 9.81),
    "tool_temperature": 30.0, "tool_output_voltage": 24, "tool_mode": 255,
}


def listen_socket(host: str, port: int) -> socket.socket:
    """A non-blocking listening TCP socket with SO_REUSEADDR."""
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError:
        sock.close()
        raise
    sock.listen(8)
    sock.setblocking(False)
    return sock


@dataclass
class _Client:
    sock: socket.socket
    kind: str  # "rtde" or "dashboard"
    cid: int
    out: bytearray = field(default_factory=bytearray)
    reader: rp.PacketReader = field(default_factory=rp.PacketReader)
    line_buf: bytearray = field(default_factory=bytearray)
    protocol: int = 1
    outputs: dict[int, tuple[rp.Recipe, float]] = field(default_factory=dict)  # id->(r, period)
    next_send: dict[int, float] = field(default_factory=dict)
    inputs: dict[int, rp.Recipe] = field(default_factory=dict)
    started: bool = False
    next_output_id: int = 1
    next_input_id: int = 1


class ControllerServer:
    """The controller's network side around a :class:`SimulatedUR`.

    Parameters
    ----------
    sim : SimulatedUR
    host : str
        Address to bind (default loopback).
    rtde_port, dashboard_port : int
        0 picks a free port; ``dashboard_port=None`` disables the dashboard server.
    rate : float
        Controller rate (Hz): simulation steps and the highest output frequency.
    controller_version : tuple of 4 int
        What ``RTDE_GET_URCONTROL_VERSION`` answers.
    """

    def __init__(self, sim: SimulatedUR, host: str = "127.0.0.1", rtde_port: int = 30004,
                 dashboard_port: int | None = 29999, rate: float = 500.0,
                 controller_version: tuple[int, int, int, int] = (5, 11, 0, 0)) -> None:
        if not 1.0 <= rate <= 2000.0:
            raise ValueError(f"controller rate must be in [1, 2000] Hz, got {rate}")
        self.sim = sim
        self.rate = float(rate)
        self.controller_version = controller_version
        self._clients: dict[int, _Client] = {}
        self._input_owner: dict[str, int] = {}
        self._next_cid = 1
        self._stop = False
        self._extra: list[tuple[object, Callable[[], None]]] = []
        self._sel = selectors.DefaultSelector()
        self._rtde = listen_socket(host, rtde_port)
        self._listeners = [self._rtde]
        self._sel.register(self._rtde, selectors.EVENT_READ, ("accept", "rtde"))
        self._dash: socket.socket | None = None
        if dashboard_port is not None:
            try:
                self._dash = listen_socket(host, dashboard_port)
            except OSError:
                self.close()
                raise
            self._listeners.append(self._dash)
            self._sel.register(self._dash, selectors.EVENT_READ, ("accept", "dashboard"))

    @property
    def rtde_port(self) -> int:
        """Bound RTDE port."""
        return int(self._rtde.getsockname()[1])

    @property
    def dashboard_port(self) -> int | None:
        """Bound dashboard port (None if disabled)."""
        return None if self._dash is None else int(self._dash.getsockname()[1])

    def add_reader(self, fileobj: object, callback: Callable[[], None]) -> None:
        """Call ``callback`` whenever ``fileobj`` (with ``fileno()``) is readable."""
        self._sel.register(fileobj, selectors.EVENT_READ, ("extra", callback))  # type: ignore
        self._extra.append((fileobj, callback))

    def stop(self) -> None:
        """Make :meth:`serve_forever` return after the current iteration."""
        self._stop = True

    def close(self) -> None:
        """Close every socket."""
        for client in list(self._clients.values()):
            self._drop(client)
        for sock in self._listeners:
            with contextlib.suppress(KeyError, ValueError):
                self._sel.unregister(sock)
            sock.close()
        self._sel.close()

    # ------------------------------------------------------------------ main loop
    def serve_forever(self) -> None:
        """Run until :meth:`stop`: tick the simulation and serve every client."""
        period = 1.0 / self.rate
        next_tick = time.monotonic()
        while not self._stop:
            timeout = max(0.0, next_tick - time.monotonic())
            for key, events in self._sel.select(timeout):
                self._dispatch(key, events)
                if self._stop:
                    break
            now = time.monotonic()
            if now >= next_tick:
                self.sim.step(now)
                self._stream(now)
                next_tick += period
                if next_tick < now - 10 * period:  # fell far behind: do not burst
                    next_tick = now + period

    def _dispatch(self, key: selectors.SelectorKey, events: int) -> None:
        tag = key.data
        if tag[0] == "accept":
            self._accept(key.fileobj, tag[1])  # type: ignore[arg-type]
            return
        if tag[0] == "extra":
            tag[1]()
            return
        client = self._clients.get(tag[1])
        if client is None:
            return
        if events & selectors.EVENT_WRITE:
            self._flush(client)
        if events & selectors.EVENT_READ and client.cid in self._clients:
            self._read(client)

    def _accept(self, listener: socket.socket, kind: str) -> None:
        try:
            sock, _ = listener.accept()
        except (BlockingIOError, InterruptedError):
            return
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        client = _Client(sock, kind, self._next_cid)
        self._next_cid += 1
        self._clients[client.cid] = client
        self._sel.register(sock, selectors.EVENT_READ, ("client", client.cid))
        if kind == "dashboard":
            self._send(client, b"Connected: Universal Robots Dashboard Server\n")

    def _read(self, client: _Client) -> None:
        try:
            data = client.sock.recv(65536)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            data = b""
        if not data:
            self._drop(client)
            return
        if client.kind == "dashboard":
            self._dashboard_data(client, data)
            return
        try:
            for packet in client.reader.feed(data):
                self._handle(client, packet)
        except rp.ProtocolError as exc:
            log.info("RTDE client %d: %s; disconnecting", client.cid, exc)
            self._send(client, rp.encode_text_message(f"protocol error: {exc}"))
            self._flush(client)
            self._drop(client)

    def _send(self, client: _Client, data: bytes) -> None:
        if len(client.out) > _MAX_UNREAD:
            log.info("client %d reads nothing back; disconnecting", client.cid)
            self._drop(client)
            return
        client.out += data
        self._flush(client)

    def _flush(self, client: _Client) -> None:
        if client.out:
            try:
                sent = client.sock.send(client.out)
                del client.out[:sent]
            except (BlockingIOError, InterruptedError):
                pass
            except OSError:
                self._drop(client)
                return
        events = selectors.EVENT_READ | (selectors.EVENT_WRITE if client.out else 0)
        with contextlib.suppress(KeyError, ValueError):
            self._sel.modify(client.sock, events, ("client", client.cid))

    def _drop(self, client: _Client) -> None:
        if self._clients.pop(client.cid, None) is None:
            return
        with contextlib.suppress(KeyError, ValueError):
            self._sel.unregister(client.sock)
        client.sock.close()
        for name in [n for n, owner in self._input_owner.items() if owner == client.cid]:
            del self._input_owner[name]

    # ------------------------------------------------------------------ RTDE
    def _handle(self, client: _Client, packet: rp.Packet) -> None:
        kind, payload = packet.kind, packet.payload
        try:
            if kind == rp.RTDE_REQUEST_PROTOCOL_VERSION:
                self._on_version(client, payload)
            elif kind == rp.RTDE_GET_URCONTROL_VERSION:
                self._send(client, rp.encode_packet(kind, struct.pack(">IIII",
                                                                      *self.controller_version)))
            elif kind == rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS:
                self._on_setup_outputs(client, payload)
            elif kind == rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS:
                self._on_setup_inputs(client, payload)
            elif kind == rp.RTDE_CONTROL_PACKAGE_START:
                ok = bool(client.outputs or client.inputs)
                client.started = client.started or ok
                now = time.monotonic()
                client.next_send = {rid: now for rid in client.outputs}
                self._send(client, rp.encode_packet(kind, bytes([int(ok)])))
            elif kind == rp.RTDE_CONTROL_PACKAGE_PAUSE:
                client.started = False
                self._send(client, rp.encode_packet(kind, b"\x01"))
            elif kind == rp.RTDE_DATA_PACKAGE:
                self._on_data(client, payload)
            elif kind == rp.RTDE_TEXT_MESSAGE:
                log.info("RTDE client %d says %r", client.cid, payload[:200])
            else:
                self._warn(client, f"unknown RTDE command {kind} ignored")
        except (rp.ProtocolError, struct.error, UnicodeDecodeError, ValueError) as exc:
            self._warn(client, f"malformed packet {chr(kind) if 32 <= kind < 127 else kind}: "
                               f"{exc}")

    def _warn(self, client: _Client, message: str) -> None:
        log.info("RTDE client %d: %s", client.cid, message)
        self._send(client, rp.encode_text_message(message, level=2))

    def _on_version(self, client: _Client, payload: bytes) -> None:
        if len(payload) != 2:
            self._send(client, rp.encode_packet(rp.RTDE_REQUEST_PROTOCOL_VERSION, b"\x00"))
            raise rp.ProtocolError(f"protocol version request of {len(payload)} bytes")
        (version,) = struct.unpack(">H", payload)
        ok = version in (1, 2)
        if ok:
            client.protocol = version
        self._send(client, rp.encode_packet(rp.RTDE_REQUEST_PROTOCOL_VERSION, bytes([int(ok)])))

    def _names(self, raw: bytes) -> list[str]:
        text = raw.decode("ascii", "replace")   # junk becomes names that are NOT_FOUND
        names = [n.strip() for n in text.split(",")]
        while names and names[-1] == "":
            names.pop()
        return names

    def _on_setup_outputs(self, client: _Client, payload: bytes) -> None:
        frequency = self.rate
        if client.protocol >= 2:
            if len(payload) < 8:
                self._send(client, rp.encode_packet(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS,
                                                    b"\x00"))
                raise rp.ProtocolError("output setup without a frequency")
            (frequency,) = struct.unpack(">d", payload[:8])
            payload = payload[8:]
        names = self._names(payload)
        types = [rp.output_type(n) or "NOT_FOUND" for n in names]
        ok = bool(names) and "NOT_FOUND" not in types
        if not 0.0 < frequency <= self.rate:
            self._warn(client, f"output frequency {frequency} Hz outside (0, {self.rate}]")
            ok = False
        rid = 0
        if ok:
            rid = client.next_output_id
            client.next_output_id = rid % 255 + 1
            client.outputs[rid] = (rp.Recipe(rid, names, types), 1.0 / frequency)
            client.next_send[rid] = time.monotonic()
        body = bytes([rid]) + ",".join(types).encode("ascii")
        self._send(client, rp.encode_packet(rp.RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS, body))

    def _on_setup_inputs(self, client: _Client, payload: bytes) -> None:
        names = self._names(payload)
        types = []
        for n in names:
            t = rp.input_type(n)
            if t is None:
                types.append("NOT_FOUND")
            elif not self._may_write(n, client):
                types.append("IN_USE")
            else:
                types.append(t)
        ok = bool(names) and not {"NOT_FOUND", "IN_USE"} & set(types)
        rid = 0
        if ok:
            rid = client.next_input_id
            client.next_input_id = rid % 255 + 1
            client.inputs[rid] = rp.Recipe(rid, names, types)
            for n in names:
                self._input_owner[n] = client.cid
        body = bytes([rid]) + ",".join(types).encode("ascii")
        self._send(client, rp.encode_packet(rp.RTDE_CONTROL_PACKAGE_SETUP_INPUTS, body))

    def _may_write(self, name: str, client: _Client) -> bool:
        """True unless another live client owns input ``name``.

        A client that reconnects closes its old socket first, but both events may arrive in
        one select round: an owner whose socket is already at EOF is dropped here.
        """
        owner = self._clients.get(self._input_owner.get(name, client.cid))
        if owner is None or owner is client:
            return True
        try:
            closed = owner.sock.recv(1, socket.MSG_PEEK | socket.MSG_DONTWAIT) == b""
        except (BlockingIOError, InterruptedError):
            closed = False
        except OSError:
            closed = True
        if closed:
            self._drop(owner)
        return closed

    def _on_data(self, client: _Client, payload: bytes) -> None:
        if not payload:
            raise rp.ProtocolError("empty data package")
        recipe = client.inputs.get(payload[0])
        if recipe is None:
            raise rp.ProtocolError(f"data package for unknown input recipe {payload[0]}")
        values = recipe.unpack(payload)
        self._apply_inputs(values)

    def _apply_inputs(self, values: dict[str, object]) -> None:
        sim = self.sim
        mask = values.get("speed_slider_mask")
        if mask is not None and int(mask) & 1 and "speed_slider_fraction" in values:
            sim.set_speed_slider(float(values["speed_slider_fraction"]))  # type: ignore[arg-type]
        if "standard_digital_output_mask" in values:
            m = int(values["standard_digital_output_mask"])  # type: ignore[call-overload]
            v = int(values.get("standard_digital_output", 0))  # type: ignore[call-overload]
            sim.digital_outputs = (sim.digital_outputs & ~m) | (v & m)
        for name, value in values.items():
            if name.startswith("input_"):
                sim.input_registers[name] = value  # type: ignore[assignment]

    def _output_values(self, now: float) -> dict[str, object]:
        sim = self.sim
        protective = sim.safety_mode == SAFETY_PROTECTIVE_STOP
        q = tuple(float(v) for v in sim.q)
        tcp = tuple(float(v) for v in sim.tcp)
        vals: dict[str, object] = dict(_STATIC_OUTPUTS)
        vals.update({
            "timestamp": now - sim.start_time,
            "target_q": q, "actual_q": q,
            "target_qd": tuple(sim.qd), "actual_qd": tuple(sim.qd),
            "target_qdd": tuple(sim.qdd),
            "actual_TCP_pose": tcp, "target_TCP_pose": tcp,
            "actual_TCP_speed": tuple(sim.tcp_speed), "target_TCP_speed": tuple(sim.tcp_speed),
            "robot_mode": sim.robot_mode,
            "joint_mode": (253,) * 6,
            "safety_mode": sim.safety_mode, "safety_status": sim.safety_mode,
            "speed_scaling": sim.speed_scaling,
            "target_speed_fraction": sim.speed_slider,
            "runtime_state": sim.runtime_state,
            "robot_status_bits": 1 | (2 if sim.runtime_state == RUNTIME_PLAYING else 0),
            "safety_status_bits": (1 if sim.safety_mode == SAFETY_NORMAL else 0)
            | (4 if protective else 0),
            "actual_digital_output_bits": sim.digital_outputs,
            "output_int_register_12": len(sim.cycle_times),
            "output_double_register_12": sim.cycle_times[-1] if sim.cycle_times else 0.0,
            "output_double_register_13": sim.trajectory_time,
            "output_double_register_14": sim.trajectory.cycle_time,
        })
        vals.update(sim.input_registers)
        return vals

    def _stream(self, now: float) -> None:
        values: dict[str, object] | None = None
        for client in list(self._clients.values()):
            if not client.started or not client.outputs:
                continue
            for rid, (recipe, period) in client.outputs.items():
                due = client.next_send.get(rid, now)
                if now + 1e-4 < due:
                    continue
                client.next_send[rid] = max(due + period, now - period)
                if len(client.out) > _MAX_BACKLOG:
                    continue  # the client is not reading: skip this package
                if values is None:
                    values = self._output_values(now)
                row = [values.get(n, _zero(t)) for n, t in zip(recipe.names, recipe.types)]
                self._send(client, rp.encode_packet(rp.RTDE_DATA_PACKAGE, recipe.pack(row)))
                if client.cid not in self._clients:
                    break

    # ------------------------------------------------------------------ dashboard
    def _dashboard_data(self, client: _Client, data: bytes) -> None:
        client.line_buf += data
        if len(client.line_buf) > 4096 and b"\n" not in client.line_buf:
            self._drop(client)
            return
        while b"\n" in client.line_buf:
            line, _, rest = bytes(client.line_buf).partition(b"\n")
            client.line_buf = bytearray(rest)
            reply = self.dashboard_command(line.decode("utf-8", "replace").strip())
            if reply is None:
                self._send(client, b"Disconnected\n")
                self._flush(client)
                self._drop(client)
                return
            self._send(client, reply.encode("utf-8") + b"\n")

    def dashboard_command(self, command: str) -> str | None:
        """Answer one dashboard command like the real server (None means disconnect).

        Besides a subset of UR's commands, the simulator understands ``sim status`` (JSON
        state), ``sim protective stop`` and ``sim speed slider <fraction>``.
        """
        sim = self.sim
        cmd = command.lower()
        if cmd == "quit":
            return None
        if cmd == "unlock protective stop":
            return ("Protective stop releasing" if sim.unlock_protective_stop()
                    else "Cannot unlock protective stop until 5s after occurrence. Always inspect"
                         " cause of protective stop before unlocking")
        if cmd in ("safetymode", "safetystatus"):
            label = "Safetymode" if cmd == "safetymode" else "Safetystatus"
            return f"{label}: {_SAFETY_NAMES.get(sim.safety_mode, 'NORMAL')}"
        if cmd == "robotmode":
            return f"Robotmode: {_ROBOT_MODE_NAMES.get(sim.robot_mode, 'RUNNING')}"
        if cmd == "close safety popup":
            return "closing safety popup"
        if cmd == "close popup":
            return "closing popup"
        if cmd == "play":
            sim.set_program_running(True)
            return "Starting program"
        if cmd == "pause":
            sim.set_program_running(False)
            return "Pausing program"
        if cmd == "stop":
            sim.set_program_running(False)
            return "Stopped"
        if cmd == "running":
            return f"Program running: {str(sim.runtime_state == RUNTIME_PLAYING).lower()}"
        if cmd == "programstate":
            state = "PLAYING" if sim.runtime_state == RUNTIME_PLAYING else "PAUSED"
            return f"{state} pick_and_place.urp"
        if cmd == "get loaded program":
            return "Loaded program: /programs/pick_and_place.urp"
        if cmd == "is in remote control":
            return "true"
        if cmd == "polyscopeversion":
            v = self.controller_version
            return f"URSoftware {v[0]}.{v[1]}.{v[2]}.{v[3]} (simulated)"
        if cmd == "get robot model":
            return sim.model.name.upper().rstrip("E")
        if cmd == "get serial number":
            return "20000000000"
        if cmd == "sim status":
            return json.dumps(sim.status())
        if cmd == "sim protective stop":
            sim.protective_stop("dashboard request")
            return "Protective stop"
        if cmd.startswith("sim speed slider "):
            try:
                ok = sim.set_speed_slider(float(cmd.rsplit(" ", 1)[1]))
            except ValueError:
                ok = False
            return "Speed slider set" if ok else "Speed slider not set"
        return f"could not understand: '{command}'"


def _zero(rtde_type: str) -> object:
    count = rp.TYPE_FORMATS[rtde_type][1]
    if rtde_type in ("DOUBLE", "VECTOR3D", "VECTOR6D"):
        return 0.0 if count == 1 else (0.0,) * count
    return 0 if count == 1 else (0,) * count
