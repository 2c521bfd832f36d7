"""Cost model of 000 §4.1.2: bounds, formulas on hand-computed cases, and the readings' optima."""

import numpy as np
import pytest

from slamlab.kdtree.cost_model import (
    calibrate_C,
    iter_time,
    minimise_iter_time,
    p_bounds,
    run_cost_model,
    t_modify,
    t_search,
)


def _simulate_tree_count(n_total, n1, q, m):
    """Sizes-only multi kd-tree (000 §3.4): add m to tree 1, then while size[i] > max[i] merge i into i+1."""
    sizes = [0] * 40
    max_sizes = [n1 * q**i for i in range(40)]
    counts = []
    n = 0
    while n < n_total:
        sizes[0] += m
        n += m
        i = 0
        while sizes[i] > max_sizes[i]:
            sizes[i + 1] += sizes[i]
            sizes[i] = 0
            i += 1
        p = max(j for j in range(40) if sizes[j] > 0) + 1
        counts.append((n, p))
    return counts


def test_p_bounds_against_a_simulated_multi_tree():
    for n1, q, m in [(3500, 5.5, 500), (1000, 2.0, 300), (500, 3.0, 650)]:
        for n, p in _simulate_tree_count(60000, n1, q, m):
            if n <= n1:  # the bounds assume tree 1 has overflowed at least once
                continue
            lo, hi = p_bounds(n, n1, q)
            # eq. (1): the p trees must hold the n points
            assert p >= lo - 1e-9
            # eq. (2) as printed, q^(p-1) n1 <= n, can be off by one right after a cascade of merges
            # (tree p-1 overflowed when it held > q^(p-2) n1 points): p <= log_q(n/n1) + 2 always
            assert p <= hi + 1 + 1e-9


def test_formulas_on_hand_computed_values():
    # p = 3 trees of sizes 1024, 2048, 4096: log2 sizes 10 + 11 + 12 = 33
    assert t_search(1024, 2.0, 3) == pytest.approx(33.0)
    assert t_modify(1024, 2.0, 3, m=10) == pytest.approx(10 * 2 * 33.0)
    # iterTime = n1 log n1 + T_modify + C s T_search with p from the upper bound
    n, n1, q = 1024 * 4, 1024.0, 2.0  # upper bound: log2(4) + 1 = 3
    expected = 1024 * 10 + 10 * 2 * 33 + 9 * 100 * 33
    assert iter_time(n1, q, n=n, s=100, m=10, C=9, p_rule="upper") == pytest.approx(expected)


def test_calibration_reproduces_000():
    assert calibrate_C(526, 0.079, 678, 0.750, 44828) == pytest.approx(8.977, abs=5e-3)


def test_readings_and_their_optima_match_the_close_reading():
    res = run_cost_model(n=50000, s=500, m=500, C=9.0)
    lit, *rest = res.readings
    (_, n1_up, q_up, _, e0), (_, n1_lo, q_lo, _, _), (_, n1_int, q_int, _, _), (_, n1_nb, _, _, e3) = rest
    # the Appendix as printed (searchKd with C inside, no factor s) -> about (1200, 2.3)
    assert lit[1] == pytest.approx(1200, abs=100)
    assert lit[2] == pytest.approx(2.3, abs=0.1)
    assert res.literal is lit
    assert res.optimum is rest[0]
    # SPEC close reading: upper -> (3430, 5.3); lower -> (3530, 4.5); integer -> (2600, 3.7-3.8); no build -> edge
    assert n1_up == pytest.approx(3430, abs=100)
    assert q_up == pytest.approx(5.3, abs=0.1)
    assert not e0
    assert n1_lo == pytest.approx(3530, abs=100)
    assert q_lo == pytest.approx(4.5, abs=0.1)
    assert n1_int == pytest.approx(2600, abs=150)
    assert 3.6 <= q_int <= 3.9
    assert n1_nb == 20000
    assert e3
    # the surface is flat: 000's (3500, 5.5) is within 1 % of the minimum
    assert res.flat_n1[0] <= 3500 <= res.flat_n1[1]
    assert res.flat_q[0] <= 5.5 <= res.flat_q[1]
    f000 = iter_time(3500, 5.5, n=50000, s=500, m=500, C=9)
    assert f000 <= 1.01 * res.optimum[3]
    assert "n1" in res.table()
    assert "3500" in res.table()


def test_literal_appendix_by_hand():
    # addKd + C searchKd at one point, every term written out (p at the upper bound, base-2 logs)
    from slamlab.kdtree.cost_model import add_kd, p_bounds, search_kd

    n1, q, n, m, C = 2000.0, 3.0, 50000.0, 500.0, 9.0
    p = np.log(n / n1) / np.log(q) + 1.0
    assert p == pytest.approx(p_bounds(n, n1, q)[1])
    search = p * np.log2(n1) + C * p * (p - 1) / 2 * np.log2(q)
    add = n1 * np.log2(n1) + m * q * p * np.log2(n1) + m * q / 2 * p * (p - 1) * np.log2(q)
    assert search_kd(n1, q, p, C) == pytest.approx(search)
    assert add_kd(n1, q, p, m) == pytest.approx(add)
    # s does not enter the literal reading
    for s in (1.0, 500.0):
        assert iter_time(n1, q, n=n, s=s, m=m, C=C, reading="literal") == pytest.approx(add + C * search)
    with pytest.raises(ValueError, match="`reading` must be one of"):
        iter_time(n1, q, reading="maple")


def test_grid_minimum_is_a_minimum():
    n1, q, val, *_ = minimise_iter_time()
    for dn1, dq in [(100, 0), (-100, 0), (0, 0.1), (0, -0.1)]:
        assert iter_time(n1 + dn1, q + dq) >= val


def test_bad_input():
    with pytest.raises(ValueError, match="`p_rule` must be one of 'upper', 'lower', 'integer'"):
        iter_time(1000, 2.0, p_rule="round")
    with pytest.raises(ValueError, match="`n1` and `q` must be > 1"):
        iter_time(1000, 1.0)
    with pytest.raises(ValueError, match="`t_search_s` must be > 0"):
        calibrate_C(526, 0.0, 678, 0.75, 44828)
