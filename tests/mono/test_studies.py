"""Studies beside 003's text: pinhole, eq. 6.4, tau, the two convergence tests (ours)."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab.studies.mono import studies


def test_eq_6_4_points_reproject_to_their_pixel_at_every_inverse_depth():
    K = np.array([[300.0, 0, 160], [0, 300.0, 120], [0, 0, 1]])
    txt = studies.inverse_depth_point_table(K, uv=(200.0, 50.0), rhos=(1.0, 0.1, 1e-6))
    assert txt.count("(200.00, 50.00)") == 3


def test_pinhole_table_projects_by_hand():
    K = np.array([[500.0, 0, 320], [0, 400.0, 240], [0, 0, 1]])
    txt = studies.pinhole_table((1.0, -0.5, 5.0), cameras={"c": (K, 640, 480)})
    assert "(420.0, 200.0)" in txt  # 500 * 1/5 + 320, 400 * -0.5/5 + 240
    with pytest.raises(ValueError, match="`X_cam` must lie in front"):
        studies.pinhole_table((0.0, 0.0, -1.0), cameras={"c": (K, 640, 480)})


def test_tau_shrinks_with_the_baseline_and_matches_its_first_order_form():
    txt = studies.tau_table(depths_m=(5.0,), baselines_m=(0.1, 0.5, 2.0), f_px=500.0)
    rows = [r.split() for r in txt.splitlines()[3:]]
    tau = [float(r[3]) for r in rows]
    assert tau[0] > tau[1] > tau[2] > 0
    t_rho, lin = float(rows[2][4]), float(rows[2][5])
    assert t_rho == pytest.approx(lin, rel=0.05)  # small tau: ½(1/(z-τ) - 1/(z+τ)) ≈ τ/z²


def test_convergence_tests_accept_accurate_seeds_and_grow_monotonically():
    c = studies.run_convergence_tests((0.0, 0.3), n_obs=30, n_seeds=200, rng=1)
    assert np.all(np.diff(c.conv_L, axis=1) >= 0)
    assert np.all(np.diff(c.conv_svo, axis=1) >= 0)
    assert c.conv_L[0, -1] > 0.9
    assert c.conv_svo[0, -1] > 0.9
    assert np.all(c.err_L < 0.05)
    assert np.all(c.err_svo < 0.05)
    with pytest.raises(ValueError, match="`outlier_rates`"):
        studies.run_convergence_tests((1.0,))
