"""Lines (rho, θ): equivalence, peaks above H_min, refinement, motion of lines (004 §Hough SLAM).

A line ``x·cos θ + y·sin θ = rho`` is the same as ``(-rho, θ ± π)``. Comparisons use
:func:`line_difference`, which takes the representation of the second line
closest in θ to the first.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._compiled import numba_enabled
from .._validate import as_finite_array, as_vector, check_int, check_positive
from .transform import HoughAccumulator

_MAX_CANDIDATES = 600

__all__ = [
    "Lines",
    "align_lines",
    "canonical_lines",
    "find_peaks",
    "line_difference",
    "merge_duplicates",
    "refine_lines",
    "transform_lines",
]


@dataclass(frozen=True)
class Lines:
    """A set of lines: ``rho``, ``theta_rad`` and the ``votes`` (points) behind each, all ``(L,)``.

    Attributes
    ----------
    rho : numpy.ndarray, shape (L,)
        Distance of each line from the sensor (the scan's range unit).
    theta_rad : numpy.ndarray, shape (L,)
        Direction of its normal [rad].
    votes : numpy.ndarray of int, shape (L,)
        Points behind each line.
    """

    rho: np.ndarray = field(repr=False)
    theta_rad: np.ndarray = field(repr=False)
    votes: np.ndarray = field(repr=False)

    def __len__(self) -> int:
        return int(self.rho.size)

    def __str__(self) -> str:
        parts = [f"({r:.2f}, {math.degrees(t):.1f}°, {int(n)})" for r, t, n in
                 zip(self.rho, self.theta_rad, self.votes, strict=True)]
        out, line = [], f"{len(self)} lines (rho, θ, votes):"
        for k, part in enumerate(parts):  # a few lines per text line: the text fits a notebook's output area
            piece = f" {part}" + ("," if k < len(parts) - 1 else "")
            if len(line) + len(piece) > 96:
                out.append(line)
                line = " "
            line += piece
        return "\n".join([*out, line])


def canonical_lines(rho, theta_rad) -> tuple[np.ndarray, np.ndarray]:
    """The representation with θ in [-π/2, π/2) (flipping rho's sign when θ moves by π).

    Parameters
    ----------
    rho : array_like
        Distances of the lines from the origin.
    theta_rad : array_like
        Directions of their normals [rad].

    Returns
    -------
    rho, theta_rad : numpy.ndarray
        The same lines, θ in [-π/2, π/2).

    Examples
    --------
    >>> r, t = canonical_lines(5.0, np.radians(135.0))
    >>> float(r), round(float(np.degrees(t)))
    (-5.0, -45)
    """
    rho = np.asarray(rho, dtype=float)
    theta = np.asarray(theta_rad, dtype=float)
    k = np.floor((theta + math.pi / 2) / math.pi)
    return np.where(k % 2 == 0, rho, -rho), theta - k * math.pi


def align_lines(rho, theta_rad, theta_ref_rad) -> tuple[np.ndarray, np.ndarray]:
    """The representation whose θ lies within ±π/2 of ``theta_ref_rad`` (broadcasts).

    Parameters
    ----------
    rho : array_like
        Distances of the lines from the origin.
    theta_rad : array_like
        Directions of their normals [rad].
    theta_ref_rad : array_like
        Reference direction [rad].

    Returns
    -------
    rho, theta_rad : numpy.ndarray
        The same lines, θ within ±π/2 of the reference.

    Examples
    --------
    >>> r, t = align_lines(-5.0, np.radians(-89.0), np.radians(89.0))
    >>> float(r), round(float(np.degrees(t)))
    (5.0, 91)
    """
    rho = np.asarray(rho, dtype=float)
    theta = np.asarray(theta_rad, dtype=float)
    ref = np.asarray(theta_ref_rad, dtype=float)
    k = np.round((theta - ref) / math.pi)
    return np.where(k % 2 == 0, rho, -rho), theta - k * math.pi


def line_difference(rho_a, theta_a_rad, rho_b, theta_b_rad) -> tuple[np.ndarray, np.ndarray]:
    """``(rho_a - rho_b', θ_a - θ_b')`` with ``(rho_b', θ_b')`` the form of line b nearest to θ_a.

    Broadcasts, so ``line_difference(r[:, None], t[:, None], r[None], t[None])`` gives
    all pairs. ``|Δθ| <= π/2``.

    Parameters
    ----------
    rho_a, theta_a_rad : array_like
        Lines a (rho, θ [rad]).
    rho_b, theta_b_rad : array_like
        Lines b.

    Returns
    -------
    d_rho, d_theta_rad : numpy.ndarray
        Differences, broadcast shape.

    Examples
    --------
    >>> d_rho, d_theta = line_difference(5.0, np.radians(89.5), -5.0, np.radians(-89.5))
    >>> round(float(d_rho), 9), round(float(np.degrees(d_theta)), 6)
    (0.0, -1.0)
    """
    rb, tb = align_lines(rho_b, theta_b_rad, theta_a_rad)
    return np.asarray(rho_a, dtype=float) - rb, np.asarray(theta_a_rad, dtype=float) - tb


def find_peaks(acc: HoughAccumulator, H_min: int, *, suppress_rho: float | None = None,
               suppress_theta_rad: float | None = None, max_lines: int | None = None) -> Lines:
    """Local maxima with at least ``H_min`` votes, false neighbours removed (004 §Hough SLAM).

    1. Candidates: cells equal to the maximum of their 3×3 neighbourhood (θ wraps to
       ``(-rho, θ ± π)``) and with ``H >= H_min`` (004: "at least H_min points lie on the line");
       a connected flat top counts once, at its centre (our choice).
    2. Suppression of false maxima "from discretisation and measurement noise": going down
       the candidates by votes, drop every one within ``suppress_rho`` and
       ``suppress_theta_rad`` of a line already kept, "keeping the line with more points".
       The two windows are ours (004 gives none): default 3·Δrho and 3·Δθ.

    Parameters
    ----------
    acc : HoughAccumulator
    H_min : int
        Smallest vote count of a line.
    suppress_rho, suppress_theta_rad : float, optional
        Suppression window.
    max_lines : int, optional
        Keep at most this many lines (the strongest).

    Returns
    -------
    Lines
        Sorted by votes, strongest first; θ in [-π/2, π/2).

    Examples
    --------
    >>> from slamlab.hough import hough_polar, line_scan
    >>> phi, r = line_scan(10.0, np.radians(45.0), r_max=16.0)
    >>> lines = find_peaks(hough_polar(phi, r, r_max=16.0), H_min=20)
    >>> len(lines), float(lines.rho[0]), round(float(np.degrees(lines.theta_rad[0])))
    (1, 10.0, 45)
    """
    if not isinstance(acc, HoughAccumulator):
        raise TypeError(f"`acc` must be a HoughAccumulator; got {type(acc).__name__}")
    H_min = check_int(H_min, "H_min", minimum=1)
    s_rho = 3 * acc.delta_rho if suppress_rho is None else check_positive(suppress_rho, "suppress_rho",
                                                                            allow_zero=True)
    s_theta = (3 * acc.delta_theta_rad if suppress_theta_rad is None
               else check_positive(suppress_theta_rad, "suppress_theta_rad", allow_zero=True))
    if max_lines is not None:
        max_lines = check_int(max_lines, "max_lines", minimum=1)
    H = acc.H
    if numba_enabled() and H.dtype == np.intp:  # the same groups, compiled (_kernels.peak_groups; issue 25)
        from ._kernels import peak_groups

        centre, votes, first = peak_groups(H, H_min, _MAX_CANDIDATES)
    else:
        centre, votes, first = _peak_groups(H, H_min)
    if votes.size == 0:
        return Lines(np.empty(0), np.empty(0), np.empty(0, dtype=np.int64))
    order = np.lexsort((first, -votes))  # by votes, ties by position: deterministic
    centre, votes = centre[order], votes[order]
    rho, theta = canonical_lines(acc.rho[0] + centre[:, 0] * acc.delta_rho,
                                 acc.theta_rad[0] + centre[:, 1] * acc.delta_theta_rad)
    keep = _greedy_keep(rho, theta, s_rho, s_theta)[:max_lines]
    return Lines(rho[keep].astype(float), theta[keep].astype(float), votes[keep].astype(np.int64))


_NB_DI = np.array([-1, -1, -1, 0, 0, 1, 1, 1])[:, None]
_NB_DK = np.array([-1, 0, 1, -1, 1, -1, 0, 1])[:, None]


def _peak_groups(H, H_min: int):
    """Step 1 of :func:`find_peaks` (numpy): the flat tops' centres ``(i, k)``, votes and first flat index.

    Parameters
    ----------
    H : numpy.ndarray, shape (n_rho, n_theta)
        Votes.
    H_min : int
        Smallest vote count.

    Returns
    -------
    centre : numpy.ndarray, shape (G, 2)
        Mean (rho index, θ index) of each group of adjacent local maxima.
    votes, first : numpy.ndarray of int, shape (G,)
        Its votes and smallest flat index ``i·n_theta + k``.
    """
    n_theta = H.shape[1]
    empty = np.empty((0, 2)), np.empty(0, dtype=np.int64), np.empty(0, dtype=np.int64)
    n_rho = H.shape[0]
    # candidates in (rho, θ) row-major order; found on the θ-major counts, which are contiguous for
    # hough_polar (a 2-D nonzero on the transposed view cost more than the rest of the search)
    flat = np.flatnonzero(H_min <= H.T)
    if flat.size == 0:
        return empty
    flat = np.sort(flat % n_rho * n_theta + flat // n_rho)
    i, k = flat // n_theta, flat % n_theta
    value = H[i, k]
    # the 8 neighbours of every candidate in one gather (rho runs off the axis into nothing: edge cells
    # compare with themselves; θ wraps: the column before -90° is +89° with rho flipped, and back)
    ii = np.clip(i + _NB_DI, 0, n_rho - 1)
    kk = k + _NB_DK
    wrap = (kk < 0) | (kk >= n_theta)
    is_max = (value >= H[np.where(wrap, n_rho - 1 - ii, ii), kk % n_theta]).all(axis=0)
    i, k, value = i[is_max], k[is_max], value[is_max]
    if i.size == 0:
        return empty
    if i.size > _MAX_CANDIDATES:  # keep the pairwise grouping below small
        top = np.sort(np.argsort(-value, kind="stable")[:_MAX_CANDIDATES])
        i, k, value = i[top], k[top], value[top]
    # a flat top (equal votes over several bins, common when Δrho is coarse) is one candidate at its centre
    adjacent = (np.abs(i[:, None] - i[None, :]) <= 1) & (np.abs(k[:, None] - k[None, :]) <= 1)
    # ... and across the θ wrap, where (rho, -90°) continues as (-rho, 90°)
    adjacent |= ((k[:, None] == 0) & (k[None, :] == n_theta - 1)
                 & (np.abs(i[:, None] - (n_rho - 1 - i[None, :])) <= 1))
    label = _components(adjacent)
    count = np.bincount(label)
    wrapped = (np.bincount(label, weights=k == 0) > 0) & (np.bincount(label, weights=k == n_theta - 1) > 0)
    move = wrapped[label] & (k >= n_theta / 2)
    ii = np.where(move, n_rho - 1 - i, i).astype(float)
    kk = np.where(move, k - n_theta, k).astype(float)
    centre = np.column_stack([np.bincount(label, weights=ii) / count, np.bincount(label, weights=kk) / count])
    votes = np.zeros(count.size, dtype=np.int64)
    votes[label] = value
    first = np.full(count.size, H.size)
    np.minimum.at(first, label, i * n_theta + k)
    return centre, votes, first


def _components(adjacent):
    """Connected-component labels ``0..K-1`` of a small adjacency matrix, edges undirected (candidates: tens).

    Minimum-label propagation with pointer jumping; the same partition as
    ``scipy.sparse.csgraph.connected_components`` without building a sparse matrix (which cost
    more than the rest of the peak search, issue 17). Callers only use the partition.
    """
    m = adjacent.shape[0]
    adjacent = adjacent | adjacent.T
    label = np.arange(m)
    while True:
        new = np.minimum(label, np.where(adjacent, label[None, :], m).min(axis=1, initial=m))
        new = new[new]
        if np.array_equal(new, label):
            return np.unique(label, return_inverse=True)[1]
        label = new


def _greedy_keep(rho, theta, s_rho, s_theta):
    """Indices kept when going down the (sorted) lines and dropping those close to a kept one.

    Parameters
    ----------
    rho, theta : numpy.ndarray, shape (L,)
        Lines, strongest first.
    s_rho, s_theta : float
        Suppression windows (rho unit, rad).

    Returns
    -------
    numpy.ndarray of intp
        Indices of the lines kept, ascending.
    """
    if numba_enabled():  # the same loop, compiled (_kernels.greedy_keep; issue 25)
        from ._kernels import greedy_keep

        return greedy_keep(np.asarray(rho, dtype=float), np.asarray(theta, dtype=float), float(s_rho), float(s_theta))
    d_rho, d_theta = line_difference(rho[:, None], theta[:, None], rho[None, :], theta[None, :])
    close = (np.abs(d_rho) <= s_rho + 1e-9) & (np.abs(d_theta) <= s_theta + 1e-9)
    keep = np.ones(rho.size, dtype=bool)
    for m in range(rho.size):  # greedy over lines (tens), not over points
        if keep[m]:
            later = close[m].copy()
            later[: m + 1] = False
            keep[later] = False
    return np.flatnonzero(keep)


def merge_duplicates(lines: Lines, *, rho_tol: float, theta_tol_rad: float) -> Lines:
    """Drop lines within ``rho_tol`` and ``theta_tol_rad`` of one with more votes (our addition).

    After the refit two peaks (a false neighbour, or the two sides of the θ = ±90° seam) may
    settle on the same wall.

    Parameters
    ----------
    lines : Lines
        Candidate lines.
    rho_tol : float
        rho tolerance (range unit).
    theta_tol_rad : float
        θ tolerance [rad].

    Returns
    -------
    Lines
        The lines kept, in input order.

    Examples
    --------
    >>> dup = Lines(np.array([5.0, -5.01, 2.0]), np.array([1.57, -1.5716, 0.0]), np.array([30, 40, 20]))
    >>> merge_duplicates(dup, rho_tol=0.1, theta_tol_rad=0.01).votes.tolist()
    [40, 20]
    """
    if not isinstance(lines, Lines):
        raise TypeError(f"`lines` must be Lines; got {type(lines).__name__}")
    rho_tol = check_positive(rho_tol, "rho_tol", allow_zero=True)
    theta_tol = check_positive(theta_tol_rad, "theta_tol_rad", allow_zero=True)
    order = np.argsort(-lines.votes, kind="stable")
    keep = order[_greedy_keep(lines.rho[order], lines.theta_rad[order], rho_tol, theta_tol)]
    return Lines(lines.rho[keep], lines.theta_rad[keep], lines.votes[keep])


def refine_lines(lines: Lines, bearings_rad, ranges, *, band: float = 1.0, n_iter: int = 3,
                 max_gap: float | None = None) -> Lines:
    """Total-least-squares refit of each line on the scan points within ``band`` of it (our addition).

    004 reads (rho, θ) off the accumulator cell (resolution Δrho, Δθ); this refit brings them
    below the resolution. Each line keeps its representation (θ moves by less than π/2);
    a line with fewer than 2 points in its band is returned unchanged. ``votes`` becomes
    the number of points used. After each fit the band shrinks to three robust standard
    deviations of the residuals (1.4826·MAD; between ``band/10`` and ``band``), which drops
    the corner points of perpendicular walls.

    With ``max_gap`` the points in the band are cut where consecutive ones (along the line)
    are more than ``max_gap`` apart and only the segment with the most points is fitted:
    a Hough peak may collect points of several objects that happen to be collinear in
    this scan only.

    Parameters
    ----------
    lines : Lines
        Lines to refit (e.g. accumulator peaks).
    bearings_rad : array_like, shape (N,)
        Beam directions of the scan [rad].
    ranges : array_like, shape (N,)
        Their ranges.
    band : float, default 1.0
        Initial half-width of the band of points fitted to a line (range unit).
    n_iter : int, default 3
        Refits per line.
    max_gap : float, optional
        Split the band's points at gaps longer than this and fit the largest segment; None keeps all.

    Returns
    -------
    Lines
        Refitted lines, ``votes`` = points used.

    Examples
    --------
    >>> phi = np.radians(np.arange(-40.0, 41.0))
    >>> r = 7.3 / np.cos(phi - 0.01)                # the line rho = 7.3, θ = 0.01 rad
    >>> rough = Lines(np.array([7.0]), np.array([0.0]), np.array([81]))
    >>> fine = refine_lines(rough, phi, r)
    >>> round(float(fine.rho[0]), 9), round(float(fine.theta_rad[0]), 9)
    (7.3, 0.01)
    """
    if not isinstance(lines, Lines):
        raise TypeError(f"`lines` must be Lines; got {type(lines).__name__}")
    phi = as_finite_array(bearings_rad, "bearings_rad", ndim=1)
    r = as_finite_array(ranges, "ranges", ndim=1)
    if phi.shape != r.shape:
        raise ValueError(f"`bearings_rad` and `ranges` must have the same length; got {phi.size} and {r.size}")
    band = check_positive(band, "band")
    n_iter = check_int(n_iter, "n_iter", minimum=1)
    gap = None if max_gap is None else check_positive(max_gap, "max_gap")
    if len(lines) == 0:
        return lines
    ok = r > 0
    x, y = r[ok] * np.cos(phi[ok]), r[ok] * np.sin(phi[ok])
    rho, theta = lines.rho.copy(), lines.theta_rad.copy()
    n = np.zeros(rho.size)
    band_l = np.full(rho.size, band)
    for _ in range(n_iter):
        dist = np.abs(np.multiply.outer(np.cos(theta), x) + np.multiply.outer(np.sin(theta), y) - rho[:, None])
        w = (dist <= band_l[:, None]).astype(float)
        if gap is not None:
            along = np.multiply.outer(-np.sin(theta), x) + np.multiply.outer(np.cos(theta), y)
            for m in range(rho.size):  # per line (a dozen), vectorised over its points
                idx = np.flatnonzero(w[m])
                if idx.size < 2:
                    continue
                order = np.argsort(along[m, idx])
                seg = np.concatenate([[0], np.cumsum(np.diff(along[m, idx[order]]) > gap)])
                best = np.bincount(seg).argmax()
                w[m, idx[order[seg != best]]] = 0.0
        n = w.sum(axis=1)
        good = n >= 2
        nn = np.where(good, n, 1.0)
        cx, cy = w @ x / nn, w @ y / nn
        sxx = w @ (x * x) / nn - cx * cx
        syy = w @ (y * y) / nn - cy * cy
        sxy = w @ (x * y) / nn - cx * cy
        direction = 0.5 * np.arctan2(2 * sxy, sxx - syy)  # the line's direction (largest spread)
        normal = direction + math.pi / 2
        k = np.round((normal - theta) / math.pi)  # keep the representation: θ moves by < π/2
        new_theta = normal - k * math.pi
        new_rho = cx * np.cos(new_theta) + cy * np.sin(new_theta)
        rho = np.where(good, new_rho, rho)
        theta = np.where(good, new_theta, theta)
        # next band: 3 robust sigmas of the residuals (MAD), between band/10 and band
        res = np.abs(np.multiply.outer(np.cos(theta), x) + np.multiply.outer(np.sin(theta), y) - rho[:, None])
        res = np.sort(np.where(w > 0, res, np.inf), axis=1)
        mid = np.take_along_axis(res, np.maximum(0, (n.astype(np.intp) - 1) // 2)[:, None], axis=1)[:, 0]
        band_l = np.where(good, np.clip(3 * 1.4826 * mid, band / 10, band), band_l)
    return Lines(rho, theta, n.astype(np.int64))


def transform_lines(rho, theta_rad, pose) -> tuple[np.ndarray, np.ndarray]:
    """Lines of frame i seen from frame j, j's pose in i being ``(Δx, Δy, Δφ)`` (004, reconstructed).

    ``θ_j = θ_i - Δφ``, ``rho_j = rho_i - (Δx·cos θ_i + Δy·sin θ_i)``; θ is not wrapped (the
    representation moves continuously, which :func:`~slamlab.hough.pose_from_two_lines` needs).

    Parameters
    ----------
    rho : array_like
        Distances of the lines from the origin.
    theta_rad : array_like
        Directions of their normals [rad].
    pose : array_like, shape (3,)
        Frame j's pose in frame i ``(Δx, Δy, Δφ)`` (range unit, rad).

    Returns
    -------
    rho, theta_rad : numpy.ndarray
        The lines in frame j.

    Examples
    --------
    >>> r, t = transform_lines(10.0, 0.0, (3.0, 1.0, 0.1))
    >>> float(r), float(t)
    (7.0, -0.1)
    """
    rho = as_finite_array(rho, "rho")
    theta = as_finite_array(theta_rad, "theta_rad")
    dx, dy, dphi = as_vector(pose, "pose", 3)
    return rho - (dx * np.cos(theta) + dy * np.sin(theta)), theta - dphi

