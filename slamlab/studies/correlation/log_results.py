"""The result of :func:`~slamlab.studies.correlation.run_log_localisation` (004 §7 + ours): correlation localisation
along a CARMEN log with corrected poses, and its tables (per scan, success rates, ambiguity, the truth check's
failures and the score's terms).

Split from :mod:`slamlab.studies.correlation.log_experiments` (which runs the localisation) unchanged.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import as_vector, check_int
from ...correlation.algorithm import LocaliseParams
from ...geometry import wrap_angle
from ...scans import GridFrame
from ._log_scan import TRUTH_COLUMNS, VOTE_SCANS, check_unit
from .studies import FAIL_CELLS, FAIL_DEG, MIN_COVERAGE, within_tolerance
from .terms import TERM_NAMES

__all__ = ["LogLocalisationResult"]


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
    coverage : numpy.ndarray, shape (n,), optional
        Per scan, the share of its end points within :data:`~slamlab.studies.correlation.studies.COVERAGE_RADIUS_CELLS`
        of an obstacle cell of its leave-out grid at the logged pose (:func:`~slamlab.scans.map_coverage`; ours);
        :attr:`covered` applies :attr:`min_coverage`.
    min_coverage : float
        The share at or above which a scan is covered (default
        :data:`~slamlab.studies.correlation.studies.MIN_COVERAGE`).
    pose_check : pandas.DataFrame, optional
        Per scan, is its logged pose consistent with its neighbours' scans?
        (:func:`~slamlab.studies.correlation.logged_pose_check`: ``move_m``, ``turn_deg``, ``doubtful``, …).
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
    coverage: np.ndarray | None = field(default=None, repr=False)  # (n,) end points near the leave-out map's walls
    min_coverage: float = MIN_COVERAGE
    pose_check: object = field(default=None, repr=False, compare=False)  # pandas.DataFrame of logged_pose_check

    @property
    def covered(self) -> np.ndarray:
        """``(n,)``: scans whose :attr:`coverage` is at least :attr:`min_coverage` (all, when not recorded)."""
        if self.coverage is None:
            return np.ones(self.scan_indices.size, dtype=bool)
        return self.coverage >= self.min_coverage

    @property
    def success(self) -> np.ndarray:
        """``(modes, n)``: within 2 cells and 5° of the logged pose."""
        return within_tolerance(self.err_pos_m, self.err_heading_rad, self.cell_m)

    def flagged(self, min_votes: int = 2) -> np.ndarray:
        """``(modes, n)``: answers fewer than ``min_votes`` of the three single-scan voters agree with (ours; needs
        ``votes=True``).

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
        rows = [[int(r.scan), int(r.joined), f"{r.err_m:.2f}", f"{r.err_deg:.1f}",
                 f"{r.score_est:.0f}", f"{r.score_truth:.0f}", f"{r.score_truth - r.score_est:+.0f}",
                 f"{r.score_est_fine:.0f}", f"{r.score_truth_fine:.0f}", f"{r.walls_truth:.2f}", f"{r.walls_est:.2f}", r.kind]
                for r in d.itertuples()]
        title = "\n".join([
            f"{self.name}: failures; scores at the estimate (est.) and at the best grid pose within {FAIL_CELLS:g} cells",
            f"and {FAIL_DEG:g}° of the logged pose (truth), their difference (diff = truth - est.), and the same off the",
            "grid (fine: every 0.5 cell and 0.5°); walls = fraction of end points on obstacle cells of the leave-out grid;",
            "scans: 1 alone, or joined by odometry"])
        return format_table(["scan", "scans", "err [m]", "err [°]", "est.", "truth", "diff", "est. fine",
                             "truth fine", "walls truth", "walls est.", "kind"], rows, title=title)

    def terms_table(self, scans=None) -> str:
        """The score's four terms (:func:`~slamlab.studies.correlation.score_terms`) and marks on unexplored cells at
        the estimate and at the best grid pose near the truth, and their difference (ours;
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
            A legend, then per case a table (rows: the estimate, the truth, truth - est.; columns: the score, its
            four terms and the counts of marks) and the origin of the truth's marks in notes under it.
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
        head = ["pose", "score", "obs/obs", "obs/free", "free/free", "free/obs", "obs/unex.", "free/unex.",
                "obs. marks"]
        blocks = ["\n".join([
            (f"{self.name}: the score's terms (a_c = {self.params.a_c:g}, a_p = {self.params.a_p:g}) at the estimate and "
            f"at the best"),
            (f"grid pose within {FAIL_CELLS:g} cells and {FAIL_DEG:g}° of the logged pose (truth); score = the four "
            "signed terms mark/map:"),
            ("obs/obs = the stamp's obstacle marks on map obstacles, obs/free = on map free cells, free/free and "
            "free/obs"),
            (f"the same for its free marks; unex. = marks on unexplored cells of the leave-out grid "
            f"({self.leave_out_text} left out),"),
            "which count 0; obs. marks = all the stamp's obstacle marks"])]
        for r, case in cases:
            vals = {}
            for who in ("est", "truth"):
                vals[who] = [r[f"{who}_{t}"] for t in TERM_NAMES] + [r[f"{who}_n_obs_unexplored"],
                                                                      r[f"{who}_n_free_unexplored"]]
                n_obs = r[f"{who}_n_obs_on_obs"] + r[f"{who}_n_obs_on_free"] + r[f"{who}_n_obs_unexplored"]
                vals[who].append(n_obs)
            score = {"est": r["score_est"], "truth": r["score_truth"]}
            rows = [[label, f"{score[who]:.0f}", *(f"{x:+.0f}" for x in vals[who][:4]),
                     *(f"{x:.0f}" for x in vals[who][4:])]
                    for who, label in (("est", "estimate"), ("truth", "truth"))]
            diff = [vals["truth"][i] - vals["est"][i] for i in range(7)]
            rows.append(["truth - est.", f"{score['truth'] - score['est']:+.0f}", *(f"{x:+.0f}" for x in diff)])
            origin = {what: " / ".join(str(int(r[f"{what}_{w}"])) for w in ("1", "2", "none"))
                      for what in ("unex_obs", "unex_free", "conf_obs")}
            notes = "\n".join([
                "origin of the truth's marks (a left-out scan 1 step away saw the cell / 2 steps away / no other scan):",
                (f"  obstacle marks on unexplored cells {origin['unex_obs']}; free marks on unexplored cells "
                f"{origin['unex_free']};"),
                f"  obstacle marks on map free cells (a scan that many steps away hit the cell) {origin['conf_obs']}"])
            blocks.append(format_table(head, rows, title=(f"scan {int(r['scan'])}, {self.mode_name(int(r['joined']))}: "
                                                          f"{case}, {r['err_m']:.1f} m and {r['err_deg']:.0f}° off"))
                          + "\n" + notes)
        return "\n".join(blocks)

    def __str__(self) -> str:
        ok = self.success
        rates = ", ".join(f"{ok[m].sum()}/{ok.shape[1]} ({k} scan{'s' if k > 1 else ''})"
                          for m, k in enumerate(self.joined))
        return f"{self.name}: localised (within {FAIL_CELLS * self.cell_m:.1f} m and {FAIL_DEG:g}°, no prior): {rates}"

    def _title(self) -> str:
        return (f"{self.name} (CARMEN, logged laser poses): grid {self.grid.shape[0]}x{self.grid.shape[1]} cells of "
                f"{self.cell_m:g} m\nfrom the other scans ({self.leave_out_text} left out), ranges < "
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
            head += ["x est", "y est", "θ est", "err [m]", "err [°]", "amb.", "ok"] if one else \
                [f"m ({k})", f"° ({k})", f"A ({k})", "ok"]
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
        modes = "" if one else ("\nper mode (k): position error [m], heading error [°], ambiguity A, success;\nmodes "
                                + ", ".join(f"({k}) {self.mode_name(k)}" for k in self.joined))
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
                 f"{FAIL_CELLS * self.cell_m:.1f} m ({FAIL_CELLS:g} cells)\nand {FAIL_DEG:g}° of the logged pose; "
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
        t = check_unit(threshold, "threshold")
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
                 "away,\nbase = median of the headings' best scores; scans per bin")
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
