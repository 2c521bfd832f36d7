"""Text tables that fit the notebook's output area: long row labels move to notes under the table."""

from __future__ import annotations

from collections.abc import Sequence

from ..._table import format_table

#: The widest line a chapter prints (JupyterLab's output area at its default width).
WIDTH = 110


def fit_table(headers: Sequence[str], rows: Sequence[Sequence], title: str | None = None, *,
              width: int = WIDTH) -> str:
    """:func:`~slamlab._table.format_table`, with the first column numbered and listed under the table when a line
    would be wider than ``width``.

    >>> print(fit_table(["setting", "x"], [["a long label", "1.0"]], width=12))
    setting    x
    -------  ---
        (1)  1.0
    (1) a long label
    """
    text = format_table(headers, rows, title)
    if max(len(line) for line in text.splitlines()) <= width:
        return text
    keys = [f"({i + 1})" for i in range(len(rows))]
    text = format_table(headers, [[k, *r[1:]] for k, r in zip(keys, rows, strict=True)], title)
    return text + "\n" + "\n".join(f"{k} {r[0]}" for k, r in zip(keys, rows, strict=True))
