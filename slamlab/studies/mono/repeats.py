"""003 §5.5's protocol on our runs: the most accurate of 3 runs beside their median (ours).

003 §5.5: the compared systems' settings "were changed in each case to get the best results, and the
results shown are those that got the highest accuracy after 3 runs". :func:`run_repeats` runs our
pipeline 3 times on each rendered case, each run with its own image noise (our runs differ by nothing
else: the pipeline is deterministic), and :class:`RepeatedRuns` prints what each of the two ways of
reporting would give.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._progress import progress_bar
from ..._table import format_table
from ..._validate import check_choice, check_int
from ...mono.params import MonoParams
from ...sweep import fresh_seed_sequence
from .experiments import CASE_ORDER, FAILURE_SETTINGS, case_seed, failure_case_frames
from .runs import MonoRunResult, run_mono

__all__ = ["RepeatedRuns", "run_repeats"]


@dataclass(frozen=True)
class RepeatedRuns:
    """``n_runs`` runs of each rendered case, each with its own image noise (:func:`run_repeats`).

    Attributes
    ----------
    cases : tuple of str
        The rendered cases.
    n_runs : int
        Runs per case.
    results : dict
        ``(case, run)`` → :class:`~slamlab.studies.mono.MonoRunResult`, run 0 the chapter's own frames.
    """

    cases: tuple
    n_runs: int
    results: dict = field(repr=False)

    def ate_m(self, case: str) -> np.ndarray:
        """``(n_runs,)`` ATE over all frames after Sim(3) [m] of each run of ``case``.

        Parameters
        ----------
        case : str
            One of ``cases``.

        Returns
        -------
        ndarray, shape (n_runs,)
        """
        return np.array([self.results[(case, i)].ate_m for i in range(self.n_runs)])

    def correct_pct(self, case: str) -> np.ndarray:
        """``(n_runs,)`` correctly tracked share [%] of each run of ``case``.

        Parameters
        ----------
        case : str
            One of ``cases``.

        Returns
        -------
        ndarray, shape (n_runs,)
        """
        return np.array([100.0 * self.results[(case, i)].fraction_tracked for i in range(self.n_runs)])

    def best(self, case: str) -> int:
        """Index of the most accurate run of ``case`` (smallest ATE over all frames; 003 §5.5's choice).

        Parameters
        ----------
        case : str
            One of ``cases``.

        Returns
        -------
        int
        """
        return int(np.argmin(self.ate_m(case)))

    def __str__(self) -> str:
        parts = [f"{c}: median ATE {np.median(self.ate_m(c)):.3f} m, best {self.ate_m(c).min():.3f} m"
                 for c in self.cases]
        return f"{self.n_runs} runs per case; " + "; ".join(parts)

    def table(self) -> str:
        """Per case: each run's correct share and ATE, their median, and the best of the runs (003 §5.5).

        Returns
        -------
        str
        """
        rows = []
        for c in self.cases:
            ate, pct = self.ate_m(c), self.correct_pct(c)
            b = self.best(c)
            rows.append([c, " / ".join(f"{p:.0f}" for p in pct), " / ".join(f"{a:.3f}" for a in ate),
                         f"{np.median(pct):.0f}", f"{np.median(ate):.3f}", f"{pct[b]:.0f}", f"{ate[b]:.3f}",
                         f"{np.median(ate) / ate[b]:.2f}"])
        n = self.n_runs
        heads = ["case", "correct, % (runs)", "ATE, m (runs)", "median %", "median ATE", "best %", "best ATE",
                 "median/best"]
        return format_table(heads, rows, title=(f"{n} runs per case, each its own image noise (run 1: the "
                                                f"chapter's frames); best of {n} = smallest ATE (003 §5.5)"))


def run_repeats(cases=("normal", "fast_motion"), *, n_runs: int = 3, size: str = "tiny", n_frames: int = 24,
                params: MonoParams | None = None, rng=0, first: dict | None = None, progress=None,
                **overrides) -> RepeatedRuns:
    """Each rendered case run ``n_runs`` times with different image noise (ours; 003 §5.5's 3 runs).

    Run 1 renders each case from :func:`~slamlab.studies.mono.experiments.case_seed` of ``rng``: the frames of
    :func:`~slamlab.studies.mono.run_failure_cases` with the same ``rng``, size and frame count. Run ``k``
    (``k`` ≥ 2) renders it from ``case_seed`` of child ``k - 1`` of ``rng``'s SeedSequence: the same poses and
    scene, other noise.

    Parameters
    ----------
    cases : sequence of str
        Rendered cases (``"normal"`` or one of :data:`~slamlab.studies.mono.experiments.FAILURE_CASES`).
    n_runs : int
        Runs per case, at least 1 (default 3, as 003).
    size : str
        Render size (default ``"tiny"``).
    n_frames : int
        Frames per run (default 24).
    params : MonoParams, optional
        Settings (default values); not the fields a case sets itself.
    rng : int, SeedSequence or Generator
        The study's seed.
    first : dict, optional
        Case → run 1 already made: the result of :func:`~slamlab.studies.mono.run_failure_cases` with the same
        ``rng``, ``size``, ``n_frames`` and settings (the chapter's), so that it is not run twice. Checked: a
        result per case, named by its case, with ``n_frames`` frames; the rest is the caller's word.
    progress : bool, callable or None
        See :mod:`slamlab._progress`.
    **overrides
        :class:`~slamlab.mono.MonoParams` fields.

    Returns
    -------
    RepeatedRuns
    """
    from ..._params import refuse_set_fields

    cases = tuple(check_choice(c, "cases", CASE_ORDER) for c in cases)
    if not cases:
        raise ValueError("`cases` must name at least one case; got none")
    n_runs = check_int(n_runs, "n_runs", minimum=1)
    p = MonoParams.resolve(params, **overrides)
    for c in cases:
        refuse_set_fields(p, list(FAILURE_SETTINGS.get(c, {})), f"the case {c!r} sets it")
    first = {} if first is None else dict(first)
    for c in cases:
        r = first.get(c)
        if r is not None and (not isinstance(r, MonoRunResult) or r.name != c or len(r.claimed) != n_frames):
            raise ValueError(f"`first[{c!r}]` must be run_failure_cases' result of {c!r} over n_frames = {n_frames} "
                             f"frames; got {getattr(r, 'name', type(r).__name__)!r}")
    children = fresh_seed_sequence(rng).spawn(n_runs - 1) if n_runs > 1 else []
    run_rngs = [rng, *children]
    out = {}
    for i, r in enumerate(progress_bar(run_rngs, desc="runs", progress=progress)):
        for c in cases:
            if i == 0 and c in first:
                out[(c, 0)] = first[c]
                continue
            imgs, Ts, K, ov = failure_case_frames(c, size, n_frames, rng=np.random.default_rng(case_seed(r, c)))
            out[(c, i)] = run_mono(imgs, Ts, K, name=f"{c}, run {i + 1}", params=p, progress=False, **ov)
    return RepeatedRuns(cases, n_runs, out)
