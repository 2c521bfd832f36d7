"""KLD, pose estimate, MCL and Markov grid localisation (003 §2.2; PR Tables 8.1-8.4; resampling and N_eff:
tests/filters/test_particles.py)."""

import copy
import math

import numpy as np
import pytest
from scipy import stats

from slamlab import localisation as L
from slamlab import sim as S
from slamlab.geometry import angle_mean, se2_integrate, se2_relative
from slamlab.studies import localisation as LS


@pytest.mark.parametrize("k", [2, 10, 50, 300])
def test_kld_bound_is_the_wilson_hilferty_chi2_quantile(k):
    # Fox 2003: n = chi2_{k-1, 1-δ} / (2ε); the bound is the Wilson-Hilferty approximation of that quantile
    exact = stats.chi2.ppf(0.99, k - 1) / (2 * 0.05)
    assert float(L.kld_bound(k, 0.05, 0.99)) == pytest.approx(exact, rel=0.02 if k > 5 else 0.1)


def test_kld_sample_count_one_bin_and_many_bins():
    one = np.tile([[5.0, 5.0, 0.1]], (1000, 1))
    assert L.kld_sample_count(one, n_min=50) == 50
    rng = np.random.default_rng(0)
    # Fox 2003 / PR Table 8.4, drawn one particle at a time: stop at the first m with m >= max(n_min, bound(k))
    z = 2.3263478740408408  # the standard normal's 0.99 quantile (tables)

    def sequential(P, n_min, eps=0.05, size=(2.0, 2.0, 0.17453292519943295)):  # 10 degrees
        bins = set()
        for m, (x, y, th) in enumerate(P, start=1):
            bins.add((math.floor(x / size[0]), math.floor(y / size[1]), math.floor((th % (2 * math.pi)) / size[2])))
            k = len(bins)
            bound = 1.0 if k <= 1 else (k - 1) / (2 * eps) * (1 - 2 / (9 * (k - 1)) + math.sqrt(2 / (9 * (k - 1))) * z) ** 3
            if m >= max(n_min, bound):
                return m
        return len(P)

    counts = []
    for width, turn, n_min in ((10.0, 0.5, 10), (2.0, 0.05, 300), (400.0, 0.5, 10)):
        P = np.column_stack([rng.uniform(0, width, 3000), rng.uniform(0, width, 3000), rng.uniform(-turn, turn, 3000)])
        counts.append(sequential(P, n_min))
        assert L.kld_sample_count(P, n_min=n_min, bin_size=(2.0, 2.0, np.radians(10))) == counts[-1]
    assert 300 < counts[0] < 3000  # the bound met
    assert counts[1] == 300  # n_min met first
    assert counts[2] == 3000  # never met: all kept


def test_pose_estimate_against_numpy_and_angle_mean():
    rng = np.random.default_rng(3)
    P = np.column_stack([rng.normal(3, 1, 500), rng.normal(-2, 0.5, 500), np.pi + rng.normal(0, 0.2, 500)])
    P[:, 2] = np.angle(np.exp(1j * P[:, 2]))  # straddles ±π
    w = rng.random(500)
    m, C = L.pose_estimate(P, w)
    wn = w / w.sum()
    assert m[2] == pytest.approx(float(angle_mean(P[:, 2], wn)), abs=1e-12)
    np.testing.assert_allclose(m[:2], wn @ P[:, :2], atol=1e-12)
    d = np.column_stack([P[:, :2] - m[:2], np.angle(np.exp(1j * (P[:, 2] - m[2])))])
    # second moments about the circular mean = covariance about the residuals' own mean + mean·meanᵀ
    mu = wn @ d
    np.testing.assert_allclose(C, np.cov(d.T, aweights=wn, bias=True) + np.outer(mu, mu), atol=1e-12)


def _run(f, P, scans, odo=None, kidnap=None):
    """Run a filter along P; odometry poses odo (default the truth)."""
    odo = P if odo is None else odo
    out = []
    for k in range(len(P)):
        prev, now = (odo[k - 1], odo[k]) if k else (None, None)
        out.append(f.step(prev, now, scans[k]))
    return out


@pytest.fixture(scope="module")
def room_run():
    M = S.test_room_200()
    P = S.path_004(61)
    scans = S.simulate_scans(M, P, S.Rangefinder(n_beams=60, max_range_cells=60, range_std_cells=0.5), rng=1)
    odo = S.simulate_odometry(P, trans_std_frac=0.05, rot_std_rad=0.01, rng=2).poses
    return M, P, scans, odo


