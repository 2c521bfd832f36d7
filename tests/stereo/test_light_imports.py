"""The plot, widget and cv2-backed names of features, kdtree and stereo (and their studies) load on first use
(tests/test_imports.py checks that importing the packages loads no cv2, ipywidgets or pyplot)."""

import subprocess
import sys
import textwrap


def _run(code: str) -> str:
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, check=True,
                         env={"MPLBACKEND": "Agg", "PATH": ""})
    return out.stdout.strip()


def test_lazy_names_still_resolve():
    code = """
    import sys, slamlab.features as F, slamlab.studies.kdtree as K, slamlab.stereo as S, slamlab.studies.stereo as SS
    print(callable(F.plot_matches), callable(K.plot_cost_contour), callable(S.plot_frame_stages), callable(SS.run_figure),
          K.store_plot.__name__, "plot_matches" in dir(F))
    """
    assert _run(code) == "True True True True slamlab.studies.kdtree.store_plot True"
