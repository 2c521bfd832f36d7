"""One route per setting (issue 42, item 1) in Ch. 8's studies: every field of ``params`` reaches the filter that
runs, or a ``ValueError`` names the field the study sets itself; the particle count is ``n_particles`` all the
way down."""

import numpy as np
import pytest

from slamlab import localisation as L
from slamlab.localisation import markov as markov_module
from slamlab.localisation import mcl as mcl_module
from slamlab.studies import localisation as LS


@pytest.fixture
def filters(monkeypatch):
    """The settings of every MCL and Markov grid made in this process (the studies run with n_jobs=1)."""
    made = []
    for cls in (mcl_module.MCL, markov_module.MarkovGrid):
        original = cls.__init__

        def spy(self, *args, _original=original, **kwargs):
            _original(self, *args, **kwargs)
            made.append(self.params)

        monkeypatch.setattr(cls, "__init__", spy)
    return made


def test_demo_run_takes_the_particle_count_from_params(filters):
    _run, rec = LS.demo_run(params=L.MCLParams(n_particles=50), n_steps=4, kidnap_step=None)
    assert [p.n_particles for p in filters] == [50]
    assert rec.snapshots[0][0].shape == (50, 3)
    assert rec.records[-1].n_particles == 50
    _, rec = LS.demo_run(n_particles=40, n_steps=3, kidnap_step=None)
    assert rec.snapshots[0][0].shape == (40, 3)


def test_kidnap_and_side_by_side_keep_params_n_particles(filters):
    k = LS.run_kidnapped((("defaults", {}),), n_runs=1, n_steps=4, kidnap_step=2,
                         params=L.MCLParams(n_particles=60, sigma_hit=3.0), progress=False)
    assert [(p.n_particles, p.sigma_hit) for p in filters] == [(60, 3.0)]
    assert k.n_particles == 60
    filters.clear()
    k = LS.run_kidnapped((("defaults", {}),), n_runs=1, n_steps=4, kidnap_step=2, progress=False)
    assert [p.n_particles for p in filters] == [1000]  # the study's own count when no params is given
    filters.clear()
    s = LS.run_correlation_side_by_side(n_runs=1, n_steps=2, params=L.MCLParams(n_particles=45), progress=False)
    assert [p.n_particles for p in filters] == [45]
    assert s.n_particles == 45


def test_ablation_count_comes_from_params_and_overrides(filters):
    a = LS.run_global_ablation(LS.ABLATION[:1], n_runs=1, n_steps=2, n_particles=55, progress=False)
    assert a.n_particles == 55
    assert [p.n_particles for p in filters] == [55]
    assert filters[0].sigma_hit == LS.CHAPTER_BEFORE["sigma_hit"]  # the variant on top of the settings


@pytest.mark.parametrize("study", ["global", "markov_vs_mcl", "score"])
def test_studies_that_vary_the_count_refuse_it_in_params(study):
    call = {"global": lambda **kw: LS.run_global_localisation((40,), n_runs=1, n_steps=2, **kw),
            "markov_vs_mcl": lambda **kw: LS.run_markov_vs_mcl((), (40,), n_runs=1, n_steps=2, **kw),
            "score": lambda **kw: LS.run_score_comparison(n_runs=1, **kw)}[study]
    with pytest.raises(ValueError, match=r"`n_particles` is set by this study itself .* sets it to 77"):
        call(params=L.MCLParams(n_particles=77))
    with pytest.raises(ValueError, match=r"`n_particles` is set by this study itself .* sets it to 78"):
        call(n_particles=78)


def test_particle_counts_reach_the_filters_and_other_fields_too(filters):
    g = LS.run_global_localisation((30, 35), n_runs=1, n_steps=2, sigma_hit=3.5, progress=False)
    assert sorted((p.n_particles, p.sigma_hit) for p in filters) == [(30, 3.5), (35, 3.5)]
    assert g.params.sigma_hit == 3.5
    filters.clear()
    sc = LS.run_score_comparison(LS.SCORE_VARIANTS[:1], n_runs=1, kidnap_particles=25, global_particles=35,
                                 progress=False)
    assert sorted(p.n_particles for p in filters) == [25, 35]
    assert (sc.kidnap.n_particles, sc.global_.n_particles) == (25, 35)


def test_real_log_runs_refuse_a_count_in_params():
    with pytest.raises(ValueError, match=r"`n_particles` is set by this study itself .*n_particles_global"):
        LS.run_log_mcl("intel", params=L.MCLParams(n_particles=10))
    with pytest.raises(ValueError, match=r"`n_particles` is set by this study itself .*n_particles_global"):
        LS.run_log_mcl("intel", global_params=L.MCLParams(n_particles=10))
    with pytest.raises(ValueError, match=r"`n_particles` is set by this study itself .*`particle_counts`"):
        LS.run_log_protocol("intel", n_particles=10)
    assert LS.log_params(0.1, "global").sigma_hit == pytest.approx(4.0)
    assert LS.log_params(0.1).sigma_hit == pytest.approx(2.0)
    with pytest.raises(ValueError, match="`run` must be one of"):
        LS.log_params(0.1, "both")


def test_real_log_settings_reach_both_runs(tmp_path, filters):
    from slamlab.io import CarmenLog

    n, beams = 6, 181  # a half circle of wall 2 m around the robot, seen from one place
    log = CarmenLog(path=str(tmp_path / "arc.log"), ranges_m=np.full((n, beams), 2.0), valid=np.ones((n, beams), bool),
                    poses=np.zeros((n, 3)), odom_poses=np.zeros((n, 3)), timestamps_s=np.arange(n, dtype=float),
                    odom=np.zeros((0, 4)), max_range_m=10.0)
    r = LS.run_log_mcl(log, n_scans=3, n_particles_track=20, n_particles_global=30, gamma=0.7, rng=1)
    assert [(p.n_particles, p.gamma) for p in filters] == [(20, 0.7), (30, 0.7)]
    assert filters[0].sigma_hit == pytest.approx(2.0)
    assert filters[1].sigma_hit == pytest.approx(4.0)
    assert (r.n_particles_track, r.n_particles_global) == (20, 30)


def test_markov_studies_take_the_grid_from_params(filters):
    mp = LS.run_markov_prior(LS.MARKOV_PRIORS[:1], n_runs=1, n_steps=2, params=L.MarkovParams(resolution=8,
                                                                                              n_headings=12),
                             uniform_floor=1e-3, progress=False)
    assert [(p.resolution, p.n_headings, p.uniform_floor) for p in filters] == [(8, 12, 1e-3)]
    assert (mp.resolution, mp.n_headings) == (8, 12)
    filters.clear()
    LS.run_markov_prior(LS.MARKOV_PRIORS[:1], n_runs=1, n_steps=2, progress=False)
    assert [(p.resolution, p.n_headings) for p in filters] == [(4, 36)]  # MARKOV_STUDY_PARAMS
    with pytest.raises(ValueError, match=r"`uniform_floor` is set by this study itself .*`floors`"):
        LS.run_markov_kidnap((0.0,), n_runs=1, params=L.MarkovParams(uniform_floor=0.01))
