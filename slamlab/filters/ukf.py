"""Unscented Kalman filter (000 §1.2.3): augmented form of 000 and the additive-noise form.

*Augmented* (000): the predict step augments the state with the process noise,
``x^a = [x; E w]``, ``P^a = blkdiag(P, Q)``, and calls ``f(x, u, w)``; the update
re-draws sigma points from ``(x_{k|k-1}, P_{k|k-1})`` augmented with ``R`` and
calls ``h(x, v)``. So ``L`` differs between predict (``n + dim w``) and update
(``n + dim v``), and neither step adds ``Q`` or ``R`` afterwards.

*Additive* (our addition; 000 has none): ``f(x, u)`` and ``h(x)``, ``L = n``,
``Q`` and ``R`` added to the transformed covariances; sigma points are re-drawn
from the prior before the update, as filterpy 2.0 does.

Weights (000): ``lambda = alpha^2 (L + kappa) - L``, ``Ws0 = lambda / (L + lambda)``,
``Wc0 = Ws0 + (1 - alpha^2 + beta)``, ``Wi = 1 / (2 (L + lambda))``; defaults
``alpha = 1e-3, kappa = 0, beta = 2``.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import block_diag

from .._validate import (
    as_covariance,
    as_measurement,
    as_vector,
    check_callable,
    check_choice,
    check_int,
    check_positive,
)
from ._linalg import CholeskyError, cholesky_lower, gain, symmetrize
from .kalman import Update

__all__ = [
    "CholeskyError",
    "UnscentedKalmanFilter",
    "sigma_points",
    "sigma_weights",
    "ukf_predict",
    "ukf_update",
    "unscented_transform",
]

FORMS = ("augmented", "additive")


def sigma_weights(L: int, alpha: float = 1e-3, beta: float = 2.0, kappa: float = 0.0):
    """Weights ``(Ws, Wc)`` of the ``2L+1`` sigma points and ``lambda`` (000 §1.2.3).

    Parameters
    ----------
    L : int
        Dimension of the (augmented) state the sigma points sample.
    alpha : float, default 1e-3
        Spread of the sigma points.
    beta : float, default 2.0
        Prior-knowledge term added to the centre covariance weight (2 for Gaussians).
    kappa : float, default 0.0
        Secondary scaling; ``L + lambda = alpha^2 (L + kappa)`` must be positive.

    Returns
    -------
    Ws, Wc : numpy.ndarray, shape (2L+1,)
        Mean and covariance weights.
    lam : float
        ``lambda``.

    Examples
    --------
    >>> Ws, Wc, lam = sigma_weights(2, alpha=1.0, beta=2.0, kappa=1.0)
    >>> Ws, Wc, lam
    (array([0.3333, 0.1667, 0.1667, 0.1667, 0.1667]), array([2.3333, 0.1667, 0.1667, 0.1667, 0.1667]), 1.0)
    """
    L = check_int(L, "L", minimum=1)
    alpha = check_positive(alpha, "alpha")
    beta = float(beta)
    kappa = float(kappa)
    lam = alpha**2 * (L + kappa) - L
    # L + lambda = alpha^2 (L + kappa), computed directly: the difference L + lambda cancels
    # catastrophically for small alpha (1e-10 relative at alpha = 1e-3, as in filterpy's weights)
    L_lam = alpha**2 * (L + kappa)
    if L_lam <= 0:
        raise ValueError(f"`kappa` must give L + lambda > 0; got L + lambda = {L_lam:.3g} (L={L}, kappa={kappa})")
    Ws = np.full(2 * L + 1, 0.5 / L_lam)
    Wc = Ws.copy()
    Ws[0] = lam / L_lam
    Wc[0] = lam / L_lam + (1.0 - alpha**2 + beta)
    return Ws, Wc, lam


def _sigma_points(x, P, alpha, kappa, step):
    L = x.shape[0]
    # columns of sqrt((L + lambda) P): A A^T = (L + lambda) P, with L + lambda = alpha^2 (L + kappa)
    A = cholesky_lower(alpha**2 * (L + kappa) * P, step)
    return np.vstack([x, x + A.T, x - A.T])


def sigma_points(x, P, alpha: float = 1e-3, kappa: float = 0.0) -> np.ndarray:
    """The ``2L+1`` sigma points as rows: ``x``, ``x + A_i``, ``x - A_i`` (000 §1.2.3).

    ``A_i`` is column ``i`` of the lower Cholesky factor of ``(L + lambda) P``.

    Parameters
    ----------
    x : array_like, shape (L,)
        Mean.
    P : array_like, shape (L, L)
        Covariance.
    alpha, kappa : float
        Sigma-point parameters, as in :func:`sigma_weights`.

    Returns
    -------
    numpy.ndarray, shape (2L+1, L)
        Sigma points as rows.

    Examples
    --------
    >>> sigma_points([0.0, 0.0], np.eye(2), alpha=1.0, kappa=2.0)
    array([[ 0.,  0.],
           [ 2.,  0.],
           [ 0.,  2.],
           [-2.,  0.],
           [ 0., -2.]])
    """
    x = as_vector(x, "x")
    P = as_covariance(P, "P", x.shape[0])
    sigma_weights(x.shape[0], alpha, 2.0, kappa)  # validates alpha, kappa
    return _sigma_points(x, P, alpha, kappa, "sigma_points")


def unscented_transform(sigmas, Ws, Wc, noise_cov=None, mean_fn=None, residual_fn=None):
    """Weighted mean and covariance of transformed sigma points (rows of ``sigmas``).

    ``mean_fn(sigmas, Ws)`` and ``residual_fn(a, b)`` (broadcasting over rows)
    replace the linear mean and subtraction, e.g. for angles.

    Parameters
    ----------
    sigmas : array_like, shape (2L+1, d)
        Transformed sigma points as rows.
    Ws, Wc : array_like, shape (2L+1,)
        Mean and covariance weights from :func:`sigma_weights`.
    noise_cov : array_like, shape (d, d), optional
        Added to the covariance (additive noise).
    mean_fn : callable, optional
        ``mean_fn(sigmas, Ws) -> (d,)``, replaces the weighted mean.
    residual_fn : callable, optional
        ``residual_fn(a, b)``, replaces subtraction.

    Returns
    -------
    mean : numpy.ndarray, shape (d,)
    cov : numpy.ndarray, shape (d, d)

    Examples
    --------
    >>> Ws, Wc, _ = sigma_weights(1, alpha=1.0, kappa=2.0)
    >>> unscented_transform(np.array([[0.0], [3.0], [-3.0]]), Ws, Wc)
    (array([0.]), array([[3.]]))
    """
    sigmas = np.asarray(sigmas, dtype=float)
    mean = Ws @ sigmas if mean_fn is None else np.asarray(mean_fn(sigmas, Ws), dtype=float)
    d = sigmas - mean if residual_fn is None else residual_fn(sigmas, mean)
    cov = (d.T * Wc) @ d
    if noise_cov is not None:
        cov = cov + noise_cov
    return mean, symmetrize(cov)


def _ukf_predict(x, P, f, Q, u, form, alpha, beta, kappa, mean_fn, residual_fn, vectorized):
    n = x.shape[0]
    if form == "augmented":
        nq = Q.shape[0]
        # x^a = [x; E w],  P^a = blkdiag(P, Q)
        xa = np.concatenate([x, np.zeros(nq)])
        Pa = block_diag(P, Q)
        Ws, Wc, _ = sigma_weights(n + nq, alpha, beta, kappa)
        chi = _sigma_points(xa, Pa, alpha, kappa, "ukf_predict (augmented sigma points)")
        # chi_{k|k-1}^i = f(chi_x^i, u, chi_w^i)
        if vectorized:
            Y = np.asarray(f(chi[:, :n], u, chi[:, n:]), dtype=float)
        else:
            Y = np.array([np.asarray(f(c[:n], u, c[n:]), dtype=float) for c in chi])
        return unscented_transform(Y, Ws, Wc, None, mean_fn, residual_fn)
    Ws, Wc, _ = sigma_weights(n, alpha, beta, kappa)
    chi = _sigma_points(x, P, alpha, kappa, "ukf_predict (sigma points)")
    Y = np.asarray(f(chi, u), dtype=float) if vectorized else np.array([np.asarray(f(c, u), float) for c in chi])
    # additive form: P_{k|k-1} = sum Wc (Y - x)(Y - x)^T + Q
    return unscented_transform(Y, Ws, Wc, Q, mean_fn, residual_fn)


def _ukf_update(x, P, z, h, R, form, alpha, beta, kappa, z_mean_fn, z_residual_fn, x_residual_fn, vectorized):
    n = x.shape[0]
    if form == "augmented":
        nr = R.shape[0]
        # x^a = [x_{k|k-1}; E v],  P^a = blkdiag(P_{k|k-1}, R)
        xa = np.concatenate([x, np.zeros(nr)])
        Pa = block_diag(P, R)
        Ws, Wc, _ = sigma_weights(n + nr, alpha, beta, kappa)
        chi = _sigma_points(xa, Pa, alpha, kappa, "ukf_update (augmented sigma points)")
        X = chi[:, :n]
        # gamma^i = h(chi_x^i, chi_v^i)
        if vectorized:
            Z = np.asarray(h(X, chi[:, n:]), dtype=float)
        else:
            Z = np.array([np.asarray(h(c[:n], c[n:]), dtype=float) for c in chi])
        z_pred, Pzz = unscented_transform(Z, Ws, Wc, None, z_mean_fn, z_residual_fn)
    else:
        Ws, Wc, _ = sigma_weights(n, alpha, beta, kappa)
        X = _sigma_points(x, P, alpha, kappa, "ukf_update (sigma points)")
        Z = np.asarray(h(X), dtype=float) if vectorized else np.array([np.asarray(h(c), float) for c in X])
        z_pred, Pzz = unscented_transform(Z, Ws, Wc, R, z_mean_fn, z_residual_fn)
    dX = X - x if x_residual_fn is None else x_residual_fn(X, x)
    dZ = Z - z_pred if z_residual_fn is None else z_residual_fn(Z, z_pred)
    # P_xz = sum Wc (chi - x)(gamma - z)^T
    Pxz = (dX.T * Wc) @ dZ
    # K = P_xz P_zz^-1
    K = gain(Pxz, Pzz, "ukf_update")
    y = z - z_pred if z_residual_fn is None else z_residual_fn(z, z_pred)
    # x = x + K (z - z_pred);  P = P - K P_zz K^T
    x_new = x + K @ y
    P_new = symmetrize(P - K @ Pzz @ K.T)
    return Update(x_new, P_new, y, Pzz, K)


def _check_common(x, P, form, alpha, beta, kappa):
    x = as_vector(x, "x")
    P = as_covariance(P, "P", x.shape[0])
    check_choice(form, "form", FORMS)
    check_positive(alpha, "alpha")
    if not np.isfinite(beta) or not np.isfinite(kappa):
        raise ValueError(f"`beta` and `kappa` must be finite; got beta={beta}, kappa={kappa}")
    return x, P


def ukf_predict(x, P, f, Q, u=None, *, form: str = "augmented", alpha: float = 1e-3, beta: float = 2.0,
                kappa: float = 0.0, mean_fn=None, residual_fn=None, vectorized: bool = False):
    """UKF predict step (000 §1.2.3).

    Parameters
    ----------
    x : array_like, shape (n,)
        Posterior state.
    P : array_like, shape (n, n)
        Its covariance.
    f : callable
        ``f(x, u, w)`` for ``form="augmented"`` (``w`` the process-noise
        component of the sigma point), ``f(x, u)`` for ``"additive"``.
    Q : array_like
        Covariance of ``w`` (augmented; any size) or of the state noise
        (additive; (n, n)).
    u : optional
        Control, passed to ``f``.
    form : {"augmented", "additive"}
        000's augmented form or the additive-noise form.
    alpha, beta, kappa : float
        Sigma-point parameters (000's defaults 1e-3, 2, 0).
    mean_fn, residual_fn : callable, optional
        State mean ``mean_fn(sigmas, Ws)`` and difference
        ``residual_fn(a, b)`` hooks (angles), broadcasting over rows.
    vectorized : bool
        ``f`` accepts all sigma points at once as rows.

    Returns
    -------
    x, P : the prior.
    """
    x, P = _check_common(x, P, form, alpha, beta, kappa)
    check_callable(f, "f")
    Q = as_covariance(Q, "Q", None if form == "augmented" else x.shape[0])
    return _ukf_predict(x, P, f, Q, u, form, alpha, beta, kappa, mean_fn, residual_fn, vectorized)


def ukf_update(x, P, z, h, R, *, form: str = "augmented", alpha: float = 1e-3, beta: float = 2.0,
               kappa: float = 0.0, z_mean_fn=None, z_residual_fn=None, x_residual_fn=None,
               vectorized: bool = False) -> Update:
    """UKF update step (000 §1.2.3): re-draws sigma points from the prior.

    ``h(x, v)`` for ``form="augmented"``, ``h(x)`` for ``"additive"``. Returns
    :class:`~slamlab.filters.Update` with ``S = P_zz`` and ``K = P_xz P_zz^-1``.

    Parameters
    ----------
    x : array_like, shape (n,)
        Prior state ``x_{k|k-1}``.
    P : array_like, shape (n, n)
        Prior covariance.
    z : array_like, shape (m,)
        Measurement.
    h : callable
        ``h(x, v)`` (augmented) or ``h(x)`` (additive), returning ``(m,)``.
    R : array_like
        Covariance of ``v`` (augmented; any size) or ``(m, m)`` (additive).
    form : {"augmented", "additive"}
        As in :func:`ukf_predict`.
    alpha, beta, kappa : float
        Sigma-point parameters (000's defaults 1e-3, 2, 0).
    z_mean_fn, z_residual_fn : callable, optional
        Mean and difference hooks in measurement space (bearings).
    x_residual_fn : callable, optional
        Difference hook in state space (headings).
    vectorized : bool
        ``h`` accepts all sigma points at once as rows.

    Returns
    -------
    Update
        Posterior ``x, P``, innovation ``y``, ``S = P_zz``, ``K``.
    """
    x, P = _check_common(x, P, form, alpha, beta, kappa)
    z = as_vector(z, "z")
    R = as_covariance(R, "R", None if form == "augmented" else z.shape[0])
    check_callable(h, "h")
    return _ukf_update(x, P, z, h, R, form, alpha, beta, kappa, z_mean_fn, z_residual_fn, x_residual_fn,
                       vectorized)


class UnscentedKalmanFilter:
    """UKF (000 §1.2.3) in the augmented (000) or additive (ours) form.

    Keeps ``x_prior, P_prior, x_post, P_post, y, S, K``. ``Q`` and ``R`` may be
    reassigned between steps. The hooks are as in :func:`ukf_predict`.

    Parameters
    ----------
    x : array_like, shape (n,)
        Initial state.
    P : array_like, shape (n, n)
        Initial covariance.
    f : callable
        Motion model, ``f(x, u, w)`` or ``f(x, u)`` by ``form``.
    Q : array_like
        Process noise covariance, as in :func:`ukf_predict`.
    h : callable
        Measurement model, ``h(x, v)`` or ``h(x)`` by ``form``.
    R : array_like
        Measurement noise covariance, as in :func:`ukf_update`.
    form : {"augmented", "additive"}
        Which UKF.
    alpha, beta, kappa : float
        Sigma-point parameters.
    x_mean_fn, x_residual_fn : callable, optional
        State-space mean and difference hooks.
    z_mean_fn, z_residual_fn : callable, optional
        Measurement-space mean and difference hooks.
    vectorized : bool
        ``f`` and ``h`` take all sigma points at once as rows.
    """

    def __init__(self, x, P, f, Q, h, R, *, form: str = "augmented", alpha: float = 1e-3, beta: float = 2.0,
                 kappa: float = 0.0, x_mean_fn=None, x_residual_fn=None, z_mean_fn=None, z_residual_fn=None,
                 vectorized: bool = False):
        self.x, self.P = _check_common(x, P, form, alpha, beta, kappa)
        self.f, self.h = check_callable(f, "f"), check_callable(h, "h")
        self.form = form
        n = self.x.shape[0]
        self.Q = as_covariance(Q, "Q", None if form == "augmented" else n)
        self.R = as_covariance(R, "R")
        self.alpha, self.beta, self.kappa = float(alpha), float(beta), float(kappa)
        self.x_mean_fn, self.x_residual_fn = x_mean_fn, x_residual_fn
        self.z_mean_fn, self.z_residual_fn = z_mean_fn, z_residual_fn
        self.vectorized = vectorized
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()
        self.x_post, self.P_post = self.x.copy(), self.P.copy()
        self.y = self.S = self.K = None

    def predict(self, u=None) -> None:
        """Predict with the stored model; sets ``x, P`` and ``x_prior, P_prior``.

        Parameters
        ----------
        u : optional
            Control passed to ``f``.
        """
        self.x, self.P = _ukf_predict(self.x, self.P, self.f, self.Q, u, self.form, self.alpha, self.beta,
                                      self.kappa, self.x_mean_fn, self.x_residual_fn, self.vectorized)
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()

    def update(self, z) -> None:
        """Update with measurement ``z``; sets ``x, P``, ``x_post, P_post`` and ``y, S, K``.

        Parameters
        ----------
        z : array_like, shape (m,)
            Measurement.
        """
        z = as_measurement(z, "z", self.R.shape[0])
        self.x, self.P, self.y, self.S, self.K = _ukf_update(
            self.x, self.P, z, self.h, self.R, self.form, self.alpha, self.beta, self.kappa,
            self.z_mean_fn, self.z_residual_fn, self.x_residual_fn, self.vectorized)
        self.x_post, self.P_post = self.x.copy(), self.P.copy()

    def __repr__(self) -> str:
        return (f"UnscentedKalmanFilter(form={self.form!r}, dim_x={self.x.shape[0]}, alpha={self.alpha}, "
                f"beta={self.beta}, kappa={self.kappa})")
