"""Extended Kalman filter (000 §1.2.2) and a finite-difference Jacobian checker.

Jacobians as in 000: ``F = df/dx`` at ``(x_{k-1|k-1}, u)``, ``H = dh/dx`` at
``x_{k|k-1}``. ``f(x, u)`` and ``h(x)`` are plain callables; ``residual`` lets
bearings wrap (``lambda a, b: ...wrap_angle...``).
"""

from __future__ import annotations

import numpy as np

from .._validate import as_covariance, as_matrix, as_measurement, as_vector, check_callable
from ._linalg import gain, symmetrize
from .kalman import Update

__all__ = ["ExtendedKalmanFilter", "check_jacobian", "ekf_predict", "ekf_update", "numerical_jacobian"]


def _ekf_predict(x, P, f, F_jac, Q, u):
    # F_{k-1} = df/dx at (x_{k-1|k-1}, u_{k-1})  (evaluated before x moves)
    F = F_jac(x, u)
    # x_{k|k-1} = f(x_{k-1|k-1}, u_{k-1})
    x = f(x, u)
    # P_{k|k-1} = F P F^T + Q
    P = symmetrize(F @ P @ F.T + Q)
    return x, P


def _ekf_update(x, P, z, h, H_jac, R, residual):
    # H_k = dh/dx at x_{k|k-1}
    H = H_jac(x)
    # y = z - h(x_{k|k-1})
    y = residual(z, h(x))
    PHt = P @ H.T
    # S = H P H^T + R ; K = P H^T S^-1
    S = H @ PHt + R
    K = gain(PHt, S, "ekf_update")
    # x = x + K y ; P = (I - K H) P = P - K (H P)
    x = x + K @ y
    P = symmetrize(P - K @ PHt.T)
    return Update(x, P, y, S, K)


def ekf_predict(x, P, f, F_jac, Q, u=None):
    """EKF predict step (000 §1.2.2).

    Parameters
    ----------
    x : array_like, shape (n,)
        Posterior state ``x_{k-1|k-1}``.
    P : array_like, shape (n, n)
        Its covariance.
    f : callable
        ``f(x, u) -> (n,)`` motion model.
    F_jac : callable
        ``F_jac(x, u) -> (n, n)``, the Jacobian ``df/dx``.
    Q : array_like, shape (n, n)
        Process noise covariance (in state space).
    u : optional
        Control passed through to ``f`` and ``F_jac`` (may be None).

    Returns
    -------
    x, P : numpy.ndarray
        The prior ``x_{k|k-1}``, shape ``(n,)``, and ``P_{k|k-1}``, shape ``(n, n)``.

    Examples
    --------
    >>> f = lambda x, u: np.array([x[0] + np.sin(x[0])])
    >>> F = lambda x, u: np.array([[1 + np.cos(x[0])]])
    >>> x, P = ekf_predict([0.0], [[1.0]], f, F, [[0.0]])
    >>> x, P
    (array([0.]), array([[4.]]))
    """
    x = as_vector(x, "x")
    n = x.shape[0]
    P = as_covariance(P, "P", n)
    Q = as_covariance(Q, "Q", n)
    check_callable(f, "f")
    check_callable(F_jac, "F_jac")
    F = as_matrix(F_jac(x, u), "F_jac(x, u)", (n, n))
    x_new = as_vector(f(x, u), "f(x, u)", n)
    return x_new, symmetrize(F @ P @ F.T + Q)


def ekf_update(x, P, z, h, H_jac, R, *, residual=np.subtract) -> Update:
    """EKF update step (000 §1.2.2).

    Parameters
    ----------
    x : array_like, shape (n,)
        Prior state ``x_{k|k-1}``.
    P : array_like, shape (n, n)
        Prior covariance.
    z : array_like, shape (m,)
        Measurement.
    h : callable
        ``h(x) -> (m,)`` measurement model.
    H_jac : callable
        ``H_jac(x) -> (m, n)``, the Jacobian ``dh/dx``.
    R : array_like, shape (m, m)
        Measurement noise covariance.
    residual : callable, default numpy.subtract
        ``residual(z, z_pred) -> y``; wrap bearings here.

    Returns
    -------
    Update
        ``(x, P, y, S, K)``: posterior, innovation, its covariance, the gain.

    Examples
    --------
    >>> upd = ekf_update([1.0], [[1.0]], [4.0], lambda x: x**2, lambda x: np.array([[2 * x[0]]]), [[1.0]])
    >>> upd.x, upd.P
    (array([2.2]), array([[0.2]]))
    """
    x = as_vector(x, "x")
    n = x.shape[0]
    P = as_covariance(P, "P", n)
    z = as_vector(z, "z")
    m = z.shape[0]
    R = as_covariance(R, "R", m)
    check_callable(h, "h")
    check_callable(H_jac, "H_jac")
    as_matrix(H_jac(x), "H_jac(x)", (m, n))
    as_vector(h(x), "h(x)", m)
    return _ekf_update(x, P, z, h, H_jac, R, residual)


