"""The correlation of the map with a scan's stamps (004 §7): the score maps of every heading, and the score at
any pose by the definition.

- :func:`score_maps` ``(M_values, T, origin, method) -> (n, H, W)``: every stamp T_n against the map, by batched
  FFTs (``"batched"``), ``scipy.signal.fftconvolve`` per heading or the definition (``"direct"``); the index
  mapping is derived in :mod:`slamlab.correlation.algorithm`, which re-exports it.
- :func:`pose_scores` ``(M_values, samples, poses) -> (m,)``: ``Σ T·M`` of a scan's
  :class:`~slamlab.correlation.samples.ScanSamples` at any poses, on the search's grid or off it (ours, issue 25);
  :func:`pose_marks` the marked cells behind each score (:class:`PoseMarks`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.signal import fftconvolve

from .._validate import as_finite_array, check_choice, check_int
from ._fft import MapSpectrum
from .samples import ScanSamples

__all__ = ["PoseMarks", "pose_marks", "pose_scores", "score_maps"]

_METHODS = ("batched", "fftconvolve", "direct")


def _direct_scores(Mv: np.ndarray, T: np.ndarray, o: int) -> np.ndarray:
    """The definition Σ_{i,j} T[i, j]·M[row + i - o, col + j - o] (slow reference; loops over T's cells)."""
    H, W = Mv.shape
    n, S, _ = T.shape
    pad = np.zeros((H + 2 * S, W + 2 * S))
    pad[S:S + H, S:S + W] = Mv
    out = np.zeros((n, H, W))
    for i, j in zip(*np.nonzero(np.any(T != 0, axis=0)), strict=True):
        block = pad[S + i - o:S + i - o + H, S + j - o:S + j - o + W]
        out += T[:, i, j][:, None, None] * block[None]
    return out


def score_maps(M_values, T, origin: int, *, method: str = "batched", dtype=np.float64,
               workers: int | None = None) -> np.ndarray:
    """Correlation of every T_n with M, indexed by the robot's cell: ``D[n, row, col]`` (004 §7).

    ``D[n, row, col] = Σ_{i,j} T_n[i, j]·M[row + i - o, col + j - o]`` with M = 0
    (= a_n) outside the map; it is the block of 004's ``C_n`` whose robot cell lies
    in the map (see the module docstring for the index mapping).

    Parameters
    ----------
    M_values : array_like, shape (H, W)
        The map with 004's constants (see :func:`slamlab.scans.grid_to_values`).
    T : array_like, shape (n, S, S)
        From :func:`~slamlab.correlation.scan_stamps`.
    origin : int
        ``o``, the robot's cell in T.
    method : {"batched", "fftconvolve", "direct"}
        One ``scipy.fft`` rfft2 of all T_n against the map's rfft2 computed once;
        ``scipy.signal.fftconvolve`` per heading; or the definition (slow).
    dtype : numpy dtype
        FFT precision of the batched method (float64 or float32).
    workers : int, optional
        ``scipy.fft`` worker threads of the batched method.

    Returns
    -------
    numpy.ndarray, shape (n, H, W)

    Examples
    --------
    >>> M = np.array([[0., 1.], [2., 3.]])
    >>> T = np.zeros((1, 4, 4)); T[0, 2, 3] = 1.0  # robot at T[2, 2], cell one column to its right
    >>> score_maps(M, T, 2).round(9).tolist()
    [[[1.0, 0.0], [3.0, 0.0]]]
    """
    Mv = as_finite_array(M_values, "M_values", ndim=2)
    if Mv.size == 0:
        raise ValueError(f"`M_values` must not be empty; got shape {Mv.shape}")
    T = as_finite_array(T, "T")
    if T.ndim != 3 or T.shape[1] != T.shape[2] or T.shape[1] < 1:
        raise ValueError(f"`T` must have shape (n, S, S); got shape {T.shape}")
    o = check_int(origin, "origin", minimum=0, maximum=T.shape[1] - 1)
    method = check_choice(method, "method", _METHODS)
    if method == "batched":
        return MapSpectrum(Mv, T.shape[1], o, dtype, workers).scores(T)
    if method == "direct":
        return _direct_scores(Mv, T, o)
    H, W = Mv.shape
    S = T.shape[1]
    out = np.empty((T.shape[0], H, W))
    for n in range(T.shape[0]):
        full = fftconvolve(Mv, T[n, ::-1, ::-1], mode="full")  # = correlation of M with T_n
        a0 = S - 1 - o  # robot row = a + o - (S - 1)
        out[n] = full[a0:a0 + H, a0:a0 + W]
    return out


@dataclass(frozen=True, eq=False)  # arrays: compare fields explicitly, not with ==
class PoseMarks:
    """The marked stamp cells of one pose: each cell once, the sample written last winning (ours, issue 25).

    Attributes
    ----------
    row, col : numpy.ndarray of int, shape (k,)
        The map cell of each mark (possibly outside the map).
    stamp : numpy.ndarray, shape (k,)
        The stamp's value there (the samples' ``free_value`` or ``obs_value``).
    map : numpy.ndarray, shape (k,)
        The map's value there (0 outside the map).
    is_obs : numpy.ndarray of bool, shape (k,)
        An obstacle sample wrote the mark (else a free one).
    """

    row: np.ndarray
    col: np.ndarray
    stamp: np.ndarray
    map: np.ndarray
    is_obs: np.ndarray


def _check_pose_args(M_values, samples, poses) -> tuple[np.ndarray, np.ndarray]:
    """The map and the ``(m, 3)`` poses of :func:`pose_scores` / :func:`pose_marks`, checked."""
    Mv = as_finite_array(M_values, "M_values", ndim=2)
    if not isinstance(samples, ScanSamples):
        raise TypeError(f"`samples` must be a ScanSamples (scan_samples, joined_samples); got {type(samples).__name__}")
    try:
        P = np.asarray(poses, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"`poses` must be numbers of shape (m, 3); got {type(poses).__name__}") from None
    if P.ndim not in (1, 2) or P.shape[-1] != 3:
        raise ValueError(f"`poses` must have shape (m, 3) or (3,) = (x, y, heading_rad); got shape {P.shape}")
    return Mv, P.reshape(-1, 3)


def _marks_at(Mv: np.ndarray, samples: ScanSamples, P: np.ndarray):
    """Yield ``(m, last, row, col, idx, vals, kind, flat)`` for each finite pose ``P[m]`` not far outside the map:
    every sample's map cell ``row, col`` (flat index ``idx`` into the padded map ``flat``), its value ``vals`` and
    kind (``kind``: obstacle), and ``last``, the samples that wrote their cell last (one per marked cell).

    At a grid pose (integer cell) the samples are rasterised exactly as the search's stamps (the heading modulo 90°
    in float32, then the quarter turn on integer offsets); off the grid the fractional part of the position is
    added before rounding. Poses more than ``4(H + W)`` cells out are skipped.
    """
    H, W = Mv.shape
    free, obs = samples.free, samples.obs
    pts = np.vstack([free.reshape(-1, 2), obs.reshape(-1, 2)])
    n_free = free.shape[0]
    vals = np.concatenate([np.full(n_free, float(samples.free_value)),
                           np.broadcast_to(np.asarray(samples.obs_value, dtype=float), (obs.shape[0],))])
    kind = np.arange(pts.shape[0]) >= n_free
    reach = float(np.sqrt(np.max(np.sum(pts ** 2, axis=1)))) if pts.size else 0.0
    pad = int(np.ceil(reach)) + 3
    Mp = np.zeros((H + 2 * pad, W + 2 * pad))
    Mp[pad:pad + H, pad:pad + W] = Mv
    flat, Wp = Mp.ravel(), W + 2 * pad
    seen = np.full(Mp.size, -1, dtype=np.int64)
    order = np.arange(pts.shape[0])
    px, py = pts[:, 0].astype(np.float32), pts[:, 1].astype(np.float32)
    last_h = None
    for m, (x, y, h) in enumerate(P):
        if not (np.isfinite(x) and np.isfinite(y)) or abs(x) > 4 * (H + W) or abs(y) > 4 * (H + W):
            continue
        if h != last_h:  # the samples turned by the heading's base (mod 90°), once per run of equal headings
            q = int(np.floor(np.mod(h, 2 * np.pi) / (np.pi / 2) + 1e-9)) % 4
            b = float(np.mod(h, np.pi / 2))
            b = 0.0 if b > np.pi / 2 - 1e-9 else round(b, 12)
            c, s = np.float32(np.cos(b)), np.float32(np.sin(b))
            xr = c * px
            xr -= s * py
            yr = s * px
            yr += c * py
            xr64, yr64, last_h = xr.astype(np.float64), yr.astype(np.float64), h
        tx, ty = np.floor(x + 0.5), np.floor(y + 0.5)
        fx, fy = x - tx, y - ty
        for _ in range(q):  # the fractional offset in the base heading's frame: R_q⁻¹ (x, y) = (y, -x)
            fx, fy = fy, -fx
        if fx == 0.0 and fy == 0.0:  # a grid pose: float32 rounding, as the stamps
            i = np.floor(xr + np.float32(0.5)).astype(np.int64)
            j = np.floor(yr + np.float32(0.5)).astype(np.int64)
        else:
            i = np.floor(xr64 + (fx + 0.5)).astype(np.int64)
            j = np.floor(yr64 + (fy + 0.5)).astype(np.int64)
        for _ in range(q):  # quarter turns on the integer offsets: (i, j) -> (-j, i)
            i, j = -j, i
        col, row = i + int(tx), j + int(ty)
        inside = (row >= -pad) & (row < H + pad) & (col >= -pad) & (col < W + pad)
        idx = np.where(inside, (row + pad) * Wp + (col + pad), 0)
        seen[idx] = order  # the last write of a cell wins, as in the stamp
        last = (seen[idx] == order) & inside
        seen[idx] = -1
        yield m, last, row, col, idx, vals, kind, flat


def pose_scores(M_values, samples: ScanSamples, poses) -> np.ndarray:
    """The correlation ``Σ T·M`` of a scan's samples at any poses, by the definition (ours, issue 25; 004 §7).

    The samples are drawn at each pose into the map's cells (free ones first, obstacle ones over them, each cell
    counted once; the map is 0 = ``a_n`` outside). At a pose on the search's grid (integer cell, a candidate
    heading) the value equals the search's ``D[n, row, col]`` (:func:`score_maps`) up to its FFT rounding; off
    the grid a sample counts in the cell it falls in.

    Parameters
    ----------
    M_values : array_like, shape (H, W)
        The map in 004's values (:func:`slamlab.scans.grid_to_values`), ``a_n`` = 0.
    samples : ScanSamples
        From :func:`~slamlab.correlation.samples.scan_samples` or :func:`~slamlab.correlation.samples.joined_samples`.
    poses : array_like, shape (m, 3)
        ``(x = col, y = row, heading_rad)`` [cells, rad].

    Returns
    -------
    numpy.ndarray, shape (m,)
        The scores (float64); NaN for a pose that is not finite or lies more than ``4(H + W)`` cells out.

    Examples
    --------
    >>> from slamlab.correlation.samples import scan_samples
    >>> from slamlab.scans import Scan
    >>> M = np.zeros((1, 6)); M[0, 4] = 1.0  # one obstacle cell, 3 cells right of the robot at column 1
    >>> pose_scores(M, scan_samples(Scan([0.0], [2.5], [True])), [[1, 0, 0.0], [1, 0, np.pi], [np.nan, 0, 0]])
    array([ 1.,  0., nan])
    """
    Mv, P = _check_pose_args(M_values, samples, poses)
    out = np.full(P.shape[0], np.nan)
    for m, last, _row, _col, idx, vals, _kind, flat in _marks_at(Mv, samples, P):
        out[m] = float(np.dot(vals[last], flat[idx[last]]))
    return out


def pose_marks(M_values, samples: ScanSamples, poses) -> list[PoseMarks | None]:
    """The marks behind :func:`pose_scores` at each pose: where each lands, its value and the map's (ours, issue 25).

    Parameters
    ----------
    M_values : array_like, shape (H, W)
        The map in 004's values, ``a_n`` = 0.
    samples : ScanSamples
        The scan's samples.
    poses : array_like, shape (m, 3)
        ``(x = col, y = row, heading_rad)`` [cells, rad].

    Returns
    -------
    list of PoseMarks or None
        One per pose (None where :func:`pose_scores` gives NaN); ``Σ stamp·map`` is the pose's score.

    Examples
    --------
    >>> from slamlab.correlation.samples import scan_samples
    >>> from slamlab.scans import Scan
    >>> mk = pose_marks(np.zeros((1, 6)), scan_samples(Scan([0.0], [1.5], [True])), [[0, 0, 0.0]])[0]
    >>> mk.col.tolist(), mk.stamp.tolist(), mk.is_obs.tolist()
    ([0, 1, 2], [-1.0, -1.0, 1.0], [False, False, True])
    """
    Mv, P = _check_pose_args(M_values, samples, poses)
    out: list[PoseMarks | None] = [None] * P.shape[0]
    for m, last, row, col, idx, vals, kind, flat in _marks_at(Mv, samples, P):
        out[m] = PoseMarks(row[last], col[last], vals[last], flat[idx[last]], kind[last])
    return out
