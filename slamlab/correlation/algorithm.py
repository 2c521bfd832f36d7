"""Correlation localisation on a known map (004 §7): rasterise the scan per heading, correlate with M by FFT.

API summary
-----------
- :func:`heading_candidates` — the headings α0n = n·Δα (full circle) or a window
  around a previous heading (tracking mode).
- :func:`~slamlab.correlation.samples.scan_samples` / :func:`~slamlab.correlation.samples.joined_samples` — the
  robot-frame points a scan (or scans joined by odometry) marks: a_c along each beam, a_p at its end or over ±Δl.
- :func:`scan_stamps` ``(scan, headings, ...) -> (T, origin)``: those points drawn into the
  images T_n of 004 (a_n elsewhere), one per heading, vectorised over beams and headings.
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
- :func:`localise_samples` ``(M_values, samples, ...) -> Localisation``: the search both run, on samples
  and a map already in 004's values (what the chapter's studies call per scan).

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

from .._validate import as_finite_array, as_vector, check_int, check_positive, check_real
from ..geometry import wrap_angle
from ..scans import Scan, check_grid, grid_to_values
from ._fft import ExploredNorm, Stamps, distinct_peaks, map_spectra, peak_search, rival_search
from .samples import ScanSamples, joined_samples, scan_samples
from .scoring import pose_scores, score_maps
from .settings import Localisation, LocaliseParams, check_constants, check_score_norm

__all__ = [
    "Localisation",
    "LocaliseParams",
    "check_constants",
    "heading_candidates",
    "heading_error",
    "localise",
    "localise_joined",
    "localise_samples",
    "scan_stamps",
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
    d = check_positive(delta_alpha_rad, "delta_alpha_rad")
    if d > np.pi:
        raise ValueError(f"`delta_alpha_rad` must be <= π; got {d}")
    if center_rad is None:
        if window_rad is not None:
            raise ValueError("`window_rad` needs `center_rad` (tracking mode searches around a previous heading)")
        n = int(np.floor(2 * np.pi / d + 1e-9))
        return d * np.arange(n)
    c = check_real(center_rad, "center_rad")
    w = check_positive(np.pi if window_rad is None else window_rad, "window_rad", allow_zero=True)
    k = int(np.floor(w / d + 1e-9))
    return c + d * np.arange(-k, k + 1)


def scan_stamps(scan: Scan, headings_rad, *, params: LocaliseParams | None = None, l_max: int | None = None,
                **overrides) -> tuple[np.ndarray, int]:
    """The stamps T_n of one scan, one image per candidate heading, vectorised over beams and headings (004 §7).

    The scan's :func:`~slamlab.correlation.samples.scan_samples` drawn around the robot's cell turned by each
    heading: ``a_c`` along each beam (times ``free_mark_weight``), ``a_p`` at its end or over ±Δl (obstacle marks
    over free ones; times the wall weights with ``wall_balance``), ``a_n`` elsewhere: exactly the images
    :func:`localise` correlates with the map.

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
        ``step_cells``, ``use_misses``, ``free_mark_weight``, ``wall_balance`` and ``dtype`` (of the returned stack).
    l_max : int, optional
        Half-size; default ``ceil(max l_i + Δl + hit_offset)`` (004: ``l_max = max(l_i) + Δl``).

    Returns
    -------
    T : numpy.ndarray, shape (n, S, S), ``S = 2(l_max + 2)``
    origin : int
        ``o = l_max + 2``: the robot's cell is ``T[:, o, o]``.

    Examples
    --------
    >>> T, o = scan_stamps(Scan([0.0], [1.5], [True]), [0.0, np.pi / 2], a_c=-1, a_p=1)
    >>> T.shape, o
    ((2, 8, 8), 4)
    >>> T[0, o, o:o + 4].tolist(), T[1, o:o + 4, o].tolist()
    ([-1.0, -1.0, 1.0, 0.0], [-1.0, -1.0, 1.0, 0.0])
    """
    p = LocaliseParams.resolve(params, **overrides)
    samples = scan_samples(scan, params=p)
    th = as_vector(headings_rad, "headings_rad")
    reach = samples.reach_cells
    if l_max is None:
        l_max = int(np.ceil(reach))
    else:
        l_max = check_int(l_max, "l_max", minimum=0)
        if l_max < reach - 1e-9:
            raise ValueError(f"`l_max` must cover the longest beam ({reach:.2f} cells); got {l_max}")
    o = l_max + 2
    stamps = Stamps(samples.free, samples.obs, th, samples.free_value, samples.obs_value, p.a_n, o, np.dtype(p.dtype))
    return stamps.take(np.arange(th.size)), o


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
    check_score_norm(score_norm, min_explored_fraction, p)
    g = check_grid(grid)
    samples = scan_samples(scan, params=p)
    return localise_samples(grid_to_values(g, p.a_c, p.a_p, p.a_n), samples, prior_heading_rad=prior_heading_rad,
                            window_rad=window_rad, score_norm=score_norm, min_explored_fraction=min_explored_fraction)


def localise_joined(grid, scans, odom_poses, *, params: LocaliseParams | None = None,
                    prior_heading_rad: float | None = None, window_rad: float | None = None,
                    score_norm: str = "none", min_explored_fraction: float = 0.8, **overrides) -> Localisation:
    """Pose of the first of several scans joined by odometry into one stamp (ours, on 004 §7).

    A single scan in a corridor or a symmetric room matches equally well turned by 180° or
    shifted along the corridor; two or three consecutive scans, placed relative to each
    other by odometry, see more of the room and break such ties. Every scan's free and
    obstacle samples are moved into the first scan's frame with
    ``odom_poses[0]⁻¹ ⊕ odom_poses[k]`` (:func:`~slamlab.correlation.samples.joined_samples`) and drawn into one
    image T_n per heading (obstacle marks over free ones, as in :func:`scan_stamps`); the search is
    :func:`localise`'s.

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
    check_score_norm(score_norm, min_explored_fraction, p)
    g = check_grid(grid)
    samples = joined_samples(scans, odom_poses, params=p)
    return localise_samples(grid_to_values(g, p.a_c, p.a_p, p.a_n), samples, prior_heading_rad=prior_heading_rad,
                            window_rad=window_rad, score_norm=score_norm, min_explored_fraction=min_explored_fraction)


