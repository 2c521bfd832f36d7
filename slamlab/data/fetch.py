"""Fetching registered files into the cache with pooch: verified, announced, and nothing bad kept.

:func:`fetch_files` downloads each file from its upstream URL (or from ``$SLAMLAB_DATA_URL``'s
mirror) with ``pooch.retrieve``: to a temporary file in the cache, checked against the
registry's sha256, and only then moved to its place, so an interrupted or corrupted download
leaves nothing behind. The first file fetched of a set prints the set's source, licence and
citation; every download prints its size and a progress bar (the ``progress=`` contract).

Failures raise one clear error, not a chain through pooch and requests:
:class:`DataUnavailableError` (no network, host or file: names the set, the URL, the size and
the two ways to provide the file) and :class:`DataIntegrityError` (a hash that differs: names
the set, the file, the URL, the expected and the received hash; the download is deleted).
"""

from __future__ import annotations

import contextlib
import logging
import os
import sys
from pathlib import Path

from .._progress import check_progress, progress_enabled
from . import derive
from .registry import (
    DATA_URL_ENV_VAR,
    DataFile,
    count_files,
    format_size,
    registry,
    source_url,
    upstream_relpath,
)

__all__ = ["DataFetchError", "DataIntegrityError", "DataUnavailableError", "download", "fetch_files", "write_atomically"]

#: Seconds pooch waits for the server (connect and each read).
TIMEOUT_S = 60

# sets whose licence and citation this process has printed
_ANNOUNCED: set[str] = set()


class DataFetchError(OSError):
    """A registered data file could not be provided."""


class DataUnavailableError(DataFetchError, FileNotFoundError):
    """The file is in no data folder and cannot be downloaded (no network, host or file)."""


class DataIntegrityError(DataFetchError):
    """A downloaded file's hash is not the registry's; the download was deleted."""


def _ways_to_provide() -> str:
    return (
        "Provide it in one of two ways:\n"
        "  1. put the data folder at ../shared/data beside the project, or set $SLAMLAB_DATA to it;\n"
        f"  2. set ${DATA_URL_ENV_VAR}=http://HOST:PORT/ to a mirror made by `python -m slamlab.data mirror DIR`\n"
        "     on a machine that has the data (serve DIR with, e.g., `python -m http.server -d DIR PORT`)."
    )


def _announce(set_name: str) -> None:
    if set_name in _ANNOUNCED:
        return
    _ANNOUNCED.add(set_name)
    s = registry().set(set_name)
    print(
        f"Data set '{s.name}' ({count_files(len(s.files))}, {format_size(s.size)}): {s.title}\n"
        f"  source:  {s.source}\n  licence: {s.licence}\n  cite:    {s.citation}",
        file=sys.stderr,
    )


class _HashingDownloader:
    """pooch's HTTP downloader that also remembers the sha256 of what it received."""

    def __init__(self, progressbar: bool):
        import pooch

        self._inner = pooch.HTTPDownloader(progressbar=progressbar, timeout=TIMEOUT_S)
        self.received_sha256: str | None = None

    def __call__(self, url, output_file, pooch_obj, check_only=False):
        self._inner(url, output_file, pooch_obj)
        self.received_sha256 = derive.sha256_bytes(Path(output_file).read_bytes())


@contextlib.contextmanager
def _quiet_pooch():
    """pooch logs every download at INFO; slamlab prints its own line with the size."""
    import pooch

    logger = pooch.get_logger()
    level = logger.level
    logger.setLevel(logging.WARNING)
    try:
        yield
    finally:
        logger.setLevel(level)


def _remove_empty_dirs(folder: Path, stop: Path) -> None:
    """Remove ``folder`` and its parents up to (not including) ``stop`` while they are empty."""
    folder, stop = folder.resolve(), stop.resolve()
    while folder != stop and stop in folder.parents:
        try:
            folder.rmdir()
        except OSError:
            return
        folder = folder.parent


