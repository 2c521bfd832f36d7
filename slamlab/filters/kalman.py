"""Linear Kalman filter (000 §1.2.1): predict, update (short and Joseph forms); the same filter on the deviation
from a nominal path of a nonlinear model (:class:`LinearisedKalmanFilter`, ours).

Index convention (000 mixes ``B_k u_k`` and ``B_k u_{k-1}``): we write the
prediction as ``x_{k|k-1} = F x_{k-1|k-1} + B u`` where ``u`` is the control
applied between the two steps, and ``Q`` the noise of that same interval.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._validate import as_covariance, as_matrix, as_measurement, as_vector, check_callable, check_choice
from ._linalg import gain, symmetrize

__all__ = ["KalmanFilter", "LinearisedKalmanFilter", "Update", "kf_predict", "kf_update", "symmetrize"]


class Update(NamedTuple):
    """Result of a measurement update: posterior ``x, P``, innovation ``y``, its covariance ``S``, gain ``K``.

    Attributes
    ----------
    x : numpy.ndarray, shape (n,)
        Posterior state.
    P : numpy.ndarray, shape (n, n)
        Posterior covariance.
    y : numpy.ndarray, shape (m,)
        Innovation.
    S : numpy.ndarray, shape (m, m)
        Innovation covariance.
    K : numpy.ndarray, shape (n, m)
        Gain.
    """

    x: np.ndarray
    P: np.ndarray
    y: np.ndarray
    S: np.ndarray
    K: np.ndarray


# --- strict core (no validation; callers have checked) ------------------------------------------


def _predict(x, P, F, Q, Bu=None):
    # x_{k|k-1} = F x_{k-1|k-1} + B u
    x = F @ x if Bu is None else F @ x + Bu
    # P_{k|k-1} = F P_{k-1|k-1} F^T + Q
    P = F @ P @ F.T + Q
    return x, symmetrize(P)


def _update(x, P, y, H, R, form="short", K=None):
    PHt = P @ H.T
    # S = H P H^T + R
    S = H @ PHt + R
    if K is None:
        K = gain(PHt, S, "kf_update")
    # x_{k|k} = x_{k|k-1} + K y
    x = x + K @ y
    if form == "short":
        # P_{k|k} = (I - K H) P_{k|k-1} = P - K (H P)   (valid for the optimal gain only)
        P = P - K @ PHt.T
    else:
        # Joseph: P_{k|k} = (I - K H) P (I - K H)^T + K R K^T   (valid for any gain)
        I_KH = np.eye(P.shape[0]) - K @ H
        P = I_KH @ P @ I_KH.T + K @ R @ K.T
    return Update(x, symmetrize(P), y, S, K)


# --- friendly layer ------------------------------------------------------------------------------


def kf_predict(x, P, F, Q, B=None, u=None):
    """Predict step (000 §1.2.1).

    Parameters
    ----------
    x : (n,) state estimate ``x_{k-1|k-1}``.
    P : (n, n) its covariance.
    F : (n, n) state transition matrix.
    Q : (n, n) process noise covariance.
    B : (n, m) control matrix, optional (needs ``u``).
    u : (m,) control vector, optional.

    Returns
    -------
    x, P : the prior ``x_{k|k-1}, P_{k|k-1}``.

    Examples
    --------
    >>> x, P = kf_predict([0.0, 1.0], np.eye(2), [[1, 1], [0, 1]], 0.1 * np.eye(2))
    >>> x
    array([1., 1.])
    >>> P
    array([[2.1, 1. ],
           [1. , 1.1]])
    """
    x = as_vector(x, "x")
    n = x.shape[0]
    P = as_covariance(P, "P", n)
    F = as_matrix(F, "F", (n, n))
    Q = as_covariance(Q, "Q", n)
    Bu = None
    if (B is None) != (u is None):
        raise ValueError("`B` and `u` must be given together; got only `" + ("B" if u is None else "u") + "`")
    if B is not None:
        B = as_matrix(B, "B", (n, None))
        u = as_vector(u, "u", B.shape[1])
        Bu = B @ u
    return _predict(x, P, F, Q, Bu)


def kf_update(x, P, z, H, R, *, form: str = "short", K=None) -> Update:
    """Update step (000 §1.2.1), short ``(I-KH)P`` or Joseph covariance form.

    Parameters
    ----------
    x : (n,) prior state ``x_{k|k-1}``.
    P : (n, n) prior covariance.
    z : (m,) measurement.
    H : (m, n) measurement matrix.
    R : (m, m) measurement noise covariance.
    form : ``"short"`` (000's ``P=(I-KH)P``, valid only for the optimal gain)
        or ``"joseph"`` (``(I-KH)P(I-KH)^T + KRK^T``, valid for any gain).
    K : (n, m) gain to use instead of the optimal ``P H^T S^-1`` (for teaching:
        shows why the short form needs the optimal gain).

    Returns
    -------
    Update
        ``(x, P, y, S, K)``: posterior, innovation, its covariance, the gain.

    Examples
    --------
    >>> upd = kf_update([0.0], [[1.0]], [2.0], [[1.0]], [[1.0]])
    >>> upd.x, upd.P
    (array([1.]), array([[0.5]]))
    """
    x = as_vector(x, "x")
    n = x.shape[0]
    P = as_covariance(P, "P", n)
    H = as_matrix(H, "H", (None, n))
    m = H.shape[0]
    z = as_vector(z, "z", m)
    R = as_covariance(R, "R", m)
    check_choice(form, "form", ("short", "joseph"))
    if K is not None:
        K = as_matrix(K, "K", (n, m))
    return _update(x, P, z - H @ x, H, R, form, K)


class KalmanFilter:
    """Linear Kalman filter (000 §1.2.1): thin state holder over :func:`kf_predict`, :func:`kf_update`.

    Keeps ``x_prior, P_prior`` (after :meth:`predict`) and ``x_post, P_post``,
    ``y, S, K`` (after :meth:`update`).

    Parameters
    ----------
    x : array_like, shape (n,)
        Initial state.
    P : array_like, shape (n, n)
        Initial covariance.
    F : array_like, shape (n, n)
        State transition matrix.
    Q : array_like, shape (n, n)
        Process noise covariance.
    H : array_like, shape (m, n)
        Measurement matrix.
    R : array_like, shape (m, m)
        Measurement noise covariance.
    B : array_like, shape (n, k), optional
        Control matrix; needed when :meth:`predict` gets a control.
    form : {"short", "joseph"}
        Covariance update form, as in :func:`kf_update`.

    Examples
    --------
    >>> kf = KalmanFilter(x=[0.0], P=[[1.0]], F=[[1.0]], Q=[[0.0]], H=[[1.0]], R=[[1.0]])
    >>> kf.predict(); kf.update([2.0]); kf.x
    array([1.])
    """

    def __init__(self, x, P, F, Q, H, R, B=None, *, form: str = "short"):
        self.x = as_vector(x, "x")
        n = self.x.shape[0]
        self.P = as_covariance(P, "P", n)
        self.F = as_matrix(F, "F", (n, n))
        self.Q = as_covariance(Q, "Q", n)
        self.H = as_matrix(H, "H", (None, n))
        self.R = as_covariance(R, "R", self.H.shape[0])
        self.B = None if B is None else as_matrix(B, "B", (n, None))
        self.form = check_choice(form, "form", ("short", "joseph"))
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()
        self.x_post, self.P_post = self.x.copy(), self.P.copy()
        m = self.H.shape[0]
        self.y, self.S, self.K = np.zeros(m), np.zeros((m, m)), np.zeros((n, m))

    @property
    def dim_x(self) -> int:
        return self.x.shape[0]

    def predict(self, u=None) -> None:
        """Predict with the stored ``F, Q`` (and ``B u`` when a control is given).

        Parameters
        ----------
        u : array_like, shape (k,), optional
            Control; requires ``B``.
        """
        Bu = None
        if u is not None:
            if self.B is None:
                raise ValueError("`u` was given but the filter has no control matrix `B`")
            Bu = self.B @ as_vector(u, "u", self.B.shape[1])
        self.x, self.P = _predict(self.x, self.P, self.F, self.Q, Bu)
        self.x_prior, self.P_prior = self.x.copy(), self.P.copy()

    def update(self, z) -> None:
        """Update with measurement ``z`` (validated for shape and finiteness).

        Parameters
        ----------
        z : array_like, shape (m,)
            Measurement.
        """
        z = as_measurement(z, "z", self.H.shape[0])
        self.x, self.P, self.y, self.S, self.K = _update(self.x, self.P, z - self.H @ self.x, self.H, self.R, self.form)
        self.x_post, self.P_post = self.x.copy(), self.P.copy()

    def __repr__(self) -> str:
        return f"KalmanFilter(dim_x={self.dim_x}, dim_z={self.H.shape[0]}, form={self.form!r})"


class LinearisedKalmanFilter:
    """Linear KF on the deviation ``dx`` from a nominal path, for a nonlinear model (000 §1.2.1 equations; ours).

    The nominal path ``x_nominal`` follows the noise-free model from the initial estimate, ``x_nom <- f(x_nom,
    u)``; the Jacobians are taken on it, never on the estimate (the EKF's difference), so the filter is the
    linear KF of :func:`kf_predict` / :func:`kf_update` on ``dx``, with the innovation
    ``y = residual(z, h(x_nom)) - H dx``. The estimate is ``x = x_nominal + dx`` (through ``x_wrap``, e.g. to
    wrap a heading). It diverges once the truth leaves the nominal path: the unicycle comparison's "LKF".
    ``Q`` and ``R`` may be replaced between steps (e.g. a control-dependent ``Q``).

    Parameters
    ----------
    x : array_like, shape (n,)
        Initial estimate: the start of the nominal path (``dx = 0``).
    P : array_like, shape (n, n)
        Initial covariance.
    f : callable
        ``f(x, u) -> (n,)`` noise-free motion model.
    F_jac : callable
        ``F_jac(x, u) -> (n, n)``, taken on the nominal path.
    Q : array_like, shape (n, n)
        Process noise covariance (attribute ``Q``, may be replaced).
    h : callable
        ``h(x) -> (m,)`` measurement model.
    H_jac : callable
        ``H_jac(x) -> (m, n)``, taken on the nominal path.
    R : array_like, shape (m, m)
        Measurement noise covariance.
    residual : callable, default numpy.subtract
        ``residual(z, z_pred)``, as in :func:`~slamlab.filters.ekf.ekf_update`.
    x_wrap : callable, optional
        ``x_wrap(x) -> (n,)`` applied to ``x_nominal + dx`` (e.g. a heading wrapped to (-π, π]).

    Examples
    --------
    >>> lkf = LinearisedKalmanFilter([0.0], [[1.0]], lambda x, u: x, lambda x, u: np.eye(1), [[0.0]],
    ...                              lambda x: x, lambda x: np.eye(1), [[1.0]])
    >>> lkf.predict(); lkf.update([2.0]); lkf.x, lkf.dx
    (array([1.]), array([1.]))
    """

    def __init__(self, x, P, f, F_jac, Q, h, H_jac, R, *, residual=np.subtract, x_wrap=None):
        self.x_nominal = as_vector(x, "x")
        n = self.x_nominal.shape[0]
        self.dx = np.zeros(n)
        self.P = as_covariance(P, "P", n)
        self.f, self.F_jac = check_callable(f, "f"), check_callable(F_jac, "F_jac")
        self.h, self.H_jac = check_callable(h, "h"), check_callable(H_jac, "H_jac")
        self.Q = as_covariance(Q, "Q", n)
        self.R = as_covariance(R, "R")
        self.residual = check_callable(residual, "residual")
        self.x_wrap = None if x_wrap is None else check_callable(x_wrap, "x_wrap")
        self.y = self.S = self.K = None

    @property
    def x(self) -> np.ndarray:
        """The estimate ``x_nominal + dx`` (through ``x_wrap``)."""
        x = self.x_nominal + self.dx
        return x if self.x_wrap is None else self.x_wrap(x)

    def predict(self, u=None) -> None:
        """Predict ``dx, P`` with ``F`` and ``Q`` on the nominal path, then move the nominal path by ``f``.

        Parameters
        ----------
        u : optional
            Control passed to ``f`` and ``F_jac``.
        """
        F = self.F_jac(self.x_nominal, u)
        self.dx, self.P = _predict(self.dx, self.P, F, self.Q)
        self.x_nominal = self.f(self.x_nominal, u)

    def update(self, z) -> None:
        """Update ``dx, P`` with measurement ``z``; sets ``y, S, K``.

        Parameters
        ----------
        z : array_like, shape (m,)
            Measurement (validated for shape and finiteness).
        """
        z = as_measurement(z, "z", self.R.shape[0])
        H = self.H_jac(self.x_nominal)
        # y = residual(z, h(x_nom)) - H dx: the innovation of the deviation
        y = self.residual(z, self.h(self.x_nominal)) - H @ self.dx
        self.dx, self.P, self.y, self.S, self.K = _update(self.dx, self.P, y, H, self.R)

    def __repr__(self) -> str:
        return f"LinearisedKalmanFilter(dim_x={self.dx.shape[0]}, dim_z={self.R.shape[0]})"
