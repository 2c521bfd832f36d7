"""The points a scan marks in its stamps T_n (004 §7): free samples along each beam, obstacle samples at its end.

:func:`scan_samples` (one scan) and :func:`joined_samples` (several scans placed by odometry, ours) return a
:class:`ScanSamples` in the robot frame, with the values the stamps give them. Every later step starts from it:
the stamps T_n (:func:`~slamlab.correlation.scan_stamps`), the FFT search
(:func:`~slamlab.correlation.algorithm.localise_samples`) and the score at any pose by the definition
(:func:`~slamlab.correlation.scoring.pose_scores`). The free samples come from the 2-D layer's one beam sampler,
:func:`slamlab.scans.free_space_samples`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.se2 import check_poses, se2_relative, se2_transform
from ..scans import Scan, free_space_samples
from .settings import LocaliseParams

__all__ = ["ScanSamples", "joined_samples", "scan_samples"]


@dataclass(frozen=True, eq=False)  # arrays: compare fields explicitly, not with ==
class ScanSamples:
    """The robot-frame points of one scan, or of scans joined by odometry, and their stamp values (004 §7).

    Attributes
    ----------
    free : numpy.ndarray, shape (k, 2)
        Free samples along the beams ``(x, y)`` [cells], in the frame of the (first) scan.
    obs : numpy.ndarray, shape (m, 2)
        Obstacle samples at the beams' ends [cells], over ±Δl and up to ``hit_offset_cells`` beyond the range.
    free_value : float
        The stamps' value at a free sample: ``a_c · free_mark_weight``.
    obs_value : float or numpy.ndarray, shape (m,)
        The stamps' value at an obstacle sample: ``a_p``, times each sample's wall weight with ``wall_balance``.
    reach_cells : float
        The farthest marked distance from the robot [cells].
    n_scans : int
        Scans joined into the samples.
    params : LocaliseParams
        The settings the samples were made with (and the search uses).
    """

    free: np.ndarray
    obs: np.ndarray
    free_value: float
    obs_value: float | np.ndarray
    reach_cells: float
    n_scans: int
    params: LocaliseParams

    @property
    def origin(self) -> int:
        """``o = ceil(reach_cells) + 2``: the robot's cell ``T[o, o]`` of the smallest stamps holding every sample."""
        return int(np.ceil(self.reach_cells)) + 2


