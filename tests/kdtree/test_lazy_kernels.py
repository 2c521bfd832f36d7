"""Memory of a student's kernel: a notebook pays only for the compiled kernels it calls (issue 45).

Checked through the kernel registry and ``sys.modules``, not RSS: cheap and the same on every machine.
"""

import os
import subprocess
import sys

import numpy as np
import pytest

from slamlab._compiled import numba_enabled

_CODE = """
import sys
import numpy as np
import slamlab as sl
from slamlab._compiled import loaded_kernels
assert loaded_kernels() == (), loaded_kernels()
X = np.random.default_rng(0).standard_normal((500, 8)).astype(np.float32)
sl.kdtree.KDTree(X).query(X[:20], k=2)
print(repr(loaded_kernels()))
print(sorted(m for m in ("slamlab.hough._kernels", "slamlab.stereo._sad_kernel", "slamlab.stereo.window_kernel",
                         "slamlab.kdtree._hamming_kernel", "slamlab.kdtree._brute_kernel") if m in sys.modules))
"""


@pytest.mark.skipif(not numba_enabled(), reason="numba switched off")
def test_one_search_loads_the_bbf_kernel_and_no_other():
    # the kd-tree search calls one kernel; the Hough, stereo and brute-force kernels stay unloaded
    # (their modules not even imported), so their machine code takes no memory in this process
    out = subprocess.run([sys.executable, "-c", _CODE], check=True, capture_output=True, text=True).stdout.split("\n")
    assert out[0] == "('slamlab.kdtree._kernels._bbf_lockstep',)"
    assert out[1] == "[]"


def test_the_numpy_path_loads_no_kernel_and_no_numba():
    code = _CODE + "assert loaded_kernels() == () and 'numba' not in sys.modules\n"
    env = {**os.environ, "SLAMLAB_NO_NUMBA": "1"}
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, env=env)


def test_the_registry_names_a_kernel_once_on_its_first_call():
    from slamlab._compiled import kernel, loaded_kernels

    def _twice(x):
        return 2 * x

    f = kernel(_twice)
    name = f"{_twice.__module__}.{_twice.__qualname__}"
    assert name not in loaded_kernels()  # defined, not called: nothing compiled
    if not numba_enabled():
        pytest.skip("numba switched off")
    assert f(np.int64(3)) == 6
    assert f(np.int64(4)) == 8
    assert loaded_kernels().count(name) == 1
