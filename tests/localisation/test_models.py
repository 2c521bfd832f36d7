"""Motion and measurement models against their closed forms on small cases (PR Tables 5.5, 5.6, 6.1, 6.3)."""

import math

import numpy as np
import pytest
from scipy import integrate, stats
from scipy.spatial import cKDTree

from slamlab import localisation as L
from slamlab import sim as S
from slamlab.scans import Scan, cast_rays


def _npdf(x, var):
    return stats.norm(0.0, math.sqrt(var)).pdf(x)


def test_odometry_density_closed_form_zero_residual():
    a = (0.1, 0.02, 0.2, 0.05)
    rot1, trans, rot2 = math.pi / 4, math.sqrt(2), math.pi / 4
    expect = (_npdf(0, a[0] * rot1**2 + a[1] * trans**2) * _npdf(0, a[2] * trans**2 + a[3] * (rot1**2 + rot2**2))
              * _npdf(0, a[0] * rot2**2 + a[1] * trans**2))
    p = L.motion_density_odometry([[1, 1, math.pi / 2]], [[0, 0, 0]], [0, 0, 0], [1, 1, math.pi / 2], a)
    assert p[0] == pytest.approx(expect, rel=1e-12)


def test_odometry_density_closed_form_off_the_reading():
    a = (0.1, 0.02, 0.2, 0.05)
    # odometry: (5, 5, 0) -> (6, 6, pi/2) = rot1 pi/4, trans sqrt 2, rot2 pi/4 (only the difference matters)
    r1, t, r2 = math.pi / 4, math.sqrt(2), math.pi / 4
    # hypothesis: from (0, 0, 0) to (1.1, 1.0, pi/2)
    h1 = math.atan2(1.0, 1.1)
    ht = math.hypot(1.1, 1.0)
    h2 = math.pi / 2 - h1
    expect = (_npdf(r1 - h1, a[0] * h1**2 + a[1] * ht**2) * _npdf(t - ht, a[2] * ht**2 + a[3] * (h1**2 + h2**2))
              * _npdf(r2 - h2, a[0] * h2**2 + a[1] * ht**2))
    p = L.motion_density_odometry([[1.1, 1.0, math.pi / 2]], [[0, 0, 0]], [5, 5, 0], [6, 6, math.pi / 2], a)
    assert p[0] == pytest.approx(expect, rel=1e-12)


def test_sampler_matches_the_model_variances():
    a = (0.1, 0.01, 0.05, 0.02)
    n = 200_000
    X = L.sample_motion_odometry(np.zeros((n, 3)), [0, 0, 0], [2, 0, 0.3], a, rng=0)
    h1 = np.arctan2(X[:, 1], X[:, 0])
    ht = np.hypot(X[:, 0], X[:, 1])
    h2 = np.angle(np.exp(1j * (X[:, 2] - h1)))
    # rot1 = 0, trans = 2, rot2 = 0.3; sampled deltas are normal around them with the Table 5.6 variances
    for got, mean, var in ((h1, 0.0, a[1] * 4), (ht, 2.0, a[2] * 4 + a[3] * 0.09), (h2, 0.3, a[0] * 0.09 + a[1] * 4)):
        assert got.mean() == pytest.approx(mean, abs=4 * math.sqrt(var / n))
        assert got.var() == pytest.approx(var, rel=0.02)


def test_zero_noise_sampler_is_exact_odometry_composition():
    X0 = np.array([[1.0, 2.0, 0.5], [-3.0, 0.0, -2.0]])
    X = L.sample_motion_odometry(X0, [0, 0, 0], [1, 1, math.pi / 2], (0, 0, 0, 0), rng=1)
    # body-frame increment of the reading, composed onto each pose
    inc = np.array([1.0, 1.0, math.pi / 2])
    for x0, x in zip(X0, X, strict=True):
        c, s = math.cos(x0[2]), math.sin(x0[2])
        np.testing.assert_allclose(x[:2], [x0[0] + c * inc[0] - s * inc[1], x0[1] + s * inc[0] + c * inc[1]],
                                   atol=1e-12)
        assert np.angle(np.exp(1j * (x[2] - x0[2] - inc[2]))) == pytest.approx(0, abs=1e-12)


def _one_obstacle():
    g = np.zeros((21, 21), np.int8)
    g[10, 10] = 1
    return g


