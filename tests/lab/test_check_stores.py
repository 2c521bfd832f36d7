"""Lab 04 tasks: solutions written from 000 §3.4, §4 and the Appendix pass, typical mistakes fail at the right case."""

from __future__ import annotations

import math

import numpy as np
import pytest

import slamlab_grading as lab
from slamlab_grading import core

# --- independent solutions (what a student should write) --------------------------------------------


def tree_sizes(n1, q, batches, *, strict=True, grow=True):
    cap = lambda i: math.floor(n1 * q**i + 1e-9)
    sizes = [0]
    for b in batches:
        sizes[0] += b
        i = 0
        while (sizes[i] > cap(i)) if strict else (sizes[i] >= cap(i) and sizes[i] > 0):
            if i + 1 == len(sizes):
                sizes.append(0)
            sizes[i + 1] += sizes[i]
            sizes[i] = 0
            i += 1
        while grow and cap(len(sizes) - 1) < sum(sizes):
            sizes.append(0)
    return sizes


def base_rule(history, base_seen_times, max_non_base_time, *, last_age=None):
    last_age = max_non_base_time if last_age is None else last_age
    seen, first, done = {}, {}, set()
    base, dropped = [], []
    for t, frame in enumerate(history):
        for i in map(int, frame):
            if i in done:
                continue
            if i in seen:
                seen[i] += 1
            else:
                seen[i], first[i] = 1, t
        for i in list(seen):
            if seen[i] >= base_seen_times:
                base.append(i)
            elif t - first[i] >= last_age:
                dropped.append(i)
            else:
                continue
            done.add(i)
            del seen[i]
    return np.sort(np.array(base, dtype=int)), np.sort(np.array(dropped, dtype=int))


def iter_time(n1, q, n, s, m, C, *, with_s=False):
    lg = math.log2
    p = math.log(n / n1) / math.log(q) + 1
    search = p * lg(n1) + C * p * (p - 1) / 2 * lg(q)
    add = n1 * lg(n1) + m * q * p * lg(n1) + m * q / 2 * p * (p - 1) * lg(q)
    return add + C * (s if with_s else 1) * search


def merge_knn(dists, ids, k, *, kind="stable"):
    D, I = np.hstack(dists), np.hstack(ids)
    o = np.argsort(D, axis=1, kind=kind)[:, :k]
    D, I = np.take_along_axis(D, o, 1), np.take_along_axis(I, o, 1)
    if D.shape[1] < k:
        pad = k - D.shape[1]
        D = np.hstack([D, np.full((len(D), pad), np.inf)])
        I = np.hstack([I, np.full((len(I), pad), -1)])
    return D, I


@pytest.mark.parametrize(("task_id", "fn"), [("04.tree_sizes", tree_sizes), ("04.base_rule", base_rule),
                                             ("04.iter_time", iter_time), ("04.merge_knn", merge_knn)])
def test_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


#: The feedback file's cases (seed 0) and the grading's: a named mistake must fail on both, at an edge case.
SEEDS = (0, core.GRADING_RNG)


def _fails_at(task_id, fn, label):
    """``fn`` fails ``task_id`` at the case whose label starts with ``label`` ("" for any case) on every seed."""
    for rng in SEEDS:
        res = lab.check(task_id, fn, rng=rng, quiet=True)
        assert res.status == "failed", (rng, res.message)
        assert f"({label}" in res.message, (rng, res.message)


def test_tree_sizes_mistakes():
    def merge_when_full(n1, q, batches):  # ">= MAX_SIZE" instead of "> MAX_SIZE"
        return tree_sizes(n1, q, batches, strict=False)

    def no_empty_trees(n1, q, batches):  # forgets to append trees until the last can hold the total
        return tree_sizes(n1, q, batches, grow=False)

    # the random cases may catch them first; the edge cases catch them whatever the seed
    for rng in SEEDS:
        assert lab.check("04.tree_sizes", merge_when_full, rng=rng, quiet=True).status == "failed"
        assert lab.check("04.tree_sizes", no_empty_trees, rng=rng, quiet=True).status == "failed"
    assert merge_when_full(5, 2.0, [5]) != tree_sizes(5, 2.0, [5])  # the edge case "a batch of exactly MAX_SIZE"
    assert no_empty_trees(5, 2.0, [4, 4, 4]) != tree_sizes(5, 2.0, [4, 4, 4])  # "the total outgrows the last tree"
    edge = [c for c in core.task("04.tree_sizes").cases(np.random.default_rng(1)) if not c.label.startswith("random")]
    for mistake in (merge_when_full, no_empty_trees):
        assert any(mistake(**c.kwargs) != tree_sizes(**c.kwargs) for c in edge), mistake.__name__


