"""MCL on the five corrected CARMEN logs (real data): tracking and global localisation with stated bounds.

Set-up (see ``run_log_mcl``): 0.1 m cells, 3000 tracking particles (in our trial with 1000, the Örebro run lost
track: particle deprivation), odometry = corrected path + 10 % of each step + 1°/step noise, 60 consecutive scans
from scan 0, seed 0, on two maps: the leave-out map (every scan but scans 0-61: the stretch and 2 on either side;
the default) and the map of all scans (``map_leave_out="none"``). Bounds (ours, set on the map of all scans from
the stated set-up with margin): tracking median error below 0.3 m on every log and at least 40 % of the steps
within 0.2 m / 2° (Örebro, with ~0.9 m between scans, is the hardest), at least 75 % on the other four; global
localisation from no prior (20 000 particles, ``global_log_settings``) ends within 0.5 m on at least three of the
five logs. On the leave-out map the tracking bounds fail on CSAIL, FHW and Örebro (strict xfails with the measured
numbers); the global bound holds (3 of 5).
"""

import numpy as np
import pytest

from slamlab.studies import localisation as LS

pytestmark = pytest.mark.realdata

#: Measured 2026-12-08 on the leave-out map (rng 0, 60 scans from scan 0): (median error [m], share within
#: 0.2 m / 2°, coverage of the stretch by its map).
_LEAVE_OUT_TRACKING = {"csail": (2.168, 0.30, 0.66), "fhw": (0.120, 0.68, 0.79), "orebro": (18.864, 0.17, 0.35)}


def _tracking_case(map_leave_out, name):
    if map_leave_out == "stretch" and name in _LEAVE_OUT_TRACKING:
        err, within, cov = _LEAVE_OUT_TRACKING[name]
        why = (f"on the leave-out map {name} tracks with median error {err} m and {within} of the steps within "
               f"0.2 m / 2° (measured 2026-12-08, rng 0; the map covers {cov} of the stretch's end points): the "
               f"bound was set on the map of all scans")
        return pytest.param(map_leave_out, name, marks=pytest.mark.xfail(strict=True, reason=why))
    return pytest.param(map_leave_out, name)


@pytest.fixture(scope="module")
def results(real_data):
    """``results(map_leave_out)`` -> {log name: LogMCLResult}, run once per map."""
    runs = {}

    def get(map_leave_out="stretch"):
        if map_leave_out not in runs:
            runs[map_leave_out] = {
                name: LS.run_log_mcl(real_data / "carmen-radish-corrected" / f"{name}-corrected.log.gz", n_scans=60,
                                     rng=0, map_leave_out=map_leave_out)
                for name in LS.CARMEN_LOGS}
        return runs[map_leave_out]

    return get


@pytest.mark.parametrize(("map_leave_out", "name"),
                         [_tracking_case(m, n) for m in ("stretch", "none") for n in LS.CARMEN_LOGS])
def test_tracking_bounds(results, map_leave_out, name):
    row = results(map_leave_out)[name].row()
    assert row["track_median_err_m"] < 0.3
    assert row["track_within"] >= (0.4 if name == "orebro" else 0.75)


@pytest.mark.parametrize("map_leave_out", ["stretch", "none"])
def test_global_localisation_from_no_prior(results, map_leave_out):
    final = np.array([r.row()["global_final_err_m"] for r in results(map_leave_out).values()])
    assert (final < 0.5).sum() >= 3, final


def test_the_leave_out_map_is_not_drawn_by_the_stretch(results, real_data):
    """On Örebro the stretch's scans (0-59) and 2 more drew no part of its map: the map is a recount of scans 62 on,
    it differs from the map of all scans, and it knows far less of the stretch (Örebro's scans are ~0.9 m apart, so
    the other scans see few of the stretch's walls; measured coverage 0.35 against 0.95). Coverage is not smaller on
    every log: on Intel, whose start the robot passes again, it is 0.96 on both maps."""
    from slamlab import scans as SC

    r, a = results("stretch")["orebro"], results("none")["orebro"]
    _, frame, scans_c, Pc, counts = LS.read_log_counts(real_data / "carmen-radish-corrected" /
                                                       "orebro-corrected.log.gz")
    np.testing.assert_array_equal(r.grid, SC.occupancy_grid(scans_c[62:], Pc[62:], frame.shape).grid)
    np.testing.assert_array_equal(a.grid, counts.grid)
    assert (r.grid != a.grid).any()
    assert r.coverage < a.coverage - 0.3


