"""Lab 03's submissions for the autograde test (issue 43): written here, not copied from the instructor's cells.

The explorations have no seed: the questions fix the store, the queries, the keypoints, the tolerance and the
grids. "other_seed" therefore answers them by another allowed route (the store in another order with the truth
from the tree's exact search; the matches from SciPy and the library's correctness test).
"""

from __future__ import annotations

from . import Submission

# --- correct, by other methods ---------------------------------------------------------------------------------

T1_PER_QUERY = '''
M, N = len(query), len(train)
dist, idx = np.full((M, 2), np.inf), np.full((M, 2), -1, dtype=int)
for m in range(M):
    d = np.sqrt(((train - query[m]) ** 2).sum(axis=1))
    order = np.lexsort((np.arange(N), d))[:2]  # by distance, then by index
    dist[m, :len(order)], idx[m, :len(order)] = d[order], order
return dist, idx
'''

T2_ROW_BY_ROW = '''
keep_000, keep_ratio = [], []
for d1, d2 in dist:
    close = d1 <= max_dist
    keep_000.append(bool(close and d2 >= factor * d1))
    keep_ratio.append(bool(close and d1 < ratio * d2))
return np.array(keep_000, dtype=bool), np.array(keep_ratio, dtype=bool)
'''

T3_POPCOUNT_TABLE = '''
bits = np.array([bin(v).count("1") for v in range(256)])
return bits[A[:, None, :] ^ B[None, :, :]].sum(axis=2)
'''

T4_MAX_HEAP = '''
t = tree.nodes
P, ids = tree.leaf_points, tree.leaf_ids  # the points in leaf order: a leaf is rows start..stop
pending = [(0.0, 0)]
best = []  # a max-heap of the k best so far: (-d², -id)
visited = 0
while pending:
    bound, node = heapq.heappop(pending)
    if len(best) == k and bound >= -best[0][0]:
        break
    while t["left"][node] != -1:
        s = q[t["split_dim"][node]] - t["split_val"][node]
        if s <= 0:
            near, far = t["left"][node], t["right"][node]
        else:
            near, far = t["right"][node], t["left"][node]
        heapq.heappush(pending, (max(bound, s * s), int(far)))
        node = near
    for row in range(t["start"][node], t["stop"][node]):
        d2 = float(((P[row] - q) ** 2).sum())
        item = (-d2, -int(ids[row]))
        if len(best) < k:
            heapq.heappush(best, item)
        elif item > best[0]:
            heapq.heapreplace(best, item)
    visited += 1
    if max_leaves is not None and visited >= max_leaves:
        break
found = sorted((-a, -b) for a, b in best)
found += [(np.inf, -1)] * (k - len(found))
return np.sqrt([d for d, _ in found]), np.array([i for _, i in found])
'''

E1_BRUTE_TRUTH = '''
img1, img2, _ = sl.features.load_oxford_pair("graf", 2, scale=0.5)
own = sl.features.detect(img1, "surf", threshold=5e-5).descriptors
store = np.concatenate([own, sl.studies.features.descriptor_pool(10000 - len(own), exclude="graf", scale=0.5,
                                                                threshold=5e-5)])
f2 = sl.features.detect(img2, "surf", threshold=5e-5)
queries = f2.descriptors[np.argsort(-f2.response)[:200]]
S = store.astype(np.float64)
truth = np.array([np.argmin(((S - x) ** 2).sum(axis=1)) for x in queries.astype(np.float64)])  # brute force
tree = sl.kdtree.KDTree(store)
for budget in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000):
    _, ids = tree.query(queries, k=2, max_leaves=budget)
    if np.mean(ids[:, 0] == truth) >= 0.9:
        return budget
'''

E1_SHUFFLED_EXACT_TREE = '''
img1, img2, _ = sl.features.load_oxford_pair("graf", 2, scale=0.5)
own = sl.features.detect(img1, "surf", threshold=5e-5).descriptors
store = np.concatenate([own, sl.studies.features.descriptor_pool(10000 - len(own))])
store = store[np.random.default_rng(SEED).permutation(len(store))]  # the order of the store does not matter
f2 = sl.features.detect(img2, "surf", threshold=5e-5)
queries = f2.descriptors[np.argsort(-f2.response, kind="stable")[:200]]
tree = sl.kdtree.KDTree(store)
_, exact = tree.query(queries, k=1)  # no leaf limit: the exact search
recall = {b: np.mean(tree.query(queries, k=1, max_leaves=b)[1][:, 0] == exact[:, 0])
          for b in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000)}
print(recall)
return min(b for b, r in recall.items() if r >= 0.9)
'''


