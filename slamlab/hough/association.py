"""Associating lines between scans and the line-history matrix L[n, i] (004 §Hough SLAM).

004's probability P_{i,j} (its formula was an image and is lost) rests on two facts:
scans are frequent, so (1) a line's accumulator peak barely moves between scans and
(2) the distances between parallel lines do not change. **Our form** (labelled as such
in the notebook)::

    P_ij = exp(-(Δrho_ij/a)² - (Δθ_ij/a_θ)²) · (1 + Σ_k max_m exp(-((s_im - s_jk)/b)²)) / (1 + n_j)

with Δrho, Δθ the peak displacement between new line i and old line j, k running over
the n_j old lines parallel to j (signed distance s_jk = rho_k - rho_j) and m over the new
lines parallel to i (s_im). As 004 advises, a = b = the largest displacement between
scans; a_θ is the largest rotation. Each row of P takes its argmax (004).
"""

from __future__ import annotations

import math

import numpy as np

from .._validate import as_finite_array, check_int, check_positive
from .lines import Lines, align_lines, line_difference

__all__ = ["LineHistory", "associate_lines", "association_probability"]


def _parallel_offsets(rho, theta, tol):
    """Signed offsets s[j, k] = rho_k' - rho_j of lines k parallel to j (NaN elsewhere, and on the diagonal)."""
    d_rho, d_theta = line_difference(rho[None, :], theta[None, :], rho[:, None], theta[:, None])
    par = np.abs(d_theta) <= tol
    np.fill_diagonal(par, False)
    return np.where(par, d_rho, np.nan)


def association_probability(new: Lines, old: Lines, *, a: float, b: float | None = None,
                            a_theta_rad: float = math.radians(5.0),
                            parallel_tol_rad: float = math.radians(3.0)) -> np.ndarray:
    """Matrix P[i, j]: probability that new line i is old line j (004; the form is ours).

    Parameters
    ----------
    new, old : Lines
        Lines of the new scan (rows) and of the previous one (columns), in one frame
        (predict ``old`` with odometry first when it is available).
    a, b : float
        Largest displacement between scans, in rho units; ``b`` defaults to ``a`` (004: a = b).
    a_theta_rad : float
        Largest rotation between scans.
    parallel_tol_rad : float
        Lines closer than this in θ count as parallel.

    Returns
    -------
    (len(new), len(old)) array in [0, 1].

    Examples
    --------
    Two parallel walls 4 apart and a cross wall, seen again after a move of 0.3:

    >>> old = Lines(np.array([1.0, 5.0, 3.0]), np.array([0.0, 0.0, np.pi / 2 - 0.01]), np.ones(3))
    >>> new = Lines(np.array([4.7, 0.7, 3.0]), np.array([0.0, 0.0, np.pi / 2 - 0.01]), np.ones(3))
    >>> associate_lines(association_probability(new, old, a=1.0)).tolist()
    [1, 0, 2]
    """
    for name, lines in (("new", new), ("old", old)):
        if not isinstance(lines, Lines):
            raise TypeError(f"`{name}` must be Lines; got {type(lines).__name__}")
    a = check_positive(a, "a")
    b = a if b is None else check_positive(b, "b")
    a_theta = check_positive(a_theta_rad, "a_theta_rad")
    tol = check_positive(parallel_tol_rad, "parallel_tol_rad", allow_zero=True)
    if len(new) == 0 or len(old) == 0:
        return np.zeros((len(new), len(old)))
    d_rho, d_theta = line_difference(new.rho[:, None], new.theta_rad[:, None], old.rho[None, :],
                                     old.theta_rad[None, :])
    P = np.exp(-((d_rho / a) ** 2) - (d_theta / a_theta) ** 2)
    s_new = _parallel_offsets(new.rho, new.theta_rad, tol)  # (I, M)
    s_old = _parallel_offsets(old.rho, old.theta_rad, tol)  # (J, K)
    # offsets run along each line's own normal: when old j's nearest form to new i is the flipped
    # one (-rho, θ ± π), the offsets of j's parallels change sign
    k = np.round((old.theta_rad[None, :] - new.theta_rad[:, None]) / math.pi)
    sign = np.where(k % 2 == 0, 1.0, -1.0)  # (I, J)
    diff = s_new[:, None, None, :] - sign[:, :, None, None] * s_old[None, :, :, None]  # (I, J, K, M)
    with np.errstate(invalid="ignore"):
        g = np.exp(-((diff / b) ** 2))
    g = np.where(np.isnan(g), 0.0, g)
    best = g.max(axis=3)  # (I, J, K): best new partner for each old parallel k
    n_par = np.sum(~np.isnan(s_old), axis=1)  # (J,)
    P *= (1.0 + best.sum(axis=2)) / (1.0 + n_par[None, :])
    return P