def numerical_jacobian(fun, x, *args, eps: float | None = None) -> np.ndarray:
    """Central-difference Jacobian ``d fun(x, *args) / dx``, shape ``(m, n)``.

    Step ``eps`` defaults to ``cbrt(machine eps) * max(1, |x_j|)`` per coordinate.

    Parameters
    ----------
    fun : callable
        ``fun(x, *args) -> (m,)``.
    x : array_like, shape (n,)
        Point of differentiation.
    *args
        Extra arguments passed to ``fun``.
    eps : float, optional
        Step for every coordinate; None for the scaled default above.

    Returns
    -------
    numpy.ndarray, shape (m, n)
        The Jacobian.

    Examples
    --------
    >>> numerical_jacobian(lambda x: np.array([x[0] * x[1]]), np.array([2.0, 3.0])).round(6)
    array([[3., 2.]])
    """
    x = as_vector(x, "x")
    check_callable(fun, "fun")
    h = np.cbrt(np.finfo(float).eps) * np.maximum(1.0, np.abs(x)) if eps is None else np.full(x.shape, eps)
    cols = []
    for j in range(x.shape[0]):
        dx = np.zeros_like(x)
        dx[j] = h[j]
        f_plus, f_minus = np.asarray(fun(x + dx, *args), float), np.asarray(fun(x - dx, *args), float)
        cols.append((f_plus - f_minus) / (2 * h[j]))
    return np.stack(cols, axis=-1)


def check_jacobian(fun, jac, x, *args, rtol: float = 1e-5, atol: float = 1e-7) -> float:
    """Compare an analytic Jacobian with :func:`numerical_jacobian`; return the max abs difference.

    Raises ``ValueError`` naming the worst entry when ``|J - J_num| > atol + rtol |J_num|``.

    Parameters
    ----------
    fun : callable
        ``fun(x, *args) -> (m,)``.
    jac : callable
        ``jac(x, *args) -> (m, n)``, the analytic Jacobian under test.
    x : array_like, shape (n,)
        Point of comparison.
    *args
        Extra arguments passed to ``fun`` and ``jac``.
    rtol, atol : float
        Relative and absolute tolerance of the entrywise check.

    Returns
    -------
    float
        The largest absolute difference between ``jac`` and the finite differences.

    Examples
    --------
    >>> check_jacobian(lambda x: x**2, lambda x: np.diag(2 * x), np.array([1.0, 2.0])) < 1e-8
    True
    """
    x = as_vector(x, "x")
    check_callable(jac, "jac")
    J = np.atleast_2d(np.asarray(jac(x, *args), dtype=float))
    J_num = np.atleast_2d(numerical_jacobian(fun, x, *args))
    if J.shape != J_num.shape:
        raise ValueError(f"`jac` returned shape {J.shape}; the numerical Jacobian has shape {J_num.shape}")
    err = np.abs(J - J_num)
    bad = err > atol + rtol * np.abs(J_num)
    if np.any(bad):
        i, j = np.unravel_index(np.argmax(err - (atol + rtol * np.abs(J_num))), err.shape)
        raise ValueError(f"`jac` disagrees with finite differences at entry ({i}, {j}): "
                         f"analytic {J[i, j]:.6g}, numerical {J_num[i, j]:.6g}")
    return float(err.max())


class ExtendedKalmanFilter:
    """EKF (000 §1.2.2): state holder over :func:`ekf_predict` / :func:`ekf_update`.

    ``f(x, u)``, ``F_jac(x, u)``, ``h(x)``, ``H_jac(x)``; ``Q`` and ``R`` may be
    replaced between steps (e.g. a control-dependent ``Q``).

    Parameters
    ----------
    x : array_like, shape (n,)
        Initial state.
    P : array_like, shape (n, n)
        Initial covariance.
    f : callable
        ``f(x, u) -> (n,)`` motion model.
    F_jac : callable
        ``F_jac(x, u) -> (n, n)``.
    Q : array_like, shape (n, n)
        Process noise covariance (attribute ``Q``, may be replaced).
    h : callable
        ``h(x) -> (m,)`` measurement model.
    H_jac : callable
        ``H_jac(x) -> (m, n)``.
    R : array_like, shape (m, m)
        Measurement noise covariance.
    residual : callable, default numpy.subtract
        ``residual(z, z_pred)``, as in :func:`ekf_update`.
    """

    def __init__(self, x, P, f, F_jac, Q, h, H_jac, R, *, residual=np.subtract):
        self.x = as_vector(x, "x")
        n = self.x.shape[0]
        self.P = as_covariance(P, "P", n)
        self.f, self.F_jac = check_callable(f, "f"), check_callable(F_jac, "F_jac")
        self.h, self.H_jac = check_callable(h, "h"), check_callable(H_jac, "H_jac")
        self.Q = as_covariance(Q, "Q", n)
        self.R = as_covariance(R, "R")
        self.residual = residual
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()
        self.x_post, self.P_post = self.x.copy(), self.P.copy()
        self.y = self.S = self.K = None

    def predict(self, u=None) -> None:
        """Predict with the stored ``f``, ``F_jac`` and ``Q``; sets ``x, P`` and ``x_prior, P_prior``.

        Parameters
        ----------
        u : optional
            Control passed to ``f`` and ``F_jac``.
        """
        self.x, self.P = _ekf_predict(self.x, self.P, self.f, self.F_jac, self.Q, u)
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()

    def update(self, z) -> None:
        """Update with measurement ``z``; sets ``x, P``, ``x_post, P_post`` and ``y, S, K``.

        Parameters
        ----------
        z : array_like, shape (m,)
            Measurement (validated for shape and finiteness).
        """
        z = as_measurement(z, "z", self.R.shape[0])
        self.x, self.P, self.y, self.S, self.K = _ekf_update(
            self.x, self.P, z, self.h, self.H_jac, self.R, self.residual)
        self.x_post, self.P_post = self.x.copy(), self.P.copy()
