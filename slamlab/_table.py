"""Fixed-width text tables for experiment results (what nbval compares)."""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["format_table"]


def format_table(headers: Sequence[str], rows: Sequence[Sequence], title: str | None = None) -> str:
    """Right-aligned columns; cells are formatted already (strings) or ``str()``-ed.

    >>> print(format_table(["a", "bb"], [["1", "2.50"], ["10", "3.00"]]))
     a    bb
    --  ----
     1  2.50
    10  3.00
    """
    cells = [[str(c) for c in r] for r in rows]
    widths = [max(len(h), *(len(r[i]) for r in cells)) if cells else len(h) for i, h in enumerate(headers)]
    fmt = "  ".join(f"{{:>{w}}}" for w in widths)
    lines = [] if title is None else [title]
    lines += [fmt.format(*headers), "  ".join("-" * w for w in widths)]
    lines += [fmt.format(*r) for r in cells]
    return "\n".join(lines)