def localise_samples(M_values, samples: ScanSamples, *, prior_heading_rad: float | None = None,
                     window_rad: float | None = None, score_norm: str = "none", min_explored_fraction: float = 0.8,
                     refine: int = 0, refine_heading_rad: float = float(np.radians(3.0))) -> Localisation:
    """The search of :func:`localise`: a scan's samples against a map in 004's values (004 §7).

    The samples are drawn into one stamp per candidate heading (``T[origin, origin]`` the robot, ``origin`` =
    ``samples.origin``) and correlated with the map by batched FFTs; the pose is the maximum of the stack, and
    with ``ambiguity`` its best rival is searched too. Every setting comes from ``samples.params``.

    Parameters
    ----------
    M_values : array_like, shape (H, W)
        The map in 004's values of ``samples.params`` (:func:`slamlab.scans.grid_to_values`).
    samples : ScanSamples
        From :func:`~slamlab.correlation.samples.scan_samples` or :func:`~slamlab.correlation.samples.joined_samples`.
    prior_heading_rad, window_rad, score_norm, min_explored_fraction
        As in :func:`localise`.
    refine : int, default 0
        Off by default. ``refine`` > 0 (ours, issue 25): the ``refine`` best distinct peaks of the grid search (more
        than 2 cells or 3° apart) are scored again off the grid by the definition
        (:func:`~slamlab.correlation.scoring.pose_scores`), every 0.5 cell within 1 cell and every 0.5° within
        ``refine_heading_rad``, and the pose is the best of those (``score`` and the rival stay the grid search's).
        Not with ``score_norm="explored"``.
    refine_heading_rad : float, default 3°
        Half-width of the refinement's headings around each peak [rad].

    Returns
    -------
    Localisation
        ``n_scans`` = ``samples.n_scans``.

    Examples
    --------
    >>> from slamlab.correlation.samples import scan_samples
    >>> from slamlab.sim import Rangefinder, test_room_200
    >>> M = test_room_200()
    >>> s = scan_samples(Rangefinder(n_beams=180, max_range_cells=60).scan(M, [70, 30, np.radians(40)]),
    ...                  delta_alpha_rad=np.radians(5))
    >>> loc = localise_samples(grid_to_values(M), s)
    >>> loc.col, loc.row, round(float(np.degrees(loc.pose[2])))
    (70, 30, 40)
    """
    from .._heap import reuse_large_blocks

    with reuse_large_blocks():  # its FFT batches: heap blocks reused, not mapped afresh (slamlab._heap)
        return _localise_samples(M_values, samples, prior_heading_rad=prior_heading_rad, window_rad=window_rad,
                                 score_norm=score_norm, min_explored_fraction=min_explored_fraction, refine=refine,
                                 refine_heading_rad=refine_heading_rad)


