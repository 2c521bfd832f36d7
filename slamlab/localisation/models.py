"""Motion and measurement models of probabilistic localisation (003 §2.2; Thrun, Burgard, Fox, *Probabilistic Robotics*).

API summary
-----------
- motion (in :mod:`slamlab.localisation.motion`, re-exported): :func:`odometry_deltas` ``(odom_prev, odom_now) -> (δrot1, δtrans, δrot2)``.
- :func:`sample_motion_odometry` ``(poses, odom_prev, odom_now, alpha, rng) -> (N, 3)``:
  Table 5.6 (PR), vectorised over the particles.
- :func:`motion_density_odometry` ``(poses_now, poses_prev, odom_prev, odom_now, alpha) -> (N,)``: Table 5.5.
- :class:`LikelihoodFieldModel`: Table 6.3 with the distance table of
  :func:`slamlab.scans.likelihood_field`; ``log_likelihood(poses, beams)`` over
  particles × beams in one gather.
- the expected ranges come from :func:`slamlab.scans.cast_rays` (exact grid traversal from many poses at once), and
  :func:`beam_model_prob` (Table 6.1: z_hit, z_short, z_max, z_rand; in :mod:`slamlab.localisation.beam_model`).
- :func:`scan_beams`: the beams of a :class:`~slamlab.scans.Scan` a filter uses.

003 names the ingredients only (an observation model giving each particle a
probability in [0, 1], and resampling); the formulas here are PR's, and the
variance form ``α1·δrot1² + α2·δtrans²`` is the one of PR's errata.
Lengths are in cells (the map's unit), angles in radians.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._params import Params, param
from .._validate import check_choice, check_int, check_positive
from ..scans import OBSTACLE, Scan, check_grid, likelihood_field
from .beam_model import beam_model_prob  # re-exported: moved there unchanged
from .motion import (  # noqa: F401 (re-exported: moved there unchanged)
    check_alpha,
    check_particles,
    motion_density_odometry,
    motion_from_noise,
    odometry_deltas,
    sample_motion_odometry,
)

__all__ = [
    "SCORES",
    "Beams",
    "LikelihoodFieldModel",
    "ModelParams",
    "beam_model_prob",
    "check_alpha",
    "check_particles",
    "motion_density_odometry",
    "odometry_deltas",
    "sample_motion_odometry",
    "scan_beams",
]


#: particles per block of the likelihood-field gather (its float64 work arrays then stay in the cache; ours)
_CHUNK = 1024

#: The observation scores a filter can weigh with (see :meth:`LikelihoodFieldModel.log_score`).
SCORES = ("likelihood", "geometric_mean", "amcl_cubes")


@dataclass(frozen=True)
class ModelParams(Params):
    """The odometry motion model and likelihood-field sensor model settings shared by :class:`MCLParams`
    and :class:`MarkovParams` (PR Tables 5.5-5.6, 6.3); lengths in cells (the map's unit).

    Parameters
    ----------
    alpha : tuple of 4 float
        Odometry motion noise α1…α4 (PR Tables 5.5-5.6), lengths in cells.
    z_hit, z_rand : float
        Weights of the hit and random components of the likelihood field (PR Table 6.3).
    sigma_hit : float
        σ of the hit component (cells).
    max_dist : float
        Cap of the distance table (cells).
    max_beams : int
        Beams per scan that weigh a pose (evenly spaced).
    gamma : float
        Exponent of the likelihood (1 = PR's product over the beams).
    """

    alpha: tuple = param((0.05, 0.002, 0.05, 0.005), "ours; PR Tables 5.5-5.6 α1…α4 (ROS: 0.2 each, in metres)")
    z_hit: float = param(0.9, "ours; PR Table 6.3 (ROS 1: 0.95, Nav2: 0.5)")
    z_rand: float = param(0.1, "ours; PR Table 6.3 (ROS 1: 0.05, Nav2: 0.5)")
    sigma_hit: float = param(1.5, "ours, cells; PR Table 6.3 (ROS: 0.2 m)")
    max_dist: float = param(8.0, "ours, cells: cap of the distance table (ROS: 2 m)")
    max_beams: int = param(30, "ours (ROS 1: 30, Nav2: 60)")
    gamma: float = param(1.0, "ours: log-likelihood exponent (1 = PR's product over beams)")

    def check(self) -> None:
        if not isinstance(self.alpha, tuple):
            raise TypeError(f"`alpha` must be a tuple of four numbers >= 0 (α1…α4); got {type(self.alpha).__name__}")
        check_alpha(self.alpha, "alpha")
        check_positive(self.z_hit, "z_hit", allow_zero=True)
        check_positive(self.z_rand, "z_rand", allow_zero=True)
        if self.z_hit + self.z_rand <= 0:
            raise ValueError("`z_hit` + `z_rand` must be > 0")
        check_positive(self.sigma_hit, "sigma_hit")
        check_positive(self.max_dist, "max_dist")
        check_int(self.max_beams, "max_beams", minimum=1)
        check_positive(self.gamma, "gamma")


@dataclass(frozen=True)
class Beams:
    """The beams of one scan a filter weighs with: bearings, ranges, and the body-frame end points.

    Parameters
    ----------
    bearings_rad : ndarray, shape (B,)
        Beam bearings in the body frame (rad).
    ranges : ndarray, shape (B,)
        Ranges (cells).
    max_range : float
        The rangefinder's maximum range (cells).
    end_xy : ndarray, shape (B, 2)
        Body-frame end points (x ahead, y left).
    """

    bearings_rad: np.ndarray  # (B,)
    ranges: np.ndarray  # (B,) in cells
    max_range: float
    end_xy: np.ndarray = field(repr=False)  # (B, 2) body-frame end points (x ahead, y left)

    @property
    def n(self) -> int:
        """Number of beams."""
        return int(self.ranges.size)


def scan_beams(scan: Scan, max_beams: int | None = None, *, keep_max: bool = False) -> Beams:
    """The beams of ``scan`` a filter weighs with: returns only (or all, ``keep_max``), at most ``max_beams``
    evenly spaced (as ROS AMCL's ``max_beams``).

    Raises ``ValueError`` when the scan holds no valid beam (nothing to weigh a particle with).

    Parameters
    ----------
    scan : Scan
        A scan in cell units.
    max_beams : int, optional
        At most this many beams, evenly spaced (None: all).
    keep_max : bool
        Keep the beams at maximum range too.

    Returns
    -------
    Beams

    Examples
    --------
    >>> s = Scan(np.radians([0, 90, 180, 270]), [1, 2, 3, 5], np.array([True, True, True, False]), max_range=5)
    >>> scan_beams(s, 2).ranges.tolist()
    [1.0, 2.0]
    """
    if not isinstance(scan, Scan):
        raise TypeError(f"`scan` must be a Scan; got {type(scan).__name__}")
    if scan.unit != "cell":
        raise ValueError(f"`scan` must be in cell units; got unit {scan.unit!r} (use scan.to_cells(cell_m))")
    idx = np.arange(scan.n_beams) if keep_max else np.flatnonzero(scan.valid)
    if idx.size == 0:
        raise ValueError("`scan` has no valid beam (no return): nothing to weigh the particles with")
    if max_beams is not None:
        m = check_int(max_beams, "max_beams", minimum=1)
        if idx.size > m:
            idx = idx[np.floor(np.arange(m) * idx.size / m).astype(np.int64)]
    b, r = scan.bearings_rad[idx], scan.ranges[idx]
    rmax = float(scan.max_range) if np.isfinite(scan.max_range) else float(scan.ranges.max())
    return Beams(b.copy(), r.copy(), rmax, np.column_stack([r * np.cos(b), r * np.sin(b)]))


# --- likelihood field (PR Table 6.3) ------------------------------------------------------------------


class LikelihoodFieldModel:
    """The likelihood-field range model (PR Table 6.3) on a grid map; the distance table comes from
    :func:`slamlab.scans.likelihood_field` (``scipy.ndimage.distance_transform_edt``).

    For a return of range ``z_k`` at bearing ``a_k`` seen from pose ``x`` the end point
    ``x + R(θ)·z_k(cos a_k, sin a_k)`` is looked up in the distance table, ``d`` (capped
    at ``max_dist``; ``max_dist`` outside the map), and scored
    ``q_k = z_hit·N(d; 0, σ_hit²) + z_rand / z_max``. Beams at ``z_max`` are skipped
    (PR line 3). ``log p(z | x) = Σ_k log q_k`` is precomputed per cell as a table, so a
    weight is one gather per beam.

    The end point's cell (ours): with ``(bx, by)`` the beam's ``Beams.end_xy``, ``col = floor(x + cos θ·bx
    − sin θ·by + 0.5)`` and ``row = floor(y + sin θ·bx + cos θ·by + 0.5)``, in float64, left to right (as
    :meth:`end_points`; an end point on a cell edge goes to the upper cell). The batched gather does exactly
    these operations (numpy rounds each one, it fuses none), so it picks the same cell as a per-particle loop
    written this way at every particle and beam, cell edges included: its per-beam ``log q`` (float32 table
    values) are the loop's bit for bit, and :meth:`log_likelihood`, their float64 sum, differs from the loop's
    sum by the summation order only (at most B ulps of ``Σ|log q_k|``; a beam in another cell would move it by
    at least one float32 step of a term, ~1e-7 relative to that term).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The map (cell codes); it needs at least one OBSTACLE cell.
    z_hit, z_rand : float
        Mixture weights (PR: z_hit + z_rand = 1; not enforced).
    sigma_hit : float
        σ_hit in cells.
    z_max : float
        The sensor's maximum range in cells (the uniform part is ``1/z_max``).
    max_dist : float
        Cap of the distance table in cells (ROS: ``laser_likelihood_max_dist``).
    """

    def __init__(self, grid, *, z_hit: float = 0.9, z_rand: float = 0.1, sigma_hit: float = 1.0,
                 z_max: float = 60.0, max_dist: float = 10.0):
        g = check_grid(grid)
        if not np.any(g == OBSTACLE):
            raise ValueError("`grid` holds no OBSTACLE cell: an empty map cannot localise anything")
        self.z_hit = check_positive(z_hit, "z_hit", allow_zero=True)
        self.z_rand = check_positive(z_rand, "z_rand", allow_zero=True)
        if self.z_hit + self.z_rand <= 0:
            raise ValueError("`z_hit` + `z_rand` must be > 0")
        self.sigma_hit = check_positive(sigma_hit, "sigma_hit")
        self.z_max = check_positive(z_max, "z_max")
        self.max_dist = check_positive(max_dist, "max_dist")
        self.grid = g
        self.shape = g.shape
        self.dist = likelihood_field(g, max_dist=self.max_dist)
        self.log_outside = float(self.log_q(np.array(self.max_dist)))
        #: log of the largest q (an end point on an obstacle): scores are ≤ 1 relative to it
        self.log_q_max = float(self.log_q(np.array(0.0)))
        #: the log-q table, padded by ``z_max`` cells of "outside" so that an end point of a pose on the
        #: map needs no bounds test (float32 values: one gather per beam is the hot loop)
        self.pad = int(np.ceil(self.z_max)) + 2
        H, W = g.shape
        T = np.full((H + 2 * self.pad, W + 2 * self.pad), self.log_outside, dtype=np.float32)
        T[self.pad:self.pad + H, self.pad:self.pad + W] = self.log_q(self.dist)
        self.log_table = self.log_q(self.dist).ravel()
        self._padded = T.ravel()
        self._padded_shape = T.shape
        D = np.full(T.shape, self.max_dist, dtype=np.float32)
        D[self.pad:self.pad + H, self.pad:self.pad + W] = self.dist
        self._padded_dist = D.ravel()

    def log_q(self, d) -> np.ndarray:
        """``log(z_hit·N(d; 0, σ_hit²) + z_rand/z_max)`` for distances ``d`` [cells].

        Parameters
        ----------
        d : array_like
            Distances to the nearest obstacle (cells).

        Returns
        -------
        ndarray
            ``log q`` for every distance, shaped like ``d``.
        """
        d = np.asarray(d, dtype=float)
        g = np.exp(-0.5 * (d / self.sigma_hit) ** 2) / (np.sqrt(2 * np.pi) * self.sigma_hit)
        with np.errstate(divide="ignore"):  # z_rand = 0 and a far end point: log 0 = -inf, handled by the filter
            return np.log(self.z_hit * g + self.z_rand / self.z_max)

    def end_points(self, poses, beams: Beams) -> tuple[np.ndarray, np.ndarray]:
        """World end points ``(N, B)`` x and y of every beam seen from every pose.

        Parameters
        ----------
        poses : array_like, shape (N, 3)
            Poses in cells and radians.
        beams : Beams
            The scan's beams.

        Returns
        -------
        x, y : ndarray, shape (N, B)
            World end points (cells).
        """
        P = np.asarray(poses, dtype=float)
        c, s = np.cos(P[:, 2])[:, None], np.sin(P[:, 2])[:, None]
        bx, by = beams.end_xy[:, 0][None, :], beams.end_xy[:, 1][None, :]
        return P[:, :1] + c * bx - s * by, P[:, 1:2] + s * bx + c * by

    def _gather(self, table, poses, beams: Beams) -> tuple[np.ndarray, np.ndarray]:
        """``table`` (a padded, raveled per-cell table) at every end point of the beams below ``z_max``:
        values ``(N, B_used)`` and the mask of those beams ``(B,)``."""
        P = check_particles(poses, "poses")
        if not isinstance(beams, Beams):
            raise TypeError(f"`beams` must be Beams (from scan_beams); got {type(beams).__name__}")
        keep = self.used(beams)
        Hp, Wp = self._padded_shape
        c, s = np.cos(P[:, 2])[:, None], np.sin(P[:, 2])[:, None]  # float64, in the class docstring's order
        bx, by = beams.end_xy[keep, 0][None, :], beams.end_xy[keep, 1][None, :]
        H, W = self.shape
        # a pose off the map: its end points may leave the padding (inside it, z_max cells each side, they cannot)
        off_map = not (P[:, 0].min() >= -1 and P[:, 0].max() <= W and P[:, 1].min() >= -1 and P[:, 1].max() <= H)
        n, m = len(P), min(len(P), _CHUNK)
        out = np.empty((n, bx.shape[1]), dtype=table.dtype)
        col, row, tmp = (np.empty((m, bx.shape[1])) for _ in range(3))  # reused: chunks stay in the cache
        idx = np.empty((m, bx.shape[1]), dtype=np.intp)
        for i in range(0, n, m):
            j = min(i + m, n)
            cl, rw, tp, ix = col[:j - i], row[:j - i], tmp[:j - i], idx[:j - i]
            np.multiply(c[i:j], bx, out=cl)  # ((x + c·bx) − s·by) + 0.5
            cl += P[i:j, :1]
            cl -= np.multiply(s[i:j], by, out=tp)
            cl += 0.5
            np.multiply(s[i:j], bx, out=rw)  # ((y + s·bx) + c·by) + 0.5
            rw += P[i:j, 1:2]
            rw += np.multiply(c[i:j], by, out=tp)
            rw += 0.5
            np.floor(cl, out=cl)
            np.floor(rw, out=rw)
            if off_map:
                np.clip(cl, -self.pad, Wp - 1 - self.pad, out=cl)
                np.clip(rw, -self.pad, Hp - 1 - self.pad, out=rw)
            rw += self.pad  # the index in the padded table, (row + pad)·Wp + col + pad: integers < 2**53, exact
            rw *= Wp
            rw += cl
            rw += self.pad
            ix[...] = rw
            np.take(table, ix, out=out[i:j])
        return out, keep

    def used(self, beams: Beams) -> np.ndarray:
        """Mask of the beams that enter the likelihood: ranges below ``z_max`` (PR Table 6.3 line 3).

        Parameters
        ----------
        beams : Beams
            The scan's beams.

        Returns
        -------
        ndarray of bool, shape (B,)
        """
        return beams.ranges < min(beams.max_range, self.z_max)

    def beam_log_q(self, poses, beams: Beams) -> np.ndarray:
        """``log q_k`` for every pose × beam, shape ``(N, B)``, float32 (beams at ``z_max`` give 0).

        Parameters
        ----------
        poses : array_like, shape (N, 3)
            Poses in cells and radians.
        beams : Beams
            The scan's beams.

        Returns
        -------
        ndarray of float32, shape (N, B)
        """
        vals, keep = self._gather(self._padded, poses, beams)
        if keep.all():
            return vals
        out = np.zeros((vals.shape[0], beams.n), dtype=np.float32)
        out[:, keep] = vals
        return out

    def beam_distances(self, poses, beams: Beams) -> tuple[np.ndarray, np.ndarray]:
        """Distance ``d`` [cells] from every end point to the nearest obstacle (capped at ``max_dist``; off
        the map ``max_dist``), shape ``(N, B_used)``, and the mask ``(B,)`` of the beams below ``z_max``.

        Parameters
        ----------
        poses : array_like, shape (N, 3)
            Poses in cells and radians.
        beams : Beams
            The scan's beams.

        Returns
        -------
        d : ndarray, shape (N, B_used)
            Distances to the nearest obstacle (cells).
        keep : ndarray of bool, shape (B,)
            The beams that enter the likelihood.
        """
        return self._gather(self._padded_dist, poses, beams)

    def log_likelihood(self, poses, beams: Beams) -> np.ndarray:
        """``log p(z | x) = Σ_k log q_k`` for every pose, shape ``(N,)``.

        Parameters
        ----------
        poses : array_like, shape (N, 3)
            Poses in cells and radians.
        beams : Beams
            The scan's beams.

        Returns
        -------
        ndarray, shape (N,)
        """
        return self.beam_log_q(poses, beams).sum(axis=1, dtype=np.float64)

    def n_used(self, beams: Beams) -> int:
        """Number of beams that enter the product (ranges below ``z_max``).

        Parameters
        ----------
        beams : Beams
            The scan's beams.

        Returns
        -------
        int
        """
        return int(np.count_nonzero(self.used(beams)))

    def score(self, log_lik, beams: Beams) -> np.ndarray:
        """The per-beam geometric mean of ``q_k / q_max``, ``exp(log p / B − log q_max)`` in [0, 1] (ours):
        one reading of 003 §2.2's "probability between 0 and 1" per particle.

        Parameters
        ----------
        log_lik : array_like, shape (N,)
            ``log p(z | x)`` per pose (:meth:`log_likelihood`).
        beams : Beams
            The scan's beams (for the number used).

        Returns
        -------
        ndarray, shape (N,)
            Scores in [0, 1].
        """
        n = max(1, self.n_used(beams))
        return np.exp(np.asarray(log_lik, dtype=float) / n - self.log_q_max)

    def log_score(self, poses, beams: Beams, score: str = "likelihood", beam_mask=None) -> np.ndarray:
        """``log`` of the per-particle observation score ``ω`` that weighs the particles, shape ``(N,)``.

        - ``"likelihood"``: ``log p(z | x) = Σ_k log q_k`` (PR Table 6.3; ROS 1 / Nav2 amcl's
          ``likelihood_field_prob`` takes the same product, in log space, with an unnormalised Gaussian);
        - ``"geometric_mean"`` (ours): ``(1/B)·Σ_k log(q_k / q_max)`` ≤ 0, the log of a score in [0, 1];
        - ``"amcl_cubes"``: ``log(1 + Σ_k p_k³)`` with ``p_k = z_hit·exp(−d_k²/(2σ_hit²)) + z_rand/z_max``,
          the ad-hoc sum of ROS 1 amcl's default ``likelihood_field`` model and Beluga's
          ``LikelihoodFieldModel`` (both say it "works well" without a derivation).

        ``beam_mask`` (B,) keeps only some beams (beam skipping); beams at ``z_max`` never count.

        Parameters
        ----------
        poses : array_like, shape (N, 3)
            Poses in cells and radians.
        beams : Beams
            The scan's beams.
        score : str
            One of :data:`SCORES`.
        beam_mask : ndarray of bool, shape (B,), optional
            Beams to use (beam skipping); None: every beam below ``z_max``.

        Returns
        -------
        ndarray, shape (N,)
        """
        check_choice(score, "score", SCORES)
        if score == "amcl_cubes":
            d, keep = self.beam_distances(poses, beams)
            p = self.z_hit * np.exp(-0.5 * (d.astype(np.float64) / self.sigma_hit) ** 2) + self.z_rand / self.z_max
            if beam_mask is not None:
                p = p[:, np.asarray(beam_mask, bool)[keep]]
            return np.log1p((p * p * p).sum(axis=1))
        lq = self.beam_log_q(poses, beams)
        if beam_mask is not None:
            m = np.asarray(beam_mask, bool)
            lq = lq[:, m]
            n = max(1, int(np.count_nonzero(m & self.used(beams))))
        else:
            n = max(1, self.n_used(beams))
        L = lq.sum(axis=1, dtype=np.float64)
        return L if score == "likelihood" else L / n - self.log_q_max
