"""The injection step's use of the random stream does not depend on how p_inj rounds (003 eq 2.11).

numpy's exp/log kernels differ in the last bits between CPUs with and without AVX-512; at the first updates the
two averages of eqs 2.9, 2.10 hold the same term, so p_inj was 0 on one machine and 1e-16 on another, and the
stream was drawn from on one of them only: notebook 08's kidnap table then differed by machine.
"""

import numpy as np
import pytest

from slamlab import localisation as L
from slamlab import sim as S
from slamlab.localisation.mcl import LOG_AVERAGE_TIE, _injection_probability


def test_a_tie_within_rounding_injects_nothing_and_a_real_gap_gives_eq_2_11():
    a = -3.2
    assert _injection_probability(a, a) == 0.0
    assert _injection_probability(a, np.nextafter(a, -np.inf)) == 0.0  # one ulp below: rounding, not a drop
    assert _injection_probability(a, a - 0.5 * LOG_AVERAGE_TIE) == 0.0
    assert _injection_probability(a, a + 1.0) == 0.0  # w_fast above w_slow
    assert _injection_probability(-np.inf, a) == 0.0  # w_slow = 0: no average yet
    # eq 2.11: max(0, 1 − w_fast / w_slow)
    assert _injection_probability(a, a + np.log(0.25)) == pytest.approx(0.75, rel=1e-14)
    assert _injection_probability(a, a - 1e-6) == pytest.approx(1 - np.exp(-1e-6), rel=1e-9)


@pytest.fixture(scope="module")
def step_inputs():
    M = S.test_room_200()
    P = S.path_004(21)
    scans = S.simulate_scans(M, P, S.Rangefinder(n_beams=60, max_range_cells=60, range_std_cells=0.5), rng=1)
    f = L.MCL(M, 60.0, n_particles=300, rng=0, init_pose=P[0], init_std=(1.0, 1.0, 0.05), resample_threshold=1.0)
    return f, scans[0]


def _step(f, scan, log_slow, log_fast):
    st = f.state
    state = L.MCLState(st.particles.copy(), st.weights.copy(), log_slow, log_fast, False, 10**6)
    rng = np.random.default_rng(7)
    new, rec = L.mcl_step(state, None, None, scan, f.model, f.params, rng)
    return new, rec, rng.bit_generator.state


def test_the_stream_is_used_alike_whether_p_inj_is_zero_or_tiny(step_inputs):
    f, scan = step_inputs
    lwa = _step(f, scan, -np.inf, -np.inf)[1].log_w_avg  # the step's w_avg does not depend on the averages
    # w_fast above w_slow (p_inj = 0) against w_fast a hair below it (p_inj ~ 1e-7, nobody injected)
    new_a, rec_a, state_a = _step(f, scan, lwa, lwa + 1.0)
    new_b, rec_b, state_b = _step(f, scan, lwa, lwa - 1e-6)
    assert rec_a.p_inject == 0.0
    assert 0.0 < rec_b.p_inject < 1e-5
    assert rec_a.n_injected == rec_b.n_injected == 0
    assert state_a == state_b  # the same draws from the stream: the next steps see the same numbers
    np.testing.assert_array_equal(new_a.particles, new_b.particles)

