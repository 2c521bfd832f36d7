"""Ch. 9's KITTI goal on two scenes (ours): one set of defaults on KITTI 06 and KITTI 01, and the ablation of the
defaults KITTI 01 informed.

The goal (ours): at least 80 % of the frames correctly tracked and an ATE (Sim(3), all frames) of at most 2 % of the
path, on both scenes with the same defaults. KITTI 06 (a town street, ~1.2 m per frame) informed the defaults of
:data:`~slamlab.studies.mono.kitti.KITTI_ABLATIONS`; KITTI 01 (a highway, ~1 m per frame, most points far away)
informed those of :data:`KITTI_GOAL_ABLATIONS`, each undone one at a time on both scenes (the configurations of
:func:`~slamlab.studies.mono.run_kitti_ablation`, one call per scene).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..._table import format_table
from ..._validate import check_positive
from .runs import MonoRunResult

__all__ = ["KITTI_GOAL_ABLATIONS", "goal_ablation_table", "kitti_goal_table"]

#: the defaults KITTI 01 informed, each undone (label → :class:`~slamlab.mono.MonoParams` overrides)
KITTI_GOAL_ABLATIONS = {
    "first tracked frame at the last pose": {"init_velocity": False},
    "'auto' counts 5-point inliers in front, 0.9": {"init_plane_share_of": "front", "init_plane_share": 0.9},
    "re-initialisation on the last velocity": {"reinit_velocity_frames": 1},
    "re-initialisation scaled by the steps": {"reinit_scale": "steps"},
    "median parallax of a new map 1 deg": {"init_min_parallax_deg": 1.0},
}


def _goal_met(r: MonoRunResult, correct_pct: float, ate_pct: float) -> bool:
    return bool(100 * r.fraction_tracked >= correct_pct and 100 * r.ate_m <= ate_pct * r.score.path_m)


def kitti_goal_table(runs: Mapping[str, MonoRunResult], informed: Mapping[str, str] | None = None, *,
                     goal_correct_pct: float = 80.0, goal_ate_pct: float = 2.0) -> str:
    """One row per KITTI run with the defaults: correct share, ATE in metres and in % of the path, the goal.

    Parameters
    ----------
    runs : mapping of str to MonoRunResult
        Set label → its run (:func:`~slamlab.studies.mono.run_kitti_mono`).
    informed : mapping of str to str, optional
        Set label → the defaults it informed (a short text column).
    goal_correct_pct, goal_ate_pct : float
        The goal: correct share at least this [%], ATE at most this share of the path [%] (defaults 80 and 2).

    Returns
    -------
    str
    """
    goal_correct_pct = check_positive(goal_correct_pct, "goal_correct_pct")
    goal_ate_pct = check_positive(goal_ate_pct, "goal_ate_pct")
    informed = dict(informed or {})
    rows = []
    for label, r in runs.items():
        rows.append([label, len(r.claimed), f"{r.score.path_m:.2f}", f"{100 * r.fraction_claimed:.0f}",
                     f"{100 * r.fraction_tracked:.0f}", f"{r.ate_m:.3f}", f"{100 * r.ate_m / r.score.path_m:.2f}",
                     "met" if _goal_met(r, goal_correct_pct, goal_ate_pct) else "missed", informed.get(label, "-")])
    return format_table(["set", "frames", "path, m", "claimed, %", "correct, %", "ATE, m", "ATE, % of path", "goal",
                         "defaults it informed"], rows,
                        title=f"One set of defaults on two KITTI scenes (goal: >= {goal_correct_pct:g} % correct, "
                              f"ATE <= {goal_ate_pct:g} % of the path)")


def goal_ablation_table(results: Mapping[tuple, MonoRunResult], *, goal_correct_pct: float = 80.0,
                        goal_ate_pct: float = 2.0, title: str | None = None) -> str:
    """One row per configuration, two columns per set (correct %, ATE % of the path) and whether the goal holds.

    Parameters
    ----------
    results : mapping
        ``(configuration, set label)`` → :class:`MonoRunResult` (the runs of
        :func:`~slamlab.studies.mono.run_kitti_ablation` on each scene, relabelled by scene).
    goal_correct_pct, goal_ate_pct : float
        The goal (defaults 80 % correct, ATE 2 % of the path).
    title : str, optional
        Table title.

    Returns
    -------
    str
    """
    sets = list(dict.fromkeys(s for _, s in results))
    labels = list(dict.fromkeys(lab for lab, _ in results))
    rows = []
    for lab in labels:
        row = [lab]
        for s in sets:
            r = results[(lab, s)]
            ate = 100 * r.ate_m / r.score.path_m
            row += [f"{100 * r.fraction_tracked:.0f}", f"{ate:.2f}" if np.isfinite(ate) else "-",
                    "met" if _goal_met(r, goal_correct_pct, goal_ate_pct) else "missed"]
        rows.append(row)
    heads = ["configuration"]
    for s in sets:
        heads += [f"{s} correct, %", f"{s} ATE, %", "goal"]
    frames = ", ".join(f"{s}: {len(results[(labels[0], s)].claimed)} frames" for s in sets)
    return format_table(heads, rows, title=(title or "The defaults KITTI 01 informed, each undone")
                        + f" ({frames}; ATE in % of the path)")
