"""The correlation goal on the five shared CARMEN logs (issue 44's protocol; its own file so that pytest-xdist runs
it beside the other correlation tests).

Every 10th scan of each log, from no prior, its ±2 neighbours left out of its grid; a scan counts when its leave-out
grid covers it at the logged pose (at least half its end points within one cell of a wall: the rule and its
reasons at ``slamlab.studies.correlation.studies.MIN_COVERAGE``, fixed before this run). The goal (issue 25, kept):
>= 75 % of the covered scans localised with one scan and >= 90 % with three joined by odometry, pooled over the five
logs, and >= 2/3 with each on every log. About 225 scans, 4-5 min on one core.
"""

import pytest

from slamlab.io import read_carmen
from slamlab.studies import correlation as CS


@pytest.mark.realdata
def test_correlation_goal_every_10th_scan_of_the_five_logs(real_data):
    logs = [read_carmen(real_data / p) for p in CS.SHARED_CARMEN_LOGS]
    r = CS.run_log_suite(logs, 10, joined=(1, 3), ambiguity=False, progress=False)
    assert r.names == ("csail", "fhw", "intel", "orebro", "seattle")
    assert all(x.exclude == 2 and x.leave_out == "window" for x in r.results)
    n = sum(x.scan_indices.size for x in r.results)
    covered = sum(int(x.covered.sum()) for x in r.results)
    assert n == 225
    # the rule sets aside map holes, not failures: at most 5 % of the scans (3 when this was written)
    assert n - covered <= 0.05 * n
    g = r.meets_goal(single=0.75, joined=0.90, per_log=2 / 3)
    assert g["pooled"][0] >= 0.75, r.goal_table()
    assert g["pooled"][1] >= 0.90, r.goal_table()
    assert min(g["lowest"]) >= 2 / 3, r.table()
