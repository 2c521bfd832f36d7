"""The data commands: list the sets, fetch them, verify every file found, write a mirror.

``python -m slamlab.data list | fetch [SET ...] | verify | mirror DIR`` (and ``make data``)
call these functions; each returns what it prints, so a notebook or a test can use it too.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from .._progress import check_progress, progress_enabled
from . import derive
from .fetch import download, write_atomically
from .locate import cache_dir, find_data, found_at
from .registry import DataFile, count_files, format_size, registry, upstream_relpath

__all__ = ["VerifyRow", "fetch_sets", "list_sets", "make_mirror", "verify"]


def _check_set_names(names) -> list[str]:
    reg = registry()
    names = list(names) if names else list(reg.set_names)
    unknown = [n for n in names if n not in reg.set_names]
    if unknown:
        raise ValueError(f"`sets`: no data set {', '.join(map(repr, unknown))}; registered: {', '.join(reg.set_names)}")
    return names


def _where(entries) -> str:
    """Where a set's files are found: one location's label, several, or 'not found'."""
    labels = []
    n_found = 0
    for e in entries:
        hits = found_at(e)
        if hits:
            n_found += 1
            if hits[0][0] not in labels:
                labels.append(hits[0][0])
    if n_found == 0:
        return "not found (fetched on first use)"
    where = " + ".join(labels)
    return where if n_found == len(entries) else f"{n_found}/{len(entries)} files: {where}"


def list_sets() -> str:
    """A table of the registered sets: files, size, licence and where each is found.

    Returns
    -------
    str
        One block per set, then the totals and the cache folder.
    """
    reg = registry()
    lines = []
    for s in reg.sets:
        lines += [
            f"{s.name}  ({count_files(len(s.files))}, {format_size(s.size)})",
            f"  {s.title}",
            f"  licence: {s.licence}",
            f"  found:   {_where(s.files)}",
        ]
    total = sum(s.size for s in reg.sets)
    lines.append(f"{len(reg.sets)} sets, {len(reg.files)} files, {format_size(total)}; cache: {cache_dir()}")
    return "\n".join(lines)


def fetch_sets(names=(), progress=None) -> str:
    """Make every file of the named sets (all by default) available, fetching what no data folder holds.

    Parameters
    ----------
    names : sequence of str
        Set names (``python -m slamlab.data list``); empty for every set.
    progress : bool, None or callable
        Download bars (the ``progress=`` contract).

    Returns
    -------
    str
        One line per set: where it is found.
    """
    lines = []
    for name in _check_set_names(names):
        folder = find_data(name, progress=progress)
        lines.append(f"{name}: {count_files(len(registry().set(name).files))} in {folder}")
    return "\n".join(lines)


@dataclass(frozen=True)
class VerifyRow:
    """One registered file at one place where it was found, and whether its hash matches.

    Attributes
    ----------
    relpath : str
        ``<set>/<path>``.
    where : str
        The data folder's label (``"-"`` when found nowhere).
    path : pathlib.Path or None
        The file found, or ``None``.
    status : str
        ``"match"``, ``"pixels match"`` (an image with the registered pixels), ``"DIFFERS"`` or ``"missing"``.
    """

    relpath: str
    where: str
    path: Path | None
    status: str  # "match", "pixels match", "DIFFERS", "missing"


def verify(names=()) -> list[VerifyRow]:
    """Re-hash every registered file everywhere it is found (shared folders and the cache).

    Parameters
    ----------
    names : sequence of str
        Set names; empty for every set.

    Returns
    -------
    list of VerifyRow
        A row per file and place; a file found nowhere gets one ``"missing"`` row.
    """
    rows = []
    for name in _check_set_names(names):
        for e in registry().set(name).files:
            hits = found_at(e)
            if not hits:
                rows.append(VerifyRow(e.relpath, "-", None, "missing"))
            for label, path in hits:
                data = path.read_bytes()
                if derive.sha256_bytes(data) == e.sha256:
                    status = "match"
                elif derive.file_matches(e, data):
                    status = "pixels match"
                else:
                    status = "DIFFERS"
                rows.append(VerifyRow(e.relpath, label, path, status))
    return rows


def verify_report(rows: list[VerifyRow], every_file: bool = False) -> tuple[str, bool]:
    """The text of :func:`verify`'s rows: per set and place, counts; every file that is not a match.

    Parameters
    ----------
    rows : list of VerifyRow
        What :func:`verify` returned.
    every_file : bool
        Also list the files that match.

    Returns
    -------
    (str, bool)
        The report and whether every registered file was found and matched everywhere.
    """
    reg = registry()
    out = []
    ok = True
    for s in reg.sets:
        mine = [r for r in rows if r.relpath.split("/", 1)[0] == s.name]
        if not mine:
            continue
        places: dict[str, list[VerifyRow]] = {}
        for r in mine:
            places.setdefault(r.where, []).append(r)
        for where, rs in places.items():
            n_match = sum(r.status in ("match", "pixels match") for r in rs)
            if where == "-":
                out.append(f"{s.name}: {len(rs)} of {len(s.files)} files MISSING (python -m slamlab.data fetch {s.name})")
            else:
                root = str(rs[0].path)[: -len(rs[0].relpath) - 1]
                out.append(f"{s.name}: {n_match}/{len(rs)} files match the registry in {where} ({root})")
        for r in mine:
            if r.status in ("DIFFERS", "missing"):
                ok = False
            if every_file or r.status not in ("match",):
                out.append(f"  {r.status:12s} {r.relpath}" + (f"  ({r.path})" if r.path is not None else ""))
    n_files = len({r.relpath for r in rows})
    n_bad = len({r.relpath for r in rows if r.status in ("DIFFERS", "missing")})
    out.append(f"{n_files} registered files checked: {n_files - n_bad} found with matching hashes, {n_bad} not")
    return "\n".join(out), ok


def _upstream_bytes(entries: list[DataFile]) -> bytes | None:
    """The upstream file shared by ``entries``, rebuilt from any of them found in a data folder."""
    for e in entries:
        for _label, path in found_at(e):
            for candidate in derive.upstream_candidates(e, path.read_bytes()):
                if derive.sha256_bytes(candidate) == e.fetched_sha256:
                    return candidate
    return None


def make_mirror(dest: str | os.PathLike, progress=None) -> str:
    """Write every registered upstream file under ``dest/<host>/<path>``, for a lab room without internet.

    Each file is taken from wherever it is found (``$SLAMLAB_DATA``, ``../shared/data``, the cache)
    and checked against its upstream sha256; a file found nowhere is fetched first. Serve ``dest``
    over http (``python -m http.server -d DIR PORT``) and set ``$SLAMLAB_DATA_URL=http://HOST:PORT/``
    on the students' machines.

    Parameters
    ----------
    dest : str or path-like
        The mirror folder (created if needed).
    progress : bool, None or callable
        Download bars for files fetched first.

    Returns
    -------
    str
        What was written: files, bytes, the folder and the variable to set.
    """
    dest = Path(dest)
    by_url: dict[str, list[DataFile]] = {}
    for e in registry().files:
        by_url.setdefault(e.url, []).append(e)
    check_progress(progress)
    bar = progress_enabled(progress) if isinstance(progress, bool | None) else False
    n_bytes = n_fetched = 0
    for url, entries in by_url.items():
        target = dest / upstream_relpath(url)
        if target.is_file() and derive.sha256_bytes(target.read_bytes()) == entries[0].fetched_sha256:
            n_bytes += target.stat().st_size
            continue
        data = _upstream_bytes(entries)
        if data is None:  # in no data folder, or only as an excerpt: download it into the mirror
            n_fetched += 1
            n_bytes += download(entries[0], dest, upstream_relpath(url), bar).stat().st_size
            continue
        write_atomically(target, data)
        n_bytes += len(data)
    return (
        f"mirror: {len(by_url)} upstream files ({n_fetched} downloaded), {format_size(n_bytes)}, in {dest.resolve()}\n"
        f"serve it (e.g. python -m http.server -d {dest} 8000) and set SLAMLAB_DATA_URL=http://HOST:8000/"
    )

