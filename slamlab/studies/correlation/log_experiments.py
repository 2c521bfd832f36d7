"""Ch. 5 experiments (004 §7) on real data: correlation localisation along a CARMEN log with corrected poses.

Part of the chapter's experiments (:mod:`slamlab.studies.correlation.experiments` holds the simulated ones;
:mod:`slamlab.studies.correlation.carmen_logs` the logs). The run and its result live here: the per-scan task
(leave-out grids, joined localisation, votes, the truth check) runs on :func:`slamlab.sweep.sweep`, and
:class:`LogLocalisationResult` tabulates its columns.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_finite_array, as_rng, as_vector, check_int, check_positive
from ...correlation.algorithm import LocaliseParams, heading_candidates, heading_error
from ...correlation.settings import check_score_norm
from ...geometry import wrap_angle
from ...scans import GridFrame
from ...scans.logmap import log_counts
from ._log_scan import TRUTH_COLUMNS, VOTE_SCANS, check_leave, localise_log_scan, log_points
from .carmen_logs import as_carmen_log
from .studies import FAIL_CELLS, FAIL_DEG, within_tolerance
from .terms import TERM_NAMES

__all__ = [
    "ODOM_STD",
    "LogLocalisationResult",
    "run_log_localisation",
]


def _check_unit(x, name: str) -> float:
    """A number in [0, 1], named ``name`` in the error."""
    x = check_positive(x, name, allow_zero=True)
    if x > 1:
        raise ValueError(f"`{name}` must lie in [0, 1]; got {x}")
    return x


#: Default odometry noise of the joined modes: σ_xy [m], σ_θ [rad] per step between consecutive scans (ours).
ODOM_STD = (0.05, float(np.radians(1.0)))


@dataclass(frozen=True)
class LogLocalisationResult:
    """Correlation localisation of scans of a CARMEN log on grids built from its logged poses (real data).

    Arrays with a leading ``modes`` axis hold one row per mode: ``joined[m]`` consecutive scans
    (1 = one scan, 004's method; 2 or 3 = joined by odometry, ours).

    Attributes
    ----------
    name : str
        The log's file name.
    scan_indices : numpy.ndarray of int, shape (n,)
        The localised scans.
    true_poses_m : numpy.ndarray, shape (n, 3)
        Logged poses ``(x_m, y_m, theta_rad)``.
    est_poses_m : numpy.ndarray, shape (modes, n, 3)
        Estimated poses.
    err_pos_m : numpy.ndarray, shape (modes, n)
        Position errors [m].
    err_heading_rad : numpy.ndarray, shape (modes, n)
        Wrapped heading errors [rad].
    ambiguity : numpy.ndarray, shape (modes, n)
        :attr:`Localisation.ambiguity` of each localisation.
    margin : numpy.ndarray, shape (modes, n), optional
        :attr:`Localisation.margin` of each localisation (None: not recorded).
    truth : dict of str to numpy.ndarray, shape (modes, n), optional
        The truth check's scores and wall fractions (``run_log_localisation(truth_check=True)``; None: not run);
        :meth:`~slamlab.studies.correlation.LogLocalisationResult.truth_check` tabulates them.
    cell_m : float
        Grid cell size [m].
    max_range_m : float
        Range limit of the scans used [m].
    exclude : int or None
        Scans on either side of a test scan left out of its grid (None with ``leave_out="used"``).
    grid : numpy.ndarray of int, shape (H, W)
        The whole log's grid.
    frame : GridFrame
        Metric frame of ``grid``.
    joined : tuple of int
        Scans joined per mode.
    odom_std : tuple of float
        ``(σ_xy [m], σ_θ [rad])`` of the simulated odometry per step.
    example_points_m : numpy.ndarray, shape (k, 2)
        The first scan's returns drawn at its mode-0 estimate [m].
    params : LocaliseParams
        Settings of the localisations.
    time_s : float
        Wall time [s] (not compared).
    leave_out : {"window", "used"}
        Which scans each test scan's grid lacks (:func:`~slamlab.studies.correlation.run_log_localisation`).
    votes : numpy.ndarray of int, shape (modes, n), optional
        Per answer, how many of the single-scan localisations of scans i, i-1, i-2 agree with it
        (``run_log_localisation(votes=True)``; None: not run); :meth:`flagged` marks those with fewer than 2.
    """

    name: str  # the log's file name
    scan_indices: np.ndarray
    true_poses_m: np.ndarray  # (n, 3) logged poses
    est_poses_m: np.ndarray  # (modes, n, 3)
    err_pos_m: np.ndarray  # (modes, n)
    err_heading_rad: np.ndarray  # (modes, n)
    ambiguity: np.ndarray  # (modes, n) Localisation.ambiguity
    cell_m: float
    max_range_m: float
    exclude: int | None
    grid: np.ndarray = field(repr=False)  # the whole log's grid (each scan is localised on it minus leave-out scans)
    frame: GridFrame = field(repr=False)
    joined: tuple[int, ...] = (1,)
    odom_std: tuple[float, float] = (0.0, 0.0)  # (m, rad) per step between consecutive scans
    example_points_m: np.ndarray = field(default=None, repr=False)  # the first scan drawn at its estimate (mode 0)
    params: LocaliseParams = field(default_factory=LocaliseParams, repr=False)
    time_s: float = field(default=0.0, compare=False)
    margin: np.ndarray | None = field(default=None, repr=False)  # (modes, n) Localisation.margin
    truth: dict | None = field(default=None, repr=False, compare=False)  # truth_check=True: _TRUTH_COLUMNS
    leave_out: str = "window"  # "window": ±exclude scans; "used": each mode's own scans
    votes: np.ndarray | None = field(default=None, repr=False)  # (modes, n) votes=True: agreeing single scans

    @property
    def success(self) -> np.ndarray:
        """``(modes, n)``: within 2 cells and 5° of the logged pose."""
        return within_tolerance(self.err_pos_m, self.err_heading_rad, self.cell_m)

    def flagged(self, min_votes: int = 2) -> np.ndarray:
        """``(modes, n)``: answers fewer than ``min_votes`` of the three single-scan voters agree with (ours, issue
        25; needs ``votes=True``).

        Parameters
        ----------
        min_votes : int, default 2
            Votes an answer needs not to be flagged (2: a majority of scans i, i-1, i-2), in 0..3.

        Returns
        -------
        numpy.ndarray of bool
        """
        t = check_int(min_votes, "min_votes", minimum=0)
        if t > VOTE_SCANS:
            raise ValueError(f"`min_votes` must lie in 0..{VOTE_SCANS}; got {t}")
        if self.votes is None:
            raise ValueError("this result has no votes: run run_log_localisation(..., votes=True)")
        return self.votes < t

    def mode_name(self, k: int) -> str:
        """The name of mode ``k`` in the tables: ``"1 scan"`` or ``"k scans + odometry"``.

        Parameters
        ----------
        k : int
            Scans joined (one of :attr:`joined`).

        Returns
        -------
        str
        """
        return "1 scan" if k == 1 else f"{k} scans + odometry"

    @property
    def leave_out_text(self) -> str:
        """What each test scan's grid lacks, in words: ``"±2 scans"`` or ``"each mode's own scans"``."""
        if self.leave_out == "used":
            return "each mode's own scans"
        return f"±{self.exclude} scans"

    def truth_check(self):
        """Per scan and mode: is a failure a score failure or a search failure? (ours, issue 25)

        Needs a run with ``truth_check=True``. Scores are the search's own (same grid, headings, stamps and
        constants), by the definition in float64. ``kind`` of a failure:

        - ``"score"``: the best grid pose within the success tolerance (2 cells, 5°) of the logged pose
          scores lower than the estimate, and so does the best pose off the grid (every 0.5 cell and
          0.5°) within that tolerance, compared with the best one around the estimate: the score prefers
          the wrong pose, no search over it finds the truth;
        - ``"search"``: a grid pose within the tolerance scores at least as high as the estimate (the search
          missed it);
        - ``"grid"``: only off the grid does the truth's neighbourhood score higher than the estimate's (a
          finer search could find it).

        Returns
        -------
        pandas.DataFrame
            One row per mode and scan: ``scan``, ``joined``, ``ok``, ``err_m``, ``err_deg``, the scores
            ``score_est``, ``score_truth`` (grid) and ``score_est_fine``, ``score_truth_fine`` (off the grid;
            NaN for a success), ``walls_truth`` / ``walls_est`` (fraction of the joined scans' end points on
            obstacle cells of the scan's leave-out grid at the logged poses / at the estimate), ``kind``
            (``"ok"`` for a success), and the columns of :meth:`terms_table`.
        """
        import pandas as pd

        if self.truth is None:
            raise ValueError("this result has no truth check: run run_log_localisation(..., truth_check=True)")
        rows = []
        for m, k in enumerate(self.joined):
            for j, i in enumerate(self.scan_indices):
                t = {c: float(self.truth[c][m, j]) for c in TRUTH_COLUMNS}
                ok = bool(self.success[m, j])
                if ok:
                    kind = "ok"
                elif t["score_truth"] >= t["score_est"]:
                    kind = "search"
                elif t["score_truth_fine"] > t["score_est_fine"]:
                    kind = "grid"
                else:
                    kind = "score"
                rows.append({"scan": int(i), "joined": k, "ok": ok, "err_m": float(self.err_pos_m[m, j]),
                             "err_deg": float(np.degrees(self.err_heading_rad[m, j])), **t, "kind": kind})
        return pd.DataFrame(rows)

    def failure_table(self) -> str:
        """The failures of :meth:`~slamlab.studies.correlation.LogLocalisationResult.truth_check`: errors, scores at the
        estimate and near the truth, wall fractions.

        Returns
        -------
        str
        """
        d = self.truth_check()
        d = d[~d["ok"]]
        rows = [[int(r.scan), self.mode_name(int(r.joined)), f"{r.err_m:.2f}", f"{r.err_deg:.1f}",
                 f"{r.score_est:.0f}", f"{r.score_truth:.0f}", f"{r.score_truth - r.score_est:+.0f}",
                 f"{r.score_est_fine:.0f}", f"{r.score_truth_fine:.0f}", f"{r.walls_truth:.2f}", f"{r.walls_est:.2f}", r.kind]
                for r in d.itertuples()]
        return format_table(["scan", "mode", "err [m]", "err [°]", "score est.", "truth (grid)", "truth - est.",
                             "est. fine", "truth fine", "walls at truth", "walls at est.", "kind"], rows,
                            title=(f"{self.name}: failures, the search's score at its estimate and the best within "
                                   f"{FAIL_CELLS:g} cells and {FAIL_DEG:g}° of the logged pose (grid; fine = every "
                                   "0.5 cell and 0.5°); walls = end points on obstacle cells of the leave-out grid"))

    def terms_table(self, scans=None) -> str:
        """The score's four terms (:func:`~slamlab.studies.correlation.score_terms`) and marks on unexplored cells at
        the estimate and at the best grid pose near the truth, and their difference (ours, issue 25;
        ``truth_check=True``; columns ``est_…`` / ``truth_…`` of :meth:`truth_check`); for the truth also where its
        marks on unexplored cells and its obstacle marks on map free cells come from (``unex_…``, ``conf_obs_…``:
        ``1`` / ``2`` = a left-out scan that many steps away saw / hit the cell, ``none`` = no other scan).

        Parameters
        ----------
        scans : sequence of int, optional
            The scans to show; default every failure and per mode the success with the median wall fraction.

        Returns
        -------
        str
        """
        d = self.truth_check()
        cases = []
        for k in self.joined:
            dk = d[d["joined"] == k]
            sel = dk[~dk["ok"]] if scans is None else dk[dk["scan"].isin(list(scans))]
            cases += [(r, "failure" if not r.ok else "success") for _i, r in sel.iterrows()]
            med = _median_success(dk)
            if scans is None and med is not None:
                cases.append((med, "median success"))
        rows = []
        for r, case in cases:
            vals = {}
            for who in ("est", "truth"):
                vals[who] = [r[f"{who}_{t}"] for t in TERM_NAMES] + [r[f"{who}_n_obs_unexplored"],
                                                                      r[f"{who}_n_free_unexplored"]]
                n_obs = r[f"{who}_n_obs_on_obs"] + r[f"{who}_n_obs_on_free"] + r[f"{who}_n_obs_unexplored"]
                vals[who].append(n_obs)
            score = {"est": r["score_est"], "truth": r["score_truth"]}
            head = [int(r["scan"]), self.mode_name(int(r["joined"])), case, f"{r['err_m']:.1f} m {r['err_deg']:.0f}°"]
            origin = "; ".join(" / ".join(str(int(r[f"{what}_{w}"])) for w in ("1", "2", "none"))
                               for what in ("unex_obs", "unex_free", "conf_obs"))
            for who, label in (("est", "estimate"), ("truth", "truth (best near)")):
                rows.append([*head, label, f"{score[who]:.0f}", *(f"{x:+.0f}" for x in vals[who][:4]),
                             *(f"{x:.0f}" for x in vals[who][4:]), origin if who == "truth" else ""])
            diff = [vals["truth"][i] - vals["est"][i] for i in range(7)]
            rows.append([*head, "truth - est.", f"{score['truth'] - score['est']:+.0f}", *(f"{x:+.0f}" for x in diff),
                         ""])
        return format_table(["scan", "mode", "case", "error", "pose", "score", "obs. on obs.", "obs. on free",
                             "free on free", "free on obs.", "obs. marks unexpl.", "free marks unexpl.", "obs. marks",
                             "origin ±1 / ±2 / none: unexpl. obs.; unexpl. free; obs. on free"], rows,
                            title=(f"{self.name}: the score's terms (a_c = {self.params.a_c:g}, "
                                   f"a_p = {self.params.a_p:g}; score = the four signed terms) at the estimate and at "
                                   f"the best grid pose within {FAIL_CELLS:g} cells and {FAIL_DEG:g}° of the "
                                   "logged pose; unexpl. = on unexplored cells of the leave-out grid "
                                   f"({self.leave_out_text} left out), which count 0; origin: the truth's obstacle and "
                                   "free marks on unexplored cells that a left-out scan 1 or 2 steps away saw (the "
                                   "leave-out removed them) or no other scan saw, and its obstacle marks on map free "
                                   "cells that such a scan hit"))

    def __str__(self) -> str:
        ok = self.success
        rates = ", ".join(f"{self.mode_name(k)} {ok[m].sum()}/{ok.shape[1]}" for m, k in enumerate(self.joined))
        return (f"{self.name}: scans localised within {FAIL_CELLS * self.cell_m:.1f} m and {FAIL_DEG:g}° "
                f"from no prior: {rates}")

    def _title(self) -> str:
        return (f"{self.name} (CARMEN, logged laser poses): grid {self.grid.shape[0]}x{self.grid.shape[1]} cells of "
                f"{self.cell_m:g} m from the other scans ({self.leave_out_text} left out), ranges < "
                f"{self.max_range_m:g} m, Δα = {np.degrees(self.params.delta_alpha_rad):g}°, no prior")

    def table(self) -> str:
        """One row per scan: the logged pose, then per mode the error, the ambiguity and success (the estimate too
        when there is one mode).

        Returns
        -------
        str
        """
        one = len(self.joined) == 1
        head = ["scan", "x [m]", "y [m]", "θ [°]"]
        for k in self.joined:
            tag = "" if one else f" ({k})"
            head += (["x est", "y est", "θ est"] if one else []) + [f"err [m]{tag}", f"err [°]{tag}", f"amb.{tag}",
                                                                    f"ok{tag}"]
        rows = []
        for j, (i, t) in enumerate(zip(self.scan_indices, self.true_poses_m, strict=True)):
            row = [int(i), f"{t[0]:.2f}", f"{t[1]:.2f}", f"{np.degrees(wrap_angle(t[2])):.1f}"]
            for m in range(len(self.joined)):
                e = self.est_poses_m[m, j]
                if one:
                    row += [f"{e[0]:.2f}", f"{e[1]:.2f}", f"{np.degrees(wrap_angle(e[2])):.1f}"]
                row += [f"{self.err_pos_m[m, j]:.2f}", f"{np.degrees(self.err_heading_rad[m, j]):.1f}",
                        f"{self.ambiguity[m, j]:.3f}", "yes" if self.success[m, j] else "NO"]
            rows.append(row)
        modes = "" if one else "; modes " + ", ".join(f"({k}) {self.mode_name(k)}" for k in self.joined)
        return format_table(head, rows, title=self._title() + modes)

    def summary_table(self) -> str:
        """Success rate per mode (success: within 2 cells and 5° of the logged pose).

        Returns
        -------
        str
        """
        ok = self.success
        rows = [[self.mode_name(k), f"{ok[m].sum()}/{ok.shape[1]}", f"{ok[m].mean():.1%}",
                 f"{np.median(self.err_pos_m[m][ok[m]]) if ok[m].any() else float('nan'):.3f}",
                 f"{np.median(np.degrees(self.err_heading_rad[m][ok[m]])) if ok[m].any() else float('nan'):.2f}"]
                for m, k in enumerate(self.joined)]
        sx, sa = self.odom_std
        title = (f"{self.name}: {ok.shape[1]} scans ({_describe(self.scan_indices)}), success = within "
                 f"{FAIL_CELLS * self.cell_m:.1f} m ({FAIL_CELLS:g} cells) and {FAIL_DEG:g}° of the logged pose; "
                 f"odometry noise σ = {sx:g} m, {np.degrees(sa):g}° per step")
        return format_table(["mode", "localised", "rate", "median err [m]", "median err [°]"], rows, title=title)

    def ambiguity_table(self, bins=(0.0, 0.5, 0.75, 0.9, 1.0), threshold: float = 0.75) -> str:
        """How well the ambiguity separates failures from successes: counts per bin and flag rates at ``threshold``.

        A scan is *flagged* when its ambiguity is at least ``threshold``; the table gives the fraction of
        failures flagged (caught) and of successes flagged (false alarms), per mode.

        Parameters
        ----------
        bins : sequence of float
            Bin edges of the ambiguity in [0, 1].
        threshold : float, default 0.75
            Ambiguity at or above which a scan is flagged.

        Returns
        -------
        str
        """
        b = as_vector(bins, "bins")
        if b.size < 2 or np.any(np.diff(b) <= 0):
            raise ValueError(f"`bins` must be at least two increasing edges; got {bins!r}")
        t = _check_unit(threshold, "threshold")
        head = ["mode", "outcome"] + [f"[{lo:g}, {hi:g}{']' if q == b.size - 2 else ')'}"
                                      for q, (lo, hi) in enumerate(itertools.pairwise(b))]
        head += [f"flagged (>= {t:g})"]
        rows = []
        for m, k in enumerate(self.joined):
            a, ok = self.ambiguity[m], self.success[m]
            for label, sel in (("success", ok), ("failure", ~ok)):
                idx = np.clip(np.searchsorted(b, a[sel], side="right") - 1, 0, b.size - 2)
                counts = np.bincount(idx, minlength=b.size - 1)
                flag = f"{np.sum(a[sel] >= t)}/{sel.sum()}"
                rows.append([self.mode_name(k), label, *(str(c) for c in counts), flag])
        title = (f"Ambiguity = (rival - base) / (best - base), rival = best score of a pose > "
                 f"{self.params.rival_radius_cells * self.cell_m:g} m or > {np.degrees(self.params.rival_heading_rad):g}° "
                 "away, base = median of the headings' best scores; scans per bin")
        return format_table(head, rows, title=title)


def _describe(idx) -> str:
    """The scans of a run in words, for the tables' titles."""
    d = np.diff(idx)
    if idx.size > 2 and np.all(d == d[0]):
        return f"every {int(d[0])}th from {int(idx[0])} to {int(idx[-1])}"
    return "scans " + ", ".join(str(int(i)) for i in idx)


def _median_success(d):
    """The row of ``d`` (one mode's :meth:`truth_check` rows) that is the success with the median wall fraction
    at the truth (the lower middle one; first scan on ties); None without a success."""
    ok = d[d["ok"]]
    if ok.empty:
        return None
    order = ok.sort_values(["walls_truth", "scan"], kind="stable")
    return order.iloc[(len(order) - 1) // 2]


def run_log_localisation(path=None, scan_indices=(50, 150, 250, 350, 450, 550, 650, 750, 850), *,
                         cell_m: float = 0.2, max_range_m: float = 10.0, exclude: int | None = None, joined=(1,),
                         odom_std=ODOM_STD, hit_ratio: float = 0.25, params: LocaliseParams | None = None, rng=2017,
                         n_jobs: int = 1, progress: bool | None = None, truth_check: bool = False,
                         refine: int = 0, refine_heading_rad: float = float(np.radians(3.0)),
                         score_norm: str = "none", min_explored_fraction: float = 0.8, leave_out: str = "window",
                         votes: bool = False, **overrides) -> LogLocalisationResult:
    """Localise scans of a CARMEN log on grids built from the log's own poses (real data; 004 §7 + ours).

    Each test scan is localised on the grid (``cell_m`` cells, 004's three values) of every
    scan of the log except ``±exclude`` scans around it (by default; see ``leave_out``), so a scan is never
    matched against cells it or its nearest neighbours drew (ours), from no prior (full 360°), and
    compared with its logged pose (SLAM-corrected in the Radish logs). A success is a pose
    within 2 cells and 5° of the logged one.

    Modes (``joined``): 1 = the scan alone (004's method); 2 or 3 = the scan and the 1 or 2
    scans before it joined by odometry (:func:`~slamlab.correlation.localise_joined`, ours).
    The corrected logs carry no raw odometry, so each step between consecutive scans is the
    logged relative pose plus Gaussian noise ``odom_std = (σ_xy [m], σ_θ [rad])``, drawn from ``rng`` once per
    step of the log, so a scan's joined odometry does not depend on which other scans are localised.
    Every result carries the ambiguity of :class:`~slamlab.correlation.Localisation`.

    Parameters
    ----------
    path : str, os.PathLike or CarmenLog, optional
        Any CARMEN log (plain or gzip); default the corrected Intel Research Lab log
        (``carmen-radish-corrected/intel-corrected.log.gz`` via :func:`slamlab.data.find_data`).
        Results are labelled with the file name.
    scan_indices : sequence of int
        The scans to localise (at least ``max(joined) - 1``: the joined scans come before).
    cell_m : float, default 0.2
        Grid cell size [m].
    max_range_m : float, default 10.0
        Returns farther than this are not used [m].
    exclude : int, optional
        Scans either side of each test scan left out of its grid (``"window"``; default 2, ``>= max(joined) - 1``).
        The real-log default (ours, issue 25): the scan and the 2 scans joined before it never draw its
        grid; the issue-17 runs left out ±10 (≈ ±10 m of path on the shared logs, whose scans are
        ≈ 1 m apart), which removed the map of places the robot passed once (csail, orebro:
        ``docs/benchmarks.md``, correlation section, the ablation table).
    joined : sequence of int in {1, ..., 5}
        The modes to run on the same scans (4 and 5: an issue-25 experiment, a longer baseline).
    odom_std : tuple of float
        ``(σ_xy [m], σ_θ [rad])`` of the noise added to each logged step (default ``ODOM_STD``, 0.05 m and 1°).
    hit_ratio : float, default 0.25
        A grid cell is an obstacle when its hits are at least ``hit_ratio`` times the beams that passed
        through it (:func:`~slamlab.scans.occupancy_grid`'s rule ``"count"``; 0: any hit), in [0, 1].
    params, **overrides
        :class:`LocaliseParams` of every localisation (``rival_radius_cells`` 5 = 1 m at 0.2 m cells).
    rng : int or numpy.random.Generator, default 2017
        Seed or generator of the odometry noise (one draw of ``n_scans × 3`` normals per call).
    n_jobs, progress
        The scans run on :func:`slamlab.sweep.sweep` (one task per scan; same result for any
        ``n_jobs``) with a progress bar unless ``progress=False`` or ``$SLAMLAB_PROGRESS=0``.
    truth_check : bool, default False
        Also score each scan near its logged pose with the search's own score (ours, issue 25): is a failure a
        score failure (the truth scores lower than the estimate) or a search failure?
        :meth:`~slamlab.studies.correlation.LogLocalisationResult.truth_check` tabulates it, ``terms_table()`` the
        score's terms. Needs ``a_n = 0`` (004's value).
    refine : int, default 0
        Off by default. ``refine`` > 0 (ours, issue 25): score the ``refine`` best distinct peaks of the grid
        search (more than 2 cells or 3° apart) again every 0.5 cell within 1 cell and every 0.5° within
        ``refine_heading_rad``,
        by the definition, and keep the best pose (against failures where the truth's neighbourhood scores
        higher than the estimate's only off the grid; ``docs/benchmarks.md``).
    refine_heading_rad : float, default 3°
        Half-width of the refinement's headings around each peak [rad] (3°: with 1°, intel scan 550 is lost,
        ``docs/benchmarks.md``; chosen on that one scan).
    score_norm : {"none", "explored"}, default "none"
        ``"explored"``: score per mark on an explored cell (:func:`~slamlab.correlation.localise`; ours, issue
        25); not with ``truth_check`` or ``refine`` (they score by the raw correlation).
    min_explored_fraction : float, default 0.8
        Its guard (:func:`~slamlab.correlation.localise`).
    leave_out : {"window", "used"}, default "window"
        ``"window"``: the ``±exclude`` scans, one grid for every mode. ``"used"`` (ours, issue 25): each mode's
        grid lacks exactly the scans it localises with (mode ``k``: scans ``i - k + 1 .. i``), so cells the
        scans after ``i`` drew may be in it; ``exclude`` must not be given.
    votes : bool, default False
        Also localise scans ``i - 1`` and ``i - 2`` alone (ours, issue 25), on a grid that lacks them and scan ``i``
        (with the ``±2`` window: the test scan's own grid), carry each answer to scan ``i`` by the same noisy
        odometry as the joined modes, and count per mode how many of these three single-scan answers (scans
        ``i, i-1, i-2``) lie within a success's tolerance of the mode's answer (``result.votes``; an answer with
        fewer than 2 is :meth:`~slamlab.studies.correlation.LogLocalisationResult.flagged`). The modes' answers are
        unchanged; about twice the single-scan work.

    Returns
    -------
    LogLocalisationResult
    """
    from ...sweep import sweep

    p = LocaliseParams.resolve(params, **overrides)
    log = as_carmen_log(path)
    cell = check_positive(cell_m, "cell_m")
    rmax = check_positive(max_range_m, "max_range_m")
    modes = tuple(int(k) for k in np.atleast_1d(np.asarray(joined)))
    if not modes or any(k not in (1, 2, 3, 4, 5) for k in modes) or len(set(modes)) != len(modes):
        raise ValueError(f"`joined` must be distinct numbers of scans from {{1, ..., 5}}; got {joined!r}")
    kmax = max(modes)
    lo, ex = check_leave(leave_out, exclude, kmax)
    hr = _check_unit(hit_ratio, "hit_ratio")
    for name, flag in (("truth_check", truth_check), ("votes", votes)):
        if not isinstance(flag, (bool, np.bool_)):
            raise TypeError(f"`{name}` must be a bool; got {type(flag).__name__}")
    rf = check_int(refine, "refine", minimum=0)
    rfh = check_positive(refine_heading_rad, "refine_heading_rad", allow_zero=True)
    if (truth_check or rf) and p.a_n != 0:
        raise ValueError(f"`truth_check` and `refine` score by the definition with a_n = 0 (004's value); got a_n = "
                         f"{p.a_n}")
    sn, frac = check_score_norm(score_norm, min_explored_fraction, p)
    if (truth_check or rf) and sn != "none":
        raise ValueError(f"`truth_check` and `refine` score by the raw correlation; got score_norm = {sn!r} (use "
                         f"'none')")
    sd = as_finite_array(odom_std, "odom_std")
    if sd.shape != (2,) or np.any(sd < 0):
        raise ValueError(f"`odom_std` must be (σ_xy_m, σ_θ_rad) >= 0; got {odom_std!r}")
    idx = np.asarray(scan_indices)
    if idx.ndim != 1 or idx.size == 0 or not np.issubdtype(idx.dtype, np.integer):
        raise ValueError(f"`scan_indices` must be a non-empty list of ints; got {scan_indices!r}")
    back = max(kmax, VOTE_SCANS) if votes else kmax  # scans read back from each test scan
    if idx.min() < back - 1 or idx.max() >= log.n_scans:
        raise ValueError(f"`scan_indices` must lie in [{back - 1}, {log.n_scans - 1}] (the {back - 1} scans before "
                         f"each are joined or vote); got {idx.min()}..{idx.max()}")
    rng = as_rng(rng)
    t0 = time.perf_counter()
    frame, scans_c, Pc, full = log_counts(log, cell_m=cell, max_range_m=rmax)
    scale = np.array([sd[0] / cell, sd[0] / cell, sd[1]])
    # one noise draw per step of the log (row m: scan m-1 -> m), so a scan's odometry is the same in any list
    steps = rng.normal(size=(log.n_scans, 3)) * scale
    noise = steps[idx[:, None] - np.arange(back - 1)[None, :]]  # (n, back - 1): steps i -> i-1, i-1 -> i-2, …
    points = log_points(idx, modes, scans_c, Pc, noise, lo, ex, votes=bool(votes))
    fixed = {"full": full, "scans_c": scans_c, "Pc": Pc, "p": p, "headings": heading_candidates(p.delta_alpha_rad),
             "joined": modes, "hit_ratio": hr, "truth_check": bool(truth_check),
             "refine": rf, "refine_heading_rad": rfh, "score_norm": sn, "min_explored_fraction": frac}
    table = sweep(localise_log_scan, points, rng_arg=None, n_jobs=n_jobs, progress=progress, fixed=fixed,
                  on_error="raise", desc="localise log scans")
    true_m = log.poses[idx]
    est_m = np.stack([frame.to_metres(table[[f"x{k}", f"y{k}", f"h{k}"]].to_numpy(dtype=float)) for k in modes])
    err_p = np.hypot(est_m[..., 0] - true_m[:, 0], est_m[..., 1] - true_m[:, 1])
    err_a = heading_error(est_m[..., 2], true_m[:, 2])
    amb = np.stack([table[f"amb{k}"].to_numpy(dtype=float) for k in modes])
    margin = np.stack([table[f"mar{k}"].to_numpy(dtype=float) for k in modes])
    example = log.scan(int(idx[0])).points(est_m[0, 0])
    truth = ({c: np.stack([table[f"{c}{k}"].to_numpy(dtype=float) for k in modes]) for c in TRUTH_COLUMNS}
             if truth_check else None)
    vote = np.stack([table[f"vote{k}"].to_numpy(dtype=int) for k in modes]) if votes else None
    return LogLocalisationResult(log.name, idx, true_m, est_m, err_p, err_a, amb, cell, rmax,
                                 ex if lo == "window" else None, full.grid, frame, modes,
                                 (float(sd[0]), float(sd[1])), example, p, time.perf_counter() - t0, margin, truth, lo,
                                 vote)
