"""Progress bars for loops that may take more than a couple of seconds (tqdm.auto).

In JupyterLab the bar is a widget, in a terminal a text bar. It is off when the
caller says ``progress=False``, or, by default, when the environment sets
``SLAMLAB_PROGRESS=0``: the test suite and the notebook runner do, so that nbval's
outputs and the tests' stderr never hold a bar.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator

__all__ = ["ENV_VAR", "progress_bar", "progress_enabled"]

ENV_VAR = "SLAMLAB_PROGRESS"


def progress_enabled(progress: bool | None = None) -> bool:
    """``progress`` if given, else whether ``$SLAMLAB_PROGRESS`` allows bars (on unless "0", "false", "no", "off").

    >>> progress_enabled(False)
    False
    """
    if progress is not None:
        if not isinstance(progress, bool):
            raise TypeError(f"`progress` must be True, False or None; got {type(progress).__name__}")
        return progress
    return os.environ.get(ENV_VAR, "1").strip().lower() not in ("0", "false", "no", "off")


class _Silent:
    """Stands in for a tqdm bar when bars are off: iterates, counts nothing, prints nothing."""

    def __init__(self, iterable: Iterable | None):
        self._iterable = iterable

    def __iter__(self) -> Iterator:
        return iter(self._iterable if self._iterable is not None else ())

    def update(self, n: int = 1) -> None:
        """Ignored."""

    def close(self) -> None:
        """Ignored."""


def progress_bar(iterable: Iterable | None = None, *, total: int | None = None, desc: str | None = None,
                 progress: bool | None = None):
    """A ``tqdm.auto`` bar over ``iterable`` (or one to ``update()`` by hand), or a silent stand-in.

    >>> [x for x in progress_bar(range(3), progress=False)]
    [0, 1, 2]
    """
    if not progress_enabled(progress):
        return _Silent(iterable)
    from tqdm.auto import tqdm

    return tqdm(iterable, total=total, desc=desc, leave=False)
