"""Wire format of Universal Robots' Real-Time Data Exchange (RTDE), protocol version 2.

Every packet starts with a big-endian header ``uint16 size`` (the size of the whole packet,
header included) and ``uint8 type``. The payload depends on the type:

===========  ====  ==================================================================
type         byte  payload (client -> controller / controller -> client)
===========  ====  ==================================================================
REQUEST_PROTOCOL_VERSION  ``V``  uint16 version / uint8 accepted
GET_URCONTROL_VERSION     ``v``  empty / uint32 major, minor, bugfix, build
TEXT_MESSAGE              ``M``  uint8 len, message, uint8 len, source, uint8 level
DATA_PACKAGE              ``U``  uint8 recipe id, then the recipe's fields
SETUP_OUTPUTS             ``O``  double frequency, "a,b,c" / uint8 id, "T1,T2,..."
SETUP_INPUTS              ``I``  "a,b,c" / uint8 id, "T1,T2,..."
START                     ``S``  empty / uint8 accepted
PAUSE                     ``P``  empty / uint8 accepted
===========  ====  ==================================================================

A setup reply names ``NOT_FOUND`` (or ``IN_USE`` for an input that another client already
writes) for each unusable variable and then carries recipe id 0, as the real controller
does. Variable names and types follow UR's RTDE guide.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

__all__ = [
    "HEADER",
    "INPUT_TYPES",
    "MAX_PACKET_SIZE",
    "OUTPUT_TYPES",
    "RTDE_CONTROL_PACKAGE_PAUSE",
    "RTDE_CONTROL_PACKAGE_SETUP_INPUTS",
    "RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS",
    "RTDE_CONTROL_PACKAGE_START",
    "RTDE_DATA_PACKAGE",
    "RTDE_GET_URCONTROL_VERSION",
    "RTDE_REQUEST_PROTOCOL_VERSION",
    "RTDE_TEXT_MESSAGE",
    "TYPE_FORMATS",
    "Packet",
    "PacketReader",
    "ProtocolError",
    "Recipe",
    "encode_packet",
    "encode_text_message",
    "input_type",
    "output_type",
]

RTDE_REQUEST_PROTOCOL_VERSION = ord("V")
RTDE_GET_URCONTROL_VERSION = ord("v")
RTDE_TEXT_MESSAGE = ord("M")
RTDE_DATA_PACKAGE = ord("U")
RTDE_CONTROL_PACKAGE_SETUP_OUTPUTS = ord("O")
RTDE_CONTROL_PACKAGE_SETUP_INPUTS = ord("I")
RTDE_CONTROL_PACKAGE_START = ord("S")
RTDE_CONTROL_PACKAGE_PAUSE = ord("P")

HEADER = struct.Struct(">HB")
#: Largest packet the simulated controller accepts from a client (the guide limits the
#: variable list of a setup to 2048 bytes).
MAX_PACKET_SIZE = 4096

#: struct format (without byte order) and value count of each RTDE type.
TYPE_FORMATS: dict[str, tuple[str, int]] = {
    "BOOL": ("?", 1),
    "UINT8": ("B", 1),
    "UINT32": ("I", 1),
    "UINT64": ("Q", 1),
    "INT32": ("i", 1),
    "DOUBLE": ("d", 1),
    "VECTOR3D": ("3d", 3),
    "VECTOR6D": ("6d", 6),
    "VECTOR6INT32": ("6i", 6),
    "VECTOR6UINT32": ("6I", 6),
}

_V6 = "VECTOR6D"
OUTPUT_TYPES: dict[str, str] = {
    "timestamp": "DOUBLE",
    "target_q": _V6, "target_qd": _V6, "target_qdd": _V6, "target_current": _V6,
    "target_moment": _V6, "actual_q": _V6, "actual_qd": _V6, "actual_current": _V6,
    "actual_current_window": _V6, "joint_control_output": _V6, "actual_TCP_pose": _V6,
    "actual_TCP_speed": _V6, "actual_TCP_force": _V6, "target_TCP_pose": _V6,
    "target_TCP_speed": _V6, "joint_temperatures": _V6, "actual_joint_voltage": _V6,
    "ft_raw_wrench": _V6, "payload_inertia": _V6,
    "actual_digital_input_bits": "UINT64", "actual_digital_output_bits": "UINT64",
    "actual_execution_time": "DOUBLE", "robot_mode": "INT32", "joint_mode": "VECTOR6INT32",
    "safety_mode": "INT32", "safety_status": "INT32", "actual_tool_accelerometer": "VECTOR3D",
    "speed_scaling": "DOUBLE", "target_speed_fraction": "DOUBLE", "actual_momentum": "DOUBLE",
    "actual_main_voltage": "DOUBLE", "actual_robot_voltage": "DOUBLE",
    "actual_robot_current": "DOUBLE", "runtime_state": "UINT32", "elbow_position": "VECTOR3D",
    "elbow_velocity": "VECTOR3D", "robot_status_bits": "UINT32",
    "safety_status_bits": "UINT32", "analog_io_types": "UINT32",
    "standard_analog_input0": "DOUBLE", "standard_analog_input1": "DOUBLE",
    "standard_analog_output0": "DOUBLE", "standard_analog_output1": "DOUBLE",
    "io_current": "DOUBLE", "tool_mode": "UINT32", "tool_analog_input_types": "UINT32",
    "tool_analog_input0": "DOUBLE", "tool_analog_input1": "DOUBLE",
    "tool_output_voltage": "INT32", "tool_output_current": "DOUBLE",
    "tool_temperature": "DOUBLE", "tcp_force_scalar": "DOUBLE",
    "output_bit_registers0_to_31": "UINT32", "output_bit_registers32_to_63": "UINT32",
    "input_bit_registers0_to_31": "UINT32", "input_bit_registers32_to_63": "UINT32",
    "payload": "DOUBLE", "payload_cog": "VECTOR3D", "script_control_line": "UINT32",
    "joint_position_deviation_ratio": "DOUBLE", "collision_detection_ratio": "DOUBLE",
    "time_scale_source": "INT32", "tool_output_mode": "UINT8",
    "tool_digital_output0_mode": "UINT8", "tool_digital_output1_mode": "UINT8",
    "actual_robot_energy_consumed": "DOUBLE",
    "actual_robot_braking_energy_dissipated": "DOUBLE",
}

INPUT_TYPES: dict[str, str] = {
    "speed_slider_mask": "UINT32", "speed_slider_fraction": "DOUBLE",
    "standard_digital_output_mask": "UINT8", "standard_digital_output": "UINT8",
    "configurable_digital_output_mask": "UINT8", "configurable_digital_output": "UINT8",
    "tool_digital_output_mask": "UINT8", "tool_digital_output": "UINT8",
    "standard_analog_output_mask": "UINT8", "standard_analog_output_type": "UINT8",
    "standard_analog_output_0": "DOUBLE", "standard_analog_output_1": "DOUBLE",
    "input_bit_registers0_to_31": "UINT32", "input_bit_registers32_to_63": "UINT32",
    "external_force_torque": _V6,
}


def _register_type(name: str, prefix: str) -> str | None:
    """Type of ``<prefix>_bit|int|double_register_N`` (N in 0..47, bits in 64..127)."""
    for kind, rtype, lo, hi in (("int", "INT32", 0, 47), ("double", "DOUBLE", 0, 47),
                                ("bit", "BOOL", 64, 127)):
        head = f"{prefix}_{kind}_register_"
        if name.startswith(head):
            tail = name[len(head):]
            if tail.isdigit() and lo <= int(tail) <= hi and str(int(tail)) == tail:
                return rtype
    return None


def output_type(name: str) -> str | None:
    """RTDE type of the output variable ``name``, or None if the controller has no such."""
    return OUTPUT_TYPES.get(name) or _register_type(name, "output") \
        or _register_type(name, "input")


def input_type(name: str) -> str | None:
    """RTDE type of the input variable ``name``, or None if the controller has no such."""
    return INPUT_TYPES.get(name) or _register_type(name, "input")


class ProtocolError(ValueError):
    """A packet that does not follow the RTDE protocol."""


@dataclass(frozen=True)
class Packet:
    """One RTDE packet: ``kind`` is the type byte, ``payload`` the bytes after the header."""

    kind: int
    payload: bytes


def encode_packet(kind: int, payload: bytes = b"") -> bytes:
    """Header plus payload."""
    size = HEADER.size + len(payload)
    if size > 0xFFFF:
        raise ValueError(f"RTDE packet of {size} bytes exceeds the 65535-byte limit")
    return HEADER.pack(size, kind) + payload


def encode_text_message(message: str, source: str = "ltl-ur-sim", level: int = 1) -> bytes:
    """An RTDE_TEXT_MESSAGE (protocol 2): level 0 exception, 1 error, 2 warning, 3 info."""
    msg = message.encode("utf-8", "replace")[:255]
    src = source.encode("utf-8", "replace")[:255]
    body = bytes([len(msg)]) + msg + bytes([len(src)]) + src + bytes([level & 0xFF])
    return encode_packet(RTDE_TEXT_MESSAGE, body)


class PacketReader:
    """Incremental splitter of a byte stream into :class:`Packet` objects.

    Parameters
    ----------
    max_size : int
        Largest accepted packet; a larger or smaller-than-header size field raises
        :class:`ProtocolError` (the stream cannot be resynchronised after that).
    """

    def __init__(self, max_size: int = MAX_PACKET_SIZE) -> None:
        self._buf = bytearray()
        self.max_size = max_size

    def feed(self, data: bytes) -> Iterator[Packet]:
        """Append ``data`` and yield every complete packet."""
        self._buf += data
        while len(self._buf) >= HEADER.size:
            size, kind = HEADER.unpack_from(self._buf)
            if size < HEADER.size or size > self.max_size:
                raise ProtocolError(f"packet size {size} outside [3, {self.max_size}]")
            if len(self._buf) < size:
                return
            payload = bytes(self._buf[HEADER.size:size])
            del self._buf[:size]
            yield Packet(kind, payload)


class Recipe:
    """A set-up list of variables with their types and a precompiled struct.

    Parameters
    ----------
    recipe_id : int
        1..255.
    names, types : sequence of str
        Variable names and RTDE types of equal length.
    """

    def __init__(self, recipe_id: int, names: Sequence[str], types: Sequence[str]) -> None:
        if len(names) != len(types):
            raise ValueError("names and types differ in length")
        self.recipe_id = recipe_id
        self.names = tuple(names)
        self.types = tuple(types)
        self.struct = struct.Struct(">B" + "".join(TYPE_FORMATS[t][0] for t in types))
        self._counts = [TYPE_FORMATS[t][1] for t in types]

    def pack(self, values: Sequence[object]) -> bytes:
        """Data-package payload for one value per variable (vectors as sequences)."""
        flat: list[object] = [self.recipe_id]
        for value, count in zip(values, self._counts):
            if count == 1:
                flat.append(value)
            else:
                flat.extend(value)  # type: ignore[arg-type]
        return self.struct.pack(*flat)

    def unpack(self, payload: bytes) -> dict[str, object]:
        """Values of a data-package payload (recipe id byte included); checks the size."""
        if len(payload) != self.struct.size:
            raise ProtocolError(f"data package for recipe {self.recipe_id} has {len(payload)}"
                                f" bytes, expected {self.struct.size}")
        flat = self.struct.unpack(payload)[1:]
        out: dict[str, object] = {}
        i = 0
        for name, count in zip(self.names, self._counts):
            out[name] = flat[i] if count == 1 else tuple(flat[i:i + count])
            i += count
        return out
