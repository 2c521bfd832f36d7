"""Progress reporting for loops that may take more than a couple of seconds: the one ``progress=`` contract.

Every slamlab function with a ``progress`` argument accepts the same three kinds of value
and hands it to :func:`progress_bar`:

- ``True`` / ``False``: a ``tqdm.auto`` bar (a widget in JupyterLab, a text bar in a
  terminal), or none;
- ``None`` (the default): a bar unless the environment sets ``SLAMLAB_PROGRESS=0`` (the
  test suite and the notebook runner do, so that nbval's outputs and the tests' stderr
  never hold a bar);
- a callable ``progress(i)``: called with the 0-based index of each item once it is done
  (after its ``update()``), and no bar. A widget uses this to drive its own progress bar,
  e.g. ``progress=lambda i: setattr(int_progress, "value", i + 1)``.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator

__all__ = ["ENV_VAR", "check_progress", "progress_bar", "progress_enabled"]

ENV_VAR = "SLAMLAB_PROGRESS"


def check_progress(progress, name: str = "progress"):
    """``progress`` unchanged if it is True, False, None or a callable, else a ``TypeError`` naming ``name``.

    Parameters
    ----------
    progress : bool, None or callable
        The value to check (see the module docstring for the contract).
    name : str
        The argument's name in the message.

    Returns
    -------
    bool, None or callable
        ``progress`` itself.

    >>> check_progress(None) is None
    True
    """
    if progress is None or isinstance(progress, bool) or callable(progress):
        return progress
    raise TypeError(f"`{name}` must be True, False, None or a callable progress(i); got {type(progress).__name__}")


def progress_enabled(progress: bool | None = None) -> bool:
    """``progress`` if given, else whether ``$SLAMLAB_PROGRESS`` allows bars (on unless "0", "false", "no", "off").

    Parameters
    ----------
    progress : bool or None
        The caller's choice; None defers to the environment.

    Returns
    -------
    bool
        Whether to show a tqdm bar.

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


class _Callback(_Silent):
    """Stands in for a tqdm bar when ``progress`` is a callable: ``callback(i)`` after each item ``i`` is done."""

    def __init__(self, iterable: Iterable | None, callback: Callable[[int], object]):
        super().__init__(iterable)
        self._callback = callback
        self._done = 0

    def __iter__(self) -> Iterator:
        for item in super().__iter__():
            yield item
            self.update()

    def update(self, n: int = 1) -> None:
        """Count ``n`` items done, calling the callback once per item with its 0-based index."""
        for _ in range(n):
            self._callback(self._done)
            self._done += 1


def progress_bar(iterable: Iterable | None = None, *, total: int | None = None, desc: str | None = None,
                 progress: bool | Callable[[int], object] | None = None):
    """A ``tqdm.auto`` bar over ``iterable`` (or one to ``update()`` by hand), a callback, or a silent stand-in.

    Parameters
    ----------
    iterable : iterable, optional
        What to iterate over; None for a bar advanced by ``update()``.
    total : int, optional
        The number of items (default: ``len(iterable)`` where tqdm can take it).
    desc : str, optional
        The bar's label.
    progress : bool, None or callable
        The one ``progress=`` contract (see the module docstring).

    Returns
    -------
    object
        Iterable, with ``update(n=1)`` and ``close()``. Iterating a callback stand-in calls
        ``progress(i)`` after the loop body of item ``i`` has run.

    >>> [x for x in progress_bar(range(3), progress=False)]
    [0, 1, 2]
    >>> done = []
    >>> [x for x in progress_bar("ab", progress=done.append)], done
    (['a', 'b'], [0, 1])
    """
    check_progress(progress)
    if callable(progress) and not isinstance(progress, bool):
        return _Callback(iterable, progress)
    if not progress_enabled(progress):
        return _Silent(iterable)
    from tqdm.auto import tqdm

    return tqdm(iterable, total=total, desc=desc, leave=False)
