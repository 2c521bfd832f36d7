"""Bad input gives a clear error naming the argument (CONVENTIONS: friendly layer over a strict core)."""

import numpy as np
import pytest

from slamlab import localisation as L
from slamlab.scans import Scan
from slamlab.studies import localisation as LS


def _room():
    g = np.zeros((20, 20), np.int8)
    g[0] = g[-1] = g[:, 0] = g[:, -1] = 1
    return g


def test_empty_map():
    with pytest.raises(ValueError, match="no OBSTACLE cell"):
        L.MCL(np.zeros((20, 20), np.int8), 30.0)
    with pytest.raises(ValueError, match="no OBSTACLE cell"):
        L.MarkovGrid(np.zeros((20, 20), np.int8), 30.0)
    with pytest.raises(ValueError, match="no FREE cell"):
        L.uniform_free_particles(np.ones((5, 5), np.int8), 3)


def test_scan_with_no_valid_beam():
    s = Scan([0.0, 1.0], [30.0, 30.0], np.zeros(2, bool), max_range=30.0)
    with pytest.raises(ValueError, match="no valid beam"):
        L.scan_beams(s)
    f = L.MCL(_room(), 30.0, n_particles=10, rng=0)
    with pytest.raises(ValueError, match="no valid beam"):
        f.step(None, None, s)
    with pytest.raises(ValueError, match="cell units"):
        L.scan_beams(Scan([0.0], [1.0], np.ones(1, bool), unit="m"))
    with pytest.raises(TypeError, match="`scan` must be a Scan"):
        L.scan_beams([1, 2])


def test_nan_poses():
    with pytest.raises(ValueError, match="`init_pose` must be finite"):
        L.MCL(_room(), 30.0, init_pose=[np.nan, 1, 0])
    with pytest.raises(ValueError, match="`poses` must be finite"):
        L.sample_motion_odometry([[0, np.nan, 0]], [0, 0, 0], [1, 0, 0], (0.1, 0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match="odometry poses must be finite"):
        L.sample_motion_odometry([[0, 0, 0]], [0, 0, np.nan], [1, 0, 0], (0.1, 0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match=r"`particles` must have shape \(N, 3\)"):
        L.check_particles(np.zeros((4, 2)))


@pytest.mark.parametrize("n", [0, -5])
def test_particle_count_must_be_positive(n):
    with pytest.raises(ValueError, match="`n_particles` must be >= 1"):
        L.MCLParams(n_particles=n)
    with pytest.raises(ValueError, match="`n` must be >= 1"):
        L.uniform_free_particles(_room(), n)
    with pytest.raises(ValueError, match="`n` must be >= 1"):
        L.low_variance_resample([0.5, 0.5], n)


def test_params_checks():
    with pytest.raises(TypeError, match="n_particles"):
        L.MCLParams(n_particles=2.5)
    with pytest.raises(ValueError, match="`alpha_fast` must be > `alpha_slow`"):
        L.MCLParams(alpha_slow=0.2, alpha_fast=0.1)
    with pytest.raises(ValueError, match="`alpha` must be four finite numbers >= 0"):
        L.MCLParams(alpha=(0.1, 0.1))
    with pytest.raises(TypeError, match="`alpha` must be a tuple of four"):
        L.MCLParams(alpha=[0.1, 0.1, 0.1, 0.1])
    with pytest.raises(ValueError, match="`alpha_ref` must be four finite numbers >= 0"):
        L.check_alpha((0.1, -1.0, 0.1, 0.1), "alpha_ref")
    with pytest.raises(ValueError, match="`sigma_hit` must be > 0"):
        L.MCLParams(sigma_hit=0.0)
    with pytest.raises(TypeError, match="has no field"):
        L.MCLParams.resolve(None, n_particle=3)
    with pytest.raises(ValueError, match="`n_headings` must be >= 4"):
        L.MarkovParams(n_headings=2)
    with pytest.raises(ValueError, match="`prior` must be"):
        L.MarkovGrid(_room(), 30.0, prior=np.ones((3, 3)))


def test_weights_errors():
    with pytest.raises(ValueError, match="`weights` must not all be 0"):
        L.low_variance_resample([0.0, 0.0])
    with pytest.raises(ValueError, match="`weights` must be a non-empty"):
        L.low_variance_resample([np.nan, 1.0])
    with pytest.raises(ValueError, match="`cov` must be a finite 3×3"):
        L.is_localised(np.eye(2))
    with pytest.raises(ValueError, match="`alpha` must be four"):
        L.motion_density_odometry([[0, 0, 0]], [[0, 0, 0]], [0, 0, 0], [1, 0, 0], (1, 2, 3))


def test_new_params_checks():
    with pytest.raises(ValueError, match="`score` must be one of"):
        L.MCLParams(score="product")
    with pytest.raises(ValueError, match="`averages` must be one of"):
        L.MCLParams(averages="zero")
    with pytest.raises(TypeError, match="`beam_skip` must be a bool"):
        L.MCLParams(beam_skip=1)
    with pytest.raises(ValueError, match="`converged_dist` must be > 0"):
        L.MCLParams(converged_dist=0.0)
    with pytest.raises(ValueError, match="`uniform_floor` must be in"):
        L.MarkovParams(uniform_floor=1.0)
    with pytest.raises(TypeError, match="`variants` must hold"):
        LS.run_global_ablation([("a", 3)], n_runs=1)
    with pytest.raises(ValueError, match="`size` must be one of"):
        LS.run_global_ablation(size="huge")
    with pytest.raises(TypeError, match="has no field"):
        LS.run_global_localisation((10,), n_runs=1, sigma=3)
    mg = L.MarkovGrid(_room(), 30.0, resolution=2, n_headings=8)
    with pytest.raises(ValueError, match="`pose` must be three finite"):
        mg.gaussian_prior([np.nan, 1, 0], 2.0, 0.3)


def test_log_with_too_few_scans_names_the_length(tmp_path):
    from slamlab.io import CarmenLog

    n = 5
    log = CarmenLog(path=str(tmp_path / "tiny.log"), ranges_m=np.ones((n, 4)), valid=np.ones((n, 4), bool),
                    poses=np.zeros((n, 3)), odom_poses=np.zeros((n, 3)), timestamps_s=np.arange(n, dtype=float),
                    odom=np.zeros((0, 4)), max_range_m=10.0)
    with pytest.raises(ValueError, match=r"`n_scans` must be <= the 5 scans of log 'tiny.log'; got 40"):
        LS.run_log_mcl(log, n_scans=40)
    with pytest.raises(ValueError, match=r"`start` \+ `n_scans` must be <= the 5 scans of log 'tiny.log'; got 4 \+ 3"):
        LS.run_log_mcl(log, start=4, n_scans=3)


def test_carmen_path_takes_a_log_name_or_any_file(tmp_path):
    f = tmp_path / "mine.log"
    f.write_text("PARAM robot_front_laser_max 10\n")
    assert LS.carmen_path(f) == f
    assert LS.carmen_path(str(f)) == f
    with pytest.raises(FileNotFoundError, match="no file"):
        LS.carmen_path(tmp_path / "missing.log")
    with pytest.raises(TypeError, match=r"`path` must be a str or os\.PathLike"):
        LS.carmen_path(3)
    with pytest.raises(ValueError, match="`cell_m` must be > 0"):
        LS.log_map(f, cell_m=0.0)
