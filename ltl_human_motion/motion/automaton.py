"""Motion automaton (Definition 2) and the transition distance of Sec. III-A.

Transition distance
-------------------
For primitives ``mp_i`` and ``mp_j`` we compare the last ``k_comp`` poses of ``mp_i`` with
the first ``k_comp`` poses of ``mp_j``, both as world joint positions in their own
primitive's start frame, after moving ``mp_j`` by the rotation about the vertical axis and
the floor-plane translation that best aligns the two windows:

    d_ij = min_{theta, x0, y0} sqrt( 1/k_comp * sum_k || M_i^(nu_i - k_comp + k)
                                       - (T(theta) M_j^k + lambda(x0, y0)) ||_2^2 )
           * (1.75 / stature)

``|| . ||_2`` is the Euclidean norm of the stacked 3m-vector of all m = 23 joints, as in the
paper; we take the quadratic mean over the k_comp frames instead of the arithmetic mean,
which makes the least-squares solution of Kovar, Gleicher & Pighin (2002, "Motion graphs",
Sec. 3.1) the exact minimizer, in closed form:

    theta = atan2(sum(a_y b_x - a_x b_y) - n (abar_y bbar_x - abar_x bbar_y),
                  sum(a_x b_x + a_y b_y) - n (abar_x bbar_x + abar_y bbar_y)),
    (x0, y0) = abar - R(theta) bbar

(our floor plane is x, y; the paper's is x, z). Distances are in metres for a 1.75 m body
(scaled by 1.75 / stature so one threshold fits every body size). ``delta`` is therefore a
bound on the root-mean-square over frames of the whole-body position error (23 joints
stacked); ``delta = 0.135`` allows an average of about 0.135 / sqrt(23) = 2.8 cm per joint.
All pairs are evaluated with a few matrix products in tiles (no loops over pairs, no
numeric optimizer).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components

from ltl_human_motion.deadline import checkpoint
from ltl_human_motion.motion.types import MotionPrimitive

__all__ = [
    "DEFAULT_DELTA",
    "DEFAULT_K_COMP",
    "REFERENCE_STATURE",
    "MotionAutomaton",
    "align_windows",
    "build_transitions",
    "largest_scc",
    "pair_distance",
    "transition_distances",
    "window_positions",
]

DEFAULT_DELTA = 0.135
DEFAULT_K_COMP = 5
REFERENCE_STATURE = 1.75


def window_positions(primitives: list[MotionPrimitive], k_comp: int,
                     end: bool) -> np.ndarray:
    """Last (``end=True``) or first ``k_comp`` poses as start-frame world positions.

    Returns
    -------
    ndarray, shape (N, k_comp, J, 3)
    """
    for mp in primitives:
        if mp.n_frames < k_comp:
            raise ValueError(f"primitive {mp.name!r} has {mp.n_frames} frames < k_comp={k_comp}")
    if not primitives:
        return np.zeros((0, k_comp, 0, 3))
    sl = slice(-k_comp, None) if end else slice(0, k_comp)
    poses = np.stack([mp.poses[sl] for mp in primitives])            # (N, k, J, 3)
    root = np.stack([mp.root[sl] for mp in primitives])              # (N, k, 4)
    c, s = np.cos(root[..., 3])[..., None], np.sin(root[..., 3])[..., None]
    out = np.empty_like(poses)
    out[..., 0] = c * poses[..., 0] - s * poses[..., 1] + root[..., None, 0]
    out[..., 1] = s * poses[..., 0] + c * poses[..., 1] + root[..., None, 1]
    out[..., 2] = poses[..., 2] + root[..., None, 2]
    return out


def _flat(win: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Split (N, k, J, 3) windows into x, y, z arrays of shape (N, n)."""
    n = win.shape[0]
    return (win[..., 0].reshape(n, -1), win[..., 1].reshape(n, -1), win[..., 2].reshape(n, -1))