def associate_lines(P, *, p_min: float = 0.05, one_to_one: bool = True) -> np.ndarray:
    """Row-wise argmax of P (004); ``-1`` where the best P is below ``p_min`` (a new line).

    ``one_to_one`` (our addition): when two new lines pick the same old one, the one with
    the higher P keeps it and the other becomes new.

    Parameters
    ----------
    P : array_like, shape (n_new, n_old)
        Association probabilities (:func:`association_probability`).
    p_min : float, default 0.05
        Below this a new line starts a new id.
    one_to_one : bool, default True
        At most one new line per old line.

    Returns
    -------
    numpy.ndarray of int, shape (n_new,)
        Index of the old line each new line continues, or -1.

    Examples
    --------
    >>> associate_lines(np.array([[0.9, 0.1], [0.8, 0.2], [0.01, 0.02]])).tolist()
    [0, -1, -1]
    """
    P = as_finite_array(P, "P", ndim=2)
    p_min = check_positive(p_min, "p_min", allow_zero=True)
    match = np.full(P.shape[0], -1, dtype=np.int64)
    if P.size == 0:
        return match
    j = P.argmax(axis=1)
    p = P[np.arange(P.shape[0]), j]
    ok = p >= p_min
    match[ok] = j[ok]
    if one_to_one:
        for col in np.unique(match[match >= 0]):
            rows = np.flatnonzero(match == col)
            if rows.size > 1:
                match[rows[rows != rows[np.argmax(p[rows])]]] = -1
    return match


class LineHistory:
    """The line-history matrix L[n, i] (004): line i's (rho, θ) in scan n, NaN when unseen.

    Line ids are global and given in order of first sighting. θ is stored *unwrapped*:
    each new sighting takes the representation nearest to the previous one, so a pose
    change is ``Δφ = θ_{n1,i} - θ_{n2,i}`` without a ±π ambiguity.

    Examples
    --------
    >>> h = LineHistory()
    >>> h.add_scan(Lines(np.array([2.0, 3.0]), np.array([0.0, 1.5]), np.array([9, 9])), np.array([-1, -1]))
    array([0, 1])
    >>> h.add_scan(Lines(np.array([-3.0]), np.array([-1.6]), np.array([9])), np.array([1]))
    array([1])
    >>> h.rho.tolist(), np.round(h.theta_rad, 4).tolist()
    ([[2.0, 3.0], [nan, 3.0]], [[0.0, 1.5], [nan, 1.5416]])
    """

    def __init__(self) -> None:
        self._rows: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self._last: dict[int, tuple[float, float]] = {}
        self.n_ids = 0

    def __len__(self) -> int:
        return len(self._rows)

    def add_scan(self, lines: Lines, match_ids) -> np.ndarray:
        """Append one scan: ``match_ids[m]`` is the id line m continues, or -1 for a new line.

        Returns the global ids of the scan's lines.

        Parameters
        ----------
        lines : Lines
            The scan's lines.
        match_ids : array_like of int, shape (L,)
            Global id each line continues, or -1 for a new line.

        Returns
        -------
        numpy.ndarray of int, shape (L,)
        """
        if not isinstance(lines, Lines):
            raise TypeError(f"`lines` must be Lines; got {type(lines).__name__}")
        match_ids = np.asarray(match_ids, dtype=np.int64).reshape(-1)
        if match_ids.size != len(lines):
            raise ValueError(f"`match_ids` must have one entry per line ({len(lines)}); got {match_ids.size}")
        if np.any(match_ids >= self.n_ids):
            raise ValueError(f"`match_ids` must be < {self.n_ids} (known ids) or -1; got {match_ids.max()}")
        ids = match_ids.copy()
        new = ids < 0
        ids[new] = self.n_ids + np.arange(int(new.sum()))
        self.n_ids += int(new.sum())
        rho, theta = lines.rho.astype(float).copy(), lines.theta_rad.astype(float).copy()
        for m in np.flatnonzero(~new):  # continue each known line in its previous representation
            _r0, t0 = self._last[int(ids[m])]
            rho[m], theta[m] = align_lines(rho[m], theta[m], t0)
        for m, i in enumerate(ids):
            self._last[int(i)] = (float(rho[m]), float(theta[m]))
        self._rows.append((ids, rho, theta, lines.votes.astype(np.int64).copy()))
        return ids

    def scan(self, n: int) -> tuple[np.ndarray, Lines]:
        """Ids and lines (unwrapped representation) of scan ``n``.

        Parameters
        ----------
        n : int
            Scan index (negative counts from the end).

        Returns
        -------
        ids : numpy.ndarray of int
        lines : Lines
        """
        n = check_int(n, "n", minimum=-len(self), maximum=len(self) - 1)
        ids, rho, theta, votes = self._rows[n]
        return ids, Lines(rho, theta, votes)

    def last_representation(self, ids) -> tuple[np.ndarray, np.ndarray]:
        """The last stored (rho, θ) of each id (unwrapped).

        Parameters
        ----------
        ids : array_like of int
            Global line ids.

        Returns
        -------
        rho, theta_rad : numpy.ndarray
        """
        pairs = np.array([self._last[int(i)] for i in np.asarray(ids).reshape(-1)]).reshape(-1, 2)
        return pairs[:, 0], pairs[:, 1]

    def _matrix(self, col: int) -> np.ndarray:
        out = np.full((len(self), self.n_ids), np.nan)
        for n, row in enumerate(self._rows):
            out[n, row[0]] = row[col]
        return out

    @property
    def rho(self) -> np.ndarray:
        """L as rho: ``(n_scans, n_ids)``, NaN where a line was not seen."""
        return self._matrix(1)

    @property
    def theta_rad(self) -> np.ndarray:
        """L as θ (unwrapped): ``(n_scans, n_ids)``."""
        return self._matrix(2)

    @property
    def seen(self) -> np.ndarray:
        """Boolean ``(n_scans, n_ids)``: line i seen in scan n."""
        out = np.zeros((len(self), self.n_ids), dtype=bool)
        for n, row in enumerate(self._rows):
            out[n, row[0]] = True
        return out
