"""Motion blending (Sec. III-C of the paper).

Consecutive placed motions overlap by ``nf`` frames. Over the overlap a cubic weight
``w`` with ``w(0) = 1``, ``w(1) = 0`` and ``w'(0) = w'(1) = 0`` (C1) mixes them
(Eq. (2)): ``M_syn = w M_i + (1 - w) M_j``. Joint positions and root positions are mixed
linearly; the heading is mixed along the shorter arc.

With ``spread > 0`` (what synthesis uses) the joint positions are joined by *offset
blending* instead (Kovar, Gleicher & Pighin, "Motion graphs", 2002, Sec. 4: the
transition's pose mismatch is spread over a window): at the centre ``c`` of each overlap
the output switches from the outgoing motion ``a`` to the incoming ``b``, and the jump
``d = b(c) - a(c)`` is removed by adding ``+d/2`` (ramped in over ``spread`` frames
before ``c``) to ``a`` and ``-d/2`` (ramped out over ``spread`` frames after ``c``) to
``b``, both with the minimum-jerk profile. A mismatch ``d`` then adds at most
``1.875 |d| / 2 / (spread / fps)`` to a joint's speed, instead of about
``1.5 |d| / (nf / fps)`` for the cross-fade over the short overlap ``nf``, which is
where the hand, knee and swing-foot speed peaks of walks came from.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ltl_human_motion.motion.skeleton import JOINT_INDEX

#: The foot joints, whose junction ramps may be longer (:func:`_add_junction`).
_FOOT_JOINTS = tuple(JOINT_INDEX[n] for n in ("l_ankle", "l_toe", "r_ankle", "r_toe"))

#: Time (s) over which synthesis spreads each junction's pose mismatch on either side of
#: it (offset blending): long enough that a 5 cm mismatch adds under 0.25 m/s to a joint,
#: short next to a goal primitive's reach (at least 0.6 s).
JUNCTION_SPREAD = 0.2
#: Speed (m/s) a junction's offset ramp may add to a foot joint (ankle, toe): a larger
#: mismatch of the feet is spread over a longer window, up to
#: :data:`JUNCTION_FOOT_SPREAD_MAX` (the ``JUNCTION_SPREAD`` design number: 5 cm adds
#: 0.23 m/s). Transitions of the gait graph leave a swing foot 5-15 cm off, whose ramp
#: at 0.2 s added 0.25-0.7 m/s near the foot's swing peak (ankle over 4.1 m/s).
JUNCTION_ADDED_SPEED = 0.25
#: Longest window (s) of a foot's ramp on either side of a junction, short of a goal
#: primitive's reach (at least 0.6 s). The rest of the body keeps ``JUNCTION_SPREAD``
#: (longer ramps of the whole leg or body turned into knee, hand and collision failures).
JUNCTION_FOOT_SPREAD_MAX = 0.5


def blend_weights(nf: int) -> np.ndarray:
    """Cubic C1 blend weights from 1 to 0 over ``nf`` frames, shape (nf,).

    ``w(s) = 1 - 3 s^2 + 2 s^3`` sampled at ``s = (k + 1) / (nf + 1)``, k = 0..nf-1, so
    neither end of the overlap is a pure copy of one input.
    """
    if nf < 0:
        raise ValueError(f"nf must be >= 0, got {nf}")
    s = np.arange(1, nf + 1, dtype=np.float64) / (nf + 1)
    return 1.0 - 3.0 * s**2 + 2.0 * s**3


def wrap_angle(a: np.ndarray | float) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return (np.asarray(a) + np.pi) % (2.0 * np.pi) - np.pi


@dataclass
class PlacedSegment:
    """One motion placed in the world, ready to be concatenated.

    Attributes
    ----------
    positions : ndarray, shape (T, J, 3)
        World joint positions.
    root_yaw : ndarray, shape (T,)
        Heading of the root about +z, radians (unwrapped within the segment).
    label : int
        Index into the task timeline, or -1 for walking between tasks.
    blend_in : int
        Number of frames this segment overlaps the previous one.
    name : str
        Name of the primitive placed.
    """

    positions: np.ndarray
    root_yaw: np.ndarray
    label: int = -1
    blend_in: int = 0
    name: str = ""


def concatenate(segments: list[PlacedSegment], spread: int = 0, fps: float | None = None,
                shares: Mapping[int, float] | None = None,
                stretch: Mapping[int, float] | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[tuple[int, int]]]:
    """Concatenate placed segments, blending each overlap with the cubic weight.

    ``spread``: frames over which each overlap's pose mismatch is spread by offset
    blending (module docstring); 0 = the cross-fade of Eq. (2). With ``fps`` (frame
    rate) a foot whose mismatch would add more than :data:`JUNCTION_ADDED_SPEED` over
    ``spread`` frames gets a longer window, up to :data:`JUNCTION_FOOT_SPREAD_MAX`.
    ``shares``: for junction ``i`` (between segments ``i`` and ``i + 1``), the share of
    its mismatch the outgoing segment takes (default one half; 0 or 1 put it all on one
    side, over twice the window, so that it adds the same speed); ``stretch``: a factor
    on junction ``i``'s windows (both the body's and the feet's; default 1).

    Returns
    -------
    positions : ndarray, shape (T, J, 3)
    root_yaw : ndarray, shape (T,)
        Continuous (unwrapped) heading.
    labels : ndarray of int, shape (T,)
        Segment label of each frame; blended frames take the incoming segment's label
        once its weight exceeds one half.
    spans : list of (start, end)
        Frame span of each segment in the result (end exclusive, overlaps included).
    """
    if not segments:
        raise ValueError("no segments to concatenate")
    # Every segment after the first starts ``nf`` frames before the end of the result so
    # far (nf: its blend, at most the length of either side); write into one buffer.
    nfs, length = [], len(segments[0].root_yaw)
    part = length
    for seg in segments[1:]:
        nf = min(int(seg.blend_in), part, len(seg.root_yaw))
        nfs.append(nf)
        part = len(seg.root_yaw) - nf
        length += part
    first = segments[0]
    positions = np.empty((length, *first.positions.shape[1:]))
    yaw = np.empty(length)
    labels = np.empty(length, dtype=np.int64)
    end = len(first.root_yaw)
    positions[:end] = first.positions
    yaw[:end] = np.unwrap(first.root_yaw)
    labels[:end] = first.label
    spans = [(0, end)]
    offset = np.zeros_like(positions) if spread > 0 else None
    for i, (seg, nf) in enumerate(zip(segments[1:], nfs)):
        yaw_in = np.unwrap(seg.root_yaw)
        # Continue the heading without a 2*pi jump.
        ref = yaw[end - nf] if nf else yaw[end - 1]
        yaw_in = yaw_in + 2.0 * np.pi * np.round((ref - yaw_in[0]) / (2.0 * np.pi))
        start = end - nf
        if nf and offset is not None:
            c = nf // 2
            d = seg.positions[c] - positions[start + c]                  # (J, 3)
            positions[start + c:end] = seg.positions[c:nf]
            _add_junction(offset, start + c, d, spread, fps,
                          0.5 if shares is None else shares.get(i, 0.5),
                          1.0 if stretch is None else stretch.get(i, 1.0))
        elif nf:
            w = blend_weights(nf)
            a_pos, b_pos = positions[start:end], seg.positions[:nf]
            positions[start:end] = w[:, None, None] * a_pos + (1.0 - w[:, None, None]) * b_pos
        if nf:
            w = blend_weights(nf)
            a_yaw, b_yaw = yaw[start:end], yaw_in[:nf]
            yaw[start:end] = a_yaw + (1.0 - w) * wrap_angle(b_yaw - a_yaw)
            labels[start:end] = np.where(w >= 0.5, labels[start:end], seg.label)
        n = len(seg.root_yaw)
        positions[end:start + n] = seg.positions[nf:]
        yaw[end:start + n] = yaw_in[nf:]
        labels[end:start + n] = seg.label
        end = start + n
        spans.append((start, end))
    if offset is not None:
        positions += offset
    return positions, yaw, labels, spans


def junction_frames(spans: list[tuple[int, int]]) -> list[int]:
    """The frame at which each junction of :func:`concatenate` switches from one segment
    to the next (the centre of their overlap), given its ``spans``."""
    return [b0 + (a1 - b0) // 2 for (_a0, a1), (b0, _b1) in itertools.pairwise(spans)]


def _add_junction(offset: np.ndarray, c: int, d: np.ndarray, spread: int,
                  fps: float | None, share: float = 0.5, stretch: float = 1.0) -> None:
    """Add the ramps of a junction with mismatch ``d`` (J, 3) at frame ``c`` to ``offset``
    (T, J, 3): over ``spread`` frames, the feet's over as many as keep their added speed
    ``1.875 |d| / 2 / (frames / fps)`` within :data:`JUNCTION_ADDED_SPEED` (at most
    :data:`JUNCTION_FOOT_SPREAD_MAX` seconds) when ``fps`` is given; ``share`` of ``d``
    on the outgoing side (:func:`_add_ramps`); both windows times ``stretch``."""
    spread = round(spread * stretch)
    if fps is None:
        _add_ramps(offset, c, d, spread, share)
        return
    feet = np.zeros(len(d), bool)
    feet[list(_FOOT_JOINTS)] = True
    d_feet = np.where(feet[:, None], d, 0.0)
    _add_ramps(offset, c, d - d_feet, spread, share)
    need = 1.875 * float(np.max(np.linalg.norm(d_feet, axis=-1))) / 2.0 / JUNCTION_ADDED_SPEED
    frames = min(int(np.ceil(need * fps * stretch)),
                 round(JUNCTION_FOOT_SPREAD_MAX * fps * stretch))
    _add_ramps(offset, c, d_feet, max(spread, frames), share)


def _add_ramps(offset: np.ndarray, c: int, d: np.ndarray, spread: int,
               share: float = 0.5) -> None:
    """Add the offset-blending correction of a jump ``d`` (J, 3) at frame ``c`` to
    ``offset`` (T, J, 3): ``share * d`` ramped in before ``c``, ``-(1 - share) * d``
    ramped out after, each over ``spread`` frames times twice its share (the same added
    speed whatever the share; one half: ``spread``)."""
    from ltl_human_motion.motion.ik import min_jerk
    T = offset.shape[0]
    before = round(2.0 * share * spread)
    if before > 0:
        lo = max(0, c - before)
        k = np.arange(lo, c)
        offset[lo:c] += (share * min_jerk((k - (c - before)) / before))[:, None, None] * d
    after = round(2.0 * (1.0 - share) * spread)
    if after > 0:
        hi = min(T, c + after)
        k = np.arange(c, hi)
        offset[c:hi] -= ((1.0 - share) * (1.0 - min_jerk((k - c) / after)))[:, None, None] * d
