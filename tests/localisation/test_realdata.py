"""MCL on the five corrected CARMEN logs (real data): tracking and global localisation with stated bounds.

Set-up (see ``run_log_mcl``): map from all scans at the corrected poses (0.1 m cells), 3000 tracking particles
(in our trial with 1000, the Örebro run lost track: particle deprivation), odometry = corrected path
+ 10 % of each step + 1°/step noise, 60 consecutive scans from scan 0, seed 0. Bounds (ours, from the stated
set-up with margin): tracking median error below 0.3 m on every log and at least 40 % of the steps within
0.2 m / 2° (Örebro, with ~0.9 m between scans, is the hardest), at least 75 % on the other four; global
localisation from no prior (20 000 particles, ``global_log_settings``) ends within 0.5 m on at least three of the
five logs.
"""

import numpy as np
import pytest

from slamlab.studies import localisation as LS

pytestmark = pytest.mark.realdata


@pytest.fixture(scope="module")
def results(real_data):
    return {name: LS.run_log_mcl(real_data / "carmen-radish-corrected" / f"{name}-corrected.log.gz", n_scans=60,
                                rng=0)
            for name in LS.CARMEN_LOGS}


@pytest.mark.parametrize("name", LS.CARMEN_LOGS)
def test_tracking_bounds(results, name):
    row = results[name].row()
    assert row["track_median_err_m"] < 0.3
    assert row["track_within"] >= (0.4 if name == "orebro" else 0.75)


def test_global_localisation_from_no_prior(results):
    final = np.array([r.row()["global_final_err_m"] for r in results.values()])
    assert (final < 0.5).sum() >= 3, final


def test_table_has_every_log(results):
    text = LS.logs_table(list(results.values()))
    for name in LS.CARMEN_LOGS:
        assert f"{name}-corrected" in text


def test_log_by_path_and_bad_path(tmp_path):
    with pytest.raises(FileNotFoundError, match="no file"):
        LS.run_log_mcl(tmp_path / "missing.log.gz")
    with pytest.raises(TypeError, match=r"`path` must be a str or os\.PathLike"):
        LS.run_log_mcl(3.5)



def test_protocol_runs_on_a_log_by_path(real_data):
    """The protocol on any CARMEN log by path: one row per stretch and count, the same stretches for every count,
    and a stretch's run does not depend on what else shares the call (its streams are keyed by log, stretch and
    count)."""
    path = real_data / "carmen-radish-corrected" / "seattle-corrected.log.gz"
    res = LS.run_log_protocol(path, (300, 600), n_runs=2, n_scans=4, rng=0, progress=False)
    df = res.table_df
    assert len(df) == 4
    assert df.groupby("n_particles")["start"].apply(list).tolist() == [[0, df["start"].max()]] * 2
    assert "seattle-corrected" in res.table()
    assert df["track_success"].notna().sum() == 2  # the ceiling: once per stretch, with the largest count
    alone = LS.run_log_protocol(path, (600,), n_runs=2, n_scans=4, rng=0, progress=False, track_particles=0)
    both = df[df["n_particles"] == 600].reset_index(drop=True)
    np.testing.assert_array_equal(alone.table_df["final_err_m"].to_numpy(), both["final_err_m"].to_numpy())


@pytest.mark.slow
def test_global_success_on_the_five_logs_is_at_least_08():
    """Issue 27's goal: global localisation from no prior succeeds in >= 0.8 of 10 stretches of 30 scans per log
    over the five shared logs with 20 000 particles (success: within 3 cells = 0.3 m and 5° at the last scan, the
    chapter's criterion). Measured 2026-11-26: 0.84 / 0.88 / 0.92 with rng 0 / 1 / 2 (within 0.2 m and 2°:
    0.76 / 0.74 / 0.88; tracking from the corrected start pose: 0.94 / 0.98 / 1.00)."""
    res = LS.run_log_protocol(LS.CARMEN_LOGS, (20000,), n_runs=10, n_scans=30, rng=0, progress=False,
                             track_particles=0)
    assert len(res.table_df) == 50
    assert res.success() >= 0.8, res.table()
