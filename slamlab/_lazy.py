"""Attributes of a package that import their module on first use (PEP 562).

``import slamlab`` must not load ipywidgets, ``matplotlib.pyplot`` or cv2
(CONVENTIONS: imports stay light). A package re-exports its plotting and widget
functions lazily::

    from .._lazy import lazy_exports
    __getattr__, __dir__ = lazy_exports(__name__, {"plot_nees": ".plot", "explore_cv_target": ".widgets"})

``pkg.plot_nees`` then imports ``pkg.plot`` the first time it is asked for. Whole submodules that load heavy
packages (``pkg.plot``, ``pkg.widgets``; the chapter subpackages of ``slamlab`` itself) are listed in
``submodules=`` and imported the first time they are asked for. The one mechanism of the package (issue 23).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, names: Mapping[str, str], submodules: Iterable[str] = ()
                 ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``: each name in ``names`` comes from its module on first use.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    names : mapping str -> str
        An attribute and the module it comes from, relative (``".plot"``) or absolute.
    submodules : iterable of str
        Submodules of ``package`` (plain names, e.g. ``"widgets"``) imported as attributes on first use.

    Returns
    -------
    __getattr__, __dir__ : callable
        Assign them to the package's module attributes of those names (PEP 562).
    """
    table = dict(names)
    subs = frozenset(submodules)

    def __getattr__(name: str) -> Any:
        if name in subs:
            return importlib.import_module(f"{package}.{name}")  # the import binds it on the package
        try:
            module = table[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(module, package), name)
        import sys

        setattr(sys.modules[package], name, value)  # cache: later look-ups skip __getattr__
        return value

    def __dir__() -> list[str]:
        import sys

        return sorted(set(vars(sys.modules[package])) | set(table) | subs)

    return __getattr__, __dir__
