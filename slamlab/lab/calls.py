"""Which library functions a student's function called: a task that asks for one's own implementation
forbids calling slamlab's (lab 01: "do not call the library's Kalman filter").

The calls are seen with :func:`sys.setprofile` while the student's function runs: every Python
function entered is named ``module.qualname``; a name under one of the task's forbidden prefixes,
and under none of its allowed ones, is reported. Functions imported under another name, wrapped in
a lambda or called through another student function are seen all the same (the profile sees the
code that runs, not the name it was called by).
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["ALLOWED", "FORBIDDEN", "call_watching"]

#: What a task forbids unless it says otherwise: every function of slamlab ...
FORBIDDEN = ("slamlab.",)
#: ... except the lab's own checks, the notebook set-up and the look-up of a lazily imported subpackage.
ALLOWED = ("slamlab.lab.", "slamlab.notebook_setup", "slamlab._lazy.")


def call_watching(fn: Callable, kwargs: Mapping[str, Any], *, forbid=FORBIDDEN, allow=ALLOWED) -> tuple[Any, list[str]]:
    """Call ``fn(**kwargs)`` and name the forbidden library functions it called.

    Parameters
    ----------
    fn : callable
        The student's function.
    kwargs : mapping
        Its arguments.
    forbid, allow : tuple of str
        Prefixes of ``module.qualname``: a call under a ``forbid`` prefix and no ``allow`` prefix is reported.

    Returns
    -------
    tuple
        ``(result, called)``: what ``fn`` returned and the forbidden functions it called, in first-call order.
        An exception from ``fn`` propagates.
    """
    called: dict[str, None] = {}
    forbid, allow = tuple(forbid), tuple(allow)
    previous = sys.getprofile()

    def profile(frame, event, arg):
        if event == "call":
            name = f"{frame.f_globals.get('__name__', '')}.{frame.f_code.co_qualname}"
            if name.startswith(forbid) and not name.startswith(allow):
                called.setdefault(name)

    sys.setprofile(profile)
    try:
        result = fn(**kwargs)
    finally:
        sys.setprofile(previous)
    return result, list(called)
