"""The fast paths of SURF (issue 17) against the plain implementations they replace.

The phase-split response maps and the shared layers of consecutive octaves must give the same
values as :func:`hessian_response` on its strided views, bit for bit (same operations in the same
order), on sizes that are and are not multiples of the grid steps.
"""

import numpy as np
import pytest

from slamlab.features import filter_sizes, hessian_response, integral_image
from slamlab.features.surf import _response_stacks


@pytest.mark.parametrize(("shape", "init_step"), [((96, 128), 2), ((101, 67), 2), ((77, 93), 1), ((64, 61), 3)])
def test_response_stacks_equal_hessian_response_bitwise(shape, init_step):
    rng = np.random.default_rng(3)
    II = integral_image(rng.random(shape))
    L = filter_sizes(4)
    stacks = _response_stacks(II, 4, init_step, workers=2)
    for o, (D, T, step) in enumerate(stacks):
        assert step == init_step * 2**o
        for i in range(4):
            det, trace = hessian_response(II, int(L[o, i]), step)
            np.testing.assert_array_equal(D[i], det)
            np.testing.assert_array_equal(T[i], trace)
