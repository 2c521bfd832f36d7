"""The variants the MCL studies compare (003 §2.2): the ablation's rows and the observation scores, as overrides
of :class:`~slamlab.localisation.MCLParams`' defaults. Used by :mod:`slamlab.studies.localisation.studies`.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ABLATION", "ABLATION_MORE", "CHAPTER_BEFORE", "PLAIN_SETUP", "SCORE_VARIANTS"]

#: A plain set-up of global localisation, the ablation's first row: PR's product weights (gamma = 1), the
#: geometric-mean score in eq 2.8, 003's averages from 0 (so no injection with α_slow = 0.001), σ_hit 2 cells, the
#: Markov grid's motion noise (a quarter of the defaults'), no jitter.
CHAPTER_BEFORE = {"score": "geometric_mean", "averages": "003", "sigma_hit": 2.0, "max_dist": 8.0,
                  "alpha": (0.05, 0.002, 0.05, 0.005), "gamma": 1.0, "jitter": (0.0, 0.0)}

#: The same plain set-up under the name the chapter uses.
PLAIN_SETUP = CHAPTER_BEFORE

#: The ablation: (label, overrides of the defaults). The first block starts from :data:`CHAPTER_BEFORE` and
#: changes one factor; the second starts from the defaults and takes one factor back.
ABLATION = (
    ("plain set-up", CHAPTER_BEFORE),
    ("plain + σ_hit 4, motion ×4, jitter, p^0.5", {**CHAPTER_BEFORE, "sigma_hit": 4.0, "max_dist": 12.0,
                                                   "alpha": (0.2, 0.008, 0.2, 0.02), "jitter": (0.6, 0.04),
                                                   "gamma": 0.5}),
    ("plain + injection (debiased averages)", {**CHAPTER_BEFORE, "averages": "debiased"}),
    ("defaults", {}),
    ("defaults, σ_hit 2 cells", {"sigma_hit": 2.0, "max_dist": 8.0}),
    ("defaults, motion noise / 4", {"alpha": (0.05, 0.002, 0.05, 0.005)}),
    ("defaults, no jitter", {"jitter": (0.0, 0.0)}),
    ("defaults, weights p^1", {"gamma": 1.0}),
    ("defaults, no injection", {"alpha_slow": 0.0, "alpha_fast": 0.0}),
)

#: More variants for the "full" ablation (benchmarks): resampling, beams, amcl's update thresholds, eq 2.8's score.
ABLATION_MORE = (
    ("defaults, eq 2.8 on p(z | x)", {"score": "likelihood"}),
    ("defaults, resample every step", {"resample_threshold": 1.0}),
    ("defaults, 60 beams", {"max_beams": 60}),
    ("defaults, amcl update thresholds", {"update_min_d": 2.0, "update_min_a": float(np.pi / 6)}),
)

#: The observation scores compared (label, overrides): eq 2.8 averages ω; the weights are p(z | x)^gamma (the
#: defaults' gamma = 0.5) in every case.
SCORE_VARIANTS = (
    ("ω = p(z | x) (PR Table 8.3)", {"score": "likelihood"}),
    ("ω = geometric mean (ours; defaults)", {"score": "geometric_mean"}),
    ("ω = 1 + Σ p³ (ROS 1 amcl, Beluga)", {"score": "amcl_cubes"}),
)