def _localise_samples(M_values, samples: ScanSamples, *, prior_heading_rad: float | None = None,
                     window_rad: float | None = None, score_norm: str = "none", min_explored_fraction: float = 0.8,
                     refine: int = 0, refine_heading_rad: float = float(np.radians(3.0))) -> Localisation:
    """:func:`localise_samples` without the heap setting."""
    Mv = as_finite_array(M_values, "M_values", ndim=2)
    if Mv.size == 0:
        raise ValueError(f"`M_values` must not be empty; got shape {Mv.shape}")
    if not isinstance(samples, ScanSamples):
        raise TypeError(f"`samples` must be a ScanSamples (scan_samples, joined_samples); got {type(samples).__name__}")
    p = samples.params
    if prior_heading_rad is None and window_rad is not None:
        raise ValueError("`window_rad` needs `prior_heading_rad` (tracking mode)")
    headings = heading_candidates(p.delta_alpha_rad, center_rad=prior_heading_rad, window_rad=window_rad)
    tracking = prior_heading_rad is not None
    score_norm, min_explored_fraction = check_score_norm(score_norm, min_explored_fraction, p)
    refine = check_int(refine, "refine", minimum=0)
    refine_heading_rad = check_positive(refine_heading_rad, "refine_heading_rad", allow_zero=True)
    if refine and score_norm == "explored":
        raise ValueError("`refine` does not support `score_norm='explored'` (it re-scores by the raw score)")
    free, obs, o = samples.free, samples.obs, samples.origin
    dtype = np.dtype(p.dtype)
    S = 2 * o
    a_c, a_p = samples.free_value, samples.obs_value
    stamps = Stamps(free, obs, headings, a_c, a_p, p.a_n, o, dtype)
    n_marks = max(1, free.shape[0] + obs.shape[0])
    amax = max(abs(p.a_c), float(np.max(np.abs(a_p), initial=0.0)), abs(p.a_n))
    tol = (1e-9 if dtype == np.float64 else 2e-5) * amax * amax * n_marks
    specs = map_spectra(Mv, stamps, S, o, dtype=dtype, workers=p.workers)
    norm = None
    if score_norm == "explored":  # scores per mark on an explored cell (ours, issue 25)
        norm = ExploredNorm(Mv, free, obs, headings, o, p.a_n, min_explored_fraction, 0.0, dtype=dtype,
                            workers=p.workers)
        # with a_n != 0 every stamp cell, not only the marks, adds to the score
        per_mark = 1.0 if p.a_n == 0 else S * S / max(1.0, float(norm.marks.min()))
        norm.floor = _explored_floor(a_c, a_p, p, min_explored_fraction, per_mark)
        tol = tol / max(1.0, min_explored_fraction * float(norm.marks.min()))
    found = peak_search(Mv, stamps, headings, S, o, dtype=dtype, workers=p.workers, chunk=p.chunk, tol=tol,
                        specs=specs, n_peaks=refine, norm=norm)
    best_val, best_idx, best_map, best, arg = found[:5]
    n, row, col = (int(i) for i in best_idx)

    def pose_of(k, rw, cl):
        hd = headings[k] if tracking else float(np.mod(headings[k], 2 * np.pi))
        return np.array([float(cl), float(rw), hd])

    rival_val, rival_pose = float("nan"), None
    if p.ambiguity:
        rival_val, ridx = rival_search(specs, stamps, headings, S, best_idx, best, arg,
                                       radius_cells=p.rival_radius_cells, heading_rad=p.rival_heading_rad,
                                       chunk=p.chunk, norm=norm)
        rival_pose = None if ridx is None else pose_of(*ridx)
    pose = pose_of(n, row, col)
    if refine:
        pose = _refine_peaks(Mv, samples, headings, found[5], refine, refine_heading_rad)
        if not tracking:
            pose[2] = float(np.mod(pose[2], 2 * np.pi))
    return Localisation(pose=pose, row=row, col=col, heading_index=n, score=best_val,
                        headings_rad=headings, best_per_heading=best, score_map=best_map, rival_score=rival_val,
                        rival_pose=rival_pose, n_scans=samples.n_scans)


