"""Where data are found: the package's own files, ``$SLAMLAB_DATA``, ``../shared/data``, the cache.

:func:`find_data` looks for a path relative to a data folder in this order:

1. the files slamlab ships inside the package (``slamlab/data/bundled/``: the maps and scenario
   files the project makes itself);
2. ``$SLAMLAB_DATA`` when the variable is set;
3. ``../shared/data`` beside the project root (the folder holding ``pyproject.toml`` and the
   ``slamlab`` package), then beside the working folder and each of its parents;
4. the per-user cache, ``$SLAMLAB_CACHE`` or ``pooch.os_cache("slamlab")``
   (``~/.cache/slamlab`` on Linux);
5. and, for a file of the registry that none of these holds, a download into the cache
   (:mod:`slamlab.data.fetch`).

A folder (a set such as ``"kitti-odometry-06-stereo"``, or ``"oxford-affine/graf"``) is found
where *every* registered file inside it is, so a set behaves the same wherever it was found.
A file found in ``$SLAMLAB_DATA`` or ``../shared/data`` is hashed once per process: one that
differs from the registry gets a :class:`DataHashWarning` naming it. A cached file that differs
is deleted and fetched again.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

from .._progress import check_progress
from .._validate import check_choice
from . import derive
from .fetch import DataUnavailableError, fetch_files
from .registry import DataFile, registry

__all__ = [
    "CACHE_ENV_VAR",
    "ENV_VAR",
    "DataHashWarning",
    "bundled_data_dir",
    "cache_dir",
    "data_locations",
    "data_root",
    "find_data",
    "found_at",
    "project_data_dir",
    "project_root",
    "shared_data_dir",
]

#: Environment variable that points at the shared (real) data folder.
ENV_VAR = "SLAMLAB_DATA"
#: Environment variable that moves the download cache (default ``pooch.os_cache("slamlab")``).
CACHE_ENV_VAR = "SLAMLAB_CACHE"

_PACKAGE_DIR = Path(__file__).resolve().parent.parent
_BUNDLED_DIR = Path(__file__).resolve().parent / "bundled"

# (path, size, mtime_ns) -> whether the file matched the registry, hashed once per process
_CHECKED: dict[tuple[str, int, int], bool] = {}


class DataHashWarning(UserWarning):
    """A data file found in ``$SLAMLAB_DATA`` or ``../shared/data`` differs from the registry."""


def project_root() -> Path | None:
    """The source checkout holding the ``slamlab`` package, or ``None`` for an installed copy.

    It is the package's parent folder when that folder has a ``pyproject.toml``.

    >>> root = project_root()
    >>> root is None or (root / "pyproject.toml").is_file()
    True
    """
    root = _PACKAGE_DIR.parent
    return root if (root / "pyproject.toml").is_file() else None


def bundled_data_dir() -> Path:
    """The small files slamlab makes itself and ships inside the package (maps, scenarios).

    >>> (bundled_data_dir() / "test_room_200.txt").is_file()
    True
    """
    return _BUNDLED_DIR


def project_data_dir() -> Path:
    """The project's own data files: :func:`bundled_data_dir` (kept for older code).

    >>> project_data_dir() == bundled_data_dir()
    True
    """
    return _BUNDLED_DIR


def cache_dir() -> Path:
    """The download cache: ``$SLAMLAB_CACHE`` or ``pooch.os_cache("slamlab")``.

    Deleting it is safe: what is missing is fetched again on first use.
    """
    env = os.environ.get(CACHE_ENV_VAR, "").strip()
    if env:
        return Path(env).expanduser().resolve()
    import pooch

    return Path(pooch.os_cache("slamlab")).resolve()


def _shared_candidates() -> list[tuple[str, Path | None]]:
    """``(label, path)`` of every shared-data location in search order (``None`` = unset)."""
    out: list[tuple[str, Path | None]] = []
    env = os.environ.get(ENV_VAR)
    out.append((f"${ENV_VAR}", Path(env).expanduser() if env else None))
    root = project_root()
    if root is not None:
        out.append(("project root ../shared/data", root.parent / "shared" / "data"))
    cwd = Path.cwd().resolve()
    for folder in (cwd, *cwd.parents):
        out.append(("working folder ../shared/data", folder.parent / "shared" / "data"))
    seen: set[Path] = set()
    unique: list[tuple[str, Path | None]] = []
    for label, path in out:
        key = path.resolve() if path is not None else None
        if key is not None and key in seen:
            continue
        if key is not None:
            seen.add(key)
        unique.append((label, key))
    return unique


def data_locations() -> list[tuple[str, Path | None]]:
    """Every data folder in search order after the bundled files: shared candidates, then the cache."""
    return [*_shared_candidates(), (f"cache (${CACHE_ENV_VAR} or the user cache)", cache_dir())]


def _describe(candidates: list[tuple[str, Path | None]]) -> str:
    return "\n".join(f"  - {label}: {'(not set)' if path is None else path}" for label, path in candidates)


def shared_data_dir() -> Path:
    """The shared (real) data folder: ``$SLAMLAB_DATA`` or ``../shared/data``.

    Returns
    -------
    pathlib.Path
        The first existing folder among the candidates (see the module docstring).

    Raises
    ------
    FileNotFoundError
        When none exists; the message lists every place searched.
    """
    candidates = _shared_candidates()
    for _label, path in candidates:
        if path is not None and path.is_dir():
            return path
    raise FileNotFoundError(
        "shared data folder not found; searched:\n"
        + _describe(candidates)
        + f"\nSet ${ENV_VAR} to the folder or place it at ../shared/data beside the project "
        "(without it, registered files are fetched into the cache: `python -m slamlab.data fetch`)."
    )


def data_root(kind: str = "shared") -> Path:
    """The data folder of the given ``kind``: ``"shared"``, ``"bundled"`` or ``"cache"``.

    Parameters
    ----------
    kind : {"shared", "bundled", "cache"}
        ``"shared"`` gives :func:`shared_data_dir`, ``"bundled"`` :func:`bundled_data_dir`,
        ``"cache"`` :func:`cache_dir`.

    Examples
    --------
    >>> data_root("bundled") == bundled_data_dir()
    True
    >>> data_root("other")
    Traceback (most recent call last):
    ...
    ValueError: `kind` must be one of 'shared', 'bundled', 'cache'; got 'other'
    """
    check_choice(kind, "kind", ("shared", "bundled", "cache"))
    return {"shared": shared_data_dir, "bundled": bundled_data_dir, "cache": cache_dir}[kind]()


def _check_relpath(relpath) -> Path:
    if not isinstance(relpath, str | os.PathLike):
        raise TypeError(f"`relpath` must be a str or path; got {type(relpath).__name__}")
    path = Path(relpath)
    if str(relpath) == "" or path == Path("."):
        raise ValueError("`relpath` must name a file or folder; got an empty path")
    if path.is_absolute():
        raise ValueError(f"`relpath` must be relative to a data folder; got absolute path {str(relpath)!r}")
    if ".." in path.parts:
        raise ValueError(f"`relpath` must stay inside the data folder; got {str(relpath)!r} with '..'")
    return path


def _matches(entry: DataFile, path: Path) -> bool:
    """Whether ``path`` is the registered file (hashed once per process per size and mtime)."""
    st = path.stat()
    key = (str(path), st.st_size, st.st_mtime_ns)
    if key not in _CHECKED:
        if st.st_size != entry.size and entry.pixels_sha256 is None:
            _CHECKED[key] = False
        else:
            _CHECKED[key] = derive.file_matches(entry, path.read_bytes())
    return _CHECKED[key]


def found_at(entry: DataFile) -> list[tuple[str, Path]]:
    """``(label, path)`` of every data folder that holds ``entry`` (shared candidates, then the cache).

    Parameters
    ----------
    entry : DataFile
        A registered file.

    Returns
    -------
    list of (str, pathlib.Path)
    """
    out = []
    for label, folder in data_locations():
        if folder is not None and (folder / entry.relpath).is_file():
            out.append((label, folder / entry.relpath))
    return out


def _warn_if_changed(entries, folder: Path, label: str) -> None:
    for e in entries:
        path = folder / e.relpath
        if not _matches(e, path):
            warnings.warn(
                f"{path} ({label}) differs from slamlab's registry (expected sha256 {e.sha256}, "
                f"{e.size} bytes): results from it may not be the documented ones; "
                "`python -m slamlab.data verify` lists every such file",
                DataHashWarning,
                stacklevel=3,
            )


def find_data(relpath: str | os.PathLike, *, fetch: bool = True, progress=None) -> Path:
    """Find ``relpath`` in a data folder, fetching a registered file into the cache when needed.

    Parameters
    ----------
    relpath : str or path-like
        A path relative to a data folder: a file (``"oxford-affine/graf/img1.png"``), a set
        (``"kitti-odometry-06-stereo"``) or a folder inside one (``"oxford-affine/graf"``).
    fetch : bool
        Download registered files that no data folder holds (default). ``False`` raises instead.
    progress : bool, None or callable
        A download bar per file (the ``progress=`` contract).

    Returns
    -------
    pathlib.Path
        The file or folder. A folder is returned from the first data folder that holds every
        registered file inside it (the cache, after fetching what it lacks, when none does).

    Raises
    ------
    FileNotFoundError
        When nothing matches and nothing can be fetched; the message lists every place searched
        (:class:`~slamlab.data.fetch.DataUnavailableError` when a download failed).
    slamlab.data.fetch.DataIntegrityError
        A downloaded file's hash is not the registry's (nothing is kept).
    TypeError, ValueError
        When ``relpath`` is not a relative path inside a data folder.

    Examples
    --------
    >>> find_data("test_room_200.txt").name
    'test_room_200.txt'
    >>> try:
    ...     find_data("no/such/file.txt")
    ... except FileNotFoundError as err:
    ...     print(str(err).splitlines()[0])
    'no/such/file.txt' not found in any data folder, and no registered data set holds it; searched:
    """
    rel = _check_relpath(relpath)
    check_progress(progress)
    bundled = _BUNDLED_DIR / rel
    if bundled.exists():
        return bundled
    entries = registry().files_under(rel.as_posix())
    locations = data_locations()
    if not entries:  # not registered: any data folder that has it (e.g. a set of one's own)
        for _label, folder in locations:
            if folder is not None and (folder / rel).exists():
                return folder / rel
        raise FileNotFoundError(
            f"{rel.as_posix()!r} not found in any data folder, and no registered data set holds it; searched:\n"
            + _describe([("bundled", _BUNDLED_DIR), *locations])
            + "\n`python -m slamlab.data list` lists the registered sets; "
            f"${ENV_VAR} or ../shared/data may hold other folders."
        )
    cache = cache_dir()
    for label, folder in locations:
        if folder is None or not all((folder / e.relpath).is_file() for e in entries):
            continue
        if folder == cache:
            stale = [e for e in entries if not _matches(e, folder / e.relpath)]
            if stale:  # a cached file changed since it was verified: drop it, look further, else fetch it again
                for e in stale:
                    (folder / e.relpath).unlink()
                continue
        else:
            _warn_if_changed(entries, folder, label)
        return folder / rel
    missing = [e for e in entries if not ((cache / e.relpath).is_file() and _matches(e, cache / e.relpath))]
    if missing and not fetch:
        raise DataUnavailableError(
            f"{rel.as_posix()!r}: {len(missing)} registered file(s) are in no data folder and fetch=False; searched:\n"
            + _describe(locations)
        )
    fetch_files(missing, cache, progress=progress)
    return cache / rel