def test_likelihood_field_single_obstacle_closed_form():
    z_hit, z_rand, sig, zmax = 0.8, 0.2, 1.3, 30.0
    m = L.LikelihoodFieldModel(_one_obstacle(), z_hit=z_hit, z_rand=z_rand, sigma_hit=sig, z_max=zmax, max_dist=6.0)
    scan = Scan([0.0, 0.0, np.pi / 2], [5.0, 3.0, 4.0], np.ones(3, bool), max_range=zmax)
    b = L.scan_beams(scan)
    q = m.beam_log_q([[5.0, 10.0, 0.0]], b)[0]
    # end points (10, 10): d = 0; (8, 10): d = 2; (5, 14): d = hypot(5, 4) capped at 6 -> hypot = 6.40 -> 6
    for got, d in zip(q, (0.0, 2.0, 6.0), strict=True):
        assert got == pytest.approx(math.log(z_hit * stats.norm(0, sig).pdf(d) + z_rand / zmax), rel=1e-5)
    # the same end point seen from a rotated pose
    q2 = m.beam_log_q([[10.0, 5.0, np.pi / 2]], L.scan_beams(Scan([0.0], [5.0], np.ones(1, bool), max_range=zmax)))
    assert q2[0, 0] == pytest.approx(q[0], rel=1e-6)


def test_likelihood_field_outside_and_max_range_beams():
    m = L.LikelihoodFieldModel(_one_obstacle(), z_hit=0.9, z_rand=0.1, sigma_hit=1.0, z_max=20.0, max_dist=5.0)
    scan = Scan([0.0, np.pi], [15.0, 20.0], np.ones(2, bool), max_range=20.0)
    q = m.beam_log_q([[10.0, 10.0, 0.0]], L.scan_beams(scan, keep_max=True))[0]
    assert q[0] == pytest.approx(math.log(0.9 * stats.norm.pdf(5.0) + 0.1 / 20), rel=1e-5)  # off the map
    assert q[1] == 0.0  # a beam at z_max is skipped (PR Table 6.3 line 3)


def test_likelihood_field_against_brute_force_nearest_obstacle():
    M = S.test_room_200()
    m = L.LikelihoodFieldModel(M, z_hit=0.7, z_rand=0.3, sigma_hit=2.0, z_max=60.0, max_dist=8.0)
    rng = np.random.default_rng(4)
    X = L.uniform_free_particles(M, 40, rng)
    scan = S.Rangefinder(n_beams=36, max_range_cells=60).scan(M, [70, 30, 0.3])
    b = L.scan_beams(scan)
    tree = cKDTree(np.argwhere(M == 1)[:, ::-1].astype(float))
    ref = np.zeros((len(X), b.n))
    ambiguous = np.zeros((len(X), b.n), bool)
    for i, x in enumerate(X):  # the per-particle, per-beam reference loop
        for k, (a, r) in enumerate(zip(b.bearings_rad, b.ranges, strict=True)):
            ex, ey = x[0] + r * math.cos(x[2] + a), x[1] + r * math.sin(x[2] + a)
            # an end point within 1e-3 of a cell edge may fall either side in float32: not compared
            ambiguous[i, k] = max(abs((ex + 0.5) % 1 - 0.5), abs((ey + 0.5) % 1 - 0.5)) > 0.499
            col, row = math.floor(ex + 0.5), math.floor(ey + 0.5)
            d = min(tree.query([col, row])[0], 8.0) if 0 <= row < 200 and 0 <= col < 200 else 8.0
            ref[i, k] = math.log(0.7 * stats.norm(0, 2.0).pdf(d) + 0.3 / 60)
    got = m.beam_log_q(X, b)
    assert ambiguous.mean() < 0.01
    np.testing.assert_allclose(got[~ambiguous], ref[~ambiguous], rtol=1e-5)
    np.testing.assert_allclose(m.log_likelihood(X, b), got.sum(axis=1, dtype=float), rtol=1e-12)


def test_score_is_in_unit_interval_and_one_on_a_perfect_fit():
    M = S.test_room_200()
    m = L.LikelihoodFieldModel(M, z_hit=0.9, z_rand=0.1, sigma_hit=1.0, z_max=60.0, max_dist=8.0)
    pose = np.array([70.0, 30.0, 0.4])
    scan = S.Rangefinder(n_beams=60, max_range_cells=60, quantum_cells=0).scan(M, pose)
    b = L.scan_beams(scan)
    X = np.vstack([pose, L.uniform_free_particles(M, 200, 1)])
    s = m.score(m.log_likelihood(X, b), b)
    assert np.all((s >= 0) & (s <= 1))
    assert s[0] > 0.6
    assert s[0] == s.max()


