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
from ltl_human_motion.ros.occupancy_cdr import OCCUPANCY_LAYOUT, CdrReader

__all__ = ["OccupancySample", "decode_human_occupancy", "occupancy_from_message"]


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
            m = CdrReader(data).read(OCCUPANCY_LAYOUT)
            segments, radii = _split(m["capsules"])
            predicted = [(p["time_from_now"], *_split(p["capsules"])) for p in m["predicted"]]
            return OccupancySample(m["human_id"], m["sec"] + m["nanosec"] * 1e-9, segments,
                                   radii, predicted)
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
