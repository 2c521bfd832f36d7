"""What the tables of Ch. 8's studies share (package-private): a number or "-", and the line of MCL settings
under a table's title.
"""

from __future__ import annotations

import numpy as np

from ...localisation.mcl import MCLParams


def fmt(x, digits: int = 2) -> str:
    """``x`` with ``digits`` decimals, or "-" for None and NaN (an empty group)."""
    return "-" if x is None or np.isnan(x) else f"{x:.{digits}f}"


def params_line(p: MCLParams) -> str:
    """The MCL settings a study ran with, on one line (printed under the table's title)."""
    return (f"score {p.score}, σ_hit {p.sigma_hit:g} cells, max_dist {p.max_dist:g}, {p.max_beams} beams, "
            f"α1…α4 = ({', '.join(f'{a:g}' for a in p.alpha)}), jitter ({p.jitter[0]:g}, {p.jitter[1]:g}), "
            f"weights p^{p.gamma:g}, averages {p.averages}, "
            f"(α_slow, α_fast) = ({p.alpha_slow:g}, {p.alpha_fast:g}), resample when N_eff < "
            f"{p.resample_threshold:g}·M{' (every step)' if p.resample_threshold >= 1 else ''}")
