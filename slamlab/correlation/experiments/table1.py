"""004 Table 1 reproduced (004 §7): ten random free poses localised from no prior."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...sim.paths import random_free_poses
from ..algorithm import LocaliseParams
from .common import _errors, _estimates, _localise_scans, _sensor, _worlds

#: 004 Table 1: α0, α0 est [rad], X, X est, Y, Y est [cells].
SOURCE_TABLE1 = np.array([
    [1.8812, 1.885, 187, 187, 15, 15],
    [0.5225, 0.5236, 30, 30, 175, 175],
    [3.1297, 3.1241, 173, 173, 94, 94],
    [1.0738, 1.0821, 69, 69, 58, 58],
    [5.1389, 5.1487, 181, 181, 188, 188],
    [3.4681, 3.4732, 167, 167, 103, 102],
    [0.5715, 0.576, 162, 162, 93, 93],
    [5.5558, 5.5501, 63, 63, 81, 81],
    [2.1229, 2.1293, 30, 30, 171, 171],
    [5.2929, 5.2883, 105, 105, 45, 45],
])


@dataclass(frozen=True)
class Table1Result:
    """004 Table 1 reproduced: 10 random free poses, Δα = 1°, range noise, unmapped clutter.

    Attributes
    ----------
    true_poses, est_poses : numpy.ndarray, shape (n, 3)
        True and estimated poses ``(x, y)`` [cells], heading [rad].
    err_heading_rad : numpy.ndarray, shape (n,)
        Wrapped heading errors [rad].
    err_x_cells, err_y_cells : numpy.ndarray, shape (n,)
        Absolute position errors [cells].
    range_std_cells : float
        Range noise std of the scans [cells].
    n_beams : int
        Beams per scan.
    params : LocaliseParams
        Settings of the localisations.
    time_s : float
        Wall time of the localisations [s] (not compared).
    """

    true_poses: np.ndarray  # (n, 3)
    est_poses: np.ndarray  # (n, 3)
    err_heading_rad: np.ndarray
    err_x_cells: np.ndarray
    err_y_cells: np.ndarray
    range_std_cells: float
    n_beams: int
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)
    time_s: float = field(default=0.0, compare=False)

    def __str__(self) -> str:
        return (f"Table 1, {self.true_poses.shape[0]} poses: max heading error {self.err_heading_rad.max():.4f} rad, "
                f"max |dX| {self.err_x_cells.max():.0f}, max |dY| {self.err_y_cells.max():.0f} cells "
                f"(004: 0.0098 rad, 0, 1)")

    def table(self) -> str:
        """Our Table 1 (rows per pose, then our and 004's maximum errors).

        Returns
        -------
        str
        """
        rows = []
        for i, (t, e) in enumerate(zip(self.true_poses, self.est_poses, strict=True)):
            rows.append([i + 1, f"{t[2]:.4f}", f"{e[2]:.4f}", f"{t[0]:.0f}", f"{e[0]:.0f}", f"{t[1]:.0f}",
                         f"{e[1]:.0f}", f"{self.err_heading_rad[i]:.4f}", f"{self.err_x_cells[i]:.0f}",
                         f"{self.err_y_cells[i]:.0f}"])
        rows.append(["max (ours)", "", "", "", "", "", "", f"{self.err_heading_rad.max():.4f}",
                     f"{self.err_x_cells.max():.0f}", f"{self.err_y_cells.max():.0f}"])
        src = SOURCE_TABLE1
        s_ea, s_ex, s_ey = _errors(src[:, [2, 4, 0]], src[:, [3, 5, 1]])
        rows.append(["max (004)", "", "", "", "", "", "", f"{s_ea.max():.4f}", f"{s_ex.max():.0f}",
                     f"{s_ey.max():.0f}"])
        head = ["#", "α0", "α0 est", "X", "X est", "Y", "Y est", "err α0", "err X", "err Y"]
        title = (f"Ours: {self.n_beams} beams over 360°, range σ = {self.range_std_cells:g} cell, 0.1-cell "
                 f"quantisation, Δα = {np.degrees(self.params.delta_alpha_rad):g}°, clutter (rad, cells)")
        return format_table(head, rows, title=title)

    def source_table(self) -> str:
        """004's Table 1 as printed (radians, cells).

        Returns
        -------
        str
        """
        src = SOURCE_TABLE1
        ea, ex, ey = _errors(src[:, [2, 4, 0]], src[:, [3, 5, 1]])
        rows = [[i + 1, f"{r[0]:.4f}", f"{r[1]:.4f}", f"{r[2]:.0f}", f"{r[3]:.0f}", f"{r[4]:.0f}", f"{r[5]:.0f}",
                 f"{ea[i]:.4f}", f"{ex[i]:.0f}", f"{ey[i]:.0f}"] for i, r in enumerate(src)]
        head = ["#", "α0", "α0 est", "X", "X est", "Y", "Y est", "err α0", "err X", "err Y"]
        return format_table(head, rows, title="004 Table 1 (its own map and poses)")


def run_table1(n_poses: int = 10, *, range_std_cells: float = 0.3, n_beams: int = 360,
               max_range_cells: float = 100.0, clutter: bool = True, params: LocaliseParams | None = None,
               rng=2010, n_jobs: int = 1, progress: bool | None = None, **overrides) -> Table1Result:
    """Localise the robot from no prior at ``n_poses`` random free poses of the test room (004 Table 1).

    The robot stands on whole cells with a uniform random heading; the scan is
    cast in the measurement room (unmapped clutter) with Gaussian range noise and
    0.1-cell quantisation, and localised on the mapped room M by the full 360°
    search. 004 does not give σ, the beam count or the range limit: ours are
    parameters. ``params`` / ``**overrides``: the :class:`LocaliseParams` of every localisation.
    ``n_jobs`` / ``progress``: the localisations run on :func:`slamlab.sweep.sweep` (same result for any ``n_jobs``).

    Parameters
    ----------
    n_poses : int, default 10
        Random free poses.
    range_std_cells : float, default 0.3
        Range noise std [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    clutter : bool, default True
        Cast in the measurement room (unmapped clutter of 004 Fig. 3b); False casts in the map itself.
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2010
        Seed or generator of poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    Table1Result
    """
    p = LocaliseParams.resolve(params, **overrides)
    n = v.check_int(n_poses, "n_poses", minimum=1)
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = v.as_rng(rng)
    M, W = _worlds(clutter, 0, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, pose, rng) for pose in poses]  # every draw here, in the order of the sequential loop
    t0 = time.perf_counter()
    est = _estimates(_localise_scans(M, scans, (p,), n_jobs=n_jobs, progress=progress))
    ea, ex, ey = _errors(poses, est)
    return Table1Result(poses, est, ea, ex, ey, float(range_std_cells), int(n_beams), p, time.perf_counter() - t0)