def _scan_beams(scan, name: str = "scan") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(bearings_rad, ranges_cells, valid)`` of a cell-unit :class:`~slamlab.scans.Scan` with a return."""
    if not isinstance(scan, Scan):
        raise TypeError(f"`{name}` must be a slamlab.scans.Scan; got {type(scan).__name__}")
    if scan.unit != "cell":
        raise ValueError(f"`{name}` must be in cell units; got unit {scan.unit!r} (use scan.to_cells(cell_m))")
    if not scan.valid.any():
        raise ValueError(f"`{name}` has no return (every beam is a miss): nothing to localise with")
    return scan.bearings_rad, scan.ranges, scan.valid


def _obstacle_offsets(p: LocaliseParams) -> np.ndarray:
    """Distances from the range of the obstacle samples of one beam: ``l - Δl + ε ≤ t ≤ l + Δl + hit_offset``
    (ε = 0.01 cell, so a range ending on a cell face marks the cell behind the face), every ``step_cells`` or less."""
    lo, hi = -p.delta_l_cells + 0.01, p.delta_l_cells + p.hit_offset_cells
    n_obs = max(int(np.ceil((hi - lo) / p.step_cells)) + 1, 1) if hi > lo else 1
    return np.linspace(lo, max(hi, lo), n_obs)


def _beam_marks(a, r, h, p: LocaliseParams) -> tuple[np.ndarray, np.ndarray]:
    """Free samples ``0 ≤ t < l - Δl`` along the beams (beams without a return only with ``use_misses``) and
    obstacle samples at the ends of the beams with a return, robot frame (004 §7)."""
    free, _beam = free_space_samples(a, r, h, step_cells=p.step_cells, hit_margin_cells=p.delta_l_cells,
                                     misses=p.use_misses)
    ah, rh = a[h], r[h]
    to = (rh[:, None] + _obstacle_offsets(p)[None, :]).clip(min=0.0)
    obs = np.column_stack([(to * np.cos(ah)[:, None]).ravel(), (to * np.sin(ah)[:, None]).ravel()])
    return free, obs


def _wall_weights(beams, rel_poses, p: LocaliseParams, n_bins: int = 12) -> np.ndarray:
    """Weight of each obstacle sample: the rarer its wall direction, the larger (ours, issue 25).

    In a corridor most returns lie on its two long walls, which fix the pose across the corridor but not along
    it; the few returns on door frames, corners and the corridor's end fix it along. Each return's wall direction
    is that of the line through its neighbours' end points (in beam order), modulo π, in ``n_bins`` bins over
    all joined scans; a return's weight is ``count(bin)^(-1/2)``, scaled to a mean of 1 over the returns and
    capped at 4 (:attr:`LocaliseParams.wall_balance`). Same order as the obstacle samples.
    """
    dirs = []
    for (a, r, h), q in zip(beams, rel_poses, strict=True):
        use = h | p.use_misses
        hit = h[use]
        ah, rh = a[use][hit], r[use][hit]
        x, y = rh * np.cos(ah), rh * np.sin(ah)
        d = np.arctan2(np.gradient(y), np.gradient(x)) if x.size >= 2 else np.zeros(x.size)
        dirs.append(d + q[2])
    d = np.mod(np.concatenate(dirs), np.pi)
    b = np.minimum((d / (np.pi / n_bins)).astype(np.int64), n_bins - 1)
    w = np.bincount(b, minlength=n_bins)[b] ** -0.5 if b.size else np.ones(0)
    w = np.minimum(w * (w.size / max(w.sum(), 1e-12)), 4.0)
    return np.repeat(w, _obstacle_offsets(p).size)  # one weight per obstacle sample of the beam


def _samples(free, obs, beams, rel_poses, reach: float, p: LocaliseParams) -> ScanSamples:
    """The :class:`ScanSamples` with the stamp values of ``p`` (wall weights from ``beams`` with ``wall_balance``)."""
    obs_value = p.a_p * _wall_weights(beams, rel_poses, p) if p.wall_balance else p.a_p
    return ScanSamples(free, obs, p.a_c * p.free_mark_weight, obs_value, reach, len(beams), p)


def scan_samples(scan: Scan, *, params: LocaliseParams | None = None, **overrides) -> ScanSamples:
    """The robot-frame points one scan marks in its stamps T_n, and their values (004 §7).

    Parameters
    ----------
    scan : Scan
        Beams ``(α_i, l_i)`` in the robot frame, in cell units, with at least one return; beams without a
        return are sampled only with ``use_misses``.
    params, **overrides
        The :class:`LocaliseParams` (its constants, ``delta_l_cells``, ``hit_offset_cells``, ``step_cells``,
        ``use_misses``, ``free_mark_weight`` and ``wall_balance`` shape the samples).

    Returns
    -------
    ScanSamples
        ``reach_cells`` = the longest beam used plus ``delta_l_cells`` and ``hit_offset_cells``.

    Examples
    --------
    >>> s = scan_samples(Scan([0.0], [1.5], [True]))
    >>> s.free.tolist(), s.obs.round(2).tolist(), s.origin
    ([[0.0, 0.0], [0.5, 0.0], [1.0, 0.0]], [[1.51, 0.0], [2.0, 0.0]], 4)
    """
    p = LocaliseParams.resolve(params, **overrides)
    a, r, h = _scan_beams(scan)
    free, obs = _beam_marks(a, r, h, p)
    reach = float(np.max(np.where(h | p.use_misses, r, 0.0))) + p.delta_l_cells + p.hit_offset_cells
    return _samples(free, obs, [(a, r, h)], np.zeros((1, 3)), reach, p)


def joined_samples(scans, odom_poses, *, params: LocaliseParams | None = None, **overrides) -> ScanSamples:
    """The points of several scans moved into the frame of the first by odometry (ours, on 004 §7).

    Each scan's samples (as :func:`scan_samples`) are placed at its pose relative to the first,
    ``odom_poses[0]⁻¹ ⊕ odom_poses[k]``, so one stamp per heading holds them all
    (:func:`~slamlab.correlation.localise_joined`).

    Parameters
    ----------
    scans : sequence of Scan
        In cell units, each with at least one return.
    odom_poses : array_like, shape (len(scans), 3)
        Pose of each scan in any common frame (cells, rad); only the relative poses matter (poses already relative
        to the first scan, whose first row is exactly zero, are used as given).
    params, **overrides
        The :class:`LocaliseParams`, as in :func:`scan_samples`.

    Returns
    -------
    ScanSamples
        In the first scan's frame; ``reach_cells`` = the distance of the farthest sample from its origin.

    Examples
    --------
    >>> s = joined_samples([Scan([0.0], [1.5], [True])] * 2, [[5, 5, 0], [6, 5, 0]])
    >>> s.n_scans, s.free.shape, round(s.reach_cells, 2)
    (2, (6, 2), 3.0)
    """
    p = LocaliseParams.resolve(params, **overrides)
    if isinstance(scans, Scan) or not isinstance(scans, (list, tuple)):
        raise TypeError(f"`scans` must be a list or tuple of Scan; got {type(scans).__name__}")
    if not scans:
        raise ValueError("`scans` must hold at least one scan; got 0")
    beams = [_scan_beams(s, f"scans[{k}]") for k, s in enumerate(scans)]
    P = check_poses(odom_poses, "odom_poses", n=len(scans))
    rel = P if not P[0].any() else se2_relative(P[0], P)  # the same poses when the first is the origin
    frees, obss = [], []
    for (a, r, h), q in zip(beams, rel, strict=True):
        f, ob = _beam_marks(a, r, h, p)
        frees.append(se2_transform(q, f) if f.size else f.reshape(0, 2))
        obss.append(se2_transform(q, ob) if ob.size else ob.reshape(0, 2))
    free, obs = np.vstack(frees), np.vstack(obss)
    reach = float(np.sqrt(np.max(np.sum(np.vstack([free, obs]) ** 2, axis=1))))
    return _samples(free, obs, beams, rel, reach, p)
