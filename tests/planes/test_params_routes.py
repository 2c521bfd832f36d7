"""One route per setting (issue 42, item 1) in Ch. 10's studies: every field of ``params`` reaches the filter
that runs, or a ``ValueError`` names the field the study sets itself."""

import numpy as np
import pytest

from slamlab import sim
from slamlab.planes import PlaneSLAMParams
from slamlab.planes import filter as filter_module
from slamlab.studies import planes as SP


@pytest.fixture(scope="module")
def flight():
    return sim.simulate_flight(3.0, rng=5)


@pytest.fixture
def filters(monkeypatch):
    """The settings of every PlaneSLAM made in this process."""
    made = []
    original = filter_module.PlaneSLAM.__init__

    def spy(self, *args, **kwargs):
        original(self, *args, **kwargs)
        made.append(self.params)

    monkeypatch.setattr(filter_module.PlaneSLAM, "__init__", spy)
    return made


def test_fig4_settings_are_params_or_fig4s_own(filters):
    SP.run_intensity_figure(n_particles=30, rng=0)
    assert [(p.n_particles, p.V_xyz_m2, p.pair_dist_m, p.intensity_weights) for p in filters] == \
        [(30, 0.09, 1.5, True), (30, 0.09, 1.5, False)]
    filters.clear()
    p = PlaneSLAMParams(n_particles=20, cell_m=0.3, pair_dist_m=1.0)
    SP.run_intensity_figure(params=p, rng=0)
    assert [q.replace(intensity_weights=True) for q in filters] == [p, p]  # every field of params, no default
    with pytest.raises(ValueError, match=r"`intensity_weights` is set by this study itself"):
        SP.run_intensity_figure(params=PlaneSLAMParams(intensity_weights=False))
    with pytest.raises(ValueError, match=r"`intensity_weights` is set by this study itself"):
        SP.run_intensity_study(1, (0.4,), intensity_weights=False)


def test_fig4_spread_varies_v_itself(filters):
    SP.run_intensity_spread((0.01, 0.04), params=PlaneSLAMParams(n_particles=20, thin=5), rng=0)
    assert sorted({(p.n_particles, p.thin, p.V_xyz_m2) for p in filters}) == [(20, 5, 0.01), (20, 5, 0.04)]
    with pytest.raises(ValueError, match=r"`V_xyz_m2` is set by this study itself .*`V_values_m2`"):
        SP.run_intensity_spread((0.01,), V_xyz_m2=0.5)


def test_ablations_take_params_and_refuse_what_they_vary(flight, filters):
    r = SP.run_pairs_ablation(flight, variants=SP.PAIR_VARIANTS[:2], params=PlaneSLAMParams(n_particles=15,
                                                                                           cell_m=0.3), rng=1)
    assert [(p.n_particles, p.cell_m, p.min_normal_rank) for p in filters] == [(15, 0.3, 2), (15, 0.3, 1)]
    assert r.results[0].params.n_particles == 15
    filters.clear()
    SP.run_frame_source_ablation(flight, n_particles=12, rng=1)
    assert [p.n_particles for p in filters] == [12] * 4
    with pytest.raises(ValueError, match=r"`min_normal_rank` is set by this study itself"):
        SP.run_pairs_ablation(flight, min_normal_rank=1)
    with pytest.raises(ValueError, match=r"`incidence_correction` is set by this study itself"):
        SP.run_incidence_ablation(flight, params=PlaneSLAMParams(incidence_correction=False))


def test_incidence_ablation_counts(flight, filters):
    r = SP.run_incidence_ablation(flight, n_particles=14, fig4_particles=16, rng=1)
    counts = [(p.n_particles, p.incidence_correction) for p in filters]
    assert counts.count((16, True)) == counts.count((16, False)) == 2  # Fig. 4: with and without the weights
    assert counts.count((14, True)) == counts.count((14, False)) == 1  # the flights
    assert r.flights[0].params.n_particles == 14
    assert np.isfinite(r.fig4[0].error_with_m)
