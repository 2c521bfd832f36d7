"""Inverse-depth seeds: Gaussian × Beta posterior, vectorised over seeds (003 §4.1.1, §4.2, §4.3.2).

003's equations are lost images; this module reconstructs them from the works it follows
(label: *reconstruction*):

* measurement model (Vogiatzis & Hernández 2011, in inverse depth as SVO, Forster et al.
  2014): ``p(x | ρ, π) = π N(x | ρ, τ²) + (1 − π) U(x | 0, ρ_range)``;
* approximate posterior ``q(ρ, π) = N(ρ | μ, σ²) Beta(π | a, b)``, updated per measurement
  by matching the first and second moments of ``q · p(x | ρ, π)`` (exact in ``ρ`` and
  ``π``; see :func:`update_seeds`);
* SVO's initialisation: ``a = b = 10``, ``μ = 1 / depth_mean``, ``ρ_range = 1 / depth_min``,
  ``σ² = ρ_range² / 36``;
* SVO's measurement noise ``τ``: one pixel of angle error pushed through the triangle
  formed by the two camera centres and the point (law of sines), see :func:`compute_tau`;
* the search band of 003 §4.2: ``ρ ± 2σ`` with ``ρ − 2σ`` replaced by 1e-10 when ≤ 0;
* two convergence tests: SVO's ``σ < ρ_range / 200`` and 003's linearity index
  ``L = 4 σ_d |cos α| / d < 0.1`` (003 §4.3.2, eq. 6.7-6.8 lost; reconstructed from
  Civera, Davison & Montiel 2008, which 003 cites: ``σ_d = σ_ρ / ρ²``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validate import as_finite_array, check_positive

__all__ = [
    "Seeds",
    "compute_tau",
    "converged_linearity",
    "converged_sigma",
    "depth_interval",
    "init_seeds",
    "inlier_ratio",
    "linearity_index",
    "seed_points",
    "update_seeds",
]

#: SVO's prior pseudo-counts of inliers and outliers (depth_filter.cpp, a = b = 10)
SVO_A0 = 10.0
SVO_B0 = 10.0
#: SVO's convergence: σ below ρ_range / 200 (Config::seed_convergence_sigma2_thresh = 200)
SVO_SIGMA_FRACTION = 1.0 / 200.0
#: 003 §4.2: the value that replaces ρ − 2σ when it is ≤ 0
RHO_FLOOR = 1e-10


@dataclass
class Seeds:
    """Struct of arrays for ``N`` seeds (003 §4.1.1): one row per candidate point.

    ``uv`` (N, 2) pixel in the reference keyframe, ``f`` (N, 3) unit bearing there,
    ``mu`` / ``sigma2`` inverse depth (1/m) mean and variance, ``a``, ``b`` the Beta
    counts, ``rho_range`` the width (1/m) of the outlier's uniform, ``ref`` the index of the
    reference keyframe, ``n_obs`` measurements taken, ``n_fail`` failed searches in a row.

    Attributes
    ----------
    uv : ndarray, shape (N, 2)
        Pixel in the reference keyframe.
    f : ndarray, shape (N, 3)
        Unit bearing in the reference keyframe.
    mu, sigma2 : ndarray, shape (N,)
        Inverse-depth mean [1/m] and variance [1/m²].
    a, b : ndarray, shape (N,)
        Beta counts (inlier, outlier).
    rho_range : ndarray, shape (N,)
        Width of the outlier's uniform [1/m].
    ref : ndarray of int, shape (N,)
        Index of the reference keyframe.
    n_obs : ndarray of int, shape (N,)
        Measurements taken.
    n_fail : ndarray of int, shape (N,)
        Failed searches in a row.
    """

    uv: np.ndarray
    f: np.ndarray
    mu: np.ndarray
    sigma2: np.ndarray
    a: np.ndarray
    b: np.ndarray
    rho_range: np.ndarray
    ref: np.ndarray
    n_obs: np.ndarray
    n_fail: np.ndarray

    def __len__(self) -> int:
        return int(self.mu.shape[0])

    def take(self, idx) -> Seeds:
        """The seeds selected by an index or boolean mask.

        Parameters
        ----------
        idx : int array or bool mask
            Seeds to keep.

        Returns
        -------
        Seeds
            The selected rows of every field.
        """
        return Seeds(**{k: getattr(self, k)[idx] for k in self.__dataclass_fields__})

    @staticmethod
    def concat(parts) -> Seeds:
        """All seeds of ``parts`` in order.

        Parameters
        ----------
        parts : iterable of Seeds
            The seed sets to join (none: an empty set).

        Returns
        -------
        Seeds
        """
        parts = list(parts)
        if not parts:
            return init_seeds(np.zeros((0, 2)), np.zeros((0, 3)), 1.0, 1.0)
        return Seeds(**{k: np.concatenate([getattr(p, k) for p in parts]) for k in Seeds.__dataclass_fields__})


def init_seeds(uv, f, depth_mean_m: float, depth_min_m: float, *, ref: int = 0,
               a0: float = SVO_A0, b0: float = SVO_B0) -> Seeds:
    """New seeds as SVO initialises them (003 §4.1.1; values from SVO's depth_filter.cpp).

    ``μ = 1/depth_mean``, ``ρ_range = 1/depth_min``, ``σ² = ρ_range²/36``, ``a = a0``, ``b = b0``.

    Parameters
    ----------
    uv : array_like, shape (N, 2)
        Pixels of the new seeds in the reference keyframe.
    f : array_like, shape (N, 3)
        Their unit bearings.
    depth_mean_m : float
        Prior mean depth [m] (the scene's median depth).
    depth_min_m : float
        Smallest expected depth [m]; sets ``rho_range``.
    ref : int
        Index of the reference keyframe (default 0).
    a0, b0 : float
        Initial Beta counts (SVO: 10, 10).

    Returns
    -------
    Seeds
        ``N`` new seeds with ``n_obs = n_fail = 0``.

    Examples
    --------
    >>> s = init_seeds([[1.0, 2.0]], [[0.0, 0.0, 1.0]], 2.0, 0.5)
    >>> float(s.mu[0]), float(s.rho_range[0]), round(float(s.sigma2[0]), 6)
    (0.5, 2.0, 0.111111)
    """
    uv = as_finite_array(uv, "uv", ndim=2)
    f = as_finite_array(f, "f", ndim=2)
    if uv.shape[1] != 2:
        raise ValueError(f"`uv` must have shape (N, 2); got {uv.shape}")
    if f.shape != (uv.shape[0], 3):
        raise ValueError(f"`f` must have shape ({uv.shape[0]}, 3); got {f.shape}")
    depth_mean_m = check_positive(depth_mean_m, "depth_mean_m")
    depth_min_m = check_positive(depth_min_m, "depth_min_m")
    a0 = check_positive(a0, "a0")
    b0 = check_positive(b0, "b0")
    n = uv.shape[0]
    norms = np.linalg.norm(f, axis=1, keepdims=True)
    if n and np.any(norms <= 0):
        raise ValueError("`f` rows must be non-zero bearing vectors")
    rho_range = 1.0 / depth_min_m
    return Seeds(
        uv=uv.copy(), f=f / np.where(norms > 0, norms, 1.0),
        mu=np.full(n, 1.0 / depth_mean_m), sigma2=np.full(n, rho_range**2 / 36.0),
        a=np.full(n, float(a0)), b=np.full(n, float(b0)), rho_range=np.full(n, rho_range),
        ref=np.full(n, int(ref), dtype=np.int64), n_obs=np.zeros(n, np.int64), n_fail=np.zeros(n, np.int64),
    )


def update_seeds(mu, sigma2, a, b, x, tau2, rho_range):
    """One Gaussian × Beta update per seed, all seeds at once (003 §4.1.1; reconstruction).

    Arrays of equal length ``N``: prior ``N(μ, σ²) Beta(a, b)``, measurement ``x`` of the
    inverse depth with variance ``tau2``, outlier density ``1/rho_range``. The exact
    posterior moments (Vogiatzis & Hernández 2011, eq. 19-23)::

        C1 ∝ a/(a+b) · N(x | μ, σ² + τ²),   C2 ∝ b/(a+b) / ρ_range,   C1 + C2 = 1
        s² = 1/(1/σ² + 1/τ²),  m = s² (μ/σ² + x/τ²)
        μ' = C1 m + C2 μ
        σ'² = C1 (s² + m²) + C2 (σ² + μ²) − μ'²
        f = E[π] = C1 (a+1)/(a+b+1) + C2 a/(a+b+1)
        e = E[π²] = C1 (a+1)(a+2)/((a+b+1)(a+b+2)) + C2 a(a+1)/((a+b+1)(a+b+2))
        a' = (e − f)/(f − e/f),  b' = a' (1 − f)/f

    Returns ``(mu, sigma2, a, b)`` as new arrays.

    Parameters
    ----------
    mu, sigma2 : array_like, shape (N,)
        Prior inverse-depth mean [1/m] and variance.
    a, b : array_like, shape (N,)
        Prior Beta counts.
    x : array_like, shape (N,)
        Measured inverse depth [1/m].
    tau2 : array_like, shape (N,)
        Measurement variance [1/m²].
    rho_range : array_like, shape (N,)
        Width of the outlier's uniform [1/m].

    Returns
    -------
    mu, sigma2, a, b : ndarray, shape (N,)
        Posterior parameters (``sigma2`` kept above the smallest positive float).
    """
    mu, sigma2, a, b, x, tau2, rho_range = np.broadcast_arrays(
        *(np.asarray(z, dtype=np.float64) for z in (mu, sigma2, a, b, x, tau2, rho_range)))
    s_tot2 = sigma2 + tau2
    norm_pdf = np.exp(-0.5 * (x - mu) ** 2 / s_tot2) / np.sqrt(2.0 * np.pi * s_tot2)
    ab = a + b
    C1 = a / ab * norm_pdf
    C2 = b / ab / rho_range
    Z = C1 + C2
    C1 = C1 / Z
    C2 = C2 / Z
    s2 = 1.0 / (1.0 / sigma2 + 1.0 / tau2)
    m = s2 * (mu / sigma2 + x / tau2)
    mu_new = C1 * m + C2 * mu
    sigma2_new = C1 * (s2 + m * m) + C2 * (sigma2 + mu * mu) - mu_new * mu_new
    f = C1 * (a + 1.0) / (ab + 1.0) + C2 * a / (ab + 1.0)
    e = (C1 * (a + 1.0) * (a + 2.0) + C2 * a * (a + 1.0)) / ((ab + 1.0) * (ab + 2.0))
    a_new = (e - f) / (f - e / f)
    b_new = a_new * (1.0 - f) / f
    return mu_new, np.maximum(sigma2_new, np.finfo(float).tiny), a_new, b_new


def inlier_ratio(a, b):
    """Mean of the Beta part, ``a / (a + b)`` (003 §4.1.1).

    Parameters
    ----------
    a, b : array_like
        Beta counts.

    Returns
    -------
    ratio : ndarray
        ``a / (a + b)``.
    """
    a = np.asarray(a, dtype=np.float64)
    return a / (a + np.asarray(b, dtype=np.float64))


def compute_tau(t_ref_cur, f, z_m, px_error_angle_rad):
    """Depth std ``τ`` (m) of a triangulation from one pixel of angle error (SVO's computeTau).

    ``t_ref_cur`` (3,) or (N, 3): the current camera centre in the reference frame;
    ``f`` (N, 3) unit bearing in the reference frame; ``z_m`` (N,) depth along ``f``.
    With ``a = f z − t``, ``α = ∠(f, t)``, ``β = ∠(a, −t)``, ``β⁺ = β + δ`` and
    ``g⁺ = π − α − β⁺``: ``z⁺ = |t| sin β⁺ / sin g⁺`` and ``τ = z⁺ − z``.
    ``δ = 2 atan(σ_px / (2 f_px))`` (SVO: σ_px = 1).

    Parameters
    ----------
    t_ref_cur : array_like, shape (3,) or (N, 3)
        Current camera centre in the reference frame [m].
    f : array_like, shape (N, 3)
        Unit bearings in the reference frame.
    z_m : array_like, shape (N,)
        Depths along ``f`` [m].
    px_error_angle_rad : float
        Angle ``δ`` of one pixel's error [rad].

    Returns
    -------
    tau_m : ndarray, shape (N,)
        Depth standard deviation [m].
    """
    t = np.broadcast_to(np.asarray(t_ref_cur, dtype=np.float64), np.shape(f))
    f = np.asarray(f, dtype=np.float64)
    z = np.asarray(z_m, dtype=np.float64)
    a = f * z[:, None] - t
    t_norm = np.linalg.norm(t, axis=1)
    a_norm = np.linalg.norm(a, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        alpha = np.arccos(np.clip(np.sum(f * t, axis=1) / t_norm, -1.0, 1.0))
        beta = np.arccos(np.clip(np.sum(a * -t, axis=1) / (t_norm * a_norm), -1.0, 1.0))
        beta_plus = beta + px_error_angle_rad
        gamma_plus = np.pi - alpha - beta_plus
        z_plus = t_norm * np.sin(beta_plus) / np.sin(gamma_plus)
    tau = z_plus - z
    return np.where(np.isfinite(tau) & (gamma_plus > 0), tau, np.inf)


def tau_inverse(z_m, tau_m):
    """Inverse-depth std from a depth std, as SVO: ``½ (1/max(z − τ, 1e-7) − 1/(z + τ))``.

    Parameters
    ----------
    z_m : array_like
        Depths [m].
    tau_m : array_like
        Depth standard deviations [m].

    Returns
    -------
    tau_inv : ndarray
        Inverse-depth standard deviations [1/m].
    """
    z = np.asarray(z_m, dtype=np.float64)
    tau = np.asarray(tau_m, dtype=np.float64)
    return 0.5 * (1.0 / np.maximum(z - tau, 1e-7) - 1.0 / (z + tau))


def depth_interval(mu, sigma, n_sigma: float = 2.0, floor: float = RHO_FLOOR):
    """Depth band ``[1/(ρ + nσ), 1/max(ρ − nσ, floor)]`` searched along the epipolar line (003 §4.2).

    Parameters
    ----------
    mu, sigma : array_like, shape (N,)
        Inverse-depth mean and standard deviation [1/m].
    n_sigma : float
        Half-width of the band in standard deviations (default 2).
    floor : float
        Smallest inverse depth used for the far end [1/m] (default 1e-10).

    Returns
    -------
    depth_min_m, depth_max_m : ndarray, shape (N,)
        Near and far ends of the band [m].

    Examples
    --------
    >>> lo, hi = depth_interval(np.array([0.5]), np.array([0.3]))
    >>> round(float(lo[0]), 4), float(hi[0])
    (0.9091, 10000000000.0)
    """
    mu = np.asarray(mu, dtype=np.float64)
    sigma = np.asarray(sigma, dtype=np.float64)
    rho_max = mu + n_sigma * sigma
    rho_min = mu - n_sigma * sigma
    rho_min = np.where(rho_min <= 0, floor, rho_min)
    return 1.0 / rho_max, 1.0 / rho_min


def converged_sigma(sigma2, rho_range, fraction: float = SVO_SIGMA_FRACTION):
    """SVO's test: ``σ < fraction · ρ_range`` (SVO: fraction = 1/200).

    Parameters
    ----------
    sigma2 : array_like
        Inverse-depth variances.
    rho_range : array_like
        Widths of the outlier's uniform [1/m].
    fraction : float
        Threshold as a fraction of ``rho_range`` (default 1/200).

    Returns
    -------
    converged : ndarray of bool
    """
    return np.sqrt(np.asarray(sigma2, dtype=np.float64)) < fraction * np.asarray(rho_range, dtype=np.float64)


def linearity_index(mu, sigma2, d_m, cos_alpha):
    """003's ``L = 4 σ_d |cos α| / d`` with ``σ_d = σ_ρ / ρ²`` (003 §4.3.2, eq. 6.7-6.8; reconstruction).

    ``d_m`` distance from the current camera to the point, ``α`` the parallax between the
    first and the current ray (Civera, Davison & Montiel 2008, the linearity index).

    Parameters
    ----------
    mu, sigma2 : array_like
        Inverse-depth mean [1/m] and variance.
    d_m : array_like
        Distance from the current camera to the point [m].
    cos_alpha : array_like
        Cosine of the parallax between the first and the current ray.

    Returns
    -------
    L : ndarray
        The linearity index.
    """
    mu = np.asarray(mu, dtype=np.float64)
    sigma_d = np.sqrt(np.asarray(sigma2, dtype=np.float64)) / np.maximum(mu, RHO_FLOOR) ** 2
    return 4.0 * sigma_d * np.abs(np.asarray(cos_alpha, dtype=np.float64)) / np.asarray(d_m, dtype=np.float64)


def converged_linearity(mu, sigma2, d_m, cos_alpha, L_max: float = 0.1):
    """003's test ``L < 0.1`` (003 §4.3.2).

    Parameters
    ----------
    mu, sigma2, d_m, cos_alpha : array_like
        As in :func:`linearity_index`.
    L_max : float
        Threshold on the index (default 0.1).

    Returns
    -------
    converged : ndarray of bool
    """
    return linearity_index(mu, sigma2, d_m, cos_alpha) < L_max


def seed_points(seeds: Seeds, T_world_ref) -> np.ndarray:
    """World points of seeds, ``X = R_F (f / ρ) + T_F`` (003 §4.1.2, eq. 6.4; reconstruction).

    ``T_world_ref`` (K, 4, 4) keyframe poses indexed by ``seeds.ref``.

    Parameters
    ----------
    seeds : Seeds
        The seeds.
    T_world_ref : array_like, shape (K, 4, 4)
        Keyframe poses (camera to world), indexed by ``seeds.ref``.

    Returns
    -------
    X : ndarray, shape (N, 3)
        World points [m].
    """
    T = np.asarray(T_world_ref, dtype=np.float64)[seeds.ref]
    p = seeds.f / np.maximum(seeds.mu, RHO_FLOOR)[:, None]
    return np.einsum("nij,nj->ni", T[:, :3, :3], p) + T[:, :3, 3]
