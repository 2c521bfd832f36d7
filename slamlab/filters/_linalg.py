"""Small dense linear algebra shared by the filters: Cholesky with errors that name the step."""

from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dposv as _dposv

__all__ = ["CholeskyError", "cholesky_lower", "gain", "symmetrize"]


class CholeskyError(np.linalg.LinAlgError):
    """Cholesky factorisation failed: the matrix is not positive definite (a ``ValueError``)."""


def symmetrize(P: np.ndarray) -> np.ndarray:
    """``(P + P^T) / 2``: keeps covariances symmetric against rounding."""
    return 0.5 * (P + P.T)


def cholesky_lower(M: np.ndarray, step: str) -> np.ndarray:
    """Lower Cholesky factor ``A`` with ``A A^T = M``; a failure names ``step``."""
    try:
        return np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        eig = np.linalg.eigvalsh(symmetrize(M)) if np.all(np.isfinite(M)) else np.array([np.nan])
        raise CholeskyError(
            f"Cholesky factorisation failed in {step}: the scaled covariance is not positive definite "
            f"(smallest eigenvalue {eig[0]:.3e}); check P, Q, R and alpha/kappa"
        ) from None


def gain(PHt: np.ndarray, S: np.ndarray, step: str) -> np.ndarray:
    """Kalman gain ``K = P H^T S^-1`` by one Cholesky solve (S symmetric positive definite).

    LAPACK ``dposv`` on the small ``S`` costs ~1 us, against ~6 us for
    ``np.linalg.solve``; a non-positive-definite ``S`` raises :class:`CholeskyError` naming ``step``.
    """
    _, KT, info = _dposv(S, PHt.T)
    if info != 0:
        raise CholeskyError(f"Cholesky factorisation failed in {step}: the innovation covariance S is not "
                            f"positive definite (LAPACK dposv info={info}); check P and R")
    return KT.T
