"""What the tables of Ch. 8's studies share (package-private): a number or "-", the lines of MCL settings under a
table's title, and a table whose title and notes wrap at the output area's width.
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

import numpy as np

from ..._params import TABLE_WIDTH
from ..._table import format_table
from ...localisation.mcl import MCLParams


def fmt(x, digits: int = 2) -> str:
    """``x`` with ``digits`` decimals, or "-" for None and NaN (an empty group)."""
    return "-" if x is None or np.isnan(x) else f"{x:.{digits}f}"


def params_line(p: MCLParams) -> str:
    """The MCL settings a study ran with (printed under the table's title; :func:`table` wraps it)."""
    return (f"score {p.score}, σ_hit {p.sigma_hit:g} cells, max_dist {p.max_dist:g}, {p.max_beams} beams, "
            f"α1…α4 = ({', '.join(f'{a:g}' for a in p.alpha)}), jitter ({p.jitter[0]:g}, {p.jitter[1]:g}), "
            f"weights p^{p.gamma:g}, averages {p.averages}, "
            f"(α_slow, α_fast) = ({p.alpha_slow:g}, {p.alpha_fast:g}), resample when N_eff < "
            f"{p.resample_threshold:g}·M{' (every step)' if p.resample_threshold >= 1 else ''}")


def wrap(text: str, width: int = TABLE_WIDTH) -> str:
    """Each line of ``text`` wrapped at ``width``, continuation lines indented by two spaces."""
    return "\n".join(textwrap.fill(line, width, subsequent_indent="  ", break_on_hyphens=False)
                     for line in text.split("\n"))


def table(headers: Sequence[str], rows: Sequence[Sequence], title: str, notes: Sequence[str] = ()) -> str:
    """:func:`~slamlab._table.format_table` with its title above and its notes (what the short column names
    mean) under it, both wrapped at the output area's width."""
    out = wrap(title) + "\n" + format_table(headers, rows)
    return out + ("\n" + wrap("\n".join(notes)) if notes else "")
