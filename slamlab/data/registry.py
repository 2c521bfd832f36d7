"""The data registry: every real data file slamlab reads, where it comes from and its hash.

The registry is the JSON file ``registry.json`` beside this module (data, not code). Each
*set* (a folder of the shared data, e.g. ``carmen-radish-corrected``) has a title, its
source repository and commit, its licence and citation; each *file* has its path in the
set, its upstream URL at the pinned commit, and the sha256 and size of the file as slamlab
uses it. A *derived* file (a few of the sets keep the first lines of a longer upstream file,
or store the upstream PPM images as lossless PNG) also records the upstream file's sha256
and size and the rule ``derive`` that makes it (see :mod:`slamlab.data.derive`).

The README's data table and the course site's data page are generated from this registry
(:func:`data_table_markdown`), so it is the one source of what the data are.
"""

from __future__ import annotations

import functools
import json
import os
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from urllib.parse import urlsplit

__all__ = [
    "DATA_URL_ENV_VAR",
    "DataFile",
    "DataSet",
    "Registry",
    "count_files",
    "data_table_markdown",
    "format_size",
    "load_registry",
    "registry",
    "source_url",
    "upstream_relpath",
]

#: Environment variable naming a mirror (``http://HOST:PORT/``) that serves every upstream file at
#: ``<mirror>/<host>/<path>`` (the layout ``python -m slamlab.data mirror DIR`` writes).
DATA_URL_ENV_VAR = "SLAMLAB_DATA_URL"

REGISTRY_PATH = Path(__file__).resolve().parent / "registry.json"


@dataclass(frozen=True)
class DataFile:
    """One registered file: ``relpath`` (``<set>/<path>``), upstream ``url``, ``sha256`` and ``size``.

    Attributes
    ----------
    set_name : str
        The set (a folder of the data layout) the file belongs to.
    path : str
        The file's path inside its set.
    url : str
        The upstream URL at the pinned commit.
    sha256 : str
        Hex sha256 of the file as slamlab uses it.
    size : int
        Its size in bytes.
    upstream_sha256, upstream_size : str, int or None
        For a derived file, the upstream file's hash and size; ``None`` for a copy.
    derive : dict or None
        ``None`` for a byte-for-byte copy of the upstream file; otherwise the rule that makes the
        file from the upstream one (:mod:`slamlab.data.derive`).
    pixels_sha256 : str or None
        For an image made from the upstream one, the hash of its decoded pixels (the PNG's bytes
        depend on the encoder).
    """

    set_name: str
    path: str
    url: str
    sha256: str
    size: int
    upstream_sha256: str | None = None
    upstream_size: int | None = None
    derive: dict | None = None
    pixels_sha256: str | None = None

    @property
    def relpath(self) -> str:
        """``<set>/<path>``: the file's place under any data folder."""
        return f"{self.set_name}/{self.path}"

    @property
    def fetched_sha256(self) -> str:
        """The hash of what is downloaded: the upstream file's."""
        return self.upstream_sha256 or self.sha256

    @property
    def fetched_size(self) -> int:
        """The size of what is downloaded, in bytes."""
        return self.upstream_size if self.upstream_size is not None else self.size


@dataclass(frozen=True)
class DataSet:
    """One registered set: its name, what it is, its source, licence, citation and files.

    Attributes
    ----------
    name : str
        The set's folder name, e.g. ``"carmen-radish-corrected"``.
    title : str
        What the set is, in one line.
    source : str
        The upstream repository and pinned commit.
    licence, citation : str
        As the source states them.
    files : tuple of DataFile
        The set's registered files.
    note : str
        How any file differs from its upstream copy ("" when none does).
    """

    name: str
    title: str
    source: str
    licence: str
    citation: str
    files: tuple[DataFile, ...]
    note: str = ""

    @property
    def size(self) -> int:
        """Bytes of the set's files as used."""
        return sum(f.size for f in self.files)


class Registry:
    """Every registered set, with look-ups by set name and by relative path.

    Parameters
    ----------
    sets : sequence of DataSet
        The sets, in registry order.
    """

    def __init__(self, sets):
        self.sets: tuple[DataSet, ...] = tuple(sets)
        self._by_relpath = {f.relpath: f for s in self.sets for f in s.files}

    def __repr__(self) -> str:
        return f"Registry({len(self.sets)} sets, {len(self._by_relpath)} files)"

    def set(self, name: str) -> DataSet:
        """The set called ``name``.

        Parameters
        ----------
        name : str
            A set's name.

        Returns
        -------
        DataSet

        Raises
        ------
        KeyError
            Naming the registered sets, when there is no such set.
        """
        for s in self.sets:
            if s.name == name:
                return s
        raise KeyError(f"no data set {name!r} in the registry; registered: {', '.join(self.set_names)}")

    @property
    def set_names(self) -> tuple[str, ...]:
        """The registered sets' names, in registry order."""
        return tuple(s.name for s in self.sets)

    @property
    def files(self) -> tuple[DataFile, ...]:
        """Every registered file."""
        return tuple(f for s in self.sets for f in s.files)

    def files_under(self, relpath: str) -> tuple[DataFile, ...]:
        """The registered file at ``relpath``, or every registered file inside the folder ``relpath``.

        Parameters
        ----------
        relpath : str
            A path relative to a data folder (``"oxford-affine/graf"``, ``"kitti-odometry-06-stereo/calib.txt"``).

        Returns
        -------
        tuple of DataFile
            Empty when ``relpath`` is neither (e.g. a file the registry does not list).
        """
        rel = PurePosixPath(relpath).as_posix()
        if rel in self._by_relpath:
            return (self._by_relpath[rel],)
        prefix = rel.rstrip("/") + "/"
        return tuple(f for f in self._by_relpath.values() if f.relpath.startswith(prefix))


