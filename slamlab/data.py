"""Locating data: the project's ``data/``, ``$SLAMLAB_DATA`` and ``../shared/data``.

Small files the project makes itself (maps, scenario configs) live in the
project's ``data/`` folder. Real public data sets (Oxford affine, KITTI, CARMEN
logs, ...) are never copied into the project: they live in a *shared data
folder*, found in this order:

1. ``$SLAMLAB_DATA`` when the variable is set;
2. ``../shared/data`` relative to the project root (the folder holding
   ``pyproject.toml`` and the ``slamlab`` package);
3. ``../shared/data`` relative to the current working directory and each of its
   parents (a fallback for notebooks run from ``notebooks/`` or a copy of the
   package installed elsewhere).

:func:`find_data` looks for a relative path in the project's ``data/`` first,
then in each of these. Whatever is not found raises ``FileNotFoundError`` whose
message names every place searched.
"""

from __future__ import annotations

import os
from pathlib import Path

from ._validate import check_choice

__all__ = [
    "ENV_VAR",
    "data_root",
    "find_data",
    "project_data_dir",
    "project_root",
    "shared_data_dir",
]

#: Environment variable that points at the shared (real) data folder.
ENV_VAR = "SLAMLAB_DATA"

_PACKAGE_DIR = Path(__file__).resolve().parent


def project_root() -> Path | None:
    """The source checkout holding the ``slamlab`` package, or ``None``.

    It is the package's parent folder when that folder has a ``pyproject.toml``
    (an editable install or a plain checkout); ``None`` for an installed copy.

    >>> (project_root() / "pyproject.toml").is_file()
    True
    """
    root = _PACKAGE_DIR.parent
    return root if (root / "pyproject.toml").is_file() else None


def project_data_dir() -> Path:
    """The project's own ``data/`` folder (small project-made files).

    Returns
    -------
    pathlib.Path
        ``<project root>/data``.

    Raises
    ------
    FileNotFoundError
        When slamlab does not run from a source checkout or the folder is missing.

    Examples
    --------
    >>> project_data_dir().name
    'data'
    """
    root = project_root()
    if root is None:
        raise FileNotFoundError(
            f"project data folder not found; searched: {_PACKAGE_DIR.parent / 'data'} "
            "(slamlab is not running from a source checkout with pyproject.toml)"
        )
    folder = root / "data"
    if not folder.is_dir():
        raise FileNotFoundError(f"project data folder not found; searched: {folder}")
    return folder


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
    # drop repeated paths, keep the first label
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


def _describe(candidates: list[tuple[str, Path | None]]) -> str:
    return "\n".join(
        f"  - {label}: {'(not set)' if path is None else path}" for label, path in candidates
    )


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

    Examples
    --------
    >>> try:
    ...     folder = shared_data_dir()
    ... except FileNotFoundError as err:
    ...     folder = None
    ...     assert "searched" in str(err)
    >>> folder is None or folder.is_dir()
    True
    """
    candidates = _shared_candidates()
    for _label, path in candidates:
        if path is not None and path.is_dir():
            return path
    raise FileNotFoundError(
        "shared data folder not found; searched:\n"
        + _describe(candidates)
        + f"\nSet ${ENV_VAR} to the folder or place it at ../shared/data beside the project."
    )


def data_root(kind: str = "shared") -> Path:
    """The data folder of the given ``kind``: ``"shared"`` (real data) or ``"project"``.

    Parameters
    ----------
    kind : {"shared", "project"}
        ``"shared"`` gives :func:`shared_data_dir`, ``"project"`` gives
        :func:`project_data_dir`.

    Examples
    --------
    >>> data_root("project") == project_data_dir()
    True
    >>> data_root("other")
    Traceback (most recent call last):
    ...
    ValueError: `kind` must be one of 'shared', 'project'; got 'other'
    """
    check_choice(kind, "kind", ("shared", "project"))
    return shared_data_dir() if kind == "shared" else project_data_dir()


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


def find_data(relpath: str | os.PathLike) -> Path:
    """Find ``relpath`` in the project ``data/`` or the shared data folder.

    Parameters
    ----------
    relpath : str or path-like
        Path relative to a data folder, e.g. ``"oxford-affine/graf/img1.png"``.

    Returns
    -------
    pathlib.Path
        The first existing match, searched in the project's ``data/``, then
        ``$SLAMLAB_DATA``, then ``../shared/data`` beside the project root, then
        beside the working folder and its parents.

    Raises
    ------
    FileNotFoundError
        When nothing matches; the message lists every path tried.
    TypeError, ValueError
        When ``relpath`` is not a relative path inside a data folder.

    Examples
    --------
    >>> try:
    ...     find_data("no/such/file.txt")
    ... except FileNotFoundError as err:
    ...     print(str(err).splitlines()[0])
    'no/such/file.txt' not found in any data folder; searched:
    """
    rel = _check_relpath(relpath)
    candidates: list[tuple[str, Path | None]] = []
    root = project_root()
    if root is not None:
        candidates.append(("project data/", root / "data"))
    candidates.extend(_shared_candidates())
    tried: list[tuple[str, Path | None]] = []
    for label, folder in candidates:
        path = None if folder is None else folder / rel
        tried.append((label, path))
        if path is not None and path.exists():
            return path
    raise FileNotFoundError(
        f"{rel.as_posix()!r} not found in any data folder; searched:\n"
        + _describe(tried)
        + f"\nSet ${ENV_VAR} to the shared data folder or place it at ../shared/data beside the project."
    )