def download(entry: DataFile, folder: Path, fname: str, progress: bool = False) -> Path:
    """Download ``entry``'s upstream file to ``folder/fname`` through ``pooch.retrieve``, verified.

    Parameters
    ----------
    entry : DataFile
        The registered file; its upstream file is downloaded (checked against ``fetched_sha256``).
    folder : pathlib.Path
        The folder (the cache, or a mirror).
    fname : str
        The path under ``folder``.
    progress : bool
        Show a download bar.

    Returns
    -------
    pathlib.Path
        ``folder/fname``.
    """
    cache = Path(folder)
    import pooch
    import requests

    url = source_url(entry.url)
    print(f"Fetching {entry.relpath} ({format_size(entry.fetched_size)}) from {url}", file=sys.stderr)
    downloader = _HashingDownloader(progressbar=progress)
    target = cache / fname
    try:
        with _quiet_pooch():
            path = pooch.retrieve(url, known_hash=f"sha256:{entry.fetched_sha256}", fname=fname, path=cache,
                                  downloader=downloader)
    except ValueError:
        if downloader.received_sha256 is None or downloader.received_sha256 == entry.fetched_sha256:
            raise
        _remove_empty_dirs(target.parent, cache)
        raise DataIntegrityError(
            f"The file fetched for '{entry.relpath}' (set {entry.set_name}) from {url} is not the registered one:\n"
            f"  expected sha256 {entry.fetched_sha256}\n  received sha256 {downloader.received_sha256}\n"
            "It was deleted and not used. The server holds another file at that address: remake the mirror, "
            "or report it if the address is the upstream one."
        ) from None
    except (requests.exceptions.RequestException, OSError) as err:
        _remove_empty_dirs(target.parent, cache)
        reason = _short_reason(err)
        raise DataUnavailableError(
            f"Cannot fetch '{entry.relpath}' (set {entry.set_name}, {format_size(entry.fetched_size)}) "
            f"from {url}: {reason}.\n" + _ways_to_provide()
        ) from None
    except BaseException:  # an interrupt: pooch has removed its temporary file; remove the folders made for it
        _remove_empty_dirs(target.parent, cache)
        raise
    return Path(path)


def _short_reason(err: Exception) -> str:
    import requests

    if isinstance(err, requests.exceptions.HTTPError) and err.response is not None:
        return f"the server answered HTTP {err.response.status_code}"
    if isinstance(err, requests.exceptions.Timeout):
        return f"no answer within {TIMEOUT_S} s"
    if isinstance(err, requests.exceptions.ConnectionError):
        return "no connection to the host (offline, or the host cannot be reached)"
    return f"{type(err).__name__}: {err}"


def write_atomically(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file beside it: a reader never sees half a file.

    Parameters
    ----------
    path : pathlib.Path
        The file to write (its folder is made if needed).
    data : bytes
        The contents.
    """
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.part-{os.getpid()}")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _fetch_one(entry: DataFile, cache: Path, progress: bool) -> Path:
    _announce(entry.set_name)
    target = cache / entry.relpath
    if entry.derive is None:
        return download(entry, cache, entry.relpath, progress)
    # a derived file: fetch the upstream file beside the cache's sets, derive, keep only the result
    fname = f".upstream/{upstream_relpath(entry.url)}"
    upstream = download(entry, cache, fname, progress)
    try:
        data = derive.make_derived(entry, upstream.read_bytes())
        if not derive.file_matches(entry, data):
            raise DataIntegrityError(
                f"'{entry.relpath}' (set {entry.set_name}) made from {entry.url} does not match the registry: "
                f"expected sha256 {entry.sha256}, made {derive.sha256_bytes(data)}. Nothing was kept."
            )
        write_atomically(target, data)
    finally:
        upstream.unlink(missing_ok=True)
        _remove_empty_dirs(upstream.parent, cache)
    return target


def fetch_files(entries, cache: Path, progress=None) -> list[Path]:
    """Fetch registered files into ``cache`` (same relative layout as the shared data folder).

    Parameters
    ----------
    entries : iterable of DataFile
        The files to fetch (whether or not they are already there: the caller decides).
    cache : pathlib.Path
        The cache folder.
    progress : bool, None or callable
        A download bar per file (the ``progress=`` contract; a callable gets no bar).

    Returns
    -------
    list of pathlib.Path
        The fetched files' paths in the cache.

    Raises
    ------
    DataUnavailableError
        No network, host or file; the message says how else to provide it.
    DataIntegrityError
        The received file's hash is not the registry's; nothing was kept.
    """
    check_progress(progress)
    bar = progress_enabled(progress) if isinstance(progress, bool | None) else False
    cache = Path(cache)
    return [_fetch_one(e, cache, bar) for e in entries]