def _explored_floor(a_c: float, a_p, p: LocaliseParams, min_fraction: float, per_mark: float = 1.0) -> float:
    """The score of a pose with too few marks on explored cells under ``score_norm="explored"``: below every
    normalised score. A pose's ``Σ T·M`` is at most ``B = max|T|·max|M|`` per mark in size (``per_mark`` times that
    when the stamp's unmarked cells, ``a_n``, count too), and it is divided by at least ``min_fraction`` of its
    marks, so ``-B·per_mark / min_fraction - 1`` (``a_c``: the stamp's free value, ``a_p``: its obstacle
    values)."""
    stamp_max = max(abs(a_c), float(np.max(np.abs(a_p), initial=0.0)), abs(p.a_n))
    map_max = max(abs(p.a_c), abs(p.a_p), abs(p.a_n))
    return -stamp_max * map_max * per_mark / min_fraction - 1.0


def _refine_peaks(Mv, samples: ScanSamples, headings, peaks, k: int,
                  heading_rad: float = float(np.radians(3.0))) -> np.ndarray:
    """The best pose off the grid near the ``k`` best distinct grid peaks (ours, issue 25).

    Each of the distinct peaks (more than 2 cells or 3° apart) is scored by the definition (:func:`pose_scores`)
    at the poses every 0.5 cell within 1 cell and every 0.5° within ``heading_rad`` of it; the pose
    ``(x = col, y = row, heading)`` with the highest score wins (first on ties, the peaks taken best first).
    """
    cand = distinct_peaks(peaks, headings, k, 2.0, float(np.radians(3.0)))
    d = 0.5 * np.arange(-2, 3)
    dx, dy = np.meshgrid(d, d)
    near = np.hypot(dx, dy) <= 1.0 + 1e-9
    m = int(np.floor(heading_rad / np.radians(0.5) + 1e-9))
    dh = np.radians(0.5) * np.arange(-m, m + 1)
    offs = np.array([[a, b, h] for h in dh for a, b in zip(dx[near], dy[near], strict=True)])
    poses = np.vstack([offs + np.array([c, r, headings[int(n)]]) for _v, n, r, c in cand])
    sc = pose_scores(Mv, samples, poses)
    return poses[int(np.argmax(sc))].copy()


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
