"""The real data of Ch. 5 (ours): the corrected CARMEN logs of the shared data, and reading one by path.

:func:`~slamlab.studies.correlation.run_log_localisation`, :func:`~slamlab.studies.correlation.run_log_suite`,
:func:`~slamlab.studies.correlation.map_check` and the widgets take a log as a path (``str`` / ``os.PathLike``),
a read :class:`~slamlab.io.CarmenLog`, or nothing (the default log); :func:`as_carmen_log` is that one rule.
"""

from __future__ import annotations

import os

__all__ = ["DEFAULT_CARMEN_LOG", "SHARED_CARMEN_LOGS", "as_carmen_log", "short_log_name"]

#: The default log of :func:`~slamlab.studies.correlation.run_log_localisation` (found by
#: :func:`slamlab.data.find_data`).
DEFAULT_CARMEN_LOG = "carmen-radish-corrected/intel-corrected.log.gz"

#: The five corrected Radish logs of the shared data (found by :func:`slamlab.data.find_data`).
SHARED_CARMEN_LOGS = tuple(f"carmen-radish-corrected/{n}-corrected.log.gz"
                           for n in ("csail", "fhw", "intel", "orebro", "seattle"))


def as_carmen_log(path=None, name: str = "path"):
    """A read CARMEN log from a path, a log already read, or nothing (the default log) (ours).

    Parameters
    ----------
    path : str, os.PathLike, CarmenLog or None
        Any CARMEN log (plain or gzip); None: :data:`DEFAULT_CARMEN_LOG` (:func:`slamlab.data.find_data`).
    name : str, default "path"
        The argument's name in the error message.

    Returns
    -------
    CarmenLog
        ``path`` itself when it is one, else :func:`slamlab.io.read_carmen` of the file.
    """
    from ...io import CarmenLog, read_carmen

    if isinstance(path, CarmenLog):
        return path
    if path is None:
        from ...data import find_data

        path = find_data(DEFAULT_CARMEN_LOG)
    elif isinstance(path, bool) or not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"`{name}` must be a str, os.PathLike or CarmenLog; got {type(path).__name__}")
    return read_carmen(path)


def short_log_name(name: str) -> str:
    """The short name of a log file: ``"intel"`` for ``"intel-corrected.log.gz"`` (ours).

    Parameters
    ----------
    name : str
        The log's file name.

    Returns
    -------
    str

    Examples
    --------
    >>> short_log_name("intel-corrected.log.gz")
    'intel'
    """
    return name.removesuffix(".gz").removesuffix(".log").removesuffix("-corrected")
