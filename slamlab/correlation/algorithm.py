"""Correlation localisation on a known map (004 §7): rasterise the scan per heading, correlate with M by FFT.

API summary
-----------
- :func:`heading_candidates` — the headings α0n = n·Δα (full circle) or a window
  around a previous heading (tracking mode).
- :func:`rasterise_scan` ``(scan, headings, ...) -> (T, origin)``: the
  images T_n of 004 (a_c along each beam, a_p at its end or over ±Δl, a_n
  elsewhere), vectorised over beams and headings.
- :func:`score_maps` ``(M_values, T, origin, method) -> (n, H, W)``: the
  correlation C_n(k, p) = Σ M(x, y)·T_n(x - k, y - p) re-indexed by the robot's
  cell, by one batched FFT (``"batched"``), per heading with
  ``scipy.signal.fftconvolve`` (``"fftconvolve"``) or by the definition (``"direct"``).
- :func:`localise` ``(grid, scan, *, params=None, **overrides) -> Localisation``: the
  maximum of the 3-D stack → heading and position, streamed over heading chunks
  (bounded memory); its settings are one :class:`LocaliseParams`. With ``ambiguity`` (default) it also
  finds the best *rival* pose more than ``rival_radius_cells`` or ``rival_heading_rad`` away
  (:attr:`Localisation.ambiguity`, ours).
- :func:`localise_joined` ``(grid, scans, odom_poses, ...) -> Localisation``: two or three
  consecutive scans placed by odometry into one T_n per heading (ours; breaks corridor and
  half-turn ties).

Scans are :class:`slamlab.scans.Scan` objects in cell units (``scan.to_cells(cell_m)``
for a metric scan).

Index mapping (0-based; 004's ``x = x0 + Ma - xc + 1`` is 1-based Matlab ``xcorr2``)
-------------------------------------------------------------------------------------
T_n is ``S × S`` with ``S = 2(l_max + 2)`` and the robot at ``T[o, o]``,
``o = l_max + 2``. Cell ``T[i, j]`` stands for map cell ``(row + i - o, col + j - o)``
when the robot is at map cell ``(row, col)``. The full linear correlation
``C[a, b] = Σ_{i,j} T[i, j]·M[i + a - (S - 1), j + b - (S - 1)]`` (size
``(H + S - 1) × (W + S - 1)``, zero padding = a_n = 0) therefore has the robot at

    row = a + o - (S - 1),   col = b + o - (S - 1),

and :func:`score_maps` returns exactly the ``H × W`` block of C whose robot cell
lies inside the map, indexed by that cell: ``D[n, row, col]``. The estimate is
the pose ``(x, y) = (col, row)`` (x along columns, see :mod:`slamlab.scans.grid`).
"""

from __future__ import annotations

import numpy as np

from .. import _validate as v
from ..geometry import wrap_angle
from ..geometry.se2 import check_poses, se2_relative, se2_transform
from ..scans import Scan, check_grid, grid_to_values
from .scoring import _ExploredNorm, _map_spectra, _peak_search, _rival_search, _Stamps, score_maps
from .settings import (
    Localisation,
    LocaliseParams,
    _check_real,
    _check_score_norm,
    _stamp_a_c,
    check_constants,
)

__all__ = [
    "Localisation",
    "LocaliseParams",
    "check_constants",
    "heading_candidates",
    "heading_error",
    "localise",
    "localise_joined",
    "rasterise_scan",
    "score_maps",
]


def heading_candidates(delta_alpha_rad: float, *, center_rad: float | None = None,
                       window_rad: float | None = None) -> np.ndarray:
    """Candidate headings α0n (004 §7).

    Full search (``center_rad`` None): ``α0n = n·Δα`` for ``0 ≤ α0n < 2π``
    (004 prints "n·360/Δα", a slip for ``n·Δα``). Tracking mode: ``center + k·Δα``
    for every integer ``k`` with ``|k·Δα| ≤ window_rad``.

    Parameters
    ----------
    delta_alpha_rad : float
        Heading step Δα [rad], in (0, π].
    center_rad : float, optional
        Previous heading [rad] (tracking mode); None searches the full circle.
    window_rad : float, optional
        Half-width of the tracking window [rad] (default π); only with ``center_rad``.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Candidate headings [rad].

    Examples
    --------
    >>> np.degrees(heading_candidates(np.radians(90))).round(6).tolist()
    [0.0, 90.0, 180.0, 270.0]
    >>> np.degrees(heading_candidates(np.radians(1), center_rad=0.0, window_rad=np.radians(2))).round(6).tolist()
    [-2.0, -1.0, 0.0, 1.0, 2.0]
    """
    d = v.check_positive(delta_alpha_rad, "delta_alpha_rad")
    if d > np.pi:
        raise ValueError(f"`delta_alpha_rad` must be <= π; got {d}")
    if center_rad is None:
        if window_rad is not None:
            raise ValueError("`window_rad` needs `center_rad` (tracking mode searches around a previous heading)")
        n = int(np.floor(2 * np.pi / d + 1e-9))
        return d * np.arange(n)
    c = _check_real(center_rad, "center_rad")
    w = v.check_positive(np.pi if window_rad is None else window_rad, "window_rad", allow_zero=True)
    k = int(np.floor(w / d + 1e-9))
    return c + d * np.arange(-k, k + 1)