def align_windows(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float, float]:
    """Closed-form alignment of one window pair (Kovar et al. 2002).

    Parameters
    ----------
    a, b : ndarray, shape (k, J, 3)
        Window of ``mp_i`` (end) and of ``mp_j`` (start).

    Returns
    -------
    d : float
        Distance (unscaled): sqrt(sum of squared errors / k).
    theta, x0, y0 : float
        Rotation about z and floor translation applied to ``b``.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.shape != b.shape or a.ndim != 3 or a.shape[-1] != 3:
        raise ValueError(f"windows must both have shape (k, J, 3), got {a.shape} and {b.shape}")
    ax, ay, az = (a[..., i].ravel() for i in range(3))
    bx, by, bz = (b[..., i].ravel() for i in range(3))
    n = ax.size
    mx, my, nx, ny = ax.mean(), ay.mean(), bx.mean(), by.mean()
    c = np.dot(ax, bx) + np.dot(ay, by) - n * (mx * nx + my * ny)
    s = np.dot(ay, bx) - np.dot(ax, by) - n * (my * nx - mx * ny)
    theta = float(np.arctan2(s, c))
    ct, st = np.cos(theta), np.sin(theta)
    x0 = mx - (ct * nx - st * ny)
    y0 = my - (st * nx + ct * ny)
    ex = ax - (ct * bx - st * by + x0)
    ey = ay - (st * bx + ct * by + y0)
    ez = az - bz
    k = a.shape[0]
    d = float(np.sqrt((np.sum(ex * ex) + np.sum(ey * ey) + np.sum(ez * ez)) / k))
    return d, theta, float(x0), float(y0)


def pair_distance(a: np.ndarray, b: np.ndarray, stature: float = REFERENCE_STATURE) -> float:
    """The transition distance d_ij of one window pair (see the module docstring)."""
    return align_windows(a, b)[0] * (REFERENCE_STATURE / stature)


def transition_distances(end_windows: np.ndarray, start_windows: np.ndarray,
                         stature: float = REFERENCE_STATURE, rows: slice | None = None,
                         dtype: type = np.float64) -> np.ndarray:
    """Distances d_ij for all pairs (or a block of rows), vectorized.

    Parameters
    ----------
    end_windows : ndarray, shape (N, k, J, 3)
        Last k poses of every primitive (from :func:`window_positions`).
    start_windows : ndarray, shape (M, k, J, 3)
        First k poses of every primitive.
    stature : float
    rows : slice, optional
        Only these rows of ``end_windows``.
    dtype : numpy dtype
        Precision of the matrix products (float32 halves the time; the floor coordinates
        are centred first, so the error stays below about 1e-4 in d).

    Returns
    -------
    D : ndarray, shape (N or len(rows), M)
    """
    sse, k = _sse(end_windows if rows is None else end_windows[rows], start_windows, dtype)
    return (np.sqrt(np.maximum(sse, 0.0) / k) * (REFERENCE_STATURE / stature)).astype(
        np.float64, copy=False)


def _prepare(windows: np.ndarray, dtype: type) -> tuple[np.ndarray, ...]:
    """Per-primitive terms of the closed form: centred floor coordinates (x | y), the
    rotated ones (y | -x), heights, and the squared norm of everything."""
    x, y, z = (v.astype(dtype, copy=False) for v in _flat(windows))
    x_c, y_c = x - x.mean(1, keepdims=True), y - y.mean(1, keepdims=True)
    P = np.concatenate([x_c, y_c], axis=1)                   # (N, 2n)
    Q = np.concatenate([y_c, -x_c], axis=1)
    sq = np.einsum("ij,ij->i", P, P) + np.einsum("ij,ij->i", z, z)
    return P, Q, np.ascontiguousarray(z), sq


def _sse_tile(a: tuple[np.ndarray, ...], b: tuple[np.ndarray, ...]) -> np.ndarray:
    """Minimum summed squared error of every pair of two prepared blocks (closed form)."""
    A1, A2, az, sq_a = a
    B1, _, bz, sq_b = b
    c = A1 @ B1.T                                           # sum a.b (centred)
    s = A2 @ B1.T                                           # sum a x b (centred)
    sse = np.hypot(c, s, out=c)
    del s
    sse += az @ bz.T
    sse *= -2.0
    sse += sq_a[:, None]
    sse += sq_b[None, :]
    return sse


def _sse(ew: np.ndarray, start_windows: np.ndarray, dtype: type) -> tuple[np.ndarray, int]:
    """Minimum summed squared error of every pair (closed form), and k."""
    if ew.shape[1:] != start_windows.shape[1:]:
        raise ValueError(f"window shapes differ: {ew.shape} vs {start_windows.shape}")
    return _sse_tile(_prepare(ew, dtype), _prepare(start_windows, dtype)), ew.shape[1]


def build_transitions(end_windows: np.ndarray, start_windows: np.ndarray, delta: float,
                      stature: float = REFERENCE_STATURE, block: int | None = None,
                      progress=None, dtype: type = np.float64) -> csr_matrix:
    """Sparse matrix of the distances of all pairs with ``d_ij < delta``.

    Pairs with distance exactly 0 are stored as a tiny positive number so they stay in the
    sparsity pattern. Pairs are processed in tiles of ``block`` rows by about 4 million /
    ``block`` columns (some 16 to 32 MB per temporary array), so memory stays bounded and
    the operands stay in cache for large libraries.

    Returns
    -------
    scipy.sparse.csr_matrix, shape (N, M)
    """
    if not delta > 0:
        raise ValueError(f"delta must be positive, got {delta!r}")
    if end_windows.shape[1:] != start_windows.shape[1:]:
        raise ValueError(f"window shapes differ: {end_windows.shape} vs "
                         f"{start_windows.shape}")
    N, M = end_windows.shape[0], start_windows.shape[0]
    if block is None:
        block = 1024
    col_block = max(1, 4_000_000 // max(block, 1))
    rows_l, cols_l, vals_l = [], [], []
    scale = REFERENCE_STATURE / stature
    k = end_windows.shape[1]
    limit = (delta / scale) ** 2 * k          # d < delta  <=>  sse < limit
    B = _prepare(start_windows, dtype)
    for r0 in range(0, N, block):
        checkpoint("library")               # a cancelled request stops a long build here
        A = _prepare(end_windows[r0:r0 + block], dtype)
        for c0 in range(0, M, col_block):
            sse = _sse_tile(A, tuple(v[c0:c0 + col_block] for v in B))
            r, c = np.nonzero(sse < limit)
            rows_l.append(r + r0)
            cols_l.append(c + c0)
            d = np.sqrt(np.maximum(sse[r, c].astype(np.float64), 0.0) / k) * scale
            vals_l.append(np.maximum(d, 1e-12))
        if progress is not None:
            progress(min(block, N - r0))
    rows = np.concatenate(rows_l) if rows_l else np.zeros(0, int)
    cols = np.concatenate(cols_l) if cols_l else np.zeros(0, int)
    vals = np.concatenate(vals_l) if vals_l else np.zeros(0)
    return csr_matrix((vals, (rows, cols)), shape=(N, start_windows.shape[0]))


def largest_scc(adjacency: csr_matrix, nodes: np.ndarray | None = None) -> np.ndarray:
    """Indices of the largest strongly connected component (optionally within ``nodes``)."""
    if nodes is None:
        nodes = np.arange(adjacency.shape[0])
    nodes = np.asarray(nodes, dtype=np.int64)
    if nodes.size == 0:
        return nodes
    sub = adjacency[nodes][:, nodes]
    _, labels = connected_components(sub, directed=True, connection="strong")
    biggest = np.argmax(np.bincount(labels))
    return nodes[labels == biggest]


@dataclass(eq=False)
class MotionAutomaton:
    """Motion automaton ``MA = (MP, Delta, MP0)`` (Definition 2).

    Attributes
    ----------
    primitives : list of MotionPrimitive
        ``MP``: the states.
    transitions : scipy.sparse.csr_matrix, shape (N, N)
        ``Delta``: entry (i, j) holds d_ij for every kept transition ``(mp_i, mp_j)``.
    initial : ndarray of int
        ``MP0``: indices of the initial primitives.
    delta, k_comp : float, int
        Threshold and window used to build ``transitions``.
    """

    primitives: list[MotionPrimitive]
    transitions: csr_matrix
    initial: np.ndarray
    delta: float = DEFAULT_DELTA
    k_comp: int = DEFAULT_K_COMP
    _index: dict[str, int] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        n = len(self.primitives)
        if self.transitions.shape != (n, n):
            raise ValueError(f"transitions must be ({n}, {n}), got {self.transitions.shape}")
        self.transitions = csr_matrix(self.transitions)
        self.transitions.sort_indices()
        self.initial = np.asarray(self.initial, dtype=np.int64)
        self._index = {mp.name: i for i, mp in enumerate(self.primitives)}

    @property
    def n_states(self) -> int:
        return len(self.primitives)

    @property
    def n_transitions(self) -> int:
        return int(self.transitions.nnz)

    @property
    def indptr(self) -> np.ndarray:
        """CSR row pointers: successors of i are ``indices[indptr[i]:indptr[i + 1]]``."""
        return self.transitions.indptr

    @property
    def indices(self) -> np.ndarray:
        return self.transitions.indices

    def successors(self, i: int) -> np.ndarray:
        """Indices j with ``(mp_i, mp_j)`` in Delta (sorted), as an int array."""
        if not 0 <= i < self.n_states:
            raise ValueError(f"state index must be in [0, {self.n_states}), got {i}")
        t = self.transitions
        return t.indices[t.indptr[i]:t.indptr[i + 1]]

    def distance(self, i: int, j: int) -> float:
        """d_ij of a kept transition; ``inf`` when ``(mp_i, mp_j)`` is not in Delta."""
        v = self.transitions[i, j]
        return float(v) if v != 0 else float("inf")

    def index(self, name: str) -> int:
        try:
            return self._index[name]
        except KeyError:
            raise ValueError(f"no primitive named {name!r}") from None

    def to_networkx(self):
        """A ``networkx.DiGraph`` with node attribute ``name``/``task``, edge ``distance``."""
        import networkx as nx

        g = nx.DiGraph()
        for i, mp in enumerate(self.primitives):
            g.add_node(i, name=mp.name, task=mp.task, initial=bool(i in set(self.initial)))
        coo = self.transitions.tocoo()
        g.add_weighted_edges_from(zip(coo.row.tolist(), coo.col.tolist(), coo.data.tolist()),
                                  weight="distance")
        return g