def _e2(squared: bool = False) -> str:
    test = "d[:, 0] ** 2 < r * d[:, 1] ** 2" if squared else "d[:, 0] < r * d[:, 1]"
    return f'''
im1, im2, H = sl.features.load_oxford_pair("boat", 2, scale=0.5)
k1 = sl.features.detect(im1, "surf", threshold=1e-4, max_points=1000)
k2 = sl.features.detect(im2, "surf", threshold=1e-4, max_points=1000)
d, idx = two_nn(k1.descriptors.astype(float), k2.descriptors.astype(float))  # Task 1
x = np.c_[k1.uv, np.ones(len(k1))] @ H.T
correct = np.linalg.norm(x[:, :2] / x[:, 2:] - k2.uv[idx[:, 0]], axis=1) < 2.5
best = None
for r in np.arange(0.30, 1.0001, 0.05):  # not rounded: 0.30000000000000004 ...
    kept = {test}
    if kept.any() and correct[kept].mean() >= 0.8:
        best = r
return best
'''


E2_TASK1 = _e2()
E2_SQUARED = _e2(squared=True)

E2_SCIPY_CORRECT_MATCHES = '''
from scipy.spatial import cKDTree

im1, im2, H = sl.features.load_oxford_pair("boat", 2, scale=0.5)
k1 = sl.features.detect(im1, "surf", threshold=1e-4, max_points=1000)
k2 = sl.features.detect(im2, "surf", threshold=1e-4, max_points=1000)
d, idx = cKDTree(k2.descriptors).query(k1.descriptors, k=2)
holds = []
for r in [0.3 + 0.05 * i for i in range(15)]:
    q = np.flatnonzero(d[:, 0] < r * d[:, 1])
    m = sl.features.Matches(q, idx[q, 0], d[q, 0], d[q, 1])
    ok = sl.features.correct_matches(k1, k2, m, H, tol_px=2.5)
    if len(ok) and ok.mean() >= 0.8:
        holds.append(r)
return max(holds)
'''

# --- mistakes --------------------------------------------------------------------------------------------------

T1_NO_PADDING = '''
D = np.linalg.norm(query[:, None, :] - train[None, :, :], axis=2)
o = np.argsort(D, axis=1, kind="stable")[:, :2]  # fewer than two columns when fewer than two are stored
return np.take_along_axis(D, o, axis=1), o
'''

T4_ONE_DESCENT = '''
t = tree.nodes
node = 0
while t["left"][node] >= 0:  # one descent, no backtracking, whatever the budget
    diff = q[t["split_dim"][node]] - t["split_val"][node]
    node = t["left"][node] if diff <= 0 else t["right"][node]
rows = t["perm"][t["start"][node]:t["stop"][node]]
d2 = ((t["points"][rows] - q) ** 2).sum(axis=1)
order = np.argsort(d2)[:k]
dist = np.full(k, np.inf)
ids = np.full(k, -1)
dist[:len(order)], ids[:len(order)] = np.sqrt(d2[order]), t["ids"][rows][order]
return dist, ids
'''

E1_NO_DISTRACTORS = '''
from scipy.spatial import cKDTree

img1, img2, _ = sl.features.load_oxford_pair("graf", 2, scale=0.5)
store = sl.features.detect(img1, "surf", threshold=5e-5).descriptors  # img1's alone: the distractors forgotten
f2 = sl.features.detect(img2, "surf", threshold=5e-5)
queries = f2.descriptors[np.argsort(-f2.response)[:200]]
_, truth = cKDTree(store).query(queries)
tree = sl.kdtree.KDTree(store)
for budget in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000):
    if np.mean(tree.query(queries, k=1, max_leaves=budget)[1][:, 0] == truth) >= 0.9:
        return budget
'''

SUBMISSIONS = [
    Submission("independent", "every task by another method (a per-query lexsort, row-by-row rules, a popcount "
                              "table, BBF with a max-heap on the leaf-ordered points); E1 with a brute-force truth, "
                              "E2 with Task 1's matches and an unrounded grid",
               bodies={"t1": T1_PER_QUERY, "t2": T2_ROW_BY_ROW, "t3": T3_POPCOUNT_TABLE, "t4": T4_MAX_HEAP,
                       "e1": E1_BRUTE_TRUTH, "e2": E2_TASK1}, lost=()),
    Submission("other_seed", "no seed to change: E1 with the store shuffled and the truth from the tree's exact "
                             "search, E2 with SciPy's neighbours and the library's correctness test",
               bodies={"e1": E1_SHUFFLED_EXACT_TREE, "e2": E2_SCIPY_CORRECT_MATCHES}, lost=()),
    Submission("mistake_no_padding_squared", "2-NN without padding for a store of fewer than two; E2's ratio test "
                                             "on squared distances",
               bodies={"t1": T1_NO_PADDING, "e2": E2_SQUARED}, lost=("t1", "e2")),
    Submission("mistake_one_descent_no_distractors", "BBF without backtracking; E1's store without the distractors",
               bodies={"t4": T4_ONE_DESCENT, "e1": E1_NO_DISTRACTORS}, lost=("t4", "e1")),
]
