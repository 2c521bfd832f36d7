"""The shared particle toolbox: log weights, N_eff, low-variance (systematic) resampling (PR §4.3, Table 4.4)."""

import numpy as np
import pytest

from slamlab.filters.particles import low_variance_resample, n_eff, normalise_log_weights, systematic_resample


def _table_4_4(w, n, r):
    """PR Table 4.4 as printed, one pointer at a time (independent reference): ``U = r + m/M``; advance ``i``
    while ``U > c``. Weights normalised first."""
    w = np.asarray(w, float) / np.sum(w)
    out, i, c = [], 0, w[0]
    for m in range(n):
        u = r + m / n
        while u >= c and i < w.size - 1:  # PR: "while U > c"; ">=" sends a pointer on a boundary to the next slice
            i += 1
            c += w[i]
        out.append(i)
    return np.array(out)


def test_matches_table_4_4_loop_for_given_offsets():
    rng = np.random.default_rng(11)
    for k, n in ((5, 5), (13, 97), (40, 10), (200, 200)):
        w = rng.random(k) ** 3
        w[rng.random(k) < 0.2] = 0.0
        w[0] += 1e-3
        for r in (0.0, 0.3 / n, 0.999 / n, float(rng.uniform(0, 1 / n))):
            np.testing.assert_array_equal(low_variance_resample(w, n, offset=r), _table_4_4(w, n, r))


def test_counts_are_floor_or_ceil_of_n_w():
    rng = np.random.default_rng(0)
    for _ in range(20):
        w = rng.random(13) ** 3
        w /= w.sum()
        n = 97
        counts = np.bincount(low_variance_resample(w, n, rng), minlength=13)
        assert counts.sum() == n
        assert np.all(counts >= np.floor(n * w) - 1e-9)
        assert np.all(counts <= np.ceil(n * w) + 1e-9)


def test_is_unbiased():
    w = np.array([0.1, 0.2, 0.3, 0.4])
    rng = np.random.default_rng(1)
    mean = np.mean([np.bincount(low_variance_resample(w, 10, rng), minlength=4) for _ in range(4000)], axis=0)
    np.testing.assert_allclose(mean, 10 * w, atol=0.03)


def test_offset_semantics_and_the_stream():
    w = np.array([0.0, 0.25, 0.0, 0.75, 0.0])
    # offset r in [0, 1/n): pointers r + m/n; zero weights are never drawn, even with r = 0 on a slice boundary
    assert low_variance_resample(w, 4, offset=0.0).tolist() == [1, 3, 3, 3]
    assert low_variance_resample(w, 4, offset=0.2499).tolist() == [1, 3, 3, 3]
    # the drawn offset is one double of the stream, U/n with U ~ U[0, 1)
    a, b = np.random.default_rng(4), np.random.default_rng(4)
    drawn = low_variance_resample(w, 4, a)
    assert np.array_equal(drawn, low_variance_resample(w, 4, offset=(1.0 / 4) * b.random()))
    assert a.random() == b.random()  # both streams advanced by exactly one draw
    assert systematic_resample is low_variance_resample  # the literature's name for the same sampler


def test_n_eff_closed_forms():
    assert n_eff(np.full(8, 1 / 8)) == pytest.approx(8)
    assert n_eff([0.5, 0.5, 0, 0]) == pytest.approx(2)
    assert n_eff([0.7, 0.1, 0.1, 0.1]) == pytest.approx(1 / (0.49 + 0.03))


def test_normalise_log_weights_never_nan_and_shift_invariant():
    w, ok = normalise_log_weights([-1e308, -np.inf, np.nan])
    assert ok
    assert w.tolist() == [1.0, 0.0, 0.0]
    w, ok = normalise_log_weights([np.nan, -np.inf])
    assert not ok
    assert np.allclose(w, 0.5)
    lw = np.log([1.0, 2.0, 5.0])
    for shift in (0.0, -800.0, 700.0):
        np.testing.assert_allclose(normalise_log_weights(lw + shift)[0], [0.125, 0.25, 0.625], rtol=1e-12)


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="`weights` must not all be 0"):
        low_variance_resample([0.0, 0.0])
    with pytest.raises(ValueError, match="`weights` must be a non-empty"):
        low_variance_resample([np.nan, 1.0])
    with pytest.raises(ValueError, match="`weights` must be a non-empty"):
        low_variance_resample([0.5, -0.5, 1.0])
    with pytest.raises(ValueError, match="`n` must be >= 1"):
        low_variance_resample([0.5, 0.5], 0)
    with pytest.raises(ValueError, match=r"`offset` must be in \[0, 1/n\)"):
        low_variance_resample([0.5, 0.5], 4, offset=0.25)
    with pytest.raises(TypeError, match="`rng` must be a numpy Generator"):
        low_variance_resample([0.5, 0.5], rng="seed")
    with pytest.raises(ValueError, match="`weights` must be a non-empty 1-D array of finite"):
        n_eff([])
    with pytest.raises(ValueError, match="`weights` must be a non-empty 1-D array of finite"):
        n_eff([0.5, np.nan])
    with pytest.raises(ValueError, match="`log_w` must be a non-empty 1-D array"):
        normalise_log_weights(np.zeros((2, 2)))
