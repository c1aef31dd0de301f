"""Serialize ``HumanOccupancy`` straight from numpy arrays to CDR (the DDS wire format).

At 100 Hz with a prediction, one message holds a few hundred capsules; building them as
Python message objects costs about a millisecond per message, which competes for the
GIL with every other node of the process. The layout of HumanOccupancy is fixed, so
this module writes the layout rclpy's serializer writes (plain CDR, little endian, the
4-byte encapsulation header first; every float64 aligned to 8 bytes from the start of
the payload; padding is zero here, unspecified there), and the node publishes the bytes
with ``Publisher.publish(bytes)``. The tests deserialize them with rclpy and compare
with the message built field by field.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

import numpy as np

_HEADER = b"\x00\x01\x00\x00"        # CDR, little endian


class _Buffer:
    """Appends CDR primitives, aligning relative to the payload start."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.size = 0                 # bytes of payload so far (after _HEADER)

    def _pad(self, align: int) -> None:
        pad = (-self.size) % align
        if pad:
            self.parts.append(b"\x00" * pad)
            self.size += pad

    def raw(self, data: bytes) -> None:
        self.parts.append(data)
        self.size += len(data)

    def uint32(self, value: int) -> None:
        self._pad(4)
        self.raw(struct.pack("<I", value))

    def int32(self, value: int) -> None:
        self._pad(4)
        self.raw(struct.pack("<i", value))

    def float64(self, value: float) -> None:
        self._pad(8)
        self.raw(struct.pack("<d", value))

    def string(self, text: str) -> None:
        data = text.encode("utf-8") + b"\x00"
        self.uint32(len(data))
        self.raw(data)

    def float64_block(self, values: np.ndarray) -> None:
        self._pad(8)
        self.raw(np.ascontiguousarray(values, dtype="<f8").tobytes())

    def bytes(self) -> bytes:
        return _HEADER + b"".join(self.parts)


def encode_human_occupancy(sec: int, nanosec: int, frame_id: str, human_id: str,
                           part_names: Sequence[str], segments: np.ndarray,
                           radii: np.ndarray, offsets: np.ndarray) -> bytes:
    """CDR bytes of a ``ltl_human_motion/msg/HumanOccupancy``.

    Parameters
    ----------
    sec, nanosec : int
        ``header.stamp``.
    segments : ndarray, shape (N, K, 2, 3)
        Capsules now (index 0) and at the predicted offsets (1..N-1).
    radii : ndarray, shape (K,)
    offsets : ndarray, shape (N,)
        Seconds from now of each sample; ``offsets[0]`` is 0 and the last one is the
        ``prediction_horizon``.
    """
    segments = np.asarray(segments, dtype=np.float64)
    radii = np.asarray(radii, dtype=np.float64)
    n, k = segments.shape[:2]
    if segments.shape[2:] != (2, 3) or radii.shape != (k,) or len(offsets) != n:
        raise ValueError(f"need segments (N, K, 2, 3), radii (K,), offsets (N,); got "
                         f"{segments.shape}, {radii.shape}, {len(offsets)}")
    return encode_occupancy_rows(sec, nanosec, frame_id, human_id, part_names,
                                 capsule_rows(segments, radii), offsets)


def capsule_rows(segments: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Capsules as CDR rows ``a.x a.y a.z b.x b.y b.z radius``: (..., K, 7) from segments
    (..., K, 2, 3) and radii (K,)."""
    segments = np.asarray(segments, dtype=np.float64)
    lead = segments.shape[:-2]
    radius = np.broadcast_to(np.asarray(radii, dtype=np.float64)[..., None], (*lead, 1))
    return np.concatenate([segments.reshape(*lead, 6), radius], axis=-1)


def encode_occupancy_rows(sec: int, nanosec: int, frame_id: str, human_id: str,
                          part_names: Sequence[str], rows: np.ndarray,
                          offsets: np.ndarray) -> bytes:
    """CDR bytes of a ``HumanOccupancy`` from capsule rows (N, K, 7)
    (:func:`capsule_rows`) at ``offsets`` (N,); see :func:`encode_human_occupancy`."""
    rows = np.asarray(rows, dtype=np.float64)
    n, k = rows.shape[:2]
    if rows.shape[2:] != (7,) or len(offsets) != n:
        raise ValueError(f"need rows (N, K, 7) and offsets (N,); got {rows.shape}, "
                         f"{len(offsets)}")
    buf = _Buffer()
    buf.int32(int(sec))
    buf.uint32(int(nanosec))
    buf.string(frame_id)
    buf.string(human_id)
    buf.uint32(len(part_names))
    for name in part_names:
        buf.string(name)
    buf.uint32(k)
    if k:
        buf.float64_block(rows[0])
    buf.float64(float(offsets[-1]) if n > 1 else 0.0)
    buf.uint32(n - 1)
    for i in range(1, n):
        buf.float64(float(offsets[i]))
        buf.uint32(k)
        if k:
            buf.float64_block(rows[i])
    return buf.bytes()
