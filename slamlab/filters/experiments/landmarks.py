"""Ch. 1 experiment on the static-landmark filter (000 §3.6): error vs number of sightings."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ... import _validate as v
from ..._table import format_table

# --- the static-landmark filter of 000 §3.6 ---------------------------------------------------------


@dataclass(frozen=True)
class LandmarkDemoResult:
    """Static landmarks refined by the §3.6 filter: error vs number of sightings.

    Attributes
    ----------
    sightings : numpy.ndarray of int, shape (S,)
        Sighting counts reported.
    rmse_filtered_m : numpy.ndarray, shape (S,)
        RMSE per coordinate of the filtered landmarks after that many sightings [m].
    rmse_single_m : numpy.ndarray, shape (S,)
        RMSE of the latest single sighting [m].
    predicted_std_m : numpy.ndarray, shape (S,)
        RMS of the filter's predicted std per coordinate [m].
    n_landmarks : int
        Landmarks observed.
    """

    sightings: np.ndarray
    rmse_filtered_m: np.ndarray
    rmse_single_m: np.ndarray
    predicted_std_m: np.ndarray
    n_landmarks: int

    def __str__(self) -> str:
        return (f"{self.n_landmarks} landmarks: RMSE {self.rmse_single_m[-1]:.4f} m from one sighting, "
                f"{self.rmse_filtered_m[-1]:.4f} m after {self.sightings[-1]} sightings")

    def table(self) -> str:
        """Table: one row per reported sighting count, with the ``1/sqrt(n)`` reference.

        Returns
        -------
        str
        """
        rows = [[f"{n}", f"{f:.4f}", f"{p:.4f}", f"{s:.4f}", f"{s / np.sqrt(n):.4f}"]
                for n, f, p, s in zip(self.sightings, self.rmse_filtered_m, self.predicted_std_m,
                                      self.rmse_single_m, strict=True)]
        return format_table(["sightings", "filtered RMSE [m]", "predicted [m]", "one sighting [m]",
                             "one / sqrt(n) [m]"], rows)


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
    from ..landmark import LandmarkFilter

    g = v.as_rng(rng)
    n_landmarks = v.check_int(n_landmarks, "n_landmarks", minimum=1)
    n_sightings = v.check_int(n_sightings, "n_sightings", minimum=1)
    obs_std_m = v.check_positive(obs_std_m, "obs_std_m")
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
