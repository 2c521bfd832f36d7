"""The fast paths of SURF (issue 17) against the plain implementations they replace.

The phase-split response maps and the shared layers of consecutive octaves must give the same
values as :func:`hessian_response` on its strided views, bit for bit (same operations in the same
order), on sizes that are and are not multiples of the grid steps.
"""

import numpy as np
import pytest

from slamlab.features import filter_sizes, hessian_response, integral_image
from slamlab.features.surf import _response_stacks


@pytest.mark.parametrize(("shape", "init_step", "n_octaves", "phase_octaves"),
                         [((96, 128), 2, 4, 1), ((101, 67), 2, 4, 4), ((77, 93), 1, 4, 2), ((64, 61), 3, 4, 4),
                          ((90, 120), 2, 6, 6), ((90, 120), 2, 6, 1)])
def test_response_stacks_equal_hessian_response_bitwise(shape, init_step, n_octaves, phase_octaves):
    """Phases (sliced from the padded image, or gathered where it is too small: octaves 5-6),
    strided views of the padded image or of a fresh one (octaves 5-6), shared layers."""
    rng = np.random.default_rng(3)
    II = integral_image(rng.random(shape))
    L = filter_sizes(n_octaves)
    stacks = _response_stacks(II, n_octaves, init_step, workers=2, phase_octaves=phase_octaves)
    for o, (D, step) in enumerate(stacks):
        assert step == init_step * 2**o
        for i in range(4):
            det, _ = hessian_response(II, int(L[o, i]), step)
            np.testing.assert_array_equal(D[i], det)
