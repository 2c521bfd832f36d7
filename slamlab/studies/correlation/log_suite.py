"""Ch. 5 on every shared CARMEN log (issue 25, ours): correlation localisation of every ``every``-th scan of each
corrected Radish log with one set of real-log defaults, and the per-log tables.

:func:`run_log_suite` runs :func:`~slamlab.studies.correlation.run_log_localisation` on each log with the same settings;
:class:`LogSuiteResult` prints the per-log success rates (:meth:`~LogSuiteResult.table`) and how well the
ambiguity, the margin and the neighbours' votes separate failures from successes
(:meth:`~LogSuiteResult.ambiguity_table`, :meth:`~LogSuiteResult.margin_table`, :meth:`~LogSuiteResult.votes_table`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ..._table import format_table
from ..._validate import check_int, check_positive
from ...correlation.settings import LocaliseParams
from ._log_scan import check_unit
from .carmen_logs import SHARED_CARMEN_LOGS, as_carmen_log, short_log_name
from .log_experiments import LogLocalisationResult, run_log_localisation
from .studies import COVERAGE_RADIUS_CELLS, FAIL_CELLS, FAIL_DEG

__all__ = ["GOAL", "LogSuiteResult", "goal_text", "more_confident", "run_log_suite"]

#: The correlation goal on real logs (ours): every ``every``-th scan of each log; of the covered scans, at least
#: ``single`` localised with one scan and ``joined`` with three joined by odometry, pooled over the logs, and at least
#: ``per_log`` with each on every log.
GOAL = {"every": 10, "single": 0.75, "joined": 0.90, "per_log": 2 / 3}


def goal_text() -> str:
    """:data:`GOAL` in words, as the chapter prints it.

    Returns
    -------
    str
    """
    return (f"goal: every {GOAL['every']}th scan of each log; of the covered scans >= {GOAL['single']:.0%} localised "
            f"with 1 scan\nand >= {GOAL['joined']:.0%} with 3, pooled over the logs, and >= {GOAL['per_log']:.1%} "
            f"with each on every log")

@dataclass(frozen=True)
class LogSuiteResult:
    """Correlation localisation on several CARMEN logs with the same settings (ours, issue 25).

    Attributes
    ----------
    results : tuple of LogLocalisationResult
        One result per log, in the order run.
    every : int
        Every ``every``-th scan was localised (from scan ``every``).
    """

    results: tuple[LogLocalisationResult, ...]
    every: int

    @property
    def names(self) -> tuple[str, ...]:
        """Short log names (``"intel"`` for ``intel-corrected.log.gz``)."""
        return tuple(short_log_name(r.name) for r in self.results)

    def rates(self) -> np.ndarray:
        """``(logs, modes)`` success rates over each log's covered scans (success: within 2 cells and 5° of the
        logged pose; covered: :attr:`~slamlab.studies.correlation.LogLocalisationResult.covered`; NaN for a log
        without a covered scan).

        Returns
        -------
        numpy.ndarray
        """
        return np.array([r.success[:, r.covered].mean(axis=1) if r.covered.any() else np.full(len(r.joined), np.nan)
                         for r in self.results])

    def table(self) -> str:
        """One row per log: scans, those not covered, then per mode the covered scans localised, the rate and the
        successes' median errors; the last row pools the logs.

        Returns
        -------
        str
        """
        r0 = self.results[0]
        head = ["log", "scans", "not covered"]
        for k in r0.joined:
            head += [f"{r0.mode_name(k)}", "rate", "med. err [m] / [°]"]
        rows = []
        for name, r in zip(self.names, self.results, strict=True):
            cov = r.covered
            ok = r.success[:, cov]
            row = [name, str(cov.size), str(int(np.sum(~cov)))]
            for m in range(len(r.joined)):
                s = ok[m]
                med = (f"{np.median(r.err_pos_m[m][cov][s]):.3f} / "
                       f"{np.median(np.degrees(r.err_heading_rad[m][cov][s])):.2f}" if s.any() else "-")
                row += [f"{s.sum()}/{s.size}", f"{s.mean():.1%}" if s.size else "-", med]
            rows.append(row)
        tot = np.concatenate([r.success[:, r.covered] for r in self.results], axis=1)
        n_all = sum(r.covered.size for r in self.results)
        rows.append(["all", str(n_all), str(n_all - tot.shape[1])]
                    + [c for m in range(tot.shape[0]) for c in (f"{tot[m].sum()}/{tot.shape[1]}",
                                                                 f"{tot[m].mean():.1%}", "")])
        title = (f"Every {self.every}th scan of each log from no prior; success = within {FAIL_CELLS:g} cells "
                 f"({FAIL_CELLS * r0.cell_m:.1f} m) and {FAIL_DEG:g}° of the logged pose;\ncells {r0.cell_m:g} m, "
                 f"ranges < {r0.max_range_m:g} m, {r0.leave_out_text} left out of each grid; rates over the covered "
                 f"scans")
        notes = (f"not covered: fewer than {r0.min_coverage:.0%} of the scan's end points within "
                 f"{COVERAGE_RADIUS_CELLS} cell of a wall\nof its leave-out grid at the logged pose")
        return format_table(head, rows, title=title) + "\n" + notes

    def coverage_table(self) -> str:
        """One row per scan not covered: its log, its coverage and whether each mode localised it anyway (such scans
        count towards no rate); a last row per log would repeat :meth:`table`'s "not covered" column.

        Returns
        -------
        str
        """
        r0 = self.results[0]
        rows = []
        for name, r in zip(self.names, self.results, strict=True):
            if r.coverage is None:
                continue
            for j in np.flatnonzero(~r.covered):
                rows.append([name, str(int(r.scan_indices[j])), f"{r.coverage[j]:.2f}",
                             *("yes" if ok else "no" for ok in r.success[:, j])])
        lowest = min((float(np.min(r.coverage)) for r in self.results if r.coverage is not None), default=np.nan)
        return format_table(["log", "scan", "coverage", *(f"{r0.mode_name(k)}: localised" for k in r0.joined)], rows,
                            title=(f"Scans not covered: fewer than {r0.min_coverage:.0%} of their end points within "
                                   f"{COVERAGE_RADIUS_CELLS} cell of a wall\nof their leave-out grid at the logged "
                                   f"pose ({len(rows)} scans; lowest coverage {lowest:.2f})"))

    def truth_table(self) -> str:
        """Per log: the logged poses its neighbours' scans doubt (:func:`~slamlab.studies.correlation.logged_pose_check`),
        the failures of each mode, and how many of those failures have a doubtful truth; then each failure with a
        doubtful truth.

        Returns
        -------
        str
        """
        r0 = self.results[0]
        rows, listed = [], []
        for name, r in zip(self.names, self.results, strict=True):
            if r.pose_check is None:
                raise ValueError("every result must carry its pose check (run by run_log_localisation)")
            doubt = r.pose_check["doubtful"].to_numpy(dtype=bool)
            fail = ~r.success
            rows.append([name, f"{int(doubt.sum())}/{doubt.size}",
                         *(f"{int(np.sum(fail[m] & doubt))}/{int(fail[m].sum())}" for m in range(len(r.joined)))])
            for j in np.flatnonzero(fail.any(axis=0) & doubt):
                c = r.pose_check.iloc[j]
                listed.append(f"{name} {int(r.scan_indices[j])}: moved {c['move_m']:.2f} m, {c['turn_deg']:.1f}°")
        out = format_table(["log", "doubtful logged poses", *(f"{r0.mode_name(k)}: failures doubtful" for k in
                                                               r0.joined)], rows,
                           title=("The logged poses: each scan aligned (ICP) to the scans just before and after it at "
                                  "their logged poses;\ndoubtful when the alignment moves it more than 0.2 m or "
                                  "2.5° (half the success tolerance)"))
        return out + ("\nfailures with a doubtful truth: " + "; ".join(listed) if listed else
                      "\nno failure has a doubtful truth")

    def meets_goal(self, single: float = GOAL["single"], joined: float = GOAL["joined"],
                   per_log: float = GOAL["per_log"], modes=(1, 3)) -> dict:
        """The correlation goal on covered scans: the rate of mode ``modes[0]`` at least ``single`` and of ``modes[1]``
        at least ``joined``, pooled over the logs, and both modes at least ``per_log`` on every log (ours).

        Parameters
        ----------
        single, joined : float
            Pooled rates the two modes must reach, in [0, 1].
        per_log : float, default 2/3
            Rate each mode must reach on every log, in [0, 1].
        modes : pair of int, default (1, 3)
            The modes (one scan, three scans joined by odometry).

        Returns
        -------
        dict
            ``{"pooled": (rate_a, rate_b), "lowest": (rate_a, rate_b), "met": bool}`` (rates over covered scans;
            ``lowest``: the lowest log's rate per mode).
        """
        for v, nm in ((single, "single"), (joined, "joined"), (per_log, "per_log")):
            check_unit(v, nm)
        a, b = _mode_pair(modes, self.results[0].joined)
        js = [self.results[0].joined.index(k) for k in (a, b)]
        tot = np.concatenate([r.success[:, r.covered] for r in self.results], axis=1)
        pooled = tuple(float(tot[j].mean()) for j in js)
        lowest = tuple(float(np.nanmin(self.rates()[:, j])) for j in js)
        met = pooled[0] >= single and pooled[1] >= joined and min(lowest) >= per_log
        return {"pooled": pooled, "lowest": lowest, "met": bool(met)}

    def goal_table(self, single: float = GOAL["single"], joined: float = GOAL["joined"],
                   per_log: float = GOAL["per_log"], modes=(1, 3)) -> str:
        """:meth:`meets_goal` as a table: per mode the pooled rate and the lowest log's, against the goal.

        Parameters
        ----------
        single, joined, per_log, modes
            As in :meth:`meets_goal`.

        Returns
        -------
        str
        """
        g = self.meets_goal(single, joined, per_log, modes)
        r0 = self.results[0]
        rates = self.rates()
        rows = []
        for j, (k, goal) in enumerate(zip(modes, (single, joined), strict=True)):
            m = r0.joined.index(k)
            low = int(np.nanargmin(rates[:, m]))
            every = np.concatenate([r.success[m] for r in self.results])
            rows.append([r0.mode_name(k), f"{g['pooled'][j]:.1%}", f">= {goal:.0%}",
                         f"{g['lowest'][j]:.1%} ({self.names[low]})", f">= {per_log:.1%}",
                         "yes" if g["pooled"][j] >= goal and g["lowest"][j] >= per_log else "no",
                         f"{every.sum()}/{every.size} ({every.mean():.1%})"])
        return format_table(["mode", "pooled", "goal", "lowest log", "goal", "met", "all scans, covered or not"], rows,
                            title="The goal on the covered scans: pooled over the logs, and on every log")

    def ambiguity_table(self, threshold: float = 0.75) -> str:
        """Per log and mode, then pooled over the logs: failures flagged (ambiguity ≥ ``threshold``) and
        successes flagged (false alarms).

        Parameters
        ----------
        threshold : float, default 0.75
            Ambiguity at or above which a localisation is flagged, in [0, 1].

        Returns
        -------
        str
        """
        t = check_positive(threshold, "threshold", allow_zero=True)
        if t > 1:
            raise ValueError(f"`threshold` must lie in [0, 1]; got {t}")
        return self._flag_table([r.ambiguity for r in self.results], lambda a: a >= t, f">= {t:g}", "ambiguity",
                                f"Ambiguity as a failure flag, threshold {t:g}")

    def margin_table(self, threshold: float = 1.2) -> str:
        """Per log and mode, then pooled over the logs: failures flagged (margin ≤ ``threshold``) and successes
        flagged (false alarms), with :attr:`~slamlab.correlation.Localisation.margin` (ours, issue 25).

        Parameters
        ----------
        threshold : float, default 1.2
            Margin at or below which a localisation is flagged, at least 0 (1.2: tuned on csail, orebro and
            seattle, ``docs/benchmarks.md``).

        Returns
        -------
        str
        """
        t = check_positive(threshold, "threshold", allow_zero=True)
        if any(r.margin is None for r in self.results):
            raise ValueError("every result must carry its margins (run by run_log_localisation)")
        return self._flag_table([r.margin for r in self.results], lambda a: a <= t, f"<= {t:g}", "margin",
                                f"Margin (best - rival) / sqrt(best - base) as a failure flag, threshold {t:g}")

    def votes_table(self, min_votes: int = 2) -> str:
        """Per log and mode, then pooled over the logs: failures flagged (fewer than ``min_votes`` of the single-scan
        localisations of scans i, i-1, i-2 agree with the answer) and successes flagged (ours, issue 25; needs
        ``votes=True``).

        Parameters
        ----------
        min_votes : int, default 2
            Votes an answer needs not to be flagged, in 0..3 (2: a majority).

        Returns
        -------
        str
        """
        for r in self.results:
            r.flagged(min_votes)  # checks min_votes, and that the votes were run
        return self._flag_table([r.votes for r in self.results], lambda a: a < min_votes, f"< {min_votes} votes",
                                "votes", f"Votes as a failure flag: scans i, i-1, i-2 localised alone and carried to "
                                f"scan i by odometry;\nflagged when fewer than {min_votes} agree (2 cells, 5°)")

    def confident_table(self, modes=(1, 3)) -> str:
        """Per log, then pooled: the scans localised by each of two modes, and by the more confident of their two
        answers per scan (:func:`more_confident`; ours, issue 25, an experiment: not a mode of
        :func:`~slamlab.studies.correlation.run_log_localisation`).

        Parameters
        ----------
        modes : pair of int, default (1, 3)
            Two of the results' modes (numbers of joined scans).

        Returns
        -------
        str
        """
        a, b = _mode_pair(modes, self.results[0].joined)
        rows, tot = [], np.zeros(3, dtype=int)
        for name, r in zip(self.names, self.results, strict=True):
            keep = more_confident(r, (a, b))
            ok = r.success[r.joined.index(a)], r.success[r.joined.index(b)]
            both = np.where(keep == a, ok[0], ok[1])
            counts = np.array([ok[0].sum(), ok[1].sum(), both.sum()])
            tot += counts
            rows.append([name, str(both.size), *(f"{c}/{both.size}" for c in counts), str(int(np.sum(keep == a)))])
        n = sum(r.success.shape[1] for r in self.results)
        rows.append(["all", str(n), *(f"{c}/{n}" for c in tot), ""])
        r0 = self.results[0]
        return format_table(["log", "scans", r0.mode_name(a), r0.mode_name(b), "more confident of the two",
                             f"answers kept from {r0.mode_name(a)}"], rows,
                            title=(f"Per scan the answer with the larger margin ({r0.mode_name(a)} or "
                                   f"{r0.mode_name(b)}; a tie keeps {r0.mode_name(b)}); {r0.leave_out_text} left out "
                                   "of each grid"))

    def _flag_table(self, values, flag, rule: str, short: str, title: str) -> str:
        """Rows per log and mode, then pooled: failures and successes ``flag``-ged, and their median ``values``."""
        def row(name, mode, a, ok):
            f = flag(a)
            return [name, mode, f"{np.sum(f[~ok])}/{np.sum(~ok)}", f"{np.sum(f[ok])}/{ok.sum()}",
                    f"{np.median(a[~ok]):.2f}" if (~ok).any() else "-", f"{np.median(a[ok]):.2f}" if ok.any() else "-"]

        rows = [row(name, r.mode_name(k), a[m], r.success[m])
                for name, r, a in zip(self.names, self.results, values, strict=True) for m, k in enumerate(r.joined)]
        for m, k in enumerate(self.results[0].joined):  # pooled over the logs
            rows.append(row("all", self.results[0].mode_name(k), np.concatenate([a[m] for a in values]),
                            np.concatenate([r.success[m] for r in self.results])))
        return format_table(["log", "mode", f"failures flagged ({rule})", "successes flagged",
                             "median (failures)", "median (successes)"], rows,
                            title=f"{title}; medians of the {short}")

    def failure_table(self) -> str:
        """Per log and mode: the failures by kind of :meth:`~slamlab.studies.correlation.LogLocalisationResult.truth_check`
        (score failure, search failure, off the grid) and the score failures' fraction of end points on walls at
        the truth (ours, issue 25; needs ``truth_check=True``).

        Returns
        -------
        str
        """
        rows = []
        for name, r in zip(self.names, self.results, strict=True):
            d = r.truth_check()
            for k in r.joined:
                dk = d[d["joined"] == k]
                fail = dk[~dk["ok"]]
                sc = fail[fail["kind"] == "score"]
                rows.append([name, r.mode_name(k), f"{len(fail)}/{len(dk)}", str(int((fail["kind"] == "score").sum())),
                             str(int((fail["kind"] == "search").sum())), str(int((fail["kind"] == "grid").sum())),
                             ", ".join(f"{s}: {w:.2f}" for s, w in zip(sc["scan"], sc["walls_truth"], strict=True))
                             or "-",
                             f"{np.median(dk[dk['ok']]['walls_truth']):.2f}" if dk["ok"].any() else "-"])
        return format_table(["log", "mode", "failures", "score", "search", "grid", "score failures: walls at truth",
                             "successes: median walls"], rows,
                            title=("Failures by kind: score = the logged pose's neighbourhood (2 cells, 5°) scores "
                                   "lower than the estimate on the grid and off it (0.5 cell, 0.5°); search = a grid "
                                   "pose near the truth scores at least as high; grid = only off the grid; walls = "
                                   "fraction of end points at the logged poses on obstacle cells of the leave-out "
                                   "grid"))

    def __str__(self) -> str:
        rates = "; ".join(f"{n} " + ", ".join(f"{ok.sum()}/{ok.size}" for ok in r.success)
                          for n, r in zip(self.names, self.results, strict=True))
        return f"{len(self.results)} logs, every {self.every}th scan, localised per mode: {rates}"


def _mode_pair(modes, joined) -> tuple[int, int]:
    """``modes`` checked: two distinct modes of ``joined``."""
    pair = tuple(np.atleast_1d(np.asarray(modes)).tolist())
    if len(pair) != 2 or pair[0] == pair[1] or any(k not in joined for k in pair):
        raise ValueError(f"`modes` must be two distinct modes of the run {tuple(joined)}; got {modes!r}")
    return int(pair[0]), int(pair[1])


def more_confident(result: LogLocalisationResult, modes=(1, 3)) -> np.ndarray:
    """Per scan, which of two modes' answers has the larger margin (ours, issue 25; an experiment).

    :attr:`~slamlab.correlation.Localisation.margin` measures how far the peak leads its rival; keeping, per
    scan, the answer that leads by more is one way to use two modes together (``docs/benchmarks.md``, "the more
    confident of the 1-scan and 3-scan answers"). A tie keeps the second mode's answer.

    Parameters
    ----------
    result : LogLocalisationResult
        A run with both modes (:func:`~slamlab.studies.correlation.run_log_localisation`).
    modes : pair of int, default (1, 3)
        The two modes (numbers of joined scans).

    Returns
    -------
    numpy.ndarray of int, shape (n,)
        The mode whose answer is kept, per scan.
    """
    if not isinstance(result, LogLocalisationResult):
        raise TypeError(f"`result` must be a LogLocalisationResult; got {type(result).__name__}")
    a, b = _mode_pair(modes, result.joined)
    if result.margin is None:
        raise ValueError("`result` carries no margins (run it with run_log_localisation)")
    ma, mb = result.margin[result.joined.index(a)], result.margin[result.joined.index(b)]
    return np.where(ma > mb, a, b)


def run_log_suite(paths=None, every: int = 25, *, joined=(1, 2, 3), params: LocaliseParams | None = None, rng=2017,
                  n_jobs: int = 1, progress: bool | None = None, **settings) -> LogSuiteResult:
    """Localise every ``every``-th scan of each CARMEN log with the same settings (ours, issue 25; 004 §7).

    Each log runs through :func:`~slamlab.studies.correlation.run_log_localisation` with its defaults (the real-log
    defaults) unless ``settings`` change them, for scans ``every, 2·every, …`` below the log's length.

    Parameters
    ----------
    paths : sequence of (str, os.PathLike or CarmenLog), optional
        The logs; default :data:`~slamlab.studies.correlation.carmen_logs.SHARED_CARMEN_LOGS` (the five corrected
        Radish logs, found by :func:`slamlab.data.find_data`).
    every : int, default 25
        Localise every ``every``-th scan (at least 3, so the joined scans come before).
    joined : sequence of int in {1, ..., 5}
        The modes (scans joined by odometry), as in :func:`~slamlab.studies.correlation.run_log_localisation`.
    params : LocaliseParams, optional
        Settings of every localisation (default :class:`LocaliseParams`'s; its fields can also be given in
        ``settings``).
    rng : int or numpy.random.Generator, default 2017
        Seed or generator of the joined modes' odometry noise; each log gets the same seed (an int), or draws
        from the one generator in turn.
    n_jobs : int, default 1
        Sweep workers per log (same result for any).
    progress : bool, optional
        Progress bars (default: unless ``$SLAMLAB_PROGRESS=0``).
    **settings
        Any other argument of :func:`~slamlab.studies.correlation.run_log_localisation` (``cell_m``, ``max_range_m``,
        ``exclude``, ``leave_out``, ``odom_std``, ``hit_ratio``, ``votes``, :class:`LocaliseParams` fields).

    Returns
    -------
    LogSuiteResult
        One :class:`LogLocalisationResult` per log; :meth:`LogSuiteResult.table` prints the per-log rates.
    """
    from ...data import find_data
    from ...io import CarmenLog

    if paths is None:
        paths = [find_data(p) for p in SHARED_CARMEN_LOGS]
    elif isinstance(paths, (str, os.PathLike, CarmenLog)) or not isinstance(paths, (list, tuple)):
        raise TypeError(f"`paths` must be a list or tuple of logs (paths or CarmenLog); got {type(paths).__name__}")
    if len(paths) == 0:
        raise ValueError("`paths` must hold at least one log; got 0")
    ev = check_int(every, "every", minimum=3)
    results = []
    for p in paths:
        if isinstance(p, bool) or not isinstance(p, (str, os.PathLike, CarmenLog)):
            raise TypeError(f"`paths` must hold str, os.PathLike or CarmenLog; got {type(p).__name__}")
        log = as_carmen_log(p)
        idx = np.arange(ev, log.n_scans, ev)
        if idx.size == 0:
            raise ValueError(f"`every` ({ev}) leaves no scan of {log.name} ({log.n_scans} scans)")
        results.append(run_log_localisation(log, idx, joined=joined, params=params, rng=rng, n_jobs=n_jobs,
                                            progress=progress, **settings))
    return LogSuiteResult(tuple(results), ev)
