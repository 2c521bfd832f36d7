"""Hough transforms of a rangefinder scan (004 §"optimised Hough transform").

Line model (004 eq. (4), reconstructed): ``x·cos θ + y·sin θ = rho``, θ in [-90°, 90°).

* :func:`hough_polar` — 004's optimised transform: each scan point (φ_i, r_i)
  votes straight from polar coordinates, ``rho_i(θ) = r_i·cos(θ - φ_i)`` (eq. (7)),
  cost ``N·180/Δθ`` (eq. (8)); rho is measured from the sensor, in
  ``[-r_max, r_max]``.
* :func:`hough_classic` — the classic transform of a rasterised image
  (eq. (5)), ``rho_{x,y}(θ) = x·cos θ + y·sin θ`` with the origin at pixel (0, 0),
  rho in ``±ceil(D/Δrho)`` with D the image diagonal (Matlab's ``hough``), cost
  ``(r_max/Δr)²·180/Δθ`` (eq. (6)). :func:`lines_about_centre` re-expresses its
  lines about the scan centre.

Both return a :class:`HoughAccumulator`: votes ``H[rho index, θ index]`` with the
two axis arrays that turn indices into (rho, θ) (004: "the result is not only H but
two more arrays").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._compiled import numba_enabled
from .._validate import as_finite_array, as_image, as_vector, check_int, check_positive

__all__ = [
    "HoughAccumulator",
    "hough_classic",
    "hough_cost",
    "hough_polar",
    "line_scan",
    "lines_about_centre",
    "rasterise_scan",
    "theta_axis",
]


@dataclass(frozen=True)
class HoughAccumulator:
    """Votes ``H`` of shape ``(n_rho, n_theta)`` with the axes ``rho`` and ``theta_rad``.

    ``H[i, k]`` counts the points on the line ``(rho[i], theta_rad[k])``. 004 quotes
    the size as θ×rho ("180×33"); :attr:`size_theta_rho` gives it that way round.

    Attributes
    ----------
    H : numpy.ndarray of int, shape (n_rho, n_theta)
        Votes.
    rho : numpy.ndarray, shape (n_rho,)
        rho of each row (pixels, or the scan's range unit).
    theta_rad : numpy.ndarray, shape (n_theta,)
        θ of each column [rad], in [-π/2, π/2).
    delta_rho : float
        rho bin width.
    delta_theta_rad : float
        θ bin width [rad].
    """

    H: np.ndarray = field(repr=False)
    rho: np.ndarray = field(repr=False)
    theta_rad: np.ndarray = field(repr=False)
    delta_rho: float = 1.0
    delta_theta_rad: float = math.pi / 180

    @property
    def size_theta_rho(self) -> tuple[int, int]:
        """``(n_theta, n_rho)``, the order 004 writes accumulator sizes in."""
        return (self.H.shape[1], self.H.shape[0])

    def line(self, i: int, k: int) -> tuple[float, float]:
        """``(rho, θ)`` of the accumulator cell ``(i, k)``.

        Parameters
        ----------
        i : int
            Row (rho index).
        k : int
            Column (θ index).

        Returns
        -------
        rho, theta_rad : float
        """
        return float(self.rho[i]), float(self.theta_rad[k])


def theta_axis(delta_theta_rad: float) -> np.ndarray:
    """θ bins ``-π/2 + k·Δθ`` covering [-90°, 90°) (004 §Hough).

    Parameters
    ----------
    delta_theta_rad : float
        Bin width Δθ [rad]; must divide 180°.

    Returns
    -------
    numpy.ndarray, shape (π/Δθ,)
        Bin values [rad].

    Examples
    --------
    >>> np.degrees(theta_axis(np.radians(45.0))).round(6).tolist()
    [-90.0, -45.0, 0.0, 45.0]
    """
    d = check_positive(delta_theta_rad, "delta_theta_rad")
    n = round(math.pi / d)
    if n < 1 or not math.isclose(n * d, math.pi, rel_tol=1e-9, abs_tol=1e-12):
        raise ValueError(f"`delta_theta_rad` must divide 180 degrees; got {math.degrees(d):.6g} degrees")
    return -math.pi / 2 + d * np.arange(n)


def _check_scan(bearings_rad, ranges):
    phi = as_finite_array(bearings_rad, "bearings_rad", ndim=1)
    r = as_finite_array(ranges, "ranges", ndim=1)
    if phi.shape != r.shape:
        raise ValueError(f"`bearings_rad` and `ranges` must have the same length; got {phi.size} and {r.size}")
    if np.any(r < 0):
        raise ValueError(f"`ranges` must be >= 0; got minimum {r.min():.6g}")
    return phi, r


def hough_polar(bearings_rad, ranges, *, delta_rho: float = 1.0, delta_theta_rad: float = math.pi / 180,
                r_max: float | None = None) -> HoughAccumulator:
    """Optimised Hough transform voting from polar scan points (004 eq. (7)-(8)).

    Every point votes once per θ bin for ``rho_i(θ) = r_i·cos(θ - φ_i)``, rounded to
    the nearest multiple of ``Δrho``; votes are summed with one ``np.bincount``.

    Parameters
    ----------
    bearings_rad, ranges : (N,) array_like
        Beam directions φ_i and ranges r_i (any length unit; ``Δrho`` in the same).
        Zero ranges (no return) do not vote.
    delta_rho : float
        rho resolution Δrho.
    delta_theta_rad : float
        θ resolution Δθ; must divide 180°.
    r_max : float, optional
        Largest range kept (longer ones do not vote); default ``max(ranges)``.
        The rho axis is ``n·Δrho`` for ``|n| <= ceil(r_max/Δrho)``.

    Returns
    -------
    HoughAccumulator

    Examples
    --------
    004's example: the line θ = 45°, rho = 10 seen to 16 cells gives a 180×33 accumulator.

    >>> phi, r = line_scan(10.0, np.radians(45.0), r_max=16.0)
    >>> acc = hough_polar(phi, r, r_max=16.0)
    >>> acc.size_theta_rho
    (180, 33)
    >>> int(acc.H.max()), phi.size        # every point votes for the line (a flat top 43°..47°)
    (103, 103)
    """
    phi, r = _check_scan(bearings_rad, ranges)
    d_rho = check_positive(delta_rho, "delta_rho")
    theta = theta_axis(delta_theta_rad)
    if r_max is None:
        r_max = float(r.max()) if r.size else d_rho
    r_max = check_positive(r_max, "r_max")
    return _hough_polar(phi, r, d_rho, theta, float(delta_theta_rad), r_max)


_VOTE_BLOCK = 16384  # votes per block: the block's float and int buffers (~130 KB each) stay in L2


def _hough_polar(phi, r, d_rho, theta, delta_theta_rad, r_max) -> HoughAccumulator:
    """:func:`hough_polar` on checked arguments (``theta`` from :func:`theta_axis`, ``r_max > 0``).

    Speed (issue 17): each vote's bin index ``x·cosθ + y·sinθ + offset`` comes from one small
    matrix product ``[cosθ, sinθ, offset] @ [x, y, 1]ᵀ`` per block of θ rows (one BLAS pass instead
    of four numpy passes), then one cast and one ``np.bincount``. The blocks (about ``_VOTE_BLOCK``
    votes) live in buffers allocated once per call: the whole N×n_θ index array at once (three
    1.5 MB temporaries for 1081 beams) missed the caches and, depending on the allocator's state,
    was mapped afresh and page-faulted on every call (~1000 faults, the 3.5× spread between scans
    of the same size).
    """
    keep = (r > 0) & (r <= r_max)
    n_half = math.ceil(r_max / d_rho - 1e-9)
    n_rho, n_theta = 2 * n_half + 1, theta.size
    rho_axis = d_rho * np.arange(-n_half, n_half + 1)
    n = int(np.count_nonzero(keep))
    pts = np.empty((3, n))
    pts[0] = (r[keep] * np.cos(phi[keep])) / d_rho
    pts[1] = (r[keep] * np.sin(phi[keep])) / d_rho
    pts[2] = 1.0
    rows = max(1, min(n_theta, _VOTE_BLOCK // max(n, 1)))
    w = np.empty((n_theta, 3))
    w[:, 0], w[:, 1] = np.cos(theta), np.sin(theta)
    w[:, 2] = (n_half + 0.5) + n_rho * (np.arange(n_theta) % rows)
    if numba_enabled():  # the same votes, compiled (slamlab.hough._kernels.vote_polar; issue 25)
        from ._kernels import vote_polar

        counts = vote_polar(pts[0], pts[1], w, rows, n_rho)
        return HoughAccumulator(counts.T, rho_axis, theta, d_rho, delta_theta_rad)
    # votes in a (θ, rho) layout so that the row offset j·n_rho (j = θ row within its block) folds
    # into the float sum: rho/Δrho + n_half + 0.5 + j·n_rho >= 0.5, so truncation = rounding to the
    # nearest bin (|rho| <= r <= r_max keeps every vote inside its θ row)
    counts = np.empty((n_theta, n_rho), dtype=np.intp)
    fbuf, ibuf = np.empty((rows, n)), np.empty((rows, n), dtype=np.intp)
    for k0 in range(0, n_theta, rows):
        k1 = min(k0 + rows, n_theta)
        f, idx = fbuf[: k1 - k0], ibuf[: k1 - k0]
        np.matmul(w[k0:k1], pts, out=f)
        idx[...] = f  # truncation (all >= 0.5)
        counts[k0:k1] = np.bincount(idx.ravel(), minlength=(k1 - k0) * n_rho).reshape(k1 - k0, n_rho)
    return HoughAccumulator(counts.T, rho_axis, theta, d_rho, delta_theta_rad)


def rasterise_scan(bearings_rad, ranges, *, cell: float = 1.0, r_max: float | None = None,
                   centre_px: int | None = None) -> tuple[np.ndarray, int]:
    """Rasterise a scan into a binary image centred on the sensor (004 Fig. 6).

    Point ``(x, y) = r·(cos φ, sin φ)`` lands in pixel ``(row, col) = (c + round(y/cell),
    c + round(x/cell))`` with ``c = centre_px`` (default ``ceil(r_max/cell)``); the image
    is ``(2c+1)×(2c+1)`` (33×33 for 004's r_max = 16). Rows grow with y (no flip).

    Parameters
    ----------
    bearings_rad : array_like, shape (N,)
        Beam directions [rad].
    ranges : array_like, shape (N,)
        Ranges (any unit; ``cell`` in the same unit); ranges ≤ 0 or beyond ``r_max`` are dropped.
    cell : float, default 1.0
        Pixel size.
    r_max : float, optional
        Longest range drawn; default the longest range.
    centre_px : int, optional
        Sensor pixel ``c``; default ``ceil(r_max/cell)``.

    Returns
    -------
    image : (2c+1, 2c+1) uint8 array of 0/255
    c : int
        Pixel index of the sensor along both axes.

    Examples
    --------
    >>> img, c = rasterise_scan([0.0, np.pi / 2], [2.0, 1.0], r_max=3.0)
    >>> img.shape, c, int(img[c, c + 2]), int(img[c + 1, c])
    ((7, 7), 3, 255, 255)
    """
    phi, r = _check_scan(bearings_rad, ranges)
    cell = check_positive(cell, "cell")
    if r_max is None:
        r_max = float(r.max()) if r.size else cell
    r_max = check_positive(r_max, "r_max")
    c = math.ceil(r_max / cell - 1e-9) if centre_px is None else check_int(centre_px, "centre_px", minimum=1)
    keep = (r > 0) & (r <= r_max)
    col = np.rint(r[keep] * np.cos(phi[keep]) / cell).astype(np.intp) + c
    row = np.rint(r[keep] * np.sin(phi[keep]) / cell).astype(np.intp) + c
    inside = (col >= 0) & (col <= 2 * c) & (row >= 0) & (row <= 2 * c)
    img = np.zeros((2 * c + 1, 2 * c + 1), dtype=np.uint8)
    img[row[inside], col[inside]] = 255
    return img, c


def hough_classic(image, *, delta_rho: float = 1.0, delta_theta_rad: float = math.pi / 180) -> HoughAccumulator:
    """Classic Hough transform of a binary image (004 eq. (5)-(6)).

    Every non-zero pixel ``(x, y) = (column, row)`` votes for
    ``rho = x·cos θ + y·sin θ``, origin at pixel (0, 0). As Matlab's ``hough``, the rho
    axis is ``n·Δrho`` for ``|n| <= ceil(D/Δrho)``, ``D = sqrt((H-1)² + (W-1)²)``: a 33×33
    image gives 93 rho bins (004's 180×93).

    Parameters
    ----------
    image : array_like, shape (H, W)
        Binary image; every non-zero pixel votes.
    delta_rho : float, default 1.0
        rho bin width [px].
    delta_theta_rad : float, default π/180
        θ bin width [rad].

    Returns
    -------
    HoughAccumulator
        rho axis in pixels about pixel (0, 0).

    Examples
    --------
    >>> img = np.zeros((33, 33), np.uint8); img[:, 5] = 1          # the line x = 5
    >>> acc = hough_classic(img)
    >>> acc.size_theta_rho
    (180, 93)
    >>> i, k = np.unravel_index(acc.H.argmax(), acc.H.shape)
    >>> float(acc.rho[i]), round(float(np.degrees(acc.theta_rad[k]))), int(acc.H[i, k])
    (5.0, 0, 33)
    """
    img = as_image(image, "image")
    d_rho = check_positive(delta_rho, "delta_rho")
    theta = theta_axis(delta_theta_rad)
    h, w = img.shape
    n_half = math.ceil(math.hypot(h - 1, w - 1) / d_rho - 1e-9)
    n_rho, n_theta = 2 * n_half + 1, theta.size
    rows, cols = np.nonzero(img)
    idx = np.multiply.outer(cols / d_rho, np.cos(theta))
    idx += np.multiply.outer(rows / d_rho, np.sin(theta))
    idx += (n_half + 0.5) + n_rho * np.arange(n_theta)
    H = np.bincount(idx.astype(np.intp).ravel(), minlength=n_rho * n_theta).reshape(n_theta, n_rho).T
    return HoughAccumulator(H, d_rho * np.arange(-n_half, n_half + 1), theta, d_rho, float(delta_theta_rad))


def lines_about_centre(rho, theta_rad, centre_px: int, *, cell: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Re-express classic-transform lines about the scan centre (004 §Hough).

    A line ``x·cos θ + y·sin θ = rho`` in image pixels (origin at pixel (0, 0)) is
    ``rho' = (rho - c·(cos θ + sin θ))·cell`` about the sensor at pixel ``(c, c)``.

    Parameters
    ----------
    rho : array_like
        rho of the lines in image pixels (origin at pixel (0, 0)).
    theta_rad : array_like
        Their θ [rad].
    centre_px : int
        The sensor's pixel ``c`` along both axes (from :func:`rasterise_scan`).
    cell : float, default 1.0
        Pixel size in the scan's range unit.

    Returns
    -------
    rho, theta_rad : numpy.ndarray
        The lines about the sensor, rho in range units.

    Examples
    --------
    >>> rho, theta = lines_about_centre([26.0], [0.0], 16)
    >>> rho.tolist(), theta.tolist()
    ([10.0], [0.0])
    """
    rho = np.asarray(as_finite_array(rho, "rho"))
    theta = np.asarray(as_finite_array(theta_rad, "theta_rad"))
    c = check_int(centre_px, "centre_px", minimum=0)
    cell = check_positive(cell, "cell")
    return (rho - c * (np.cos(theta) + np.sin(theta))) * cell, theta.copy()


def line_scan(rho: float, theta_rad: float, *, r_max: float, bearings_rad=None,
              delta_phi_rad: float = math.pi / 180) -> tuple[np.ndarray, np.ndarray]:
    """Exact ranges from the origin to the line ``(rho, θ)`` (004 Fig. 5).

    ``r(φ) = rho / cos(φ - θ)`` for the beams that hit the line within ``r_max``.

    Parameters
    ----------
    rho, theta_rad : float
        The line; ``rho > 0``.
    r_max : float
        Longest range kept.
    bearings_rad : (M,) array_like, optional
        Beam directions; default every ``delta_phi_rad`` over [-180°, 180°).
    delta_phi_rad : float, default π/180
        Beam spacing [rad] when ``bearings_rad`` is None.

    Returns
    -------
    bearings_rad, ranges : (N,) arrays of the beams that hit.

    Examples
    --------
    >>> phi, r = line_scan(10.0, np.radians(45.0), r_max=16.0)
    >>> phi.size, float(r.min())
    (103, 10.0)
    """
    rho = check_positive(rho, "rho")
    theta = float(as_vector(theta_rad, "theta_rad", 1)[0])
    r_max = check_positive(r_max, "r_max")
    if bearings_rad is None:
        d = check_positive(delta_phi_rad, "delta_phi_rad")
        bearings_rad = -math.pi + d * np.arange(round(2 * math.pi / d))
    phi = as_finite_array(bearings_rad, "bearings_rad", ndim=1)
    c = np.cos(phi - theta)
    with np.errstate(divide="ignore"):
        r = np.where(c > 0, rho / np.where(c > 0, c, 1.0), np.inf)
    hit = r <= r_max * (1 + 1e-12)
    return phi[hit], r[hit]


def hough_cost(*, n_points: int | None = None, r_max: float | None = None, delta_r: float = 1.0,
               delta_theta_rad: float = math.pi / 180) -> float:
    """Operation counts of 004: polar ``N·180/Δθ`` (eq. (8)) or classic ``(r_max/Δr)²·180/Δθ`` (eq. (6)).

    Give ``n_points`` for the polar transform or ``r_max`` for the classic one.

    Parameters
    ----------
    n_points : int, optional
        Scan points (polar transform).
    r_max : float, optional
        Longest range (classic transform over the ``(r_max/Δr)²`` image).
    delta_r : float, default 1.0
        Image cell size, in the unit of ``r_max``.
    delta_theta_rad : float, default π/180
        θ bin width [rad].

    Returns
    -------
    float
        Operation count.

    Examples
    --------
    >>> hough_cost(n_points=103), hough_cost(r_max=33.0)
    (18540.0, 196020.0)
    """
    n_theta = theta_axis(delta_theta_rad).size
    if (n_points is None) == (r_max is None):
        raise ValueError("give exactly one of `n_points` (polar) and `r_max` (classic)")
    if n_points is not None:
        return float(check_int(n_points, "n_points", minimum=0) * n_theta)
    ratio = check_positive(r_max, "r_max") / check_positive(delta_r, "delta_r")
    return float(ratio**2 * n_theta)
