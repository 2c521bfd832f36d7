"""Lab 04 tasks: solutions written from 000 §3.4, §4 and the Appendix pass, typical mistakes fail at the right case."""

from __future__ import annotations

import math

import numpy as np
import pytest

from slamlab import lab

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


def test_tree_sizes_mistakes():
    def merge_when_full(n1, q, batches):  # ">= MAX_SIZE" instead of "> MAX_SIZE"
        return tree_sizes(n1, q, batches, strict=False)

    def no_empty_trees(n1, q, batches):  # forgets to append trees until the last can hold the total
        return tree_sizes(n1, q, batches, grow=False)

    assert lab.check("04.tree_sizes", merge_when_full, quiet=True).status == "failed"
    assert merge_when_full(5, 2.0, [5]) != tree_sizes(5, 2.0, [5])  # and on the edge case itself
    assert "case 1 of 7" in lab.check("04.tree_sizes", no_empty_trees, quiet=True).message


def test_base_rule_mistakes():
    def one_frame_short(history, base_seen_times, max_non_base_time):  # drops a frame too early
        return base_rule(history, base_seen_times, max_non_base_time, last_age=max_non_base_time - 1)

    def drop_before_promote(history, base_seen_times, max_non_base_time):  # the window check first
        b, d = base_rule(history, base_seen_times, max_non_base_time)
        late_base = [i for i in b if i == 0 and len(history) == 13]  # the edge case's id 0 is promoted at age 7
        return np.setdiff1d(b, late_base), np.union1d(d, late_base).astype(int)

    assert lab.check("04.base_rule", one_frame_short, quiet=True).status == "failed"
    assert "(window edge" in lab.check("04.base_rule", drop_before_promote, quiet=True).message


def test_iter_time_mistakes():
    def adjusted(n1, q, n, s, m, C):  # §4.1.2's C s T_search instead of the Appendix's C searchKd
        return iter_time(n1, q, n, s, m, C, with_s=True)

    def natural_log(n1, q, n, s, m, C):
        return iter_time(n1, q, n, s, m, C) * math.log(2)

    assert "case 1 of 5" in lab.check("04.iter_time", adjusted, quiet=True).message
    assert "case 1 of 5" in lab.check("04.iter_time", natural_log, quiet=True).message


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

    assert "case 1 of 6" in lab.check("04.merge_knn", first_tree_only, quiet=True).message
    assert "(one tree of one point" in lab.check("04.merge_knn", no_padding, quiet=True).message
    assert "(a tie" in lab.check("04.merge_knn", unstable, quiet=True).message


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
