"""Unicycle robot with a range-bearing landmark sensor (Ch. 1 nonlinear example).

State ``[x_m, y_m, heading_rad]``; control ``[v_mps, omega_radps]`` held for
``dt_s``; first-order (Euler) motion. Every function broadcasts over leading
axes, so sigma points can be pushed through in one call.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._validate import as_finite_array, as_rng, as_vector, check_positive
from ..geometry import angle_mean, wrap_angle

__all__ = ["RangeBearingSensor", "UnicycleModel", "simulate_unicycle"]


@dataclass(frozen=True)
class UnicycleModel:
    """Unicycle motion with control noise ``w ~ N(0, diag(v_std^2, omega_std^2))``.

    Attributes
    ----------
    dt_s : float
        Time step [s].
    v_std_mps : float
        Speed noise std [m/s].
    omega_std_radps : float
        Turn-rate noise std [rad/s].
    """

    dt_s: float = 0.5
    v_std_mps: float = 0.1
    omega_std_radps: float = 0.05

    def __post_init__(self):
        check_positive(self.dt_s, "dt_s")
        check_positive(self.v_std_mps, "v_std_mps", allow_zero=True)
        check_positive(self.omega_std_radps, "omega_std_radps", allow_zero=True)

    @property
    def M(self) -> np.ndarray:
        """Control-noise covariance (2, 2)."""
        return np.diag([self.v_std_mps**2, self.omega_std_radps**2])

    def f(self, x, u, w=None):
        """``x_k = f(x_{k-1}, u + w)``: Euler step of the unicycle (noise ``w`` on the control).

        Parameters
        ----------
        x : array_like, shape (..., 3)
            State(s) ``(x_m, y_m, theta_rad)``.
        u : array_like, shape (2,)
            Control ``(v_mps, omega_radps)``.
        w : array_like, shape (..., 2), optional
            Control noise (augmented UKF).

        Returns
        -------
        numpy.ndarray, shape (..., 3)
            Heading wrapped.
        """
        x = np.asarray(x, dtype=float)
        u = np.asarray(u, dtype=float)
        vel = u[0] if w is None else u[0] + np.asarray(w)[..., 0]
        om = u[1] if w is None else u[1] + np.asarray(w)[..., 1]
        th = x[..., 2]
        return np.stack([x[..., 0] + vel * self.dt_s * np.cos(th),
                         x[..., 1] + vel * self.dt_s * np.sin(th),
                         wrap_angle(th + om * self.dt_s)], axis=-1)

    def F_jac(self, x, u):
        """``df/dx`` (3, 3) at ``(x, u)``.

        Parameters
        ----------
        x : array_like, shape (3,)
            State ``(x_m, y_m, theta_rad)``.
        u : array_like, shape (2,)
            Control ``(v_mps, omega_radps)``.

        Returns
        -------
        numpy.ndarray, shape (3, 3)
        """
        th, s = x[2], u[0] * self.dt_s
        return np.array([[1.0, 0.0, -s * np.sin(th)], [0.0, 1.0, s * np.cos(th)], [0.0, 0.0, 1.0]])

    def V_jac(self, x, u):
        """``df/du`` (3, 2): maps control noise into the state.

        Parameters
        ----------
        x : array_like, shape (3,)
            State ``(x_m, y_m, theta_rad)``.
        u : array_like, shape (2,)
            Control ``(v_mps, omega_radps)``.

        Returns
        -------
        numpy.ndarray, shape (3, 2)
        """
        th, dt = x[2], self.dt_s
        return np.array([[dt * np.cos(th), 0.0], [dt * np.sin(th), 0.0], [0.0, dt]])

    def Q(self, x, u):
        """State-space process noise ``V M V^T`` linearised at ``(x, u)`` (EKF, additive UKF).

        Parameters
        ----------
        x : array_like, shape (3,)
            State ``(x_m, y_m, theta_rad)``.
        u : array_like, shape (2,)
            Control ``(v_mps, omega_radps)``.

        Returns
        -------
        numpy.ndarray, shape (3, 3)
        """
        V = self.V_jac(x, u)
        return V @ self.M @ V.T

    @staticmethod
    def residual(a, b):
        """State difference with the heading wrapped.

        Parameters
        ----------
        a, b : array_like, shape (..., 3)
            States ``(x, y, θ)``.

        Returns
        -------
        numpy.ndarray
            ``a − b`` with the heading difference wrapped to [−π, π).
        """
        d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
        d[..., 2] = wrap_angle(d[..., 2])
        return d

    @staticmethod
    def mean(sigmas, weights):
        """Weighted mean of sigma points; heading averaged in the chart around the centre point.

        Parameters
        ----------
        sigmas : numpy.ndarray, shape (n, 3)
            Sigma points ``(x, y, θ)``; row 0 is the centre point.
        weights : numpy.ndarray, shape (n,)
            Mean weights.

        Returns
        -------
        numpy.ndarray, shape (3,)
        """
        m = weights @ sigmas
        m[2] = angle_mean(sigmas[:, 2], weights, ref=sigmas[0, 2])
        return m


@dataclass(frozen=True)
class RangeBearingSensor:
    """Range and bearing to every landmark: ``z = [r_1, b_1, r_2, b_2, ...]``.

    Attributes
    ----------
    landmarks_m : numpy.ndarray, shape (M, 2)
        Landmark positions [m].
    range_std_m : float
        Range noise std [m].
    bearing_std_rad : float
        Bearing noise std [rad].
    """

    landmarks_m: np.ndarray = field(default_factory=lambda: np.array([[5.0, 5.0], [-5.0, 5.0], [0.0, -5.0]]))
    range_std_m: float = 0.1
    bearing_std_rad: float = np.deg2rad(2.0)

    def __post_init__(self):
        lm = as_finite_array(self.landmarks_m, "landmarks_m", ndim=2)
        if lm.shape[1] != 2 or lm.shape[0] < 1:
            raise ValueError(f"`landmarks_m` must have shape (M, 2) with M >= 1; got {lm.shape}")
        object.__setattr__(self, "landmarks_m", lm)
        check_positive(self.range_std_m, "range_std_m")
        check_positive(self.bearing_std_rad, "bearing_std_rad")

    @property
    def dim_z(self) -> int:
        return 2 * self.landmarks_m.shape[0]

    @property
    def R(self) -> np.ndarray:
        return np.diag(np.tile([self.range_std_m**2, self.bearing_std_rad**2], self.landmarks_m.shape[0]))

    def h(self, x, v_noise=None):
        """Predicted measurement (..., 2M); ``v_noise`` is added (augmented UKF).

        Parameters
        ----------
        x : array_like, shape (..., 3)
            State(s) ``(x_m, y_m, theta_rad)``.
        v_noise : array_like, shape (..., 2M), optional
            Measurement noise to add.

        Returns
        -------
        numpy.ndarray, shape (..., 2M)
            Ranges [m] and bearings [rad] (wrapped), interleaved.
        """
        x = np.asarray(x, dtype=float)
        dx = self.landmarks_m[:, 0] - x[..., 0, None]
        dy = self.landmarks_m[:, 1] - x[..., 1, None]
        r = np.hypot(dx, dy)
        b = np.arctan2(dy, dx) - x[..., 2, None]
        z = np.stack([r, b], axis=-1).reshape(*x.shape[:-1], -1)
        if v_noise is not None:
            z = z + np.asarray(v_noise)
        z[..., 1::2] = wrap_angle(z[..., 1::2])
        return z

    def H_jac(self, x):
        """``dh/dx`` (2M, 3).

        Parameters
        ----------
        x : array_like, shape (3,)
            State ``(x_m, y_m, theta_rad)``.

        Returns
        -------
        numpy.ndarray, shape (2M, 3)
        """
        dx = self.landmarks_m[:, 0] - x[0]
        dy = self.landmarks_m[:, 1] - x[1]
        q = dx**2 + dy**2
        r = np.sqrt(q)
        H = np.zeros((self.dim_z, 3))
        H[0::2, 0], H[0::2, 1] = -dx / r, -dy / r
        H[1::2, 0], H[1::2, 1], H[1::2, 2] = dy / q, -dx / q, -1.0
        return H

    @staticmethod
    def residual(a, b):
        """Measurement difference with bearings wrapped.

        Parameters
        ----------
        a, b : array_like, shape (..., 2k)
            Measurements ``(r_1, φ_1, …, r_k, φ_k)``.

        Returns
        -------
        numpy.ndarray
            ``a − b`` with every bearing difference wrapped to [−π, π).
        """
        d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
        d[..., 1::2] = wrap_angle(d[..., 1::2])
        return d

    @staticmethod
    def mean(sigmas, weights):
        """Weighted mean of sigma points; bearings averaged in the chart around the centre point.

        Parameters
        ----------
        sigmas : numpy.ndarray, shape (n, 2k)
            Sigma points of the measurement ``(r_1, φ_1, …)``; row 0 is the centre point.
        weights : numpy.ndarray, shape (n,)
            Mean weights.

        Returns
        -------
        numpy.ndarray, shape (2k,)
        """
        m = weights @ sigmas
        m[1::2] = angle_mean(sigmas[:, 1::2], weights, ref=sigmas[0, 1::2])
        return m


def simulate_unicycle(model: UnicycleModel, sensor: RangeBearingSensor, x0, controls, rng=None):
    """True path and measurements: control noise from ``model.M``, sensor noise from ``sensor.R``.

    ``controls`` is ``(K, 2)``; returns ``(X, Z)`` with ``X (K, 3)`` the true
    states after each step and ``Z (K, 2M)`` the measurements taken there.

    Parameters
    ----------
    model : UnicycleModel
        Motion model and control noise.
    sensor : RangeBearingSensor
        Landmarks and measurement noise.
    x0 : array_like, shape (3,)
        Initial state.
    controls : array_like, shape (K, 2)
        Commanded ``(v_mps, omega_radps)`` per step.
    rng : int or numpy.random.Generator, optional
        Seed or generator of both noises.

    Returns
    -------
    X : numpy.ndarray, shape (K, 3)
    Z : numpy.ndarray, shape (K, 2M)
    """
    rng = as_rng(rng)
    x = as_vector(x0, "x0", 3)
    U = as_finite_array(controls, "controls", ndim=2)
    if U.shape[1] != 2:
        raise ValueError(f"`controls` must have shape (K, 2); got {U.shape}")
    K = U.shape[0]
    W = rng.normal(size=(K, 2)) * np.sqrt(np.diag(model.M))
    Vn = rng.normal(size=(K, sensor.dim_z)) * np.sqrt(np.diag(sensor.R))
    X = np.empty((K, 3))
    for k in range(K):
        x = model.f(x, U[k], W[k])
        X[k] = x
    return X, sensor.h(X, Vn)
