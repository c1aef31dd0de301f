"""Decode ``HumanOccupancy`` CDR bytes straight into numpy arrays (the reverse of
:mod:`.occupancy_cdr`).

Plain little-endian CDR (what rclpy and Fast DDS send) is read with numpy, a few
microseconds for a message of 250 capsules; anything else goes through rclpy's
deserializer. The result is the core's :class:`~ltl_human_motion.robot.fusion.OccupancySample`.
"""

from __future__ import annotations

import struct
from typing import Any

import numpy as np
from rclpy.serialization import deserialize_message

from ltl_human_motion.msg import HumanOccupancy
from ltl_human_motion.robot.fusion import OccupancySample
from ltl_human_motion.ros.common import stamp_seconds

__all__ = ["OccupancySample", "decode_human_occupancy", "occupancy_from_message"]


class _Reader:
    """Reads plain little-endian CDR, aligning relative to the payload start."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 4                                      # after the encapsulation header

    def _align(self, n: int) -> None:
        self.pos += (-(self.pos - 4)) % n

    def uint32(self) -> int:
        self._align(4)
        (value,) = struct.unpack_from("<I", self.data, self.pos)
        self.pos += 4
        return value

    def int32(self) -> int:
        self._align(4)
        (value,) = struct.unpack_from("<i", self.data, self.pos)
        self.pos += 4
        return value

    def float64(self) -> float:
        self._align(8)
        (value,) = struct.unpack_from("<d", self.data, self.pos)
        self.pos += 8
        return value

    def string(self) -> str:
        n = self.uint32()
        if n == 0 or self.pos + n > len(self.data):
            raise ValueError("bad string length")
        text = self.data[self.pos:self.pos + n - 1].decode("utf-8")
        self.pos += n
        return text

    def capsules(self) -> np.ndarray:
        k = self.uint32()
        if k == 0:
            return np.zeros((0, 7))
        self._align(8)
        end = self.pos + 56 * k
        if end > len(self.data):
            raise ValueError("capsule sequence runs past the message")
        rows = np.frombuffer(self.data, dtype="<f8", count=7 * k, offset=self.pos)
        self.pos = end
        return rows.reshape(k, 7).astype(np.float64)


def _split(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return rows[:, :6].reshape(-1, 2, 3), rows[:, 6].copy()


def decode_human_occupancy(data: bytes) -> OccupancySample:
    """Decode serialized ``HumanOccupancy`` bytes straight into numpy arrays.

    Plain little-endian CDR (what rclpy and Fast DDS send) is read with numpy, a few
    microseconds for a message of 250 capsules; anything else goes through rclpy's
    deserializer. Raises ValueError on malformed data.
    """
    data = bytes(data)
    if data[:2] == b"\x00\x01":
        try:
            r = _Reader(data)
            sec, nanosec = r.int32(), r.uint32()
            r.string()                                    # frame_id
            human_id = r.string()
            for _ in range(r.uint32()):
                r.string()                                # part names
            segments, radii = _split(r.capsules())
            r.float64()                                   # prediction_horizon
            predicted = []
            for _ in range(r.uint32()):
                horizon = r.float64()
                predicted.append((horizon, *_split(r.capsules())))
            return OccupancySample(human_id, sec + nanosec * 1e-9, segments, radii, predicted)
        except (struct.error, ValueError, UnicodeDecodeError):
            pass                                          # let rclpy decide below
    try:
        msg = deserialize_message(data, HumanOccupancy)
    except Exception as exc:  # rclpy raises several types for garbage
        raise ValueError(f"cannot deserialize HumanOccupancy: {exc}") from None
    return occupancy_from_message(msg)


def _capsule_rows(capsules: Any) -> np.ndarray:
    return np.array([[c.a.x, c.a.y, c.a.z, c.b.x, c.b.y, c.b.z, c.radius] for c in capsules],
                    dtype=np.float64).reshape(-1, 7)


def occupancy_from_message(msg: Any) -> OccupancySample:
    """An :class:`OccupancySample` from a ``HumanOccupancy`` message object."""
    segments, radii = _split(_capsule_rows(msg.capsules))
    predicted = [(float(p.time_from_now), *_split(_capsule_rows(p.capsules)))
                 for p in msg.predicted]
    return OccupancySample(msg.human_id, stamp_seconds(msg.header.stamp), segments, radii,
                           predicted)