def _scan_beams(scan, name: str = "scan") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(bearings_rad, ranges_cells, valid)`` of a cell-unit :class:`~slamlab.scans.Scan` with a return."""
    if not isinstance(scan, Scan):
        raise TypeError(f"`{name}` must be a slamlab.scans.Scan; got {type(scan).__name__}")
    if scan.unit != "cell":
        raise ValueError(f"`{name}` must be in cell units; got unit {scan.unit!r} (use scan.to_cells(cell_m))")
    if not scan.valid.any():
        raise ValueError(f"`{name}` has no return (every beam is a miss): nothing to localise with")
    return scan.bearings_rad, scan.ranges, scan.valid


def _beam_samples(angles, ranges, hit, *, delta_l_cells, hit_offset_cells, step_cells, use_misses):
    """Robot-frame sample points: free ones along the beams, obstacle ones at the ends (004 §7).

    Free: ``0 ≤ t < l - Δl``; obstacle: ``l - Δl + ε ≤ t ≤ l + Δl + hit_offset`` (ε = 0.01 cell,
    so a range ending on a cell face marks the cell behind the face).
    """
    use = hit | use_misses
    a, r, h = angles[use], ranges[use], hit[use]
    l_free = np.where(h, np.maximum(r - delta_l_cells - 1e-6, 0.0), r)
    k = int(np.ceil(l_free.max() / step_cells)) + 1 if l_free.size else 1
    t = step_cells * np.arange(k)
    m = t[None, :] < l_free[:, None]
    bi, ki = np.nonzero(m)
    free = np.column_stack([t[ki] * np.cos(a[bi]), t[ki] * np.sin(a[bi])])
    ah, rh = a[h], r[h]
    lo, hi = -delta_l_cells + 0.01, delta_l_cells + hit_offset_cells
    n_obs = max(int(np.ceil((hi - lo) / step_cells)) + 1, 1) if hi > lo else 1
    offs = np.linspace(lo, max(hi, lo), n_obs)
    to = (rh[:, None] + offs[None, :]).clip(min=0.0)
    obs = np.column_stack([(to * np.cos(ah)[:, None]).ravel(), (to * np.sin(ah)[:, None]).ravel()])
    return free, obs


def rasterise_scan(scan: Scan, headings_rad, *, params: LocaliseParams | None = None, l_max: int | None = None,
                   **overrides) -> tuple[np.ndarray, int]:
    """The images T_n of one scan at every candidate heading (004 §7), vectorised over beams and headings.

    Parameters
    ----------
    scan : Scan
        Beams ``(α_i, l_i)`` in the robot frame, in cell units; beams without a
        return (``valid`` False) are skipped unless ``use_misses``.
    headings_rad : array_like, shape (n,)
        Candidate headings α0n.
    params, **overrides
        The :class:`LocaliseParams` that :func:`localise` uses: 004's constants
        ``a_c, a_p, a_n``, ±Δl ``delta_l_cells``, ``hit_offset_cells`` (the obstacle mark
        sits this far beyond the range, which ends on the obstacle cell's face),
        ``step_cells``, ``use_misses`` and ``dtype`` (of the returned stack).
    l_max : int, optional
        Half-size; default ``ceil(max l_i + Δl + hit_offset)`` (004: ``l_max = max(l_i) + Δl``).

    Returns
    -------
    T : numpy.ndarray, shape (n, S, S), ``S = 2(l_max + 2)``
    origin : int
        ``o = l_max + 2``: the robot's cell is ``T[:, o, o]``.

    Examples
    --------
    >>> T, o = rasterise_scan(Scan([0.0], [1.5], [True]), [0.0, np.pi / 2], a_c=-1, a_p=1)
    >>> T.shape, o
    ((2, 8, 8), 4)
    >>> T[0, o, o:o + 4].tolist(), T[1, o:o + 4, o].tolist()
    ([-1.0, -1.0, 1.0, 0.0], [-1.0, -1.0, 1.0, 0.0])
    """
    p = LocaliseParams.resolve(params, **overrides)
    a, r, h = _scan_beams(scan)
    th = v.as_vector(headings_rad, "headings_rad")
    reach = _reach(r, h, p)
    if l_max is None:
        l_max = int(np.ceil(reach))
    else:
        l_max = v.check_int(l_max, "l_max", minimum=0)
        if l_max < reach - 1e-9:
            raise ValueError(f"`l_max` must cover the longest beam ({reach:.2f} cells); got {l_max}")
    o = l_max + 2
    free, obs = _beam_samples(a, r, h, delta_l_cells=p.delta_l_cells, hit_offset_cells=p.hit_offset_cells,
                              step_cells=p.step_cells, use_misses=p.use_misses)
    stamps = _Stamps(free, obs, th, _stamp_a_c(p), p.a_p, p.a_n, o, np.dtype(p.dtype))
    return stamps.take(np.arange(th.size)), o


def _reach(r, h, p) -> float:
    """Longest marked distance of a beam: its range plus ±Δl and the obstacle offset (cells)."""
    return float(np.max(np.where(h | p.use_misses, r, 0.0))) + p.delta_l_cells + p.hit_offset_cells


def localise(grid, scan: Scan, *, params: LocaliseParams | None = None, prior_heading_rad: float | None = None,
             window_rad: float | None = None, score_norm: str = "none", min_explored_fraction: float = 0.8,
             **overrides) -> Localisation:
    """Pose of the robot on map ``grid`` from one scan: maximum of the correlation stack (004 §7).

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The known map M as cell codes (see :mod:`slamlab.scans.grid`); it is turned
        into values with ``a_c, a_p, a_n``.
    scan : Scan
        A :class:`~slamlab.scans.Scan` in cell units.
    params : LocaliseParams, optional
        The settings (Δα, 004's constants a_c/a_p/a_n, rasterisation, FFT dtype…).
    prior_heading_rad, window_rad : float, optional
        Tracking mode: search only ``prior ± window`` (default window ±π when only
        the prior is given); full circle when the prior is None.
    score_norm : {"none", "explored"}
        ``"explored"`` (ours, issue 25; default ``"none"``): a pose scores the correlation divided by the number of
        the stamp's marked cells that fall on explored map cells (free or obstacle), the mean match per mark the
        map can judge, so a pose is not penalised for the map's holes (a leave-out's). The count is one more
        batched FFT correlation, of the stamps' marks with the explored cells. ``score``, ``score_map``,
        ``best_per_heading`` and the rival are then in these units (the margin's counting argument no longer
        holds).
    min_explored_fraction : float
        With ``score_norm="explored"``: a pose whose marks on explored cells are fewer than this fraction of the
        stamp's marks scores ``-max|T|·max|M| / min_explored_fraction - 1`` (below every normalised score; ``T``:
        the stamp's values, ``M``: the map's; with ``a_n`` ≠ 0 times the stamp's cells per mark), in (0, 1];
        default 0.8
        (the best of 0.5, 0.7, 0.8, 0.9 and 0.95 on the five shared CARMEN logs, ``docs/benchmarks.md``; still
        worse than no normalisation there).
    **overrides
        Fields of :class:`LocaliseParams` to change, e.g. ``delta_alpha_rad=np.radians(5)``.

    Returns
    -------
    Localisation
        Ties within ``1e-9·max|D|`` (float64; ``2e-5·…`` float32) go to the first
        heading, then the first row and column.

    Examples
    --------
    >>> from slamlab.sim import Rangefinder, test_room_200
    >>> M = test_room_200()
    >>> scan = Rangefinder(n_beams=180, max_range_cells=60).scan(M, [70, 30, np.radians(40)])
    >>> loc = localise(M, scan, delta_alpha_rad=np.radians(5))
    >>> loc.col, loc.row, round(float(np.degrees(loc.pose[2])))
    (70, 30, 40)
    """
    p = LocaliseParams.resolve(params, **overrides)
    sn, frac = _check_score_norm(score_norm, min_explored_fraction, p)
    g = check_grid(grid)
    a, r, h = _scan_beams(scan)
    if prior_heading_rad is None and window_rad is not None:
        raise ValueError("`window_rad` needs `prior_heading_rad` (tracking mode)")
    headings = heading_candidates(p.delta_alpha_rad, center_rad=prior_heading_rad, window_rad=window_rad)
    return _localise(grid_to_values(g, p.a_c, p.a_p, p.a_n), a, r, h, headings, p,
                     tracking=prior_heading_rad is not None, score_norm=sn, min_explored_fraction=frac)


def _localise(Mv, a, r, h, headings, p: LocaliseParams, *, tracking: bool, score_norm: str = "none",
              min_explored_fraction: float = 0.8) -> Localisation:
    """The search itself, on checked arguments: ``Mv`` the map in 004's values (called per scan by the runs)."""
    free, obs = _beam_samples(a, r, h, delta_l_cells=p.delta_l_cells, hit_offset_cells=p.hit_offset_cells,
                              step_cells=p.step_cells, use_misses=p.use_misses)
    return _localise_samples(Mv, free, obs, int(np.ceil(_reach(r, h, p))) + 2, headings, p, tracking=tracking,
                             obs_weights=_wall_weights([(a, r, h)], np.zeros((1, 3)), p) if p.wall_balance else None,
                             score_norm=score_norm, min_explored_fraction=min_explored_fraction)


def _wall_weights(beams, rel_poses, p: LocaliseParams, n_bins: int = 12) -> np.ndarray:
    """Weight of each obstacle sample of :func:`_joined_samples`: the rarer its wall direction, the larger (ours).

    In a corridor most returns lie on its two long walls, which fix the pose across the corridor but not along
    it; the few returns on door frames, corners and the corridor's end fix it along. Each return's wall direction
    is that of the line through its neighbours' end points (in beam order), modulo π, in ``n_bins`` bins over
    all joined scans; a return's weight is ``count(bin)^(-1/2)``, scaled to a mean of 1 over the returns and
    capped at 4 (issue 25, ours; :attr:`LocaliseParams.wall_balance`). Same order as the obstacle samples.
    """
    lo, hi = -p.delta_l_cells + 0.01, p.delta_l_cells + p.hit_offset_cells
    n_obs = max(int(np.ceil((hi - lo) / p.step_cells)) + 1, 1) if hi > lo else 1  # marks per beam, as sampled
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
    return np.repeat(w, n_obs)


def _explored_floor(a_c: float, a_p, p: LocaliseParams, min_fraction: float, per_mark: float = 1.0) -> float:
    """The score of a pose with too few marks on explored cells under ``score_norm="explored"``: below every
    normalised score. A pose's ``Σ T·M`` is at most ``B = max|T|·max|M|`` per mark in size (``per_mark`` times that
    when the stamp's unmarked cells, ``a_n``, count too), and it is divided by at least ``min_fraction`` of its
    marks, so ``-B·per_mark / min_fraction - 1`` (``a_c``: the stamp's free value, ``a_p``: its obstacle
    values)."""
    stamp_max = max(abs(a_c), float(np.max(np.abs(a_p), initial=0.0)), abs(p.a_n))
    map_max = max(abs(p.a_c), abs(p.a_p), abs(p.a_n))
    return -stamp_max * map_max * per_mark / min_fraction - 1.0


def _localise_samples(Mv, free, obs, o, headings, p: LocaliseParams, *, tracking: bool, n_scans: int = 1,
                      obs_weights=None, refine: int = 0, refine_heading_rad: float = float(np.radians(3.0)),
                      score_norm: str = "none", min_explored_fraction: float = 0.8):
    """Rasterise the robot-frame samples ``free`` / ``obs`` (stamp half-size ``o``), search the peak and its rival.

    ``obs_weights`` (one per obstacle sample, optional) multiply ``a_p`` in the stamps (:func:`_wall_weights`).
    ``refine`` > 0 (ours, issue 25; off by default): the ``refine`` best distinct peaks of the grid search
    (more than 2 cells or 3° apart) are scored again off the grid, every 0.5 cell within 1 cell and every
    0.5° within ``refine_heading_rad`` (:func:`_refine_peaks`), and the pose is the best of those (``score``
    and the rival stay the grid search's). ``score_norm`` / ``min_explored_fraction``: as in :func:`localise`
    (checked by the caller).
    """
    dtype = np.dtype(p.dtype)
    S = 2 * o
    a_p = p.a_p if obs_weights is None else p.a_p * np.asarray(obs_weights, dtype=float)
    a_c = _stamp_a_c(p)
    stamps = _Stamps(free, obs, headings, a_c, a_p, p.a_n, o, dtype)
    n_marks = max(1, free.shape[0] + obs.shape[0])
    amax = max(abs(p.a_c), float(np.max(np.abs(a_p), initial=0.0)), abs(p.a_n))
    tol = (1e-9 if dtype == np.float64 else 2e-5) * amax * amax * n_marks
    specs = _map_spectra(Mv, stamps, S, o, dtype=dtype, workers=p.workers)
    norm = None
    if score_norm == "explored":  # scores per mark on an explored cell (ours, issue 25)
        norm = _ExploredNorm(Mv, free, obs, headings, o, p.a_n, min_explored_fraction, 0.0, dtype=dtype,
                             workers=p.workers)
        # with a_n != 0 every stamp cell, not only the marks, adds to the score
        per_mark = 1.0 if p.a_n == 0 else S * S / max(1.0, float(norm.marks.min()))
        norm.floor = _explored_floor(a_c, a_p, p, min_explored_fraction, per_mark)
        tol = tol / max(1.0, min_explored_fraction * float(norm.marks.min()))
    found = _peak_search(Mv, stamps, headings, S, o, dtype=dtype, workers=p.workers, chunk=p.chunk, tol=tol,
                         specs=specs, n_peaks=refine, norm=norm)
    best_val, best_idx, best_map, best, arg = found[:5]
    n, row, col = (int(i) for i in best_idx)

    def pose_of(k, rw, cl):
        hd = headings[k] if tracking else float(np.mod(headings[k], 2 * np.pi))
        return np.array([float(cl), float(rw), hd])

    rival_val, rival_pose = float("nan"), None
    if p.ambiguity:
        rival_val, ridx = _rival_search(specs, stamps, headings, S, best_idx, best, arg,
                                        radius_cells=p.rival_radius_cells, heading_rad=p.rival_heading_rad,
                                        chunk=p.chunk, norm=norm)
        rival_pose = None if ridx is None else pose_of(*ridx)
    pose = pose_of(n, row, col)
    if refine:
        if norm is not None:
            raise ValueError("`refine` does not support `score_norm='explored'` (it re-scores by the raw score)")
        pose = _refine_peaks(Mv, free, obs, a_c, a_p, headings, found[5], refine, refine_heading_rad)
        if not tracking:
            pose[2] = float(np.mod(pose[2], 2 * np.pi))
    return Localisation(pose=pose, row=row, col=col, heading_index=n, score=best_val,
                        headings_rad=headings, best_per_heading=best, score_map=best_map, rival_score=rival_val,
                        rival_pose=rival_pose, n_scans=n_scans)


def _refine_peaks(Mv, free, obs, a_c, a_p, headings, peaks, k: int,
                  heading_rad: float = float(np.radians(3.0))) -> np.ndarray:
    """The best pose off the grid near the ``k`` best distinct grid peaks (ours, issue 25).

    Each peak of :func:`~slamlab.correlation.scoring._distinct_peaks` (more than 2 cells or 3° apart) is
    scored by the definition (:func:`~slamlab.correlation.scoring._pose_scores`) at the poses every 0.5 cell
    within 1 cell and every 0.5° within ``heading_rad`` of it; the pose ``(x = col, y = row, heading)`` with the
    highest score wins (first on ties, the peaks taken best first).
    """
    from .scoring import _distinct_peaks, _pose_scores

    cand = _distinct_peaks(peaks, headings, k, 2.0, float(np.radians(3.0)))
    d = 0.5 * np.arange(-2, 3)
    dx, dy = np.meshgrid(d, d)
    near = np.hypot(dx, dy) <= 1.0 + 1e-9
    m = int(np.floor(heading_rad / np.radians(0.5) + 1e-9))
    dh = np.radians(0.5) * np.arange(-m, m + 1)
    offs = np.array([[a, b, h] for h in dh for a, b in zip(dx[near], dy[near], strict=True)])
    poses = np.vstack([offs + np.array([c, r, headings[int(n)]]) for _v, n, r, c in cand])
    sc = _pose_scores(Mv, free, obs, a_c, a_p, poses)
    return poses[int(np.argmax(sc))].copy()


def _joined_samples(beams, rel_poses, p: LocaliseParams):
    """Free / obstacle samples of several scans in the frame of the first one, and the stamp half-size (ours).

    ``beams``: ``(bearings, ranges, valid)`` per scan; ``rel_poses`` ``(k, 3)``: each scan's pose in the
    first scan's frame (cells, rad; the first row is the zero pose).
    """
    frees, obss = [], []
    for (a, r, h), q in zip(beams, rel_poses, strict=True):
        f, ob = _beam_samples(a, r, h, delta_l_cells=p.delta_l_cells, hit_offset_cells=p.hit_offset_cells,
                              step_cells=p.step_cells, use_misses=p.use_misses)
        frees.append(se2_transform(q, f) if f.size else f.reshape(0, 2))
        obss.append(se2_transform(q, ob) if ob.size else ob.reshape(0, 2))
    free, obs = np.vstack(frees), np.vstack(obss)
    reach = float(np.sqrt(np.max(np.sum(np.vstack([free, obs]) ** 2, axis=1))))
    return free, obs, int(np.ceil(reach)) + 2


def localise_joined(grid, scans, odom_poses, *, params: LocaliseParams | None = None,
                    prior_heading_rad: float | None = None, window_rad: float | None = None,
                    score_norm: str = "none", min_explored_fraction: float = 0.8, **overrides) -> Localisation:
    """Pose of the first of several scans joined by odometry into one stamp (ours, on 004 §7).

    A single scan in a corridor or a symmetric room matches equally well turned by 180° or
    shifted along the corridor; two or three consecutive scans, placed relative to each
    other by odometry, see more of the room and break such ties. Every scan's free and
    obstacle samples are moved into the first scan's frame with
    ``odom_poses[0]⁻¹ ⊕ odom_poses[k]`` and drawn into one image T_n per heading (obstacle
    marks over free ones, as in :func:`rasterise_scan`); the search is :func:`localise`'s.

    Parameters
    ----------
    grid : array_like of int, shape (H, W)
        The known map (cell codes).
    scans : sequence of Scan
        In cell units; the pose of ``scans[0]`` is estimated.
    odom_poses : array_like, shape (len(scans), 3)
        Odometry pose of each scan in any common frame (cells, rad); only the relative
        poses matter.
    params, prior_heading_rad, window_rad, score_norm, min_explored_fraction, **overrides
        As in :func:`localise`.

    Returns
    -------
    Localisation
        The pose of the first scan; ``n_scans`` = number of scans joined.

    Examples
    --------
    >>> from slamlab.sim import Rangefinder, test_room_200
    >>> M = test_room_200()
    >>> rf = Rangefinder(n_beams=180, max_range_cells=60)
    >>> poses = np.array([[70, 30, np.radians(40)], [66, 27, np.radians(40)]])
    >>> loc = localise_joined(M, [rf.scan(M, q) for q in poses], poses, delta_alpha_rad=np.radians(5))
    >>> loc.col, loc.row, round(float(np.degrees(loc.pose[2]))), loc.n_scans
    (70, 30, 40, 2)
    """
    p = LocaliseParams.resolve(params, **overrides)
    sn, frac = _check_score_norm(score_norm, min_explored_fraction, p)
    g = check_grid(grid)
    if isinstance(scans, Scan) or not isinstance(scans, (list, tuple)):
        raise TypeError(f"`scans` must be a list or tuple of Scan; got {type(scans).__name__}")
    if not scans:
        raise ValueError("`scans` must hold at least one scan; got 0")
    beams = [_scan_beams(s, f"scans[{k}]") for k, s in enumerate(scans)]
    P = check_poses(odom_poses, "odom_poses", n=len(scans))
    if prior_heading_rad is None and window_rad is not None:
        raise ValueError("`window_rad` needs `prior_heading_rad` (tracking mode)")
    headings = heading_candidates(p.delta_alpha_rad, center_rad=prior_heading_rad, window_rad=window_rad)
    rel = se2_relative(P[0], P)
    free, obs, o = _joined_samples(beams, rel, p)
    return _localise_samples(grid_to_values(g, p.a_c, p.a_p, p.a_n), free, obs, o, headings, p,
                             tracking=prior_heading_rad is not None, n_scans=len(scans),
                             obs_weights=_wall_weights(beams, rel, p) if p.wall_balance else None,
                             score_norm=sn, min_explored_fraction=frac)


def heading_error(est_rad, true_rad):
    """Absolute wrapped heading difference ``|wrap(est - true)|`` [rad].

    Parameters
    ----------
    est_rad, true_rad : array_like
        Estimated and true headings [rad] (broadcast together).

    Returns
    -------
    numpy.ndarray
        ``|wrap(est - true)|`` in [0, π] [rad].
    """
    return np.abs(wrap_angle(np.asarray(est_rad, dtype=float) - np.asarray(true_rad, dtype=float)))
