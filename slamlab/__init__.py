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
__all__ = ["__version__", "chapters", "data", "filters", "geometry", "notebook_setup", "plotting", "sim"]


# the chapter subpackages and modules, found without importing them
__getattr__, __dir__ = lazy_exports(
    __name__, {}, submodules=[m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_")])


def notebook_setup(*, dpi: int = 80, precision: int = 4) -> None:
    """Shared notebook set-up: deterministic printing and plot defaults.

    Sets numpy print options (fixed ``precision``, no scientific noise on tiny
    values) and matplotlib rcParams (figure size, ``dpi``, grid, a style that
    prints the same on every machine). Safe to call more than once.
    """
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