def test_table_has_every_log(results):
    text = LS.logs_table(list(results().values()))
    for name in LS.CARMEN_LOGS:
        assert f"{name}-corrected" in text
    assert "map without the stretch ±2 scans" in text


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
    table = res.table()
    assert "  seattle " in table
    assert "untuned logs" in table  # Seattle is not a log the settings were tuned on
    assert "  tuned logs" not in table
    assert (df["left_out"] == 4 + 2).all()  # 4 scans from the log's start (clipped) or end, and 2 beside them
    assert df["coverage"].between(0.5, 1.0).all()
    assert df["track_success"].notna().sum() == 2  # the ceiling: once per stretch, with the largest count
    alone = LS.run_log_protocol(path, (600,), n_runs=2, n_scans=4, rng=0, progress=False, track_particles=0)
    both = df[df["n_particles"] == 600].reset_index(drop=True)
    np.testing.assert_array_equal(alone.table_df["final_err_m"].to_numpy(), both["final_err_m"].to_numpy())


#: Why the goal fails on leave-out maps (measured 2026-12-08, 10 stretches of 30 scans per log, 20 000 particles).
_GOAL_ON_LEAVE_OUT = (
    "on leave-out maps (each stretch and 2 scans on either side left out of its map) the success is 0.58 / 0.60 / "
    "0.62 with rng 0 / 1 / 2 (tuned logs fhw, intel, orebro: 0.47 / 0.47 / 0.50; untuned csail, seattle: 0.75 / "
    "0.80 / 0.80; rng 0 per log: intel 0.70, fhw 0.60, orebro 0.10, csail 0.60, seattle 0.90), below the goal 0.8")


@pytest.mark.slow
@pytest.mark.parametrize("map_leave_out", [pytest.param("stretch", marks=pytest.mark.xfail(strict=True,
                                                                                           reason=_GOAL_ON_LEAVE_OUT)),
                                           "none"])
def test_global_success_on_the_five_logs_is_at_least_08(map_leave_out):
    """Issue 27's goal: global localisation from no prior succeeds in >= 0.8 of 10 stretches of 30 scans per log
    over the five shared logs with 20 000 particles (success: within 3 cells = 0.3 m and 5° at the last scan, the
    chapter's criterion).

    On leave-out maps (the default; measured 2026-12-08, about 1-2 min a run): 0.58 / 0.60 / 0.62 with rng 0 / 1 / 2
    (within 0.2 m and 2°: 0.48 / 0.52 / 0.58; tracking from the corrected start pose: 0.72 / 0.72 / 0.72); tuned
    logs 0.47 / 0.47 / 0.50, untuned 0.75 / 0.80 / 0.80; Örebro 0.10 / 0.10 / 0.20, whose stretches' maps cover
    0.48 of their end points (the other logs 0.78-0.93). The goal fails: a strict xfail, the bound kept.

    On maps of all scans (``map_leave_out="none"``; measured 2026-12-08): 0.86 / 0.88 / 0.92 with rng 0 / 1 / 2
    (within 0.2 m and 2°: 0.76 / 0.74 / 0.86; tracking: 0.98 / 0.96 / 1.00); tuned logs 0.77 / 0.80 / 0.87, untuned
    1.00 / 1.00 / 1.00, coverage 0.94. With rng 0 the bound holds with a margin of 3 runs (43 of 50)."""
    res = LS.run_log_protocol(LS.CARMEN_LOGS, (20000,), n_runs=10, n_scans=30, rng=0, progress=False,
                             track_particles=0, map_leave_out=map_leave_out)
    assert len(res.table_df) == 50
    assert res.success() >= 0.8, res.table()
