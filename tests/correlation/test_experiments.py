"""Ch. 5 experiments and a real CARMEN log given by path."""

import shutil

import numpy as np
import pytest

from slamlab import correlation as C
from slamlab import sim as S
from slamlab.io import read_carmen
from slamlab.studies import correlation as CS


def test_table1_small_run_meets_the_source_bounds():
    r = CS.run_table1(4, rng=5)
    assert r.true_poses.shape == r.est_poses.shape == (4, 3)
    # 004: position error <= 1 cell; heading error within about one 1° step
    assert r.err_x_cells.max() <= 1
    assert r.err_y_cells.max() <= 1
    assert r.err_heading_rad.max() <= np.radians(1.5)
    t = r.table()
    assert "max (004)" in t
    assert "0.0098" in t
    assert "0.0098" in r.source_table()
    assert "004: 0.0098 rad" in str(r)
    # true poses are whole free cells
    M = S.test_room_200()
    assert np.all(r.true_poses[:, :2] == np.round(r.true_poses[:, :2]))
    assert np.all(M[r.true_poses[:, 1].astype(int), r.true_poses[:, 0].astype(int)] == S.FREE)


def test_table1_noise_free_without_clutter_is_exact():
    r = CS.run_table1(3, range_std_cells=0.0, clutter=False, rng=9)
    assert r.err_x_cells.max() == 0
    assert r.err_y_cells.max() == 0
    # true headings are continuous, estimates on the 1° grid: at most half a step off
    assert r.err_heading_rad.max() <= np.radians(0.5) + 1e-9


def test_monte_carlo_small():
    r = CS.run_monte_carlo(6, rng=3)
    assert r.n_poses == 6
    assert r.failure_rate <= 1 / 6
    assert "failures" in r.table()
    with pytest.raises(ValueError, match="`size` must be one of"):
        CS.run_monte_carlo("huge")


def test_constants_study_runs_both_choices_and_checks_the_sharper_peak():
    r = CS.run_constants_study(3, extra_clutter=10, rng=1)
    assert r.half_max_area.shape == (2, 3)
    assert len(r.example_maps) == 2
    assert r.example_maps[0].shape == (200, 200)
    assert "a_c=0, a_p=1" in r.table()
    # 004 §7: the peak is sharpest at a_p = -a_c. In heading it is (a larger margin, every pose);
    # in position a_c = -1 scores free space too, a broad hill: its half-maximum area is the larger one
    assert np.all(r.heading_margin[0] > r.heading_margin[1])
    assert np.all(r.half_max_area[0] > r.half_max_area[1])
    # the example maps (at the first pose's heading) peak within one cell of its true cell for both choices
    p0 = r.example_pose
    for m in r.example_maps:
        row, col = np.unravel_index(np.argmax(m), m.shape)
        assert max(abs(row - p0[1]), abs(col - p0[0])) <= 1
    with pytest.raises(ValueError, match="`a_c` and `a_p` must differ"):
        CS.run_constants_study(1, choices=((1.0, 1.0, 0.0),))


def test_run_params_and_overrides():
    r = CS.run_table1(1, rng=5, delta_alpha_rad=np.radians(2.0))
    assert r.params.delta_alpha_rad == pytest.approx(np.radians(2.0))
    assert "Δα = 2°" in r.table()
    assert CS.run_table1(1, rng=5, params=C.LocaliseParams(delta_alpha_rad=np.radians(2.0))).est_poses.tolist() \
        == r.est_poses.tolist()
    # the run_* and localise share one default set
    assert CS.run_table1(1, rng=5).params == C.LocaliseParams()


def test_bad_input(tmp_path):
    with pytest.raises(TypeError, match=r"`path` must be a str, os.PathLike or CarmenLog; got int"):
        CS.run_log_localisation(3)
    with pytest.raises(FileNotFoundError, match=r"no file at .*missing.log"):
        CS.run_log_localisation(str(tmp_path / "missing.log"))
    with pytest.raises(TypeError, match=r"LocaliseParams has no field.*'delta_alpha_deg'"):
        CS.run_table1(1, delta_alpha_deg=1.0)
    with pytest.raises(TypeError, match="`table1` must be a Table1Result"):
        CS.ours_vs_source(None)


