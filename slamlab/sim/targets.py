"""Linear targets: the constant-velocity model and a linear-Gaussian simulator (Ch. 1)."""

from __future__ import annotations

import numpy as np

from .._validate import as_covariance, as_matrix, as_rng, as_vector, check_int, check_positive

__all__ = ["constant_velocity_model", "simulate_linear"]


def constant_velocity_model(dt_s: float = 1.0, accel_std: float = 0.1, pos_std_m: float = 1.0, dims: int = 2):
    """``F, Q, H, R`` of a constant-velocity target observed in position.

    State per axis ``[p_m, v_mps]`` (axes stacked: ``[x, vx, y, vy]`` for 2-D);
    ``Q`` is the discretised white-noise-acceleration model
    ``q [[dt^3/3, dt^2/2], [dt^2/2, dt]]`` with ``q = accel_std^2``.

    Parameters
    ----------
    dt_s : float, default 1.0
        Time step [s].
    accel_std : float, default 0.1
        Std of the white acceleration noise [m/s²].
    pos_std_m : float, default 1.0
        Position measurement std per axis [m].
    dims : int, default 2
        Number of axes (1 to 3).

    Returns
    -------
    F, Q : numpy.ndarray, shape (2 dims, 2 dims)
    H : numpy.ndarray, shape (dims, 2 dims)
    R : numpy.ndarray, shape (dims, dims)

    Examples
    --------
    >>> F, Q, H, R = constant_velocity_model(1.0, 1.0, 1.0, dims=1)
    >>> F, H
    (array([[1., 1.],
           [0., 1.]]), array([[1., 0.]]))
    """
    dt_s = check_positive(dt_s, "dt_s")
    accel_std = check_positive(accel_std, "accel_std", allow_zero=True)
    pos_std_m = check_positive(pos_std_m, "pos_std_m")
    dims = check_int(dims, "dims", minimum=1, maximum=3)
    F1 = np.array([[1.0, dt_s], [0.0, 1.0]])
    Q1 = accel_std**2 * np.array([[dt_s**3 / 3, dt_s**2 / 2], [dt_s**2 / 2, dt_s]])
    H1 = np.array([[1.0, 0.0]])
    eye = np.eye(dims)
    return np.kron(eye, F1), np.kron(eye, Q1), np.kron(eye, H1), pos_std_m**2 * eye


def simulate_linear(F, Q, H, R, x0, n_steps: int, rng=None):
    """Simulate ``x_k = F x_{k-1} + w``, ``z_k = H x_k + v`` for ``n_steps`` steps.

    Returns ``(X, Z)``: true states ``(n_steps, n)`` (after each transition) and
    measurements ``(n_steps, m)``.

    Parameters
    ----------
    F : array_like, shape (n, n)
        State transition.
    Q : array_like, shape (n, n)
        Process noise covariance.
    H : array_like, shape (m, n)
        Measurement matrix.
    R : array_like, shape (m, m)
        Measurement noise covariance.
    x0 : array_like, shape (n,)
        Initial state (before the first transition).
    n_steps : int
        Steps.
    rng : int or numpy.random.Generator, optional
        Seed or generator.

    Returns
    -------
    X : numpy.ndarray, shape (n_steps, n)
    Z : numpy.ndarray, shape (n_steps, m)
    """
    rng = as_rng(rng)
    x = as_vector(x0, "x0")
    n = x.shape[0]
    F = as_matrix(F, "F", (n, n))
    Q = as_covariance(Q, "Q", n)
    H = as_matrix(H, "H", (None, n))
    R = as_covariance(R, "R", H.shape[0])
    n_steps = check_int(n_steps, "n_steps", minimum=1)
    W = rng.multivariate_normal(np.zeros(n), Q, size=n_steps, method="eigh")
    V = rng.multivariate_normal(np.zeros(H.shape[0]), R, size=n_steps, method="eigh")
    X = np.empty((n_steps, n))
    for k in range(n_steps):
        x = F @ x + W[k]
        X[k] = x
    return X, X @ H.T + V
