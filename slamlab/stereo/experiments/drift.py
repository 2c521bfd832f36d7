"""The same run at several calibration-drift levels (our experiment for 000 §3.2), on :func:`slamlab.sweep.sweep`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ... import _validate as v
from ..._table import format_table
from ..params import RenderParams, StereoParams
from .runs import SIZES, run_closed_loop, run_turn_in_place  # noqa: F401 (drift_level looks the runners up in globals())


@dataclass(frozen=True)
class DriftStudy:
    """Runs of one experiment at several calibration-drift levels (000 §3.2; our experiment).

    Attributes
    ----------
    experiment : str
        "turn in place" or "closed loop".
    drift_std_rad : tuple of float
        Random-walk step of the right camera per axis and frame [rad], one per level.
    runs : tuple of StereoRunResult
        One run per level.
    """

    experiment: str
    drift_std_rad: tuple
    runs: tuple = field(repr=False)  # StereoRunResult per level

    def table(self) -> str:
        """Errors, stereo matches and inliers per drift level (fixed precision).

        Returns
        -------
        str
        """
        rows = []
        for d, r in zip(self.drift_std_rad, self.runs, strict=True):
            c = r.counts
            # the random walk's typical accumulated angle at the last frame: sqrt(N) sigma per axis
            rows.append([f"{1e3 * d:.1f}", f"{1e3 * d * np.sqrt(r.n_frames):.1f}", f"{r.pos_err_m.max():.2f}",
                         f"{np.rad2deg(np.abs(r.yaw_err_rad).max()):.1f}", f"{np.median(c['n_stereo']):.0f}",
                         f"{np.min(c['n_stereo']):.0f}", f"{np.median(c['n_inliers'][1:]):.0f}", f"{len(r.degenerate)}"])  # fmt: skip
        head = ["drift, mrad/frame", "~drift at end, mrad", "max pos. err, m", "max heading err, deg",
                "stereo matches (median)", "(min)", "inliers (median)", "degenerate"]  # fmt: skip
        return format_table(head, rows, title=f"calibration drift of the right camera: {self.experiment} ({self.runs[0].detector})")


_RUNNERS = {"turn in place": "run_turn_in_place", "closed loop": "run_closed_loop"}


def drift_level(*, drift_std_rad: float, experiment: str, size: str, n_frames, params: StereoParams,
                render: RenderParams, seed) -> dict:
    """One task of :func:`run_drift_study`: the experiment at one drift level (deterministic from ``seed``).

    Parameters
    ----------
    drift_std_rad : float
        Drift level [rad per axis and frame].
    experiment : {"turn in place", "closed loop"}
        The run.
    size : {"small", "full"}
        Frame step.
    n_frames : int or None
        Keep only the first frames.
    params : StereoParams
        Pipeline settings.
    render : RenderParams
        Renderer settings (its ``drift_std_rad`` is replaced).
    seed : int or SeedSequence
        The run's seed, the same for every level.

    Returns
    -------
    dict
        ``{"run": StereoRunResult}``.
    """
    runner = globals()[_RUNNERS[experiment]]
    return {"run": runner(size, n_frames=n_frames, params=params, render=render.replace(drift_std_rad=drift_std_rad),
                          progress=False, rng=seed)}


def run_drift_study(
    drift_std_rad=(0.0, 0.5e-3, 1e-3, 2e-3), experiment: str = "turn in place", size: str = "small", *,
    n_frames: int | None = None, params: StereoParams | None = None, render: RenderParams | None = None, rng=0,
    n_jobs: int = 1, progress: bool | None = None, **overrides,
) -> DriftStudy:
    """The same run at several calibration-drift levels (our experiment for 000 §3.2), on :func:`slamlab.sweep.sweep`.

    The right camera's orientation takes a random-walk step of ``drift_std_rad`` per axis and
    frame while the pipeline keeps the nominal calibration; ``params`` + ``overrides`` set the
    pipeline (``detector``, ``policy``, ...), ``render`` the rest of the renderer. Every level uses
    the same seed ``rng`` (common random numbers: the level is the only change), so each task is
    deterministic and the sweep gives it no stream of its own (``rng_arg=None``); the study is
    the same for any ``n_jobs``. ``progress``: a bar over the levels (default: on unless
    ``$SLAMLAB_PROGRESS=0``).

    Parameters
    ----------
    drift_std_rad : sequence of float
        Drift levels [rad per axis and frame], ≥ 0.
    experiment : {"turn in place", "closed loop"}
        The run.
    size : {"small", "full"}
        Frame step.
    n_frames : int, optional
        Keep only the first frames.
    params : StereoParams, optional
        Pipeline settings (default :class:`StereoParams`).
    render : RenderParams, optional
        Renderer settings (``arena_seed``, ``camera_height_m``, ``noise_std``, ``drift_std_rad``).
    rng : int, numpy.random.Generator or SeedSequence, default 0
        Seed shared by every level.
    n_jobs : int, default 1
        Worker processes.
    progress : bool or None
        A bar over the levels.
    **overrides
        :class:`StereoParams` fields to change.

    Returns
    -------
    DriftStudy
    """
    from ...sweep import fresh_seed_sequence, sweep

    v.check_choice(experiment, "experiment", _RUNNERS)
    v.check_choice(size, "size", SIZES)
    levels = tuple(float(d) for d in np.atleast_1d(v.as_finite_array(drift_std_rad, "drift_std_rad", ndim=1)))
    if min(levels) < 0:
        raise ValueError(f"`drift_std_rad` must be >= 0; got {levels}")
    seed = fresh_seed_sequence(rng)  # every level's run from the same (fresh) SeedSequence
    p = StereoParams.resolve(params, **overrides)
    render = RenderParams.resolve(render)
    table = sweep(drift_level, {"drift_std_rad": levels}, rng_arg=None, n_jobs=n_jobs, progress=progress,
                  on_error="raise", desc=f"calibration drift study ({experiment})",
                  fixed={"experiment": experiment, "size": size, "n_frames": n_frames, "params": p, "render": render,
                         "seed": seed})
    return DriftStudy(experiment, levels, tuple(table["run"]))