def test_base_rule_mistakes():
    def one_frame_short(history, base_seen_times, max_non_base_time):  # drops a frame too early
        return base_rule(history, base_seen_times, max_non_base_time, last_age=max_non_base_time - 1)

    def drop_before_promote(history, base_seen_times, max_non_base_time):  # the window check first
        b, d = base_rule(history, base_seen_times, max_non_base_time)
        late_base = [i for i in b if i == 0 and len(history) == 13]  # the edge case's id 0 is promoted at age 7
        return np.setdiff1d(b, late_base), np.union1d(d, late_base).astype(int)

    for rng in SEEDS:
        assert lab.check("04.base_rule", one_frame_short, rng=rng, quiet=True).status == "failed"
    _fails_at("04.base_rule", drop_before_promote, "window edge")
    edge = next(c for c in core.task("04.base_rule").cases(np.random.default_rng(1)) if c.label.startswith("window"))
    for a, b in zip(one_frame_short(**edge.kwargs), base_rule(**edge.kwargs), strict=True):
        if not np.array_equal(a, b):
            break
    else:
        raise AssertionError("the window-edge case does not catch one_frame_short")


def test_iter_time_mistakes():
    def adjusted(n1, q, n, s, m, C):  # §4.1.2's C s T_search instead of the Appendix's C searchKd
        return iter_time(n1, q, n, s, m, C, with_s=True)

    def natural_log(n1, q, n, s, m, C):
        return iter_time(n1, q, n, s, m, C) * math.log(2)

    _fails_at("04.iter_time", adjusted, "000's optimum")
    _fails_at("04.iter_time", natural_log, "000's optimum")


def test_merge_knn_mistakes():
    def first_tree_only(dists, ids, k):
        return merge_knn(dists[:1], ids[:1], k)

    def no_padding(dists, ids, k):
        D, I = np.hstack(dists), np.hstack(ids)
        o = np.argsort(D, axis=1, kind="stable")[:, :k]
        return np.take_along_axis(D, o, 1), np.take_along_axis(I, o, 1)

    def unstable(dists, ids, k):  # sorting on (distance, -id): ties broken the wrong way
        D, I = merge_knn(dists, ids, sum(d.shape[1] for d in dists))
        o = np.lexsort((-I, D), axis=1)[:, :k]
        return merge_knn([np.take_along_axis(D, o, 1)], [np.take_along_axis(I, o, 1)], k)

    for rng in SEEDS:
        assert lab.check("04.merge_knn", first_tree_only, rng=rng, quiet=True).status == "failed"
    _fails_at("04.merge_knn", no_padding, "one tree of one point")
    _fails_at("04.merge_knn", unstable, "a tie")
    edge = next(c for c in core.task("04.merge_knn").cases(np.random.default_rng(1)) if c.label.startswith("a tie"))
    assert not np.array_equal(first_tree_only(**edge.kwargs)[1], merge_knn(**edge.kwargs)[1])  # whatever the seed


def _library_calls():
    """The library's own functions wrapped to each task's signature (what the forbid check must catch)."""
    from slamlab.kdtree import cost_model, knn, stores

    def base_rule_with_the_store(history, base_seen_times, max_non_base_time):
        book, known, base, dropped = stores.SightingBook(base_seen_times, max_non_base_time), set(), [], []
        for frame in history:
            frame = np.asarray(frame, dtype=np.int64)
            book.observe(frame[[int(i) in known for i in frame]] if frame.size else frame)
            book.add(frame[[int(i) not in known for i in frame]] if frame.size else frame)
            known.update(int(i) for i in frame)
            p, d = book.step()
            base += p.tolist()
            dropped += d.tolist()
        return np.sort(np.array(base, dtype=int)), np.sort(np.array(dropped, dtype=int))

    return {"04.tree_sizes": lambda n1, q, batches: list(stores.multi_tree_sizes(n1, q, batches)[-1]),
            "04.base_rule": base_rule_with_the_store,
            "04.iter_time": lambda n1, q, n, s, m, C: cost_model.iter_time(n1, q, n=n, s=s, m=m, C=C,
                                                                           reading="literal"),
            "04.merge_knn": lambda dists, ids, k: knn.merge_knn(dists, ids, k)}


