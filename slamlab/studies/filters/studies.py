"""Ch. 1 studies that need no simulated world (000 §1.2.1, §3.6): the Joseph form against the short form, the
static-landmark filter, and the landmark layout of the unicycle scenario."""

from __future__ import annotations

import numpy as np

from ..._validate import as_rng, as_vector, check_int, check_positive
from ...filters.kalman import kf_update
from .results import JosephResult, LandmarkDemoResult


def run_joseph_vs_short(gain_scales=(0.0, 0.5, 0.8, 1.0, 1.2, 1.5, 2.0), *, n_samples: int = 100_000,
                        rng=2010) -> JosephResult:
    """Scale the optimal gain and compare both covariance updates with the sampled error variance.

    One position/velocity prior, a position measurement; the true posterior
    error is sampled ``n_samples`` times per gain.

    Parameters
    ----------
    gain_scales : sequence of float
        Multiples of the optimal gain to try.
    n_samples : int, default 100000
        Sampled prior states and measurements (at least 100).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of the samples.

    Returns
    -------
    JosephResult
    """
    g = as_rng(rng)
    n_samples = check_int(n_samples, "n_samples", minimum=100)
    scales = as_vector(gain_scales, "gain_scales")
    P = np.array([[4.0, 1.0], [1.0, 1.0]])
    H, R = np.array([[1.0, 0.0]]), np.array([[1.0]])
    x = np.zeros(2)
    K_opt = kf_update(x, P, [0.0], H, R).K
    x_true = g.multivariate_normal(x, P, size=n_samples)
    z = x_true @ H.T + g.normal(size=(n_samples, 1))
    vs, vj, vm = [], [], []
    for s in scales:
        K = s * K_opt
        vs.append(kf_update(x, P, [0.0], H, R, form="short", K=K).P[0, 0])
        vj.append(kf_update(x, P, [0.0], H, R, form="joseph", K=K).P[0, 0])
        err = x_true - (x + (z - x @ H.T) @ K.T)
        vm.append(np.mean(err[:, 0] ** 2))
    return JosephResult(scales, np.array(vs), np.array(vj), np.array(vm), n_samples)


def default_landmarks() -> np.ndarray:
    """Three landmarks near the circular path (start at the origin heading +x, radius 5 m).

    Returns
    -------
    numpy.ndarray, shape (3, 2)
        Landmark positions [m].
    """
    return np.array([[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])


def run_landmark_filter(n_landmarks: int = 500, n_sightings: int = 20, *, obs_std_m: float = 0.05,
                        state_std_m: float = 0.0, report=(1, 2, 3, 5, 10, 20), rng=2010) -> LandmarkDemoResult:
    """Observe static 3-D landmarks repeatedly and refine them with :class:`LandmarkFilter` (000 §3.6).

    RMSE is per coordinate, over all landmarks. With ``state_std_m = 0`` the
    estimate is the running mean of the sightings, so its error falls as
    ``1/sqrt(n)``.

    Parameters
    ----------
    n_landmarks : int, default 500
        Landmarks, uniform in a 10 m cube.
    n_sightings : int, default 20
        Sightings of each landmark.
    obs_std_m : float, default 0.05
        Std of one sighting per coordinate [m].
    state_std_m : float, default 0.0
        Std the filter lets a landmark drift per step [m].
    report : sequence of int
        Sighting counts at which to record the errors (those beyond ``n_sightings`` are dropped).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator.

    Returns
    -------
    LandmarkDemoResult
    """
    from ...filters.landmark import LandmarkFilter

    g = as_rng(rng)
    n_landmarks = check_int(n_landmarks, "n_landmarks", minimum=1)
    n_sightings = check_int(n_sightings, "n_sightings", minimum=1)
    obs_std_m = check_positive(obs_std_m, "obs_std_m")
    report = [int(r) for r in report if 1 <= r <= n_sightings]
    truth = g.uniform(-5.0, 5.0, size=(n_landmarks, 3))
    lf = LandmarkFilter(state_var=state_std_m**2, obs_var=obs_std_m**2, dim=3)
    idx = lf.add(truth + obs_std_m * g.normal(size=truth.shape))
    filt, single, pred = [], [], []
    for n in range(1, n_sightings + 1):
        if n > 1:
            z = truth + obs_std_m * g.normal(size=truth.shape)
            lf.observe(idx, z)
        else:
            z = lf.X.copy()
        if n in report:
            filt.append(np.sqrt(np.mean((lf.X - truth) ** 2)))
            single.append(np.sqrt(np.mean((z - truth) ** 2)))
            pred.append(np.sqrt(np.mean(np.trace(lf.P, axis1=1, axis2=2) / 3)))
    return LandmarkDemoResult(np.array(report), np.array(filt), np.array(single), np.array(pred), n_landmarks)
