"""004's constants a_c, a_p, a_n compared on the same cluttered scans (004 §7): peak sharpness, failures."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ...sim.paths import random_free_poses
from ..algorithm import LocaliseParams, heading_error, localise
from .common import FAIL_CELLS, FAIL_DEG, _estimates, _localise_scans, _sensor, _worlds


@dataclass(frozen=True)
class ConstantsResult:
    """Peak sharpness and robustness to unmapped clutter of two choices of 004's constants.

    Attributes
    ----------
    labels : tuple of str
        One label per choice of constants.
    constants : tuple of tuple of float
        ``(a_c, a_p, a_n)`` per choice.
    half_max_area : numpy.ndarray, shape (k, n)
        Cells scoring at least halfway from the median to the peak at the best heading.
    heading_margin : numpy.ndarray, shape (k, n)
        (Peak minus the best score ≥ 3° away) over (peak minus the median over headings).
    failure_rate : numpy.ndarray, shape (k,)
        Share of failed poses per choice.
    err_pos_cells : numpy.ndarray, shape (k, n)
        Position errors [cells].
    extra_clutter : int
        Random discs added to 004's clutter.
    example_maps : tuple of numpy.ndarray
        Score maps of the first scan at its true heading, one per choice.
    example_pose : numpy.ndarray, shape (3,)
        The first scan's true pose.
    time_s : float
        Wall time [s] (not compared).
    """

    labels: tuple[str, ...]
    constants: tuple[tuple[float, float, float], ...]
    half_max_area: np.ndarray  # (k, n) cells with score >= median + (peak - median)/2 at the best heading
    heading_margin: np.ndarray  # (k, n) (peak - best >= 3° away) / (peak - median over headings)
    failure_rate: np.ndarray  # (k,)
    err_pos_cells: np.ndarray  # (k, n)
    extra_clutter: int
    example_maps: tuple = field(default=(), repr=False)  # score maps at the truth's heading, one per choice
    example_pose: np.ndarray = field(default=None, repr=False)
    time_s: float = field(default=0.0, compare=False)

    def __str__(self) -> str:
        return "; ".join(f"{lb}: failures {fr:.0%}" for lb, fr in zip(self.labels, self.failure_rate, strict=True))

    def table(self) -> str:
        """Median sharpness measures and failure rate per choice.

        Returns
        -------
        str
        """
        rows = []
        for k, lb in enumerate(self.labels):
            rows.append([lb, f"{np.median(self.half_max_area[k]):.0f}", f"{np.median(self.heading_margin[k]):.3f}",
                         f"{np.mean(self.err_pos_cells[k] <= 1.5):.0%}", f"{self.failure_rate[k]:.0%}"])
        title = (f"{self.err_pos_cells.shape[1]} poses, clutter of 004 Fig. 3b + {self.extra_clutter} extra discs; "
                 "medians; a sharper peak has a smaller half-max area and a larger heading margin")
        return format_table(["constants", "half-max area", "heading margin", "pos. err <= 1.5", "failures"],
                            rows, title=title)


def run_constants_study(n_poses: int = 12, *, extra_clutter: int = 60, range_std_cells: float = 0.3,
                        n_beams: int = 360, max_range_cells: float = 100.0,
                        choices=((-1.0, 1.0, 0.0), (0.0, 1.0, 0.0)), params: LocaliseParams | None = None,
                        rng=2012, n_jobs: int = 1, progress: bool | None = None, **overrides) -> ConstantsResult:
    """Compare 004's constant choices on the same cluttered scans (004 §7).

    004: the peak is sharpest at ``a_p = -a_c``; with unmapped objects,
    ``a_c = a_n = 0, a_p > 0`` can be more robust. Each choice localises the same
    scans (cast in the room with 004's clutter plus ``extra_clutter`` random
    discs). Our sharpness measures: the half-maximum area of the score map at the
    best heading (cells scoring at least halfway from the median to the peak), the
    heading margin (peak minus the best score ≥ 3° away, over peak minus the median
    over headings), and the failure rate. ``params`` / ``**overrides``: the other
    :class:`LocaliseParams` fields (each choice replaces ``a_c, a_p, a_n``).

    The scans are drawn here; the ``len(choices) × n_poses`` localisations run on
    :func:`slamlab.sweep.sweep` with ``n_jobs`` workers (same result for any ``n_jobs``)
    and a progress bar unless ``progress=False`` or ``$SLAMLAB_PROGRESS=0``.

    Parameters
    ----------
    n_poses : int, default 12
        Random free poses, the same scans for every choice.
    extra_clutter : int, default 60
        Random unmapped discs added to 004's clutter.
    range_std_cells : float, default 0.3
        Range noise std [cells].
    n_beams : int, default 360
        Beams over 360°.
    max_range_cells : float, default 100.0
        Range limit [cells].
    choices : sequence of tuple of float
        ``(a_c, a_p, a_n)`` triples to compare.
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`).
    rng : int or numpy.random.Generator, default 2012
        Seed or generator of clutter, poses and scan noise.
    n_jobs : int, default 1
        Worker processes for the localisations (same result for any value).
    progress : bool or None
        Progress bar: None shows one in a notebook only.
    **overrides
        :class:`LocaliseParams` fields to change.

    Returns
    -------
    ConstantsResult
    """
    base = LocaliseParams.resolve(params, **overrides)
    n = v.check_int(n_poses, "n_poses", minimum=1)
    ec = v.check_int(extra_clutter, "extra_clutter", minimum=0)
    settings = tuple(base.replace(a_c=float(c[0]), a_p=float(c[1]), a_n=float(c[2])) for c in choices)
    consts = tuple((q.a_c, q.a_p, q.a_n) for q in settings)
    if not consts:
        raise ValueError("`choices` must hold at least one (a_c, a_p, a_n) triple")
    rf = _sensor(n_beams, max_range_cells, range_std_cells)
    rng = v.as_rng(rng)
    M, W = _worlds(True, ec, rng)
    poses = random_free_poses(W, n, margin_cells=2, rng=rng)
    scans = [rf.scan(W, p, rng) for p in poses]
    k = len(consts)
    t0 = time.perf_counter()
    table = _localise_scans(M, scans, settings, margins=True, n_jobs=n_jobs, progress=progress)
    est = _estimates(table).reshape(k, n, 3)
    pm = table["half_max_area"].to_numpy(dtype=float).reshape(k, n)
    hm = table["heading_margin"].to_numpy(dtype=float).reshape(k, n)
    ep = np.hypot(est[..., 0] - poses[:, 0], est[..., 1] - poses[:, 1])
    failed = (ep > FAIL_CELLS) | (np.degrees(heading_error(est[..., 2], poses[:, 2])) > FAIL_DEG)
    h0 = np.radians(np.round(np.degrees(poses[0, 2])))
    maps = [localise(M, scans[0], params=q, prior_heading_rad=h0, window_rad=0.0).score_map for q in settings]
    labels = tuple(f"a_c={c[0]:g}, a_p={c[1]:g}, a_n={c[2]:g}" for c in consts)
    return ConstantsResult(labels, consts, pm, hm, failed.mean(axis=1), ep, ec, tuple(maps), poses[0].copy(),
                           time.perf_counter() - t0)
