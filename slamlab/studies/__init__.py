"""The chapters' studies: experiments, ablations, figure builders, tables and widgets, one subpackage per chapter.

This layer sits above the algorithm packages (``slamlab.filters``, ``slamlab.localisation``, ...) and the
simulator (``slamlab.sim``): it imports both, and only the notebooks, the labs, the benchmarks, the tests and
the course site import it. A reader of an algorithm finds the method, its settings, its result type and its
plots in the algorithm's own package; the chapter's runs of it live here, e.g.
``sl.studies.localisation.run_global_localisation``.

- ``filters``: 01 Kalman filters;
- ``features``: 02 detectors, 03 matching;
- ``kdtree``: 03 matching, 04 landmark stores;
- ``stereo``: 05 stereo SLAM;
- ``correlation``: 06 correlation localisation;
- ``hough``: 07 Hough SLAM;
- ``localisation``: 08 probabilistic localisation;
- ``mono``: 09 monocular mapping;
- ``planes``: 10 plane-based 3-D SLAM.
"""

from __future__ import annotations

import pkgutil

from .._lazy import lazy_exports

# each chapter's studies load on first use (`sl.studies.localisation`), so `import slamlab.studies` stays light
__getattr__, __dir__ = lazy_exports(__name__, {}, submodules=[m.name for m in pkgutil.iter_modules(__path__)])