@pytest.mark.parametrize("narrow", [False, True])
def test_mcl_tracking_stays_within_a_cell(room_run, narrow):
    """The defaults and issue 12's narrow settings (σ_hit 2, small motion noise, no jitter, no injection) both track
    within 1.5 cells and 3°; the narrow cloud is also 'localised' (σ < 2 cells and 5°) at every step after the 5th
    (the defaults' cloud is wider by design: σ_hit 4, 4 × the motion noise, jitter, injected particles)."""
    M, P, scans, odo = room_run
    kw = {**LS.CHAPTER_BEFORE, "alpha_slow": 0.0, "alpha_fast": 0.0} if narrow else {}
    f = L.MCL(M, 60.0, n_particles=500, rng=0, init_pose=P[0], init_std=(1.0, 1.0, 0.05), **kw)
    recs = _run(f, P, scans, odo)
    err = np.array([math.hypot(*(r.mean[:2] - p[:2])) for r, p in zip(recs, P, strict=True)])
    herr = np.array([abs(math.remainder(r.mean[2] - p[2], 2 * math.pi)) for r, p in zip(recs, P, strict=True)])
    assert err.max() < 1.5
    assert np.degrees(herr).max() < 3
    if narrow:
        assert all(r.localised for r in recs[5:])


def test_mcl_function_and_class_agree(room_run):
    M, _P, scans, _ = room_run
    f = L.MCL(M, 60.0, n_particles=200, rng=5)
    X0 = f.state.particles.copy()
    rng = copy.deepcopy(f.rng)  # the filter's own stream, as the step will find it
    rec = f.step(None, None, scans[0])
    state, rec2 = L.mcl_step(L.MCLState(X0, np.full(200, 1 / 200)), None, None, scans[0], f.model, f.params, rng)
    np.testing.assert_allclose(rec.mean, rec2.mean, atol=1e-12)
    np.testing.assert_allclose(f.state.particles, state.particles, atol=1e-12)


def test_augmented_mcl_recovers_from_kidnapping_and_plain_mcl_does_not():
    M = S.test_room_200()
    P = S.path_004(121)
    # kidnap after step 20: the robot is carried from P[20] to P[80]; odometry reports ordinary motion
    order = list(range(21)) + list(range(80, 121))
    true = P[order]
    inc = se2_relative(true[:-1], true[1:])
    inc[20] = se2_relative(P[20], P[21])
    odo = se2_integrate(true[0], inc)
    scans = S.simulate_scans(M, true, S.Rangefinder(n_beams=60, max_range_cells=60, range_std_cells=0.5), rng=1)

    def final_error(**kw):
        f = L.MCL(M, 60.0, n_particles=1500, rng=3, init_pose=true[0], init_std=(1.0, 1.0, 0.05), **kw)
        recs = _run(f, true, scans, odo)
        return math.hypot(*(recs[-1].mean[:2] - true[-1, :2])), sum(r.n_injected for r in recs)

    e_aug, n_inj = final_error()  # the defaults: (α_slow, α_fast) = (0.001, 0.1), bias-corrected averages
    e_plain, n0 = final_error(alpha_slow=0.0, alpha_fast=0.0)
    assert n0 == 0
    assert n_inj > 0
    assert e_aug < 2.0
    assert e_plain > 10.0


def test_all_vanishing_weights_inject_or_say_so():
    g = np.zeros((40, 40), np.int8)
    g[0] = g[-1] = g[:, 0] = g[:, -1] = 1
    from slamlab.scans import Scan
    scan = Scan(np.array([0.0]), np.array([10.0]), np.array([True]), max_range=30.0)
    # z_rand = 0 and a tiny σ_hit: every end point that is not on a wall has probability exactly 0
    far = np.tile([[20.0, 20.0, np.pi / 4]], (50, 1))
    for slow, fast, injected in ((0.0, 0.0, False), (0.1, 0.5, True)):
        f = L.MCL(g, 30.0, n_particles=50, rng=0, z_rand=0.0, sigma_hit=0.01, alpha_slow=slow, alpha_fast=fast)
        f.state = L.MCLState(far.copy(), np.full(50, 1 / 50))
        rec = f.step(None, None, scan)
        assert rec.weights_vanished
        assert np.all(np.isfinite(f.state.weights))
        assert np.all(np.isfinite(rec.mean))
        assert ("re-drawn" in rec.note) == injected
        assert ("no injection" in rec.note) != injected
        assert (rec.n_injected == 50) == injected


