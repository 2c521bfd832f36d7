"""Ch. 10 ablations: one pair vs two normal directions, incidence correction, where the flight's error comes from."""

import numpy as np
import pytest

from slamlab import sim
from slamlab.studies.planes import (
    flight_head,
    in_frame_rotation_error_deg,
    map_normal_error_deg,
    ours_vs_source,
    run_frame_source_ablation,
    run_incidence_ablation,
    run_pairs_ablation,
    run_pairs_figure,
)


@pytest.fixture(scope="module")
def flight():
    return sim.simulate_flight(6.0, rng=3)


def test_frames_from_the_odometry_set_the_error_floor(flight):
    r = run_frame_source_ablation(flight, n_particles=100, rng=3)
    rms = [res.rms()[0] for res in r.results]
    assert rms[1][3] < 0.1
    assert rms[3][3] < 0.1
    assert rms[0][3] > 2 * rms[1][3]                    # 002's frames: the odometry's in-frame error shows
    assert np.all(np.abs(rms[2] - rms[0]) < 0.5 * rms[0] + 1e-3)   # true increments change little
    assert "odometry alone" in r.table()
    e = in_frame_rotation_error_deg(flight)
    assert e.shape == (3,)
    assert np.all(e > 0)


def test_pairs_ablation_keeps_frames_only_when_asked(flight):
    r = run_pairs_ablation(flight, n_particles=60, rng=3)
    kept = [res.n_kept_prediction for res in r.results]
    assert kept[1] == kept[3] == kept[4] == 0           # one pair is enough: every frame is used
    assert kept[2] > 0                                  # the two largest planes are often parallel (floor, ceiling)
    assert r.results[4].mean_planes == 1.0
    assert "one pair" in r.table()


def test_incidence_ablation_and_closing_rows(flight):
    r = run_incidence_ablation(flight, n_particles=60, fig4_particles=100, rng=3)
    assert len(r.fig4) == len(r.flights) == 2
    assert "off" in r.table()
    p = run_pairs_ablation(flight, n_particles=30, rng=3)
    tab = ours_vs_source(r.flights[0], run_pairs_figure(20), r.fig4[0], one_pair=p, incidence=r)
    assert "largest plane only" in tab
    assert "incidence correction" in tab


def test_map_tilt_follows_the_frames(flight):
    r = run_frame_source_ablation(flight, n_particles=60, rng=3)
    odo, true = (map_normal_error_deg(x, flight.room) for x in r.results[:2])
    assert true < 0.1 < odo                               # the odometry's in-frame error tilts the map
    assert "median angle" in r.table()


def test_bad_input(flight):
    with pytest.raises(TypeError, match="flight"):
        run_pairs_ablation("x")
    with pytest.raises(ValueError, match="duration_s"):
        flight_head(flight, 100.0)
    with pytest.raises(TypeError, match="flight"):
        flight_head("x", 1.0)
    assert len(flight_head(flight, 2.0)) == 80
