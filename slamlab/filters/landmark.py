"""The static-landmark Kalman filter of 000 §3.6, batched over many landmarks.

000 §3.6: a landmark does not move, so ``F = H = I`` and ``B = 0``; ``Q`` and
``R`` are identity matrices scaled by variance estimates. 000 literally scales
``R`` by the *state* variance and ``Q`` by the *observation* error (swapped
against its own §1.2.1); we use the conventional reading: ``Q = state_var I``
(how much a landmark estimate may drift per step), ``R = obs_var I`` (the
triangulation error of one sighting).
"""

from __future__ import annotations

import numpy as np

from .._validate import as_finite_array, check_int, check_positive

__all__ = ["LandmarkFilter", "landmark_predict", "landmark_update"]


def _batched_cov(C, name, N, k):
    C = as_finite_array(C, name)
    if C.ndim == 0:
        return np.broadcast_to(C * np.eye(k), (N, k, k))
    if C.shape == (k, k):
        return np.broadcast_to(C, (N, k, k))
    if C.shape != (N, k, k):
        raise ValueError(f"`{name}` must be a scalar variance, ({k}, {k}) or ({N}, {k}, {k}); got shape {C.shape}")
    return C


def landmark_predict(P, Q):
    """Predict for static landmarks (000 §3.6): ``x`` unchanged, ``P = P + Q`` (F = I, B = 0).

    ``P`` is ``(N, k, k)``; ``Q`` a scalar variance, ``(k, k)`` or ``(N, k, k)``.

    Parameters
    ----------
    P : array_like, shape (N, k, k)
        Covariances of ``N`` landmarks.
    Q : float or array_like
        Process noise: a scalar variance, ``(k, k)`` or ``(N, k, k)``.

    Returns
    -------
    numpy.ndarray, shape (N, k, k)
        Predicted covariances.

    Examples
    --------
    >>> landmark_predict(np.eye(2)[None], 0.5)[0]
    array([[1.5, 0. ],
           [0. , 1.5]])
    """
    P = as_finite_array(P, "P", ndim=3)
    N, k, _ = P.shape
    return P + _batched_cov(Q, "Q", N, k)


def landmark_update(X, P, Z, R):
    """Update ``N`` static landmarks at once with observations ``Z`` (000 §3.6, H = I).

    ``K = P (P + R)^-1``, ``x = x + K (z - x)``, ``P = (I - K) P``.

    Parameters
    ----------
    X : array_like, shape (N, k)
        Landmark positions.
    P : array_like, shape (N, k, k)
        Their covariances.
    Z : array_like, shape (N, k)
        New observations of the same landmarks.
    R : float or array_like
        Observation covariance: a scalar variance, ``(k, k)`` or ``(N, k, k)``.

    Returns
    -------
    X, P : updated positions and covariances.

    Examples
    --------
    >>> X, P = landmark_update(np.zeros((1, 3)), np.eye(3)[None], np.ones((1, 3)), 1.0)
    >>> X, np.diag(P[0])
    (array([[0.5, 0.5, 0.5]]), array([0.5, 0.5, 0.5]))
    """
    X = as_finite_array(X, "X", ndim=2)
    N, k = X.shape
    P = as_finite_array(P, "P", ndim=3)
    if P.shape != (N, k, k):
        raise ValueError(f"`P` must have shape ({N}, {k}, {k}); got {P.shape}")
    Z = as_finite_array(Z, "Z", ndim=2)
    if Z.shape != (N, k):
        raise ValueError(f"`Z` must have shape ({N}, {k}); got {Z.shape}")
    R = _batched_cov(R, "R", N, k)
    return _landmark_update(X, P, Z, R)


def _landmark_update(X, P, Z, R):
    # S = P + R ; K = P S^-1   (H = I)
    S = P + R
    K = np.linalg.solve(S, P).transpose(0, 2, 1)  # S symmetric: (S^-1 P)^T = P S^-1
    # x = x + K (z - x)
    X = X + np.einsum("nij,nj->ni", K, Z - X)
    # P = (I - K) P
    P = P - K @ P
    return X, 0.5 * (P + P.transpose(0, 2, 1))


class LandmarkFilter:
    """Landmark positions refined by the static Kalman filter of 000 §3.6.

    Holds ``X (N, k)`` and ``P (N, k, k)``. :meth:`add` appends new landmarks
    with covariance ``obs_var I``; :meth:`observe` runs predict + update on the
    landmarks ``idx`` with their new observations.

    Parameters
    ----------
    state_var : float, default 1e-4
        Variance added per observation step (``Q = state_var I``); 0 gives the running mean.
    obs_var : float, default 1e-2
        Variance of one sighting per coordinate (``R = obs_var I``, also a new landmark's covariance).
    dim : int, default 3
        Landmark dimension ``k``.

    Examples
    --------
    >>> lf = LandmarkFilter(state_var=0.0, obs_var=1.0, dim=2)
    >>> _ = lf.add([[0.0, 0.0]]); lf.observe([0], [[2.0, 2.0]]); lf.X
    array([[1., 1.]])
    """

    def __init__(self, state_var: float = 1e-4, obs_var: float = 1e-2, dim: int = 3):
        self.state_var = check_positive(state_var, "state_var", allow_zero=True)
        self.obs_var = check_positive(obs_var, "obs_var")
        self.dim = check_int(dim, "dim", minimum=1)
        self.X = np.empty((0, self.dim))
        self.P = np.empty((0, self.dim, self.dim))

    def __len__(self) -> int:
        return self.X.shape[0]

    def add(self, Z) -> np.ndarray:
        """Append landmarks first seen at ``Z (M, k)``; returns their indices.

        Parameters
        ----------
        Z : array_like, shape (M, k)
            First sightings of the new landmarks.

        Returns
        -------
        numpy.ndarray, shape (M,)
            Indices of the new landmarks.
        """
        Z = as_finite_array(Z, "Z", ndim=2)
        if Z.shape[1] != self.dim:
            raise ValueError(f"`Z` must have shape (M, {self.dim}); got {Z.shape}")
        start = len(self)
        self.X = np.vstack([self.X, Z])
        self.P = np.concatenate([self.P, np.broadcast_to(self.obs_var * np.eye(self.dim), (len(Z), self.dim, self.dim))])
        return np.arange(start, len(self))

    def observe(self, idx, Z) -> None:
        """Predict (``P += state_var I``) and update the landmarks ``idx`` with ``Z``.

        Parameters
        ----------
        idx : array_like of int, shape (M,)
            Indices of existing landmarks, no repeats.
        Z : array_like, shape (M, k)
            Their new observations, in the order of ``idx``.
        """
        idx = np.asarray(idx)
        if idx.ndim != 1 or not np.issubdtype(idx.dtype, np.integer):
            raise TypeError(f"`idx` must be a 1-D integer index array; got dtype {idx.dtype}, shape {idx.shape}")
        if idx.size and (idx.min() < 0 or idx.max() >= len(self)):
            raise ValueError(f"`idx` must index existing landmarks 0..{len(self) - 1}")
        if np.unique(idx).size != idx.size:
            raise ValueError("`idx` must not repeat a landmark")
        Z = as_finite_array(Z, "Z", ndim=2)
        if Z.shape != (idx.size, self.dim):
            raise ValueError(f"`Z` must have shape ({idx.size}, {self.dim}); got {Z.shape}")
        I = np.eye(self.dim)
        P = self.P[idx] + self.state_var * I
        X, P = _landmark_update(self.X[idx], P, Z, np.broadcast_to(self.obs_var * I, P.shape))
        self.X[idx], self.P[idx] = X, P
