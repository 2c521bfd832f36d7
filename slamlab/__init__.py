"""slamlab: SLAM lab kit — a library plus numbered notebooks rebuilding the source chapters.

The notebooks start with::

    %matplotlib inline
    import numpy as np
    import slamlab as sl
    sl.notebook_setup()
    SEED = 2010
"""

from __future__ import annotations

import pkgutil

from . import chapters, data, geometry
from ._lazy import lazy_exports

__version__ = "0.1.0"

# Every other subpackage (filters, sim, plotting, features, ...) is imported on first use by
# lazy_exports' __getattr__ below, so `import slamlab` loads no ipywidgets, matplotlib.pyplot or cv2 (tested).
__all__ = ["__version__", "chapters", "data", "filters", "geometry", "notebook_setup", "plotting", "sim",
           "versions_line"]


# the chapter subpackages and modules, found without importing them
__getattr__, __dir__ = lazy_exports(
    __name__, {}, submodules=[m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")])


#: the distributions whose versions a notebook's first output states (label, distribution names tried in order)
_STORED_WITH = (("numpy", ("numpy",)), ("scipy", ("scipy",)),
                ("OpenCV", ("opencv-python-headless", "opencv-python", "opencv-contrib-python-headless",
                            "opencv-contrib-python")),
                ("slamlab", ("slamlab",)))


def versions_line() -> str:
    """The versions of numpy, scipy, OpenCV and slamlab in this environment, as one line.

    A notebook's first output (:func:`notebook_setup`) prints it, so the stored outputs say which versions they were
    stored with; a student whose line differs knows why a number may differ (``make test-latest`` lists such cells).
    The versions are read from the installed distributions' metadata, so nothing (not even ``cv2``) is imported.

    Returns
    -------
    str
        ``"stored with numpy 2.4.0 · scipy 1.17.0 · OpenCV 5.0.0.93 · slamlab 0.1.0"``; a package that is not
        installed shows as ``"not installed"``.
    """
    from importlib import metadata

    parts = []
    for label, names in _STORED_WITH:
        version = "not installed"
        for name in names:
            try:
                version = metadata.version(name)
                break
            except metadata.PackageNotFoundError:
                continue
        if label == "slamlab" and version == "not installed":
            version = __version__
        parts.append(f"{label} {version}")
    return "stored with " + " · ".join(parts)


def notebook_setup(*, dpi: int = 80, precision: int = 4, show_versions: bool = True) -> None:
    """Shared notebook set-up: deterministic printing, plot defaults and the versions line.

    Sets numpy print options (fixed ``precision``, no scientific noise on tiny
    values) and matplotlib rcParams (figure size, ``dpi``, grid, a style that
    prints the same on every machine). Safe to call more than once.

    Parameters
    ----------
    dpi : int
        Figure and savefig resolution.
    precision : int
        numpy's print precision.
    show_versions : bool
        Print :func:`versions_line` (the notebook's first output: the versions its outputs were stored with).

    Notes
    -----
    On Linux with glibc it also caps malloc's arenas and fixes its mmap threshold (``slamlab._heap``), so that a
    kernel's freed large arrays go back to the system (a student's kernel in 512 MiB).
    """
    from ._heap import limit_heap_growth

    limit_heap_growth()
    import matplotlib as mpl
    import numpy as np

    np.set_printoptions(precision=precision, suppress=True, linewidth=100)
    mpl.rcParams.update(
        {
            "figure.figsize": (7.0, 4.2),
            "figure.dpi": dpi,
            "savefig.dpi": dpi,
            "axes.grid": True,
            "grid.alpha": 0.3,
            "axes.spines.top": False,
            "axes.spines.right": False,
            "legend.frameon": False,
            "font.size": 10,
            "image.cmap": "viridis",
        }
    )
    if show_versions:
        print(versions_line())
