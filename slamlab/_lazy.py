"""Attributes of a package that import their module on first use (PEP 562).

``import slamlab`` must not load ipywidgets, ``matplotlib.pyplot`` or cv2
(CONVENTIONS: imports stay light). A package re-exports its plotting and widget
functions lazily::

    from .._lazy import lazy_exports
    __getattr__, __dir__ = lazy_exports(__name__, {"plot_nees": ".plot", "explore_cv_target": ".widgets"})

``pkg.plot_nees`` then imports ``pkg.plot`` the first time it is asked for.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, names: Mapping[str, str]) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for ``package``: each name in ``names`` comes from its module on first use.

    ``names`` maps an attribute to a module, relative (``".plot"``) or absolute.
    """
    table = dict(names)

    def __getattr__(name: str) -> Any:
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

        return sorted(set(vars(sys.modules[package])) | set(table))

    return __getattr__, __dir__
