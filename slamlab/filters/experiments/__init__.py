"""Ch. 1 experiments (000 §1.2): seeded Monte Carlo runs returning printable results.

Each ``run_*`` returns a frozen dataclass: ``str(result)`` is a one-line summary,
``result.table()`` a fixed-precision text table (what the notebook prints and
nbval compares); arrays for plotting are kept in fields.

Families (CONVENTIONS: experiments.py split by experiment family): ``linear`` (constant-velocity
target, Joseph form, sigma-point weight), ``unicycle`` (filter comparison, stabilising noise),
``landmarks`` (the §3.6 landmark filter) and ``versus_source`` (the closing table).
"""

from __future__ import annotations

from ._common import DIVERGED_RMSE_M, FILTER_NAMES
from .landmarks import LandmarkDemoResult, run_landmark_filter
from .linear import (
    CVTargetResult,
    JosephResult,
    SigmaAlphaResult,
    run_cv_target,
    run_joseph_vs_short,
    run_sigma_alpha_study,
)
from .unicycle import (
    StabilisingNoiseResult,
    UnicycleResult,
    default_landmarks,
    run_stabilising_noise,
    run_unicycle_comparison,
)
from .versus_source import ours_vs_source

__all__ = [
    "DIVERGED_RMSE_M",
    "FILTER_NAMES",
    "CVTargetResult",
    "JosephResult",
    "LandmarkDemoResult",
    "SigmaAlphaResult",
    "StabilisingNoiseResult",
    "UnicycleResult",
    "default_landmarks",
    "ours_vs_source",
    "run_cv_target",
    "run_joseph_vs_short",
    "run_landmark_filter",
    "run_sigma_alpha_study",
    "run_stabilising_noise",
    "run_unicycle_comparison",
]