@pytest.mark.parametrize("task_id", ["04.tree_sizes", "04.base_rule", "04.iter_time", "04.merge_knn"])
def test_the_librarys_own_function_is_refused(task_id):
    import slamlab as sl

    fn = _library_calls()[task_id]
    for res in (lab.check(task_id, fn, quiet=True), sl.lab.check(task_id, fn, quiet=True)):  # grading, feedback
        assert res.status == "failed", res.message
        assert "called the library's slamlab.kdtree." in res.message, res.message


def test_exploration_answers():
    import slamlab as sl

    n1 = sl.kdtree.cost_model.minimise_iter_time(n=50000, s=500, m=500, C=9.0, reading="literal")[0]
    assert n1 == pytest.approx(1200.0)
    assert lab.answer("04.explore.literal_n1", n1, quiet=True).passed
    assert lab.answer("04.explore.literal_n1", 3500, quiet=True).status == "failed"

    rebuilt = _rebuilt(1000, 3.0, [500] * 40)
    assert rebuilt == 71000
    assert lab.answer("04.explore.points_rebuilt", rebuilt, quiet=True).passed
    assert lab.answer("04.explore.points_rebuilt", rebuilt + 500, quiet=True).status == "failed"


def _rebuilt(n1, q, batches):
    """Points put into newly built trees: tree 1 after every batch, and every tree a merge lands in."""
    cap = lambda i: math.floor(n1 * q**i + 1e-9)
    sizes, total = [0], 0
    for b in batches:
        sizes[0] += b
        changed, i = {0}, 0
        while sizes[i] > cap(i):
            if i + 1 == len(sizes):
                sizes.append(0)
            sizes[i + 1] += sizes[i]
            sizes[i] = 0
            changed.add(i + 1)
            i += 1
        total += sum(sizes[j] for j in changed)
    return total


# --- explorations: every reasonable grid passes, each misconception is rejected on 30 settings -------------------


def _grids():
    """30 grids over 000's plot ranges: n1 steps 5-100, q steps 0.005-0.1 (the question fixes no grid)."""
    return [(dn, dq) for dn in (5.0, 10.0, 20.0, 25.0, 50.0, 100.0) for dq in (0.005, 0.01, 0.02, 0.05, 0.1)]


def test_literal_n1_every_grid_passes_and_each_misconception_is_rejected_on_30_grids():
    from slamlab_grading import tasks_stores as tso

    lo, hi = core.task("04.explore.literal_n1").accepted_range()
    for dn, dq in _grids():
        N1, Q = np.arange(500.0, 20000.0 + 1e-9, dn), np.arange(1.5, 10.0 + 1e-9, dq)
        literal = tso.literal_iter_time(N1[:, None], Q[None, :])
        i, j = np.unravel_index(np.argmin(literal), literal.shape)
        assert lo <= N1[i] <= hi, (dn, dq, N1[i])
        assert lab.answer("04.explore.literal_n1", float(N1[i]), quiet=True).passed
        # the changed search term C s T_search: the literal cost plus C (s - 1) searchKd (log2 as in the Appendix)
        n1, q = N1[:, None], Q[None, :]
        p = np.log(50000 / n1) / np.log(q) + 1
        search = p * np.log2(n1) + 9.0 * p * (p - 1) / 2 * np.log2(q)
        F = literal + 9.0 * 499 * search
        ia, _ = np.unravel_index(np.argmin(F), F.shape)
        for wrong in (3500.0, float(N1[ia]), float(Q[j])):  # 000's reading, the changed search term, q
            assert not lo <= wrong <= hi, (dn, dq, wrong)
            assert lab.answer("04.explore.literal_n1", wrong, quiet=True).status == "failed"


def _workloads():
    rng = np.random.default_rng(43)
    out = [(1000, 3.0, (500,) * 40)]
    while len(out) < 30:
        n1, q = int(rng.integers(20, 2000)), float(rng.choice([1.5, 2.0, 2.5, 3.0, 4.0, 5.5]))
        out.append((n1, q, tuple(int(b) for b in rng.integers(1, 2 * n1, int(rng.integers(10, 60))))))
    return out


def test_points_rebuilt_misconceptions_differ_from_the_count_on_30_workloads():
    from slamlab_grading import tasks_stores as tso

    for n1, q, batches in _workloads():
        right = _rebuilt(n1, q, batches)
        assert right == tso.rebuilt_count(n1, q, batches)  # two independent counts
        stored, one_tree = sum(batches), int(np.sum(np.cumsum(batches)))
        for wrong in (stored, one_tree, tso.rebuilt_count(n1, q, batches, merges_only=True),
                      tso.rebuilt_count(n1, q, batches, count_emptied=True)):
            assert wrong != right, (n1, q, batches)
