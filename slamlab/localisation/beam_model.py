"""The beam model of range finders (PR Table 6.1, eqs 6.4-6.12).

Moved unchanged from :mod:`slamlab.localisation.models` (which re-exports it). Lengths in cells.
"""

from __future__ import annotations

import numpy as np
from scipy.special import erf

from .._validate import check_positive

__all__ = ["beam_model_prob"]


def beam_model_prob(z, z_star, *, z_max: float, z_hit: float = 0.8, z_short: float = 0.1,
                    z_max_w: float = 0.05, z_rand: float = 0.05, sigma_hit: float = 1.0,
                    lambda_short: float = 0.1) -> np.ndarray:
    """``p(z_k | x, m)`` of the beam model (PR Table 6.1 and eqs 6.4-6.12), element-wise.

    ``z_hit·p_hit + z_short·p_short + z_max_w·p_max + z_rand·p_rand`` with ``p_hit`` a
    normal ``N(z; z*, σ_hit²)`` truncated to ``[0, z_max]`` (normaliser from ``erf``),
    ``p_short = η·λ·exp(−λz)`` on ``[0, z*]`` with ``η = 1/(1 − exp(−λz*))``,
    ``p_max = 1`` at ``z = z_max`` (a point mass) and ``p_rand = 1/z_max`` on ``[0, z_max)``.

    Parameters
    ----------
    z : array_like
        Measured ranges.
    z_star : array_like
        Expected ranges (ray cast), broadcast with ``z``.
    z_max : float
        Maximum range.
    z_hit, z_short, z_max_w, z_rand : float
        Mixture weights of the hit, short, max-range and random components.
    sigma_hit : float
        σ of the hit component.
    lambda_short : float
        Rate λ of the short component.

    Returns
    -------
    ndarray
        ``p(z_k | x, m)`` element-wise.

    Examples
    --------
    >>> round(float(beam_model_prob(5.0, 5.0, z_max=10.0, z_hit=1, z_short=0, z_max_w=0, z_rand=0)), 6)
    0.398942
    """
    z = np.asarray(z, dtype=float)
    zs = np.asarray(z_star, dtype=float)
    zmax = check_positive(z_max, "z_max")
    for name, val in (("z_hit", z_hit), ("z_short", z_short), ("z_max_w", z_max_w), ("z_rand", z_rand)):
        check_positive(val, name, allow_zero=True)
    sig = check_positive(sigma_hit, "sigma_hit")
    lam = check_positive(lambda_short, "lambda_short")
    inside = (z >= 0) & (z < zmax)
    # eq 6.4-6.6: truncated normal
    eta_hit = 1.0 / (0.5 * (erf((zmax - zs) / (np.sqrt(2) * sig)) - erf((0 - zs) / (np.sqrt(2) * sig))))
    p_hit = np.where(inside, eta_hit * np.exp(-0.5 * ((z - zs) / sig) ** 2) / (np.sqrt(2 * np.pi) * sig), 0.0)
    # eq 6.7-6.9: unexpected objects
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        eta_short = np.where(zs > 0, 1.0 / (1.0 - np.exp(-lam * zs)), 0.0)
    p_short = np.where((z >= 0) & (z <= zs) & (zs > 0), eta_short * lam * np.exp(-lam * z), 0.0)
    p_max = (z >= zmax).astype(float)  # eq 6.10
    p_rand = np.where(inside, 1.0 / zmax, 0.0)  # eq 6.11
    return z_hit * p_hit + z_short * p_short + z_max_w * p_max + z_rand * p_rand