@pytest.mark.realdata
def test_log_localisation_from_no_prior(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    idx = (50, 150, 350, 450, 550, 750, 850, 250, 650)
    r = CS.run_log_localisation(log, idx)
    # bound: at least 6 of 9 scans within 2 cells (0.4 m) and 5° of the corrected pose, from no prior;
    # the successful ones within 0.25 m and 3° (the grid is 0.2 m, headings 1°)
    assert r.success.shape == (1, 9)
    assert r.success.sum() >= 6
    assert np.all(r.err_pos_m[r.success] <= 0.25)
    assert np.all(np.degrees(r.err_heading_rad[r.success]) <= 3.0)
    assert r.grid.shape[0] > 100
    assert np.all((r.ambiguity >= 0) & (r.ambiguity <= 1))
    assert "intel-corrected.log.gz (CARMEN" in r.table()


@pytest.mark.realdata
@pytest.mark.slow
def test_log_localisation_every_25th_scan_single_and_joined(real_data):
    """The issue-17 run: every 25th Intel scan (25..900, 36 scans, ±10 scans left out of each grid), one scan vs
    three joined by odometry."""
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    r = CS.run_log_localisation(log, range(25, log.n_scans, 25), joined=(1, 3), exclude=10)
    ok = r.success
    assert ok.shape == (2, 36)
    # bounds: one scan localises at least 2/3 of the scans; three joined scans at least 5/6 and at least
    # 3 more than one scan (the joined scans see past corridor and half-turn ties)
    assert ok[0].sum() >= 24
    assert ok[1].sum() >= 30
    assert ok[1].sum() >= ok[0].sum() + 3
    # the ambiguity separates: most single-scan failures read >= 0.75, few successes do
    amb = r.ambiguity[0]
    assert np.mean(amb[~ok[0]] >= 0.75) >= 2 / 3
    assert np.mean(amb[ok[0]] >= 0.75) <= 0.25
    assert "flagged (>= 0.75)" in r.ambiguity_table()
    assert "3 scans + odometry" in r.summary_table()


@pytest.mark.realdata
def test_log_localisation_joined_mode_bad_input(real_data):
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    with pytest.raises(ValueError, match=r"`joined` must be distinct numbers of scans from \{1, \.\.\., 5\}"):
        CS.run_log_localisation(log, (150,), joined=(1, 6))
    with pytest.raises(ValueError, match=r"`scan_indices` must lie in \[2, 909\]"):
        CS.run_log_localisation(log, (1,), joined=(3,))
    with pytest.raises(ValueError, match="`exclude` must be >= 2"):
        CS.run_log_localisation(log, (150,), joined=(3,), exclude=1)
    with pytest.raises(ValueError, match="`odom_std` must be"):
        CS.run_log_localisation(log, (150,), odom_std=(-1.0, 0.0))
    r = CS.run_log_localisation(log, (150,), delta_alpha_rad=np.radians(5.0))
    with pytest.raises(ValueError, match="`bins` must be at least two increasing edges"):
        r.ambiguity_table(bins=(0.5, 0.2))
    with pytest.raises(ValueError, match=r"`threshold` must lie in \[0, 1\]"):
        r.ambiguity_table(threshold=2.0)


@pytest.mark.realdata
def test_log_localisation_takes_any_path_and_labels_from_it(real_data, tmp_path):
    copy = tmp_path / "my_lab_run.log.gz"
    shutil.copy(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz", copy)
    r = CS.run_log_localisation(str(copy), (150,), delta_alpha_rad=np.radians(2.0))
    assert r.name == "my_lab_run.log.gz"
    assert str(r).startswith("my_lab_run.log.gz:")
    assert r.table().startswith("my_lab_run.log.gz (CARMEN")
    assert "Intel" not in r.table()
    assert "intel" not in r.table()
    assert "my_lab_run.log.gz" in CS.ours_vs_source(CS.run_table1(1, rng=1), log=r)


def _sequential_reference(n, rng, clutter=0, n_beams=360, range_std_cells=0.3):
    """The Monte Carlo as one sequential loop (draw a scan, localise it, next pose): what sweep must reproduce."""
    g = np.random.default_rng(rng)
    M, W = S.test_room_200(), S.measurement_room_200()
    if clutter:
        W = S.add_clutter(W, CS.random_clutter(W, clutter, rng=g))
    poses = S.random_free_poses(W, n, margin_cells=2, rng=g)
    rf = S.Rangefinder(n_beams=n_beams, fov_rad=2 * np.pi, max_range_cells=100.0, range_std_cells=range_std_cells,
                       quantum_cells=0.1)
    est = []
    for pose in poses:
        scan = rf.scan(W, pose, g)
        est.append(C.localise(M, scan).pose)
    return poses, np.array(est)


def test_monte_carlo_on_sweep_equals_the_sequential_loop_for_one_and_two_workers():
    poses, est = _sequential_reference(3, 21, clutter=5)
    ea, ex, ey = CS.studies.absolute_errors(poses, est)
    one = CS.run_monte_carlo(3, extra_clutter=5, rng=21, n_jobs=1)
    two = CS.run_monte_carlo(3, extra_clutter=5, rng=21, n_jobs=2)
    for r in (one, two):
        np.testing.assert_array_equal(r.err_heading_rad, ea)
        np.testing.assert_array_equal(r.err_pos_cells, np.hypot(ex, ey))
    np.testing.assert_array_equal(one.failed, two.failed)
    assert one.table() == two.table()


def test_constants_study_identical_for_one_and_two_workers():
    one = CS.run_constants_study(2, extra_clutter=10, rng=4, n_jobs=1)
    two = CS.run_constants_study(2, extra_clutter=10, rng=4, n_jobs=2)
    for name in ("half_max_area", "heading_margin", "failure_rate", "err_pos_cells", "example_pose"):
        np.testing.assert_array_equal(getattr(one, name), getattr(two, name))
    for a, b in zip(one.example_maps, two.example_maps, strict=True):
        np.testing.assert_array_equal(a, b)
    assert one.table() == two.table()


def test_localisation_table_has_one_row_per_choice_and_pose():
    scans = [S.Rangefinder(n_beams=90, max_range_cells=40.0).scan(S.test_room_200(), [60.0, 40.0, 0.5])] * 2
    settings = (C.LocaliseParams(delta_alpha_rad=np.radians(10.0)),
                C.LocaliseParams(delta_alpha_rad=np.radians(10.0), a_c=0.0))
    table = CS.batch.localise_scans(S.test_room_200(), scans, settings, margins=True, progress=False)
    assert table.columns.tolist() == ["choice", "pose_index", "x", "y", "heading_rad", "half_max_area",
                                      "heading_margin"]
    assert table[["choice", "pose_index"]].to_numpy().tolist() == [[0, 0], [0, 1], [1, 0], [1, 1]]


@pytest.mark.realdata
def test_log_localisation_progress_bar_only_when_asked(real_data, capsys):
    log = read_carmen(real_data / "carmen-radish-corrected" / "intel-corrected.log.gz")
    quiet = CS.run_log_localisation(log, (150,), delta_alpha_rad=np.radians(5.0))  # SLAMLAB_PROGRESS=0 in tests
    assert capsys.readouterr().err == ""
    shown = CS.run_log_localisation(log, (150,), delta_alpha_rad=np.radians(5.0), progress=True)
    assert "localise log scans" in capsys.readouterr().err
    np.testing.assert_array_equal(quiet.est_poses_m, shown.est_poses_m)
