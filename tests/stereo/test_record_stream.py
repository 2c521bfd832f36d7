"""The stereo pipeline's store calls recorded as a workload for the store chapter."""

def test_recorded_stereo_stream_replays_through_the_stores():
    """A real descriptor stream recorded from the stereo pipeline (issue 4's 'real stream')."""
    from slamlab.studies.kdtree.experiments import run_store_comparison
    from slamlab.studies.stereo import record_stereo_stream

    w = record_stereo_stream(6, detector="sift", rng=0)
    assert len(w) >= 5
    assert all(it.queries.shape[1] == 128 for it in w.iterations if it.queries.size)
    assert sum(it.observed.size for it in w.iterations) > 0  # landmarks were re-sighted
    res = run_store_comparison(w, stores=("multi", "brute"), checks=10**9)  # unlimited BBF: exact
    assert res.recall["brute"] == 1.0
    assert res.recall["multi"] == 1.0