def test_kld_adapts_the_particle_count(room_run):
    M, P, scans, odo = room_run
    f = L.MCL(M, 60.0, n_particles=4000, rng=0, use_kld=True, n_min=100, resample_threshold=1.0)
    recs = _run(f, P[:25], scans[:25], odo[:25])
    counts = [r.n_particles for r in recs]  # after each resampling
    assert f.params.n_particles == 4000
    assert min(counts) >= 100
    assert max(counts[-5:]) < 1000


def test_markov_likelihood_equals_the_particle_model_at_cell_poses():
    M = S.test_room_200()
    mg = L.MarkovGrid(M, 60.0, resolution=4, n_headings=12)
    scan = S.Rangefinder(n_beams=24, max_range_cells=60).scan(M, [70, 30, 0.3])
    b = L.scan_beams(scan)
    Lg = L.markov_log_likelihood(mg.model, b, 12, 4, mg.shape)
    poses = mg.cell_poses().reshape(-1, 3)
    ref = mg.model.log_likelihood(poses, b).reshape(Lg.shape)
    np.testing.assert_allclose(Lg, ref, rtol=1e-5)


def test_markov_global_localisation_finds_the_pose(room_run):
    M, P, scans, odo = room_run
    mg = L.MarkovGrid(M, 60.0, resolution=2, n_headings=36)
    for k in range(12):
        mg.step(odo[k - 1] if k else None, odo[k] if k else None, scans[k])
    m, _C = mg.estimate()
    assert math.hypot(*(m[:2] - P[11, :2])) < 3.0
    assert abs(math.remainder(m[2] - P[11, 2], 2 * math.pi)) < math.radians(10)
    assert mg.belief.sum() == pytest.approx(1.0)


def test_markov_predict_conserves_mass_and_moves_the_mode():
    b = np.zeros((8, 30, 30))
    b[2, 10, 10] = 1.0  # heading 90°: moving "forward" is +y (rows)
    out = L.markov_predict(b, [0, 0, 0], [4, 0, 0], resolution=1, alpha=(0.01, 0.001, 0.01, 0.001), min_blur=0.5)
    assert out.sum() == pytest.approx(1.0)
    assert np.unravel_index(np.argmax(out), out.shape) == (2, 14, 10)


def test_markov_vs_mcl_methods_share_the_runs():
    from slamlab.studies.localisation.experiments import run_markov_vs_mcl

    res = run_markov_vs_mcl(markov=((8, 12),), particle_counts=(50, 60), n_runs=3, n_steps=3, rng=4)
    df = res.table_df
    starts = {m: g[["start_x", "start_y"]].to_numpy() for m, g in df.groupby("variant", sort=False)}
    first = next(iter(starts.values()))
    assert len(starts) == 3
    assert len({tuple(map(tuple, v)) for v in starts.values()}) == 1  # every method ran the same 3 runs
    assert len({tuple(r) for r in first}) > 1  # and the runs differ from each other


def test_studies_take_params_and_any_rng():
    """The run_* contract: ``params=`` (+ overrides) and ``rng=`` as an int, a SeedSequence or a Generator."""
    from slamlab.studies.localisation.experiments import run_markov_vs_mcl

    kw = {"markov": (), "particle_counts": (40,), "n_runs": 2, "n_steps": 3}
    cols = ["start_x", "start_y", "final_err_cells"]
    ref = run_markov_vs_mcl(**kw, rng=4).table_df[cols]
    assert ref.equals(run_markov_vs_mcl(**kw, rng=np.random.SeedSequence(4)).table_df[cols])
    assert ref.equals(run_markov_vs_mcl(**kw, rng=np.random.default_rng(4)).table_df[cols])
    # params= and the same settings as overrides are one run; the study's own axis (the counts) is refused in both
    a = run_markov_vs_mcl(**kw, params=L.MCLParams(sigma_hit=3.0), rng=4).table_df[cols]
    b = run_markov_vs_mcl(**kw, sigma_hit=3.0, rng=4).table_df[cols]
    assert a.equals(b)
    assert not a.equals(ref)
    with pytest.raises(ValueError, match=r"`n_particles` is set by this study itself .*`particle_counts`.* 999"):
        run_markov_vs_mcl(**kw, params=L.MCLParams(sigma_hit=3.0, n_particles=999))
    with pytest.raises(ValueError, match="`n_particles` is set by this study itself"):
        run_markov_vs_mcl(**kw, n_particles=999)
    with pytest.raises(TypeError, match="`params` must be a MCLParams or None; got dict"):
        run_markov_vs_mcl(**kw, params={"sigma_hit": 3.0})


