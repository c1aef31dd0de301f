"""Serialize ``HumanOccupancy`` straight from numpy arrays to CDR (the DDS wire format).

At 100 Hz with a prediction, one message holds a few hundred capsules; building them as
Python message objects costs about a millisecond per message, which competes for the
GIL with every other node of the process. The layout of HumanOccupancy is fixed, so
this module writes the layout rclpy's serializer writes (plain CDR, little endian, the
4-byte encapsulation header first; every float64 aligned to 8 bytes from the start of
the payload; padding is zero here, unspecified there), and the node publishes the bytes
with ``Publisher.publish(bytes)``. The field table :data:`OCCUPANCY_LAYOUT` drives both
:class:`CdrWriter` and :class:`CdrReader` (:mod:`.occupancy_decode`). The tests
deserialize the bytes with rclpy and compare with the message built field by field.
"""

from __future__ import annotations

import struct
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["OCCUPANCY_LAYOUT", "PREDICTED_LAYOUT", "CdrReader", "CdrWriter", "capsule_rows",
           "encode_human_occupancy", "encode_occupancy_rows"]

_HEADER = b"\x00\x01\x00\x00"        # CDR, little endian

#: Primitive CDR types: struct format (little endian); the size is the alignment.
_PRIMITIVES = {"int32": struct.Struct("<i"), "uint32": struct.Struct("<I"),
               "float64": struct.Struct("<d")}

#: One ``PredictedOccupancy`` on the wire, field by field.
PREDICTED_LAYOUT: tuple[tuple[str, object], ...] = (
    ("time_from_now", "float64"),
    ("capsules", "capsules"),
)
#: ``HumanOccupancy`` on the wire, field by field, for the writer and the reader alike:
#: a primitive of :data:`_PRIMITIVES`, ``"string"``, ``"string[]"``, ``"capsules"`` (a
#: ``Capsule[]``, as rows ``a.x a.y a.z b.x b.y b.z radius`` of shape (K, 7)) or a nested
#: layout (a sequence of those structs).
OCCUPANCY_LAYOUT: tuple[tuple[str, object], ...] = (
    ("sec", "int32"),                       # header.stamp
    ("nanosec", "uint32"),
    ("frame_id", "string"),                 # header.frame_id
    ("human_id", "string"),
    ("part_names", "string[]"),
    ("capsules", "capsules"),
    ("prediction_horizon", "float64"),
    ("predicted", PREDICTED_LAYOUT),
)


class CdrWriter:
    """Appends plain little-endian CDR, aligning relative to the payload start."""

    def __init__(self) -> None:
        self.parts: list[bytes] = []
        self.size = 0                 # bytes of payload so far (after _HEADER)

    def _pad(self, align: int) -> None:
        pad = (-self.size) % align
        if pad:
            self.parts.append(b"\x00" * pad)
            self.size += pad

    def _raw(self, data: bytes) -> None:
        self.parts.append(data)
        self.size += len(data)

    def primitive(self, kind: str, value: float) -> None:
        fmt = _PRIMITIVES[kind]
        self._pad(fmt.size)
        self._raw(fmt.pack(value))

    def string(self, text: str) -> None:
        data = text.encode("utf-8") + b"\x00"
        self.primitive("uint32", len(data))
        self._raw(data)

    def capsules(self, rows: np.ndarray) -> None:
        """A ``Capsule[]`` from rows (K, 7)."""
        self.primitive("uint32", len(rows))
        if len(rows):
            self._pad(8)
            self._raw(np.ascontiguousarray(rows, dtype="<f8").tobytes())

    def write(self, layout: tuple[tuple[str, object], ...], values: Mapping[str, Any]) -> None:
        """Every field of ``layout`` from ``values`` (by field name), in order."""
        for name, kind in layout:
            value = values[name]
            if kind == "string":
                self.string(value)
            elif kind == "string[]":
                self.primitive("uint32", len(value))
                for text in value:
                    self.string(text)
            elif kind == "capsules":
                self.capsules(value)
            elif isinstance(kind, tuple):
                self.primitive("uint32", len(value))
                for item in value:
                    self.write(kind, item)
            else:
                self.primitive(kind, value)

    def bytes(self) -> bytes:
        return _HEADER + b"".join(self.parts)


class CdrReader:
    """Reads plain little-endian CDR, aligning relative to the payload start; raises
    ValueError (or struct.error) where the data ends early or a length is wrong."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.pos = 4                                      # after the encapsulation header

    def _align(self, n: int) -> None:
        self.pos += (-(self.pos - 4)) % n

    def primitive(self, kind: str) -> Any:
        fmt = _PRIMITIVES[kind]
        self._align(fmt.size)
        (value,) = fmt.unpack_from(self.data, self.pos)
        self.pos += fmt.size
        return value

    def string(self) -> str:
        n = self.primitive("uint32")
        if n == 0 or self.pos + n > len(self.data):
            raise ValueError("bad string length")
        text = self.data[self.pos:self.pos + n - 1].decode("utf-8")
        self.pos += n
        return text

    def capsules(self) -> np.ndarray:
        """A ``Capsule[]`` as rows (K, 7)."""
        k = self.primitive("uint32")
        if k == 0:
            return np.zeros((0, 7))
        self._align(8)
        end = self.pos + 56 * k
        if end > len(self.data):
            raise ValueError("capsule sequence runs past the message")
        rows = np.frombuffer(self.data, dtype="<f8", count=7 * k, offset=self.pos)
        self.pos = end
        return rows.reshape(k, 7).astype(np.float64)

    def read(self, layout: tuple[tuple[str, object], ...]) -> dict[str, Any]:
        """Every field of ``layout``, in order, by field name."""
        out: dict[str, Any] = {}
        for name, kind in layout:
            if kind == "string":
                out[name] = self.string()
            elif kind == "string[]":
                out[name] = [self.string() for _ in range(self.primitive("uint32"))]
            elif kind == "capsules":
                out[name] = self.capsules()
            elif isinstance(kind, tuple):
                out[name] = [self.read(kind) for _ in range(self.primitive("uint32"))]
            else:
                out[name] = self.primitive(kind)
        return out


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
    n = len(rows)
    if rows.ndim != 3 or rows.shape[2:] != (7,) or len(offsets) != n:
        raise ValueError(f"need rows (N, K, 7) and offsets (N,); got {rows.shape}, "
                         f"{len(offsets)}")
    buf = CdrWriter()
    buf.write(OCCUPANCY_LAYOUT, {
        "sec": int(sec), "nanosec": int(nanosec), "frame_id": frame_id, "human_id": human_id,
        "part_names": part_names, "capsules": rows[0] if n else np.zeros((0, 7)),
        "prediction_horizon": float(offsets[-1]) if n > 1 else 0.0,
        "predicted": [{"time_from_now": float(offsets[i]), "capsules": rows[i]}
                      for i in range(1, n)]})
    return buf.bytes()
