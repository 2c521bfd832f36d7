"""Ch. 10 experiments (002 Fig. 2, Fig. 4, a flight): properties that must hold, not stored numbers."""

import numpy as np
import pytest

from slamlab.studies.planes import (
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


def test_fig4_as_002_sets_it():
    r = run_intensity_figure(rng=0, n_particles=200)
    assert (r.n_planes, r.normal_rank, r.rounds) == (3, 2, 1)     # three planes, two parallel; one cycle
    assert r.spread_solved_m[1] < 1e-3         # y pinned by the walls (up to the weak prior)
    assert r.spread_solved_m[0] > 0.1          # x free along the line
    assert np.std(r.predicted[:, 0]) == pytest.approx(np.sqrt(r.V_xyz_m2), rel=0.15)   # V is a variance
    assert r.error_with_m < r.error_without_m - 0.05                # one cycle moves the pose towards the truth
    assert r.error_without_m > 0.3                                  # the odometry's 0.4 m stays
    assert r.peak == pytest.approx(r.sad_bound(), rel=1e-9)         # SAD* = max - SAD: the identity
    d = np.abs(r.solved[:, 0] - r.true_t[0])
    near, far = r.weights[d < 0.1].mean(), r.weights[d > 0.4].mean()
    assert near > 2 * far                       # the weights peak at the truth
    assert "0.0 - 0.1" in r.profile_table()


def test_fig4_more_cycles_converge():
    r = run_intensity_figure(rng=0, n_particles=200, rounds=5)
    assert r.error_with_m < 0.15
    assert "5 cycles" in r.table()


def test_intensity_spread_and_bad_input():
    from slamlab.studies.planes import run_intensity_spread

    s = run_intensity_spread((0.01, 0.36), n_particles=100, rng=1)
    assert len(s.results) == 2
    assert all(r.peak < 2.5 for r in s.results)    # the SAD* weights stay flat whatever the spread
    assert "sqrt V" in s.table()
    with pytest.raises(ValueError, match="V_values_m2"):
        run_intensity_spread(())
    with pytest.raises(ValueError, match="V_xyz_m2"):
        run_intensity_figure(V_xyz_m2=-0.1)


def test_flight_tracks_and_reports(flight):
    assert flight.n_frames == 6
    assert flight.n_kept_prediction == 0
    assert np.abs(flight.errors[:, :3]).max() < 0.3
    assert len(flight.map) >= 5
    assert "ATE" in flight.table()
    t = flight.mean_stage_times()
    assert t["total"] == pytest.approx(sum(t[s] for s in t if s not in ("total", "cpu")))
    assert t["cpu"] > 0
    tab = timing_table(t, load="1.0")
    assert f"{SOURCE_TIMES_S['total']:.3f}" in tab
    assert "total (CPU)" in tab
    assert "goal 0.09 s" in tab
    assert flight.mean_points > 40000                               # 002: "over 40000 points" per frame
    assert "plane / line / point" in ours_vs_source(flight, run_pairs_figure(50), run_intensity_figure(n_particles=50))


def test_timing_goal_is_half_of_002():
    from slamlab.studies.planes import GOAL_S, timing_goal

    stages = [SOURCE_TIMES_S[s] for s in ("extraction", "description", "motion", "equations", "weights", "pose")]
    assert sum(stages) == pytest.approx(SOURCE_TIMES_S["total"], abs=5e-4)   # 002's table adds up
    assert pytest.approx(SOURCE_TIMES_S["total"] / 2, abs=0.002) == GOAL_S
    assert "0.091" in timing_goal()


def test_bad_arguments():
    with pytest.raises(ValueError, match="size"):
        run_flight(size="huge")
    with pytest.raises(ValueError, match="frame_lines"):
        run_flight(1.0, frame_lines=40)
    with pytest.raises(TypeError, match="flight"):
        run_flight(flight="x")
    with pytest.raises(ValueError, match="n_particles"):
        run_pairs_figure(1)
    with pytest.raises(ValueError, match="frame_poses"):
        run_flight(2.0, frame_poses="gps")


@pytest.mark.slow
def test_a_20_s_flight_beats_the_odometry():
    r = run_flight(20.0, rng=3)
    assert r.n_kept_prediction == 0
    assert r.ate_m < 0.3 * r.ate_odo_m           # the odometry drifts; the planes hold the pose
    assert np.abs(r.errors[:, 5]).max() < 3.0    # yaw within 3 degrees all the way


def test_intensity_study_runs_through_sweep():
    from slamlab.studies.planes import run_intensity_study

    s = run_intensity_study(2, (0.4,), n_particles=60, rng=1, progress=False)
    assert len(s.runs) == 2
    assert (s.runs.error_without_m > 0.3).all()
    assert "0.40" in s.table()
    with pytest.raises(ValueError, match="n_seeds"):
        run_intensity_study(0)
