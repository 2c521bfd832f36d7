"""Markov (histogram) grid localisation over (x, y, θ) (003 §2.2.1; PR Table 8.1 / §8.2).

003: the world is cut into cells, each with the probability that the robot is
there, summing to 1; uniform without a prior; updated from odometry (motion
model) and from the sensor. Pro: it re-localises and takes priors; con: the cost
grows with the number of cells.

Our discretisation (the source gives none):

- **belief** ``bel[k, i, j]`` over ``K`` headings ``θ_k = 2πk/K`` and a grid of
  ``resolution`` × ``resolution`` map cells per belief cell; cells whose centre
  is not FREE on the map hold 0.
- **motion** (PR Table 5.5 approximated; ours): every heading layer is shifted by
  the odometry translation along ``θ_k + δrot1`` (``scipy.ndimage.shift``, linear),
  the heading axis by ``δrot1 + δrot2`` (wrapping), then blurred by a Gaussian
  (``scipy.ndimage.gaussian_filter``) of σ from α1…α4 (position σ² = α3·δtrans² +
  α4·(δrot1² + δrot2²), heading σ² = α1·(δrot1² + δrot2²) + 2·α2·δtrans²) plus
  ``min_blur`` (the grid's own uncertainty).
- **sensor** (PR Table 6.3): the log-likelihood of a scan for every cell and every
  heading at once: per (heading, beam) the end-point offset is rounded to whole map
  cells and the log-q table is added as one shifted, strided slice.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from .._params import param
from .._validate import check_int, check_positive
from ..geometry import wrap_angle
from ..scans import FREE
from .models import Beams, LikelihoodFieldModel, ModelParams, odometry_deltas, scan_beams

__all__ = ["MarkovGrid", "MarkovParams", "markov_correct", "markov_predict"]


@dataclass(frozen=True)
class MarkovParams(ModelParams):
    """Settings of Markov grid localisation; lengths in map cells. The motion and sensor model's
    fields (the same as MCL's) come first (:class:`~slamlab.localisation.models.ModelParams`).

    Parameters
    ----------
    alpha, z_hit, z_rand, sigma_hit, max_dist, max_beams, gamma : see ModelParams
        The motion and sensor model (:class:`~slamlab.localisation.models.ModelParams`).
    resolution : int
        Map cells per belief cell.
    n_headings : int
        Heading bins.
    min_blur : float
        Gaussian σ (belief cells and heading bins) added at each motion step.
    uniform_floor : float
        Share of a uniform belief mixed in after each motion step.
    """

    resolution: int = param(2, "ours: map cells per belief cell (003: not given)")
    n_headings: int = param(72, "ours: 5° heading bins (003: not given)")
    min_blur: float = param(0.5, "ours: Gaussian σ (belief cells and heading bins) added at each motion step")
    uniform_floor: float = param(0.0, "ours: share ε of a uniform belief mixed in after each motion step (the "
                                      "grid's random injection; 0 = PR Table 8.1)")

    def check(self) -> None:
        super().check()
        check_int(self.resolution, "resolution", minimum=1)
        check_int(self.n_headings, "n_headings", minimum=4)
        check_positive(self.min_blur, "min_blur", allow_zero=True)
        e = check_positive(self.uniform_floor, "uniform_floor", allow_zero=True)
        if e >= 1:
            raise ValueError(f"`uniform_floor` must be in [0, 1); got {e}")


def markov_predict(bel, odom_prev, odom_now, *, resolution: int, alpha, min_blur: float = 0.5,
                   free_mask=None) -> np.ndarray:
    """Motion update of a ``(K, h, w)`` belief by one odometry reading (our shift + blur form of PR Table 5.5).

    Parameters
    ----------
    bel : array_like, shape (K, h, w)
        The belief over heading bins and belief cells.
    odom_prev, odom_now : array_like, shape (3,)
        The odometry reading (map cells, rad).
    resolution : int
        Map cells per belief cell.
    alpha : sequence of 4 float
        α1…α4 of the odometry model.
    min_blur : float
        Gaussian σ added to the motion blur (belief cells and heading bins).
    free_mask : ndarray, shape (h, w), optional
        1 on the belief cells a robot can be in; the belief elsewhere is set to 0.

    Returns
    -------
    ndarray, shape (K, h, w)
        The predicted belief, normalised (all zeros when nothing is left).

    Examples
    --------
    >>> b = np.zeros((4, 5, 5)); b[0, 2, 1] = 1.0
    >>> out = markov_predict(b, [0, 0, 0], [2, 0, 0], resolution=1, alpha=(0, 0, 0, 0), min_blur=0)
    >>> np.argwhere(out > 0.99).tolist()
    [[0, 2, 3]]
    """
    B = np.asarray(bel, dtype=float)
    if B.ndim != 3:
        raise ValueError(f"`bel` must have shape (K, h, w); got {B.shape}")
    K = B.shape[0]
    a = np.asarray(alpha, dtype=float)
    rot1, trans, rot2 = (float(d) for d in odometry_deltas(odom_prev, odom_now))
    s = float(resolution)
    th = 2 * np.pi * np.arange(K) / K
    out = np.empty_like(B)
    for k in range(K):  # one whole-layer shift per heading (K calls, each vectorised over the cells)
        d = trans / s
        out[k] = ndimage.shift(B[k], (d * np.sin(th[k] + rot1), d * np.cos(th[k] + rot1)), order=1,
                               mode="constant", cval=0.0, prefilter=False)
    dth = wrap_angle(rot1 + rot2) * K / (2 * np.pi)
    if dth != 0:
        out = ndimage.shift(out, (dth, 0, 0), order=1, mode="grid-wrap", prefilter=False)
    sig_pos = np.sqrt(a[2] * trans**2 + a[3] * (rot1**2 + rot2**2)) / s + min_blur
    sig_th = np.sqrt(a[0] * (rot1**2 + rot2**2) + 2 * a[1] * trans**2) * K / (2 * np.pi) + min_blur
    if sig_pos > 0 or sig_th > 0:
        out = ndimage.gaussian_filter(out, (sig_th, sig_pos, sig_pos), mode=("wrap", "constant", "constant"),
                                      truncate=3.0)
    if free_mask is not None:
        out *= free_mask
    total = out.sum()
    return out / total if total > 0 else out


def markov_log_likelihood(model: LikelihoodFieldModel, beams: Beams, n_headings: int, resolution: int,
                          shape: tuple[int, int]) -> np.ndarray:
    """``log p(z | x)`` for every belief cell and heading, shape ``(K, h, w)``: per (heading, beam) one
    shifted strided slice of the log-q table (all cells at once).

    Parameters
    ----------
    model : LikelihoodFieldModel
        The sensor model on the map.
    beams : Beams
        The scan's beams.
    n_headings : int
        Heading bins K.
    resolution : int
        Map cells per belief cell.
    shape : tuple of int
        ``(h, w)`` of the belief grid.

    Returns
    -------
    ndarray, shape (K, h, w)
    """
    K, (h, w), s = n_headings, shape, resolution
    th = 2 * np.pi * np.arange(K) / K
    c, sn = np.cos(th)[:, None], np.sin(th)[:, None]
    used = beams.ranges < min(beams.max_range, model.z_max)
    bx, by = beams.end_xy[used, 0][None, :], beams.end_xy[used, 1][None, :]
    dx = np.floor(c * bx - sn * by + 0.5).astype(np.int64)  # (K, B) end-point offsets in map cells
    dy = np.floor(sn * bx + c * by + 0.5).astype(np.int64)
    H, W = model.shape
    pad = int(max(np.abs(dx).max(initial=0), np.abs(dy).max(initial=0))) + 1
    T = np.full((H + 2 * pad + s * h, W + 2 * pad + s * w), model.log_outside)
    T[pad:pad + H, pad:pad + W] = model.log_table.reshape(H, W)
    L = np.zeros((K, h, w))
    for k in range(K):
        acc = L[k]
        for oy, ox in zip(dy[k] + pad, dx[k] + pad, strict=True):
            acc += T[oy:oy + s * h:s, ox:ox + s * w:s]
    return L


def markov_correct(bel, L, *, gamma: float = 1.0, free_mask=None) -> tuple[np.ndarray, bool]:
    """Sensor update ``bel ∝ bel · exp(gamma·L)``; returns the belief and whether it kept any mass.

    When every cell with belief has probability 0 under the scan, the belief is left
    unchanged and ``False`` is returned (the caller says so; never NaN).

    Parameters
    ----------
    bel : array_like, shape (K, h, w)
        The predicted belief.
    L : array_like, shape (K, h, w)
        ``log p(z | x)`` per cell (:func:`markov_log_likelihood`).
    gamma : float
        Exponent of the likelihood.
    free_mask : ndarray, shape (h, w), optional
        1 on the cells a robot can be in.

    Returns
    -------
    bel : ndarray, shape (K, h, w)
        The corrected belief (the input when no mass is left).
    kept : bool
        Whether the belief kept any mass.
    """
    B = np.asarray(bel, dtype=float)
    Lg = gamma * np.asarray(L, dtype=float)
    support = B > 0
    if not support.any():
        return B, False
    m = Lg[support].max()
    out = B * np.exp(Lg - m)
    if free_mask is not None:
        out *= free_mask
    total = out.sum()
    if not (total > 0 and np.isfinite(total)):
        return B, False
    return out / total, True


class MarkovGrid:
    """Markov grid localisation over (x, y, θ) on a grid map (003 §2.2.1).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
    z_max : float
        The rangefinder's maximum range in cells.
    params : MarkovParams, optional
    prior : array_like, shape (K, h, w), optional
        Initial belief (normalised here); default uniform over the free cells (003).
    **overrides
        Fields of :class:`MarkovParams`.

    Examples
    --------
    >>> g = np.zeros((20, 20), np.int8); g[0] = g[-1] = g[:, 0] = g[:, -1] = 1
    >>> m = MarkovGrid(g, 30.0, resolution=2, n_headings=8)
    >>> m.belief.shape, round(float(m.belief.sum()), 12)
    ((8, 10, 10), 1.0)
    """

    def __init__(self, grid, z_max: float, *, params: MarkovParams | None = None, prior=None, **overrides):
        self.params = p = MarkovParams.resolve(params, **overrides)
        self.model = LikelihoodFieldModel(grid, z_hit=p.z_hit, z_rand=p.z_rand, sigma_hit=p.sigma_hit, z_max=z_max,
                                          max_dist=p.max_dist)
        s = p.resolution
        H, W = self.model.shape
        self.shape = (int(np.ceil(H / s)), int(np.ceil(W / s)))
        centres = self.model.grid[::s, ::s]
        self.free_mask = (centres == FREE).astype(float)[None, :, :]
        if not self.free_mask.any():
            raise ValueError("`grid` has no FREE cell at the belief resolution: nowhere for the robot to be")
        K = p.n_headings
        if prior is None:
            bel = np.broadcast_to(self.free_mask, (K, *self.shape)).copy()
        else:
            bel = np.asarray(prior, dtype=float)
            if bel.shape != (K, *self.shape) or np.any(bel < 0) or not np.all(np.isfinite(bel)):
                raise ValueError(f"`prior` must be a finite, non-negative array of shape {(K, *self.shape)}")
            bel = bel * self.free_mask
            if bel.sum() <= 0:
                raise ValueError("`prior` puts no probability on a free cell")
        self.belief = bel / bel.sum()
        self.headings_rad = 2 * np.pi * np.arange(K) / K
        self.last_ok = True

    def predict(self, odom_prev, odom_now) -> None:
        """Motion update from one odometry reading.

        Parameters
        ----------
        odom_prev, odom_now : array_like, shape (3,)
            The odometry reading (map cells, rad).

        Returns
        -------
        None
        """
        p = self.params
        self.belief = markov_predict(self.belief, odom_prev, odom_now, resolution=p.resolution, alpha=p.alpha,
                                     min_blur=p.min_blur, free_mask=self.free_mask)
        if p.uniform_floor > 0:
            u = np.broadcast_to(self.free_mask, self.belief.shape)
            self.belief = (1 - p.uniform_floor) * self.belief + p.uniform_floor * u / u.sum()

    def correct(self, scan) -> bool:
        """Sensor update from a scan (cell units) or its beams; False when the scan ruled out every cell.

        Parameters
        ----------
        scan : Scan or Beams
            The scan in cell units (or its beams).

        Returns
        -------
        bool
            Whether the belief kept any mass.
        """
        beams = scan if isinstance(scan, Beams) else scan_beams(scan, self.params.max_beams)
        L = markov_log_likelihood(self.model, beams, self.params.n_headings, self.params.resolution, self.shape)
        self.belief, self.last_ok = markov_correct(self.belief, L, gamma=self.params.gamma, free_mask=self.free_mask)
        return self.last_ok

    def step(self, odom_prev, odom_now, scan) -> np.ndarray:
        """Predict (when odometry is given) then correct; returns the mean pose.

        Parameters
        ----------
        odom_prev, odom_now : array_like, shape (3,), or None
            The odometry reading (None: no motion).
        scan : Scan or Beams
            The scan in cell units (or its beams).

        Returns
        -------
        ndarray, shape (3,)
            The mean pose (map cells, rad).
        """
        if odom_prev is not None and odom_now is not None:
            self.predict(odom_prev, odom_now)
        self.correct(scan)
        return self.estimate()[0]

    def cell_poses(self) -> np.ndarray:
        """``(K, h, w, 3)`` pose (map cells, rad) of every belief cell."""
        K = self.params.n_headings
        h, w = self.shape
        s = self.params.resolution
        y, x = np.mgrid[0:h, 0:w].astype(float) * s
        P = np.empty((K, h, w, 3))
        P[..., 0] = x
        P[..., 1] = y
        P[..., 2] = self.headings_rad[:, None, None]
        return P

    def estimate(self) -> tuple[np.ndarray, np.ndarray]:
        """Mean pose (circular mean heading) and covariance of the belief, in map cells and rad."""
        b = self.belief
        s = self.params.resolution
        pk = b.sum(axis=(1, 2))
        py = b.sum(axis=(0, 2))
        px = b.sum(axis=(0, 1))
        ys = np.arange(self.shape[0]) * s
        xs = np.arange(self.shape[1]) * s
        mx, my = float(px @ xs), float(py @ ys)
        th = float(np.arctan2(pk @ np.sin(self.headings_rad), pk @ np.cos(self.headings_rad)))
        dth = wrap_angle(self.headings_rad - th)
        bxy = b.sum(axis=0)
        cxx = float(px @ (xs - mx) ** 2)
        cyy = float(py @ (ys - my) ** 2)
        cxy = float(((ys - my)[:, None] * (xs - mx)[None, :] * bxy).sum())
        ctt = float(pk @ dth**2)
        cxt = float((b.sum(axis=1) * dth[:, None] * (xs - mx)[None, :]).sum())
        cyt = float((b.sum(axis=2) * dth[:, None] * (ys - my)[None, :]).sum())
        C = np.array([[cxx, cxy, cxt], [cxy, cyy, cyt], [cxt, cyt, ctt]])
        return np.array([mx, my, th]), C

    def mode(self) -> np.ndarray:
        """The most probable cell's pose."""
        k, i, j = np.unravel_index(int(np.argmax(self.belief)), self.belief.shape)
        s = self.params.resolution
        return np.array([j * s, i * s, self.headings_rad[k]], dtype=float)

    def gaussian_prior(self, pose, pos_std: float, heading_std_rad: float) -> np.ndarray:
        """A belief ``∝ exp(−½(Δx² + Δy²)/σ_pos² − ½Δθ²/σ_θ²)`` around ``pose`` (map cells, rad), on the free
        cells: a prior for :class:`MarkovGrid` (003 §2.2.1: priors are easy on a grid).

        Parameters
        ----------
        pose : array_like, shape (3,)
            The prior's centre (map cells, rad).
        pos_std : float
            Its position σ (map cells).
        heading_std_rad : float
            Its heading σ (rad).

        Returns
        -------
        ndarray, shape (K, h, w)
            The prior, normalised.
        """
        p = np.asarray(pose, dtype=float)
        if p.shape != (3,) or not np.all(np.isfinite(p)):
            raise ValueError(f"`pose` must be three finite numbers (x, y, heading); got {pose!r}")
        sp = check_positive(pos_std, "pos_std")
        st = check_positive(heading_std_rad, "heading_std_rad")
        P = self.cell_poses()
        d2 = ((P[..., 0] - p[0]) ** 2 + (P[..., 1] - p[1]) ** 2) / sp**2 + wrap_angle(P[..., 2] - p[2]) ** 2 / st**2
        b = np.exp(-0.5 * (d2 - d2.min())) * self.free_mask
        if b.sum() <= 0:
            raise ValueError("the prior puts no probability on a free cell")
        return b / b.sum()

    @property
    def nbytes(self) -> int:
        """Memory of the belief array in bytes."""
        return int(self.belief.nbytes)
