"""Issue 42, one route per setting: every field of LocaliseParams given to a Ch. 5 run (as ``params=`` or as an
override) reaches the settings of every localisation the run makes, or the run refuses it with a ValueError naming
the field. The localisations are replaced by a recorder (no search runs), so the test checks the routing only."""

import numpy as np
import pytest

from slamlab import correlation as C
from slamlab.studies import correlation as CS
from slamlab.studies.correlation import _log_scan, batch
from slamlab.studies.correlation import experiments as E

#: A valid value other than the default for every field.
NON_DEFAULT = {"delta_alpha_rad": float(np.radians(2.0)), "a_c": -0.5, "a_p": 2.0, "a_n": 0.25, "delta_l_cells": 0.5,
               "hit_offset_cells": 0.25, "step_cells": 0.25, "use_misses": True, "chunk": 4, "dtype": "float64",
               "workers": 1, "ambiguity": False, "rival_radius_cells": 3.0,
               "rival_heading_rad": float(np.radians(20.0)), "wall_balance": True, "free_mark_weight": 0.5}


def test_every_field_has_a_non_default_value():
    assert set(NON_DEFAULT) == set(C.LocaliseParams.field_names())
    default = C.LocaliseParams()
    assert all(getattr(default, k) != v for k, v in NON_DEFAULT.items())
    C.LocaliseParams(**NON_DEFAULT)  # valid together


def _fake_localisation(pose=(60.0, 40.0, 0.5)):
    return C.Localisation(pose=np.array(pose, dtype=float), row=40, col=60, heading_index=0, score=1.0,
                          headings_rad=np.zeros(8), best_per_heading=np.linspace(1.0, 0.0, 8),
                          score_map=np.zeros((4, 4)))


@pytest.fixture
def recorder(monkeypatch):
    """The settings of every localisation of the simulated runs (their search replaced by a stub)."""
    seen = []

    def localise(grid, scan, *, params=None, **kw):
        seen.append(params)
        return _fake_localisation()

    def localise_joined(grid, scans, odom_poses, *, params=None, **kw):
        seen.append(params)
        return _fake_localisation()

    monkeypatch.setattr(E, "localise", localise)
    monkeypatch.setattr(batch, "localise", localise)  # localise_scans: the batches of run_table1, run_monte_carlo
    monkeypatch.setattr(E, "localise_joined", localise_joined)
    return seen


SIM_RUNS = {
    "run_table1": lambda **kw: CS.run_table1(1, n_beams=36, rng=1, **kw),
    "run_monte_carlo": lambda **kw: CS.run_monte_carlo(1, n_beams=36, rng=1, **kw),
    "run_constants_study": lambda **kw: CS.run_constants_study(1, extra_clutter=0, n_beams=36, rng=1, **kw),
    "run_corridor_tie": lambda **kw: CS.run_corridor_tie(**kw),
}


@pytest.mark.parametrize("run", sorted(SIM_RUNS))
@pytest.mark.parametrize("field", sorted(NON_DEFAULT))
@pytest.mark.parametrize("route", ["params", "override"])
def test_a_field_reaches_every_localisation_of_a_simulated_run(recorder, run, field, route):
    value = NON_DEFAULT[field]
    kw = {"params": C.LocaliseParams(**{field: value})} if route == "params" else {field: value}
    if run == "run_constants_study" and field in ("a_c", "a_p", "a_n"):  # the study's own axis
        with pytest.raises(ValueError, match=f"`{field}` is set by `choices`"):
            SIM_RUNS[run](**kw)
        assert recorder == []
        return
    result = SIM_RUNS[run](**kw)
    assert recorder
    assert all(getattr(p, field) == value for p in recorder)
    assert getattr(result.params, field) == value  # and the result records it


def test_the_simulated_runs_keep_the_other_fields(recorder):
    # the runs change nothing else: the rival search is off in the batch runs only (they report no ambiguity)
    p = C.LocaliseParams(**{k: v for k, v in NON_DEFAULT.items() if k not in ("a_c", "a_p", "a_n")})
    CS.run_table1(1, n_beams=36, rng=1, params=p)
    assert recorder == [p.replace(ambiguity=False)]
    recorder.clear()
    CS.run_corridor_tie(params=p)
    assert recorder == [p, p]


def test_corridor_tie_defaults_only_without_params(recorder):
    CS.run_corridor_tie()
    CS.run_corridor_tie(step_cells=0.25)
    CS.run_corridor_tie(params=C.LocaliseParams())
    assert recorder[0] == E.CORRIDOR_PARAMS
    assert recorder[0].dtype == "float64"
    assert recorder[0].delta_alpha_rad == pytest.approx(np.radians(10.0))
    assert recorder[2] == E.CORRIDOR_PARAMS.replace(step_cells=0.25)  # an override on the study's settings
    assert recorder[4] == C.LocaliseParams()  # params win whole: no study default beats them
    with pytest.raises(ValueError, match="`spacing_cells` must be > 0"):
        CS.run_corridor_tie(spacing_cells=0.0)


def test_constants_study_refuses_its_axis_by_name():
    for name in ("a_c", "a_p", "a_n"):
        with pytest.raises(ValueError, match=f"`{name}` is set by `choices` in run_constants_study"):
            CS.run_constants_study(1, params=C.LocaliseParams(**{name: NON_DEFAULT[name]}))


@pytest.mark.realdata
@pytest.mark.parametrize("run", ["run_log_localisation", "run_log_suite"])
@pytest.mark.parametrize("route", ["params", "override"])
def test_every_field_reaches_the_log_runs(real_data, monkeypatch, run, route):
    from slamlab.io import read_carmen

    seen = []

    def localise_samples(M_values, samples, **kw):
        seen.append(samples.params)
        return _fake_localisation()

    monkeypatch.setattr(_log_scan, "localise_samples", localise_samples)
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    kw = {"params": C.LocaliseParams(**NON_DEFAULT)} if route == "params" else dict(NON_DEFAULT)
    if run == "run_log_localisation":
        CS.run_log_localisation(log, (150,), joined=(1, 2), votes=True, **kw)
    else:
        CS.run_log_suite([log], every=log.n_scans - 1, joined=(1, 2), **kw)
    assert seen
    assert all(p == C.LocaliseParams(**NON_DEFAULT) for p in seen)
