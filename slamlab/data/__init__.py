"""The data: a registry of every real data file, found where it is and fetched where it is not.

Small files the project makes itself (maps, scenario configs) ship inside the package
(``slamlab/data/bundled/``). Real public data sets (Oxford affine, KITTI, the CARMEN logs, ...)
are never copied into the project: the registry (``registry.json``, :mod:`.registry`) names every
file the notebooks, labs, tests, benchmarks and the course site read, with its upstream URL at a
pinned commit, its sha256, size, licence and citation. :func:`find_data` finds a file or a set in
``$SLAMLAB_DATA``, then ``../shared/data``, then the per-user cache, and otherwise fetches it from
its upstream host (or from ``$SLAMLAB_DATA_URL``'s mirror) into the cache, verified (:mod:`.locate`,
:mod:`.fetch`).

From a shell (``make data`` runs ``fetch``)::

    python -m slamlab.data list            # sets, sizes, licences, where each is found
    python -m slamlab.data fetch [SET ...]  # fetch what no data folder holds (all sets by default)
    python -m slamlab.data verify          # re-hash every registered file found
    python -m slamlab.data mirror DIR      # write DIR/<host>/<path> for a room without internet
"""

from __future__ import annotations

from .commands import VerifyRow, fetch_sets, list_sets, make_mirror, verify, verify_report
from .fetch import DataFetchError, DataIntegrityError, DataUnavailableError
from .locate import (
    CACHE_ENV_VAR,
    ENV_VAR,
    DataHashWarning,
    bundled_data_dir,
    cache_dir,
    data_locations,
    data_root,
    find_data,
    project_data_dir,
    project_root,
    shared_data_dir,
)
from .registry import DATA_URL_ENV_VAR, DataFile, DataSet, Registry, data_table_markdown, registry

__all__ = [
    "CACHE_ENV_VAR",
    "DATA_URL_ENV_VAR",
    "ENV_VAR",
    "DataFetchError",
    "DataFile",
    "DataHashWarning",
    "DataIntegrityError",
    "DataSet",
    "DataUnavailableError",
    "Registry",
    "VerifyRow",
    "bundled_data_dir",
    "cache_dir",
    "data_locations",
    "data_root",
    "data_table_markdown",
    "fetch_sets",
    "find_data",
    "list_sets",
    "make_mirror",
    "project_data_dir",
    "project_root",
    "registry",
    "shared_data_dir",
    "verify",
    "verify_report",
]
