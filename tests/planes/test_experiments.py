"""Ch. 10 experiments (002 Fig. 2, Fig. 4, a flight): properties that must hold, not stored numbers."""

import numpy as np
import pytest

from slamlab.planes.experiments import (
    SOURCE_TIMES_S,
    ours_vs_source,
    run_flight,
    run_intensity_figure,
    run_pairs_figure,
    timing_table,
)


@pytest.fixture(scope="module")
def flight():
    return run_flight(6.0, rng=0, n_particles=100)


def test_fig2_locus_dimensions():
    r = run_pairs_figure(200, rng=1)
    dims = [int(np.sum(s > 1e-6)) for s in r.spread_after]
    assert dims == [2, 1, 0]
    np.testing.assert_allclose(r.after[2], np.broadcast_to(r.true_t, r.after[2].shape), atol=1e-9)
    assert "point" in r.table()


def test_fig4_intensity_weights_resolve_the_line():
    r = run_intensity_figure(rng=0, n_particles=200)
    assert r.spread_solved_m[1] < 1e-3         # y pinned by the walls (up to the weak prior)
    assert r.spread_solved_m[0] > 0.1          # x free along the corridor
    assert r.error_with_m < 0.5 * r.error_without_m
    assert r.error_without_m > 0.3                                  # the odometry's 0.4 m stays


def test_flight_tracks_and_reports(flight):
    assert flight.n_frames == 6
    assert flight.n_kept_prediction == 0
    assert np.abs(flight.errors[:, :3]).max() < 0.3
    assert len(flight.map) >= 5
    assert "ATE" in flight.table()
    t = flight.mean_stage_times()
    assert t["total"] == pytest.approx(sum(t[s] for s in t if s != "total"))
    tab = timing_table(t, load="1.0")
    assert f"{SOURCE_TIMES_S['total']:.3f}" in tab
    assert "plane / line / point" in ours_vs_source(flight, run_pairs_figure(50), run_intensity_figure(n_particles=50))


def test_bad_arguments():
    with pytest.raises(ValueError, match="size"):
        run_flight(size="huge")
    with pytest.raises(ValueError, match="frame_lines"):
        run_flight(1.0, frame_lines=40)
    with pytest.raises(TypeError, match="flight"):
        run_flight(flight="x")
    with pytest.raises(ValueError, match="n_particles"):
        run_pairs_figure(1)


@pytest.mark.slow
def test_a_20_s_flight_beats_the_odometry():
    r = run_flight(20.0, rng=3)
    assert r.n_kept_prediction == 0
    assert r.ate_m < 0.3 * r.ate_odo_m           # the odometry drifts; the planes hold the pose
    assert np.abs(r.errors[:, 5]).max() < 3.0    # yaw within 3 degrees all the way


def test_intensity_study_runs_through_sweep():
    from slamlab.planes.experiments import run_intensity_study

    s = run_intensity_study(2, (0.4,), n_particles=60, seed=1, progress=False)
    assert len(s.runs) == 2
    assert (s.runs.error_without_m > 0.3).all()
    assert "0.40" in s.table()
    with pytest.raises(ValueError, match="n_seeds"):
        run_intensity_study(0)