def test_ray_cast_expected_ranges_closed_form_in_a_box():
    """z* of the beam model for many particles: the distance to the box's wall faces (x = 0.5, 58.5; y = 0.5,
    38.5) along each beam, min over the two axes (the traversal itself: tests/scans/test_raycast.py)."""
    M = S.make_grid(40, 60, S.OBSTACLE)
    M[1:39, 1:59] = S.FREE
    X = L.uniform_free_particles(M, 15, 2)
    ang = S.beam_angles(37)
    z = cast_rays(M, X, ang, 200.0)[0]
    th = X[:, 2:3] + ang
    c, s = np.cos(th), np.sin(th)
    with np.errstate(divide="ignore"):
        tx = np.where(c > 0, (58.5 - X[:, :1]) / c, np.where(c < 0, (0.5 - X[:, :1]) / c, np.inf))
        ty = np.where(s > 0, (38.5 - X[:, 1:2]) / s, np.where(s < 0, (0.5 - X[:, 1:2]) / s, np.inf))
    assert z.shape == (15, 37)
    np.testing.assert_allclose(z, np.minimum(tx, ty), atol=1e-9)
    assert np.all(cast_rays(M, X, ang, 5.0)[0] <= 5.0)


def test_beam_model_integrates_to_one_and_matches_scipy_parts():
    zmax, zs, sig, lam = 20.0, 7.0, 0.8, 0.3
    w = {"z_hit": 0.7, "z_short": 0.1, "z_max_w": 0.05, "z_rand": 0.15}

    def pdf(z):
        return float(L.beam_model_prob(z, zs, z_max=zmax, sigma_hit=sig, lambda_short=lam, **w))

    total, _ = integrate.quad(pdf, 0, zmax, points=[zs], limit=200)
    assert total + w["z_max_w"] == pytest.approx(1.0, abs=1e-6)  # + the point mass at z_max
    z = np.array([0.5, 6.5, 7.2, 15.0])
    hit = stats.truncnorm((0 - zs) / sig, (zmax - zs) / sig, loc=zs, scale=sig).pdf(z)
    short = stats.truncexpon(b=lam * zs, scale=1 / lam).pdf(z)
    ref = w["z_hit"] * hit + w["z_short"] * short + w["z_rand"] / zmax
    np.testing.assert_allclose(L.beam_model_prob(z, zs, z_max=zmax, sigma_hit=sig, lambda_short=lam, **w), ref,
                               rtol=1e-10)
    assert float(L.beam_model_prob(zmax, zs, z_max=zmax, **w)) == pytest.approx(w["z_max_w"])


def test_odometry_deltas_tiny_translation_has_no_first_rotation():
    r1, _t, r2 = L.odometry_deltas([0, 0, 0.2], [1e-9, 0, 0.5])
    assert float(r1) == 0.0
    assert float(r2) == pytest.approx(0.3)


def test_the_three_scores_against_per_beam_loops():
    """log_score: 'likelihood' = Σ log q_k, 'geometric_mean' = mean log(q_k/q_max), 'amcl_cubes' = log(1 + Σ p_k³)
    with amcl's unnormalised p_k (amcl_laser.cpp LikelihoodFieldModel), from the distance table by a loop."""
    M = S.test_room_200()
    m = L.LikelihoodFieldModel(M, z_hit=0.8, z_rand=0.2, sigma_hit=3.0, z_max=60.0, max_dist=9.0)
    X = L.uniform_free_particles(M, 30, np.random.default_rng(8))
    scan = S.Rangefinder(n_beams=40, max_range_cells=60, range_std_cells=0.3).scan(M, [100, 60, 1.0], 3)
    b = L.scan_beams(scan)
    d, keep = m.beam_distances(X, b)
    assert keep.sum() == d.shape[1] == m.n_used(b)
    lq = m.beam_log_q(X, b)[:, keep].astype(float)
    np.testing.assert_allclose(np.log(0.8 * stats.norm(0, 3.0).pdf(d) + 0.2 / 60), lq, rtol=1e-5)
    cubes = np.array([math.log(1 + sum((0.8 * math.exp(-dk * dk / 18.0) + 0.2 / 60) ** 3 for dk in row))
                      for row in d.astype(float)])
    np.testing.assert_allclose(m.log_score(X, b, "likelihood"), lq.sum(axis=1), rtol=1e-6)
    np.testing.assert_allclose(m.log_score(X, b, "geometric_mean"), lq.mean(axis=1) - m.log_q_max, rtol=1e-6)
    np.testing.assert_allclose(m.log_score(X, b, "amcl_cubes"), cubes, rtol=1e-9)
    np.testing.assert_allclose(np.exp(m.log_score(X, b, "geometric_mean")), m.score(m.log_likelihood(X, b), b),
                               rtol=1e-6)
    mask = np.zeros(b.n, bool)
    mask[np.flatnonzero(keep)[:5]] = True
    np.testing.assert_allclose(m.log_score(X, b, "likelihood", mask), lq[:, :5].sum(axis=1), rtol=1e-6)
    with pytest.raises(ValueError, match="`score` must be one of"):
        m.log_score(X, b, "beam")
