"""003 §5.1.2's observations of SDVL at work, each set beside what our runs print (or "not tested").

003 §5.1.2 ran SDVL under ROS on a monocular camera and reports three observations, with no numbers:
abrupt camera motion troubles it; smooth motion runs fast and without delays; and the camera has to be
held still for a few seconds at the start to initialise the map. :func:`run_still_start` asks the third
of our pipeline (ours); :func:`practice_findings_table` sets all three beside our runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..._table import format_table
from ..._validate import check_int
from ...mono.params import MonoParams
from .experiments import case_seed, mono_sim, render_sequence, sequence_poses
from .repeats import RepeatedRuns
from .runs import MonoRunResult, run_mono
from .studies import table_notes

__all__ = ["SOURCE_PRACTICE", "StillStart", "practice_findings_table", "run_still_start"]

#: 003 §5.1.2's observations (our translation)
SOURCE_PRACTICE = (
    ("abrupt motion", "'it is rather sensitive to abrupt movements of the camera'"),
    ("smooth motion", "'if the camera moves smoothly, the algorithm works fast and without any delays'"),
    ("still start", ("'to get good results, the camera has to be held still for a few seconds at the start to "
                    "initialise the map'")),
)


@dataclass(frozen=True)
class StillStart:
    """The rendered strafe with and without ``n_still`` frames held still first (:func:`run_still_start`).

    Attributes
    ----------
    n_still : int
        Frames held at the first pose before the motion.
    moving : MonoRunResult
        The run that moves from its first frame.
    still : MonoRunResult
        The run whose first ``n_still`` frames stand still.
    """

    n_still: int
    moving: MonoRunResult = field(repr=False)
    still: MonoRunResult = field(repr=False)

    def moving_correct_pct(self) -> tuple:
        """Correctly tracked share [%] of the moving frames: ``(moving run, still-start run)``."""
        return (100.0 * float(np.mean(self.moving.tracked)),
                100.0 * float(np.mean(self.still.tracked[self.n_still:])))

    def first_map_after_motion(self) -> tuple:
        """Frames of motion before the first claimed frame: ``(moving run, still-start run)`` (-1: never)."""
        def first(r, skip):
            k = np.flatnonzero(r.claimed[skip:])
            return int(k[0]) if k.size else -1

        return first(self.moving, 0), first(self.still, self.n_still)

    def __str__(self) -> str:
        a, b = self.moving_correct_pct()
        return f"still start ({self.n_still} frames): moving frames correct {b:.0f} % (without: {a:.0f} %)"

    def table(self) -> str:
        """Both runs: frames, frames of motion before the first map, moving frames correct, ATE of claimed frames.

        Returns
        -------
        str
        """
        pct, first = self.moving_correct_pct(), self.first_map_after_motion()
        rows = [[label, f"{len(r.claimed)}", f"{k}", f"{p:.0f}", f"{r.ate_claimed_m:.3f}"]
                for label, r, k, p in (("moving from frame 0", self.moving, first[0], pct[0]),
                                       (f"held still {self.n_still} frames first", self.still, first[1], pct[1]))]
        return format_table(["start", "frames", "motion frames before the map", "moving frames correct, %",
                             "ATE claimed, m"], rows, title="003 §5.1.2's still start on our rendered strafe")


def run_still_start(n_still: int = 10, *, size: str = "tiny", n_frames: int = 24, params: MonoParams | None = None,
                    rng=0, moving: MonoRunResult | None = None, **overrides) -> StillStart:
    """The rendered strafe run as is and with its first pose held for ``n_still`` frames (ours, 003 §5.1.2).

    Both render from the ``"normal"`` case's stream of ``rng``
    (:func:`~slamlab.studies.mono.experiments.case_seed`): the run without a still start is the chapter's
    normal run; the other has ``n_still`` more frames in front (so its later frames get other noise).

    Parameters
    ----------
    n_still : int
        Frames held still before the motion, at least 1 (default 10).
    size : str
        Render size (default ``"tiny"``).
    n_frames : int
        Frames of motion (default 24).
    params : MonoParams, optional
        Settings (default values).
    rng : int, SeedSequence or Generator
        The chapter's seed.
    moving : MonoRunResult, optional
        The run without a still start, already made: ``run_failure_cases(...)["normal"]`` with the same ``rng``,
        ``size``, ``n_frames`` and settings (the chapter's). Checked: named ``"normal"``, ``n_frames`` frames.
    **overrides
        :class:`~slamlab.mono.MonoParams` fields.

    Returns
    -------
    StillStart
    """
    n_still = check_int(n_still, "n_still", minimum=1)
    n_frames = check_int(n_frames, "n_frames", minimum=2)
    p = MonoParams.resolve(params, **overrides)
    if moving is not None and (not isinstance(moving, MonoRunResult) or moving.name != "normal"
                               or len(moving.claimed) != n_frames):
        raise ValueError(f"`moving` must be run_failure_cases' result of 'normal' over n_frames = {n_frames} frames; "
                         f"got {getattr(moving, 'name', type(moving).__name__)!r}")
    poses = sequence_poses("strafe", n_frames)
    out = [] if moving is None else [moving]
    for k in (0, n_still)[len(out):]:
        sim = mono_sim(size, rng=np.random.default_rng(case_seed(rng, "normal")))
        imgs, Ts = render_sequence(sim, np.vstack([np.repeat(poses[:1], k, axis=0), poses]), progress=False)
        out.append(run_mono(imgs, Ts, sim.rig.left.K, name=f"strafe, {k} still", params=p, progress=False))
    return StillStart(n_still, *out)


def practice_findings_table(failures: dict, repeats: RepeatedRuns, still: StillStart) -> str:
    """003 §5.1.2's three observations beside our runs (ours), 003's words in the notes.

    Parameters
    ----------
    failures : dict
        Case → :class:`~slamlab.studies.mono.MonoRunResult` with ``"normal"`` and ``"fast_motion"``
        (:func:`~slamlab.studies.mono.run_failure_cases`).
    repeats : RepeatedRuns
        The repeated runs of ``"normal"`` and ``"fast_motion"`` (:func:`~slamlab.studies.mono.run_repeats`).
    still : StillStart
        :func:`run_still_start`.

    Returns
    -------
    str
    """
    for c in ("normal", "fast_motion"):
        if c not in failures or c not in repeats.cases:
            raise ValueError(f"`failures` and `repeats` must hold the case {c!r}")
    nm, fm = failures["normal"], failures["fast_motion"]
    pn, pf = repeats.correct_pct("normal"), repeats.correct_pct("fast_motion")
    runs = lambda x: " / ".join(f"{v:.0f}" for v in x)
    lost = lambda r: r.counts.get("lost", 0)
    s0, s1 = still.moving_correct_pct()
    f0, f1 = still.first_map_after_motion()
    rows = [
        ["abrupt motion", f"fast_motion: {lost(fm)} lost; correct {runs(pf)} % in {repeats.n_runs} runs",
         "yes" if np.median(pf) < np.median(pn) and lost(fm) > lost(nm) else "not shown"],
        ["smooth motion", f"normal: {lost(nm)} lost; correct {runs(pn)} %; speed: the timing table",
         "no loss: yes" if lost(nm) == 0 else "no"],
        ["still start", (f"{still.n_still} still frames first: {s1:.0f} % of the moving frames correct "
                         f"({s0:.0f} % without)"), "not needed" if s1 >= s0 else "helps"],
    ]
    notes = [f"{q}: {w}" for q, w in SOURCE_PRACTICE]
    notes.append(f"still start (ours): the first map comes {f1} frames after the motion starts ({f0} without): our "
                 "initialiser waits for its corners to move (init_disparity_px), not for stillness; 003 gives no reason "
                 "for its advice.")
    return (format_table(["003 §5.1.2", f"our rendered runs ({len(nm.claimed)} frames)", "003 holds here?"], rows,
                         title="003 §5.1.2's observations beside our runs")
            + "\n" + table_notes("003 §5.1.2 says (our translation):", notes))