def test_amcl_convergence_test_is_a_box_around_the_mean():
    rng = np.random.default_rng(0)
    X = np.column_stack([rng.uniform(-1, 1, 50), rng.uniform(-1, 1, 50), rng.uniform(-3, 3, 50)])
    box = np.abs(X[:, :2] - X[:, :2].mean(axis=0)).max()
    assert L.amcl_converged(X, box + 1e-9)
    assert not L.amcl_converged(X, box - 1e-9)


@pytest.mark.parametrize("alpha", [0.001, 0.1, 0.5])
def test_debiased_averages_of_a_constant_are_the_constant(alpha):
    """Bias correction: an average started at 0 and divided by 1 − (1 − α)^t returns a constant input at once,
    so w_fast/w_slow = 1 and nothing is injected while the score does not change; the log-space update equals
    the linear one."""
    from slamlab.localisation.mcl import _log_average, _log_bias

    lw, w = -np.inf, 0.0
    for t in range(1, 30):
        x = 0.3 + 0.01 * t
        lw = _log_average(lw, math.log(x), alpha)
        w = w + alpha * (x - w)
        assert math.exp(lw) == pytest.approx(w, rel=1e-12)
    lc = -np.inf
    for t in range(1, 30):
        lc = _log_average(lc, math.log(0.42), alpha)
        assert math.exp(lc - _log_bias(alpha, t)) == pytest.approx(0.42, rel=1e-12)


def test_injection_fires_with_the_defaults_after_a_kidnap_and_not_with_003_averages():
    """Issue 27: with 003's averages from 0 and (α_slow, α_fast) = (0.001, 0.1) nothing is injected; with the
    defaults (the same α, bias-corrected averages) a kidnap triggers injection."""
    run = LS.simulate_run(30, start=0, kidnap_step=12, rng=11)
    inj = {}
    for avg in ("003", "debiased"):
        r = LS.run_filter(run, init="tracking", n_particles=500, rng=2, averages=avg)
        inj[avg] = [x.n_injected for x in r.records]
    assert sum(inj["003"]) == 0
    assert sum(inj["debiased"][12:]) > 500


def test_beam_skipping_keeps_the_beams_most_particles_agree_with():
    from slamlab.localisation.mcl import _beam_mask

    M = S.test_room_200()
    p = L.MCLParams(beam_skip=True)
    m = p.model(M, 60.0)
    pose = np.array([70.0, 30.0, 0.4])
    scan = S.Rangefinder(n_beams=30, max_range_cells=60, quantum_cells=0).scan(M, pose)
    b = L.scan_beams(scan)
    X = pose + np.random.default_rng(1).normal(0, [0.3, 0.3, 0.005], (200, 3))
    assert _beam_mask(m, X, b, p).sum() == m.n_used(b)  # a converged cloud at the truth: every beam agrees
    b2 = L.Beams(b.bearings_rad, b.ranges.copy(), b.max_range, b.end_xy.copy())
    b2.ranges[:5] *= 0.5  # five returns from an object not in the map (e.g. a person)
    b2 = L.Beams(b2.bearings_rad, b2.ranges, b2.max_range, np.column_stack([b2.ranges * np.cos(b2.bearings_rad),
                                                                             b2.ranges * np.sin(b2.bearings_rad)]))
    mask = _beam_mask(m, X, b2, p)
    assert not mask[:5].any()
    assert mask[5:][m.used(b2)[5:]].all()


@pytest.mark.slow
def test_markov_prior_and_uniform_floor_studies():
    """003's two claims as runs: with a weak sensor (3 beams) a prior at the truth localises where the uniform
    belief does not; after a kidnap a grid with a uniform floor is back within the bounds."""
    mp = LS.run_markov_prior(LS.MARKOV_PRIORS[:2], n_runs=2, n_steps=8, rng=2026, progress=False, max_beams=3)
    assert mp.success(LS.MARKOV_PRIORS[1][0]) > mp.success(LS.MARKOV_PRIORS[0][0])
    mk = LS.run_markov_kidnap((1e-3,), n_runs=1, n_steps=12, kidnap_step=6, rng=1, progress=False)
    assert mk.success(mk.labels[0], 5) == 1.0  # tracking before the kidnap
    assert mk.success(mk.labels[0]) == 1.0  # and back after it
    with pytest.raises(ValueError, match="`priors` must hold"):
        LS.run_markov_prior([("x", "flat", 0.0)])
