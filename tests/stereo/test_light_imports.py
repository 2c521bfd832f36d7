"""``import slamlab.features, slamlab.kdtree, slamlab.stereo`` loads no cv2, ipywidgets or pyplot (CONVENTIONS)."""

import subprocess
import sys
import textwrap

import pytest

HEAVY = ("cv2", "ipywidgets", "matplotlib.pyplot")


def _run(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, check=True,
                         env={"MPLBACKEND": "Agg", "PATH": ""})
    return out.stdout.strip()


def test_the_three_packages_import_nothing_heavy_themselves():
    # every heavy import is attributed to the module that asked for it; ours (features, kdtree,
    # stereo) must ask for none at import time (plots, widgets and cv2 load on first use)
    code = f"""
    import builtins, sys
    heavy, seen, orig = {HEAVY!r}, [], builtins.__import__
    def hook(name, globals=None, locals=None, fromlist=(), level=0):
        if name in heavy and name not in sys.modules:
            seen.append(f"{{(globals or {{}}).get('__name__')}} -> {{name}}")
        return orig(name, globals, locals, fromlist, level)
    builtins.__import__ = hook
    import slamlab.features, slamlab.kdtree, slamlab.stereo
    print(";".join(s for s in seen if s.startswith(("slamlab.features", "slamlab.kdtree", "slamlab.stereo"))))
    """
    assert _run(code) == ""


def test_lazy_names_still_resolve():
    code = """
    import sys, slamlab.features as F, slamlab.kdtree as K, slamlab.stereo as S
    print(callable(F.plot_matches), callable(K.plot_cost_contour), callable(S.run_figure),
          K.store_plot.__name__, "plot_matches" in dir(F))
    """
    assert _run(code) == "True True True slamlab.kdtree.store_plot True"


@pytest.mark.xfail(strict=True, reason="outside this part: slamlab/__init__ imports filters (filters.plot -> pyplot, "
                   "filters.widgets -> ipywidgets) and sim (sim.arena -> cv2) at import time")
def test_import_loads_no_cv2_ipywidgets_or_pyplot():
    code = f"""
    import slamlab.features, slamlab.kdtree, slamlab.stereo, sys
    print(",".join(m for m in {HEAVY!r} if m in sys.modules))
    """
    assert _run(code) == ""