def _file_from_json(set_name: str, entry: dict) -> DataFile:
    return DataFile(set_name=set_name, **entry)


def load_registry(path: str | os.PathLike = REGISTRY_PATH) -> Registry:
    """Read a registry file (the package's own ``registry.json`` by default).

    Parameters
    ----------
    path : str or path-like
        A JSON file in the registry's format.

    Returns
    -------
    Registry

    Examples
    --------
    >>> reg = load_registry()
    >>> reg.set("carmen-radish-corrected").files[0].relpath
    'carmen-radish-corrected/csail-corrected.log.gz'
    """
    raw = json.loads(Path(path).read_text(encoding="utf-8"))
    if raw.get("format") != 1:
        raise ValueError(f"{path}: registry format {raw.get('format')!r} is not 1")
    sets = []
    for s in raw["sets"]:
        files = tuple(_file_from_json(s["name"], e) for e in s["files"])
        meta = {k: s.get(k, "") for k in ("title", "source", "licence", "citation", "note")}
        sets.append(DataSet(name=s["name"], files=files, **meta))
    return Registry(tuple(sets))


@functools.cache
def registry() -> Registry:
    """The package's registry (read once per process)."""
    return load_registry()


def upstream_relpath(url: str) -> str:
    """``<host>/<path>`` of an upstream URL: its place in a mirror folder.

    Parameters
    ----------
    url : str
        An http(s) URL.

    Returns
    -------
    str

    Examples
    --------
    >>> upstream_relpath("https://raw.githubusercontent.com/o/r/abc/data/x.log.gz")
    'raw.githubusercontent.com/o/r/abc/data/x.log.gz'
    """
    parts = urlsplit(url)
    return f"{parts.netloc}{parts.path}"


def source_url(url: str) -> str:
    """Where to fetch ``url`` from: the URL itself, or ``<$SLAMLAB_DATA_URL>/<host>/<path>`` when that is set.

    Parameters
    ----------
    url : str
        A registered upstream URL.

    Returns
    -------
    str
    """
    mirror = os.environ.get(DATA_URL_ENV_VAR, "").strip()
    if not mirror:
        return url
    return mirror.rstrip("/") + "/" + upstream_relpath(url)


def count_files(n: int) -> str:
    """``'1 file'``, ``'5 files'``.

    Parameters
    ----------
    n : int
        A file count.

    Returns
    -------
    str

    Examples
    --------
    >>> count_files(1), count_files(347)
    ('1 file', '347 files')
    """
    return f"{n} file" if n == 1 else f"{n} files"


def format_size(n_bytes: int) -> str:
    """A byte count for people: ``'448 kB'``, ``'27.8 MB'`` (decimal units, as pip prints them).

    Parameters
    ----------
    n_bytes : int
        A size in bytes.

    Returns
    -------
    str

    Examples
    --------
    >>> format_size(448366), format_size(27_812_345), format_size(177)
    ('448 kB', '27.8 MB', '177 B')
    """
    if n_bytes < 1000:
        return f"{n_bytes} B"
    if n_bytes < 1_000_000:
        return f"{n_bytes / 1000:.0f} kB"
    return f"{n_bytes / 1e6:.1f} MB"


def data_table_markdown(reg: Registry | None = None) -> str:
    """The data sets as a Markdown table: name, what, files, size, source, licence, citation.

    The README's data section and the course site's data page print this table, so both
    follow the registry.

    Parameters
    ----------
    reg : Registry or None
        The registry (the package's own by default).

    Returns
    -------
    str
        The table, with a final row of totals.
    """
    reg = registry() if reg is None else reg
    rows = [
        "| set | what | files | size | source (pinned commit) | licence | cite |",
        "|---|---|---|---|---|---|---|",
    ]
    for s in reg.sets:
        cells = [f"`{s.name}`", s.title, str(len(s.files)), format_size(s.size), s.source, s.licence, s.citation]
        rows.append("| " + " | ".join(c.replace("|", "\\|").replace("<", "\\<") for c in cells) + " |")
    total = sum(s.size for s in reg.sets)
    n_files = sum(len(s.files) for s in reg.sets)
    rows.append(f"| **all** | | {n_files} | {format_size(total)} | | | |")
    return "\n".join(rows) + "\n"
