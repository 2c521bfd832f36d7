"""Lab 04's submissions (issue 43): independent methods, another setting, and two named mistakes."""

from __future__ import annotations

from . import Submission

_REPLAY = '''
import math

def count(n1, q, batches, merges_only=False):
    cap = lambda i: math.floor(n1 * q**i + 1e-9)
    trees, total = [], 0
    for b in batches:
        carry, i, touched = b, 0, []
        while True:
            if i == len(trees):
                trees.append(0)
            trees[i] += carry
            touched.append(i)
            if trees[i] <= cap(i):
                break
            carry, trees[i] = trees[i], 0
            i += 1
        total += sum(trees[j] for j in touched if j or not merges_only)
    return total
'''

SUBMISSIONS = [
    Submission(
        "independent", "every task by another loop structure; exploration 1 by SciPy's minimiser, 2 by replaying "
                       "the rule",
        bodies={
            "t1": """
import math
cap = lambda i: math.floor(n1 * q**i + 1e-9)
sizes = []
for b in batches:
    carry, i = b, 0
    while True:
        if i == len(sizes):
            sizes.append(0)
        sizes[i] += carry
        if sizes[i] <= cap(i):
            break
        carry, sizes[i] = sizes[i], 0
        i += 1
while cap(len(sizes) - 1) < sum(sizes):
    sizes.append(0)
return sizes
""",
            "t2": """
state = {}  # id -> [first frame, sightings, outcome]
for t, frame in enumerate(history):
    for i in (int(v) for v in frame):
        if i not in state:
            state[i] = [t, 1, None]
        elif state[i][2] is None:
            state[i][1] += 1
    for st in state.values():
        if st[2] is None:
            if st[1] >= base_seen_times:
                st[2] = "base"
            elif t - st[0] >= max_non_base_time:
                st[2] = "dropped"
base = sorted(i for i, st in state.items() if st[2] == "base")
dropped = sorted(i for i, st in state.items() if st[2] == "dropped")
return np.array(base, dtype=int), np.array(dropped, dtype=int)
""",
            "t3": """
import math
p = math.log(n / n1, q) + 1
lg_n1, lg_q = math.log2(n1), math.log2(q)
search = p * lg_n1 + C * p * (p - 1) / 2 * lg_q
add = n1 * lg_n1 + m * q * p * lg_n1 + m * q / 2 * p * (p - 1) * lg_q
return add + C * search
""",
            "t4": """
M = dists[0].shape[0]
D, I = np.full((M, k), np.inf), np.full((M, k), -1)
for r in range(M):
    cands = sorted((float(d[r, c]), j, c, int(ids[j][r, c])) for j, d in enumerate(dists)
                   for c in range(d.shape[1]))
    for col, (d, _, _, i) in enumerate(cands[:k]):
        D[r, col], I[r, col] = d, i
return D, I
""",
            "e1": """
import math
from scipy.optimize import minimize

def cost(v):
    n1, q = v
    if not (500 <= n1 <= 20000 and 1.5 <= q <= 10):
        return 1e30
    p = math.log(50000 / n1, q) + 1
    search = p * math.log2(n1) + 9 * p * (p - 1) / 2 * math.log2(q)
    add = n1 * math.log2(n1) + 500 * q * p * math.log2(n1) + 250 * q * p * (p - 1) * math.log2(q)
    return add + 9 * search

best = min((minimize(cost, x0=[a, b], method="Nelder-Mead", options={"xatol": 1e-3, "fatol": 1e-6,
                                                                      "maxiter": 4000})
            for a in (1000.0, 3000.0, 8000.0) for b in (2.0, 4.0, 7.0)), key=lambda r: r.fun)
return float(best.x[0])
""",
            "e2": _REPLAY + "return count(1000, 3.0, [500] * 40)",
        }),
    Submission(
        "other_seed", "exploration 1 on a coarser grid (step 50, 0.05); exploration 2 with the library's store on "
                      "other data",
        bodies={
            "e1": """
N1, Q = np.arange(500.0, 20000.0 + 1e-9, 50.0), np.arange(1.5, 10.0 + 1e-9, 0.05)
F = iter_time(N1[:, None], Q[None, :], 50000, 500, 500, 9.0)
return float(N1[np.unravel_index(np.argmin(F), F.shape)[0]])
""",
            "e2": """
rng = np.random.default_rng(7)
store = sl.kdtree.MultiKDTree(1000, 3.0, tree="ckdtree")
for b in range(40):
    store.add(rng.normal(size=(500, 3)), np.arange(500 * b, 500 * (b + 1)))
return store.counters.points_rebuilt
""",
        }),
    Submission(
        "mistake_merge_when_full", "Task 1 merges a full tree (>= MAX_SIZE); exploration 2 counts merges only",
        bodies={
            "t1": """
import math
cap = lambda i: math.floor(n1 * q**i + 1e-9)
sizes = [0]
for b in batches:
    sizes[0] += b
    i = 0
    while sizes[i] >= cap(i) and sizes[i] > 0:
        if i + 1 == len(sizes):
            sizes.append(0)
        sizes[i + 1] += sizes[i]
        sizes[i] = 0
        i += 1
    while cap(len(sizes) - 1) < sum(sizes):
        sizes.append(0)
return sizes
""",
            "e2": _REPLAY + "return count(1000, 3.0, [500] * 40, merges_only=True)",
        },
        lost=("t1", "e2")),
    Submission(
        "mistake_plot_reading", "Task 3 with natural logarithms; exploration 1 answered with 000's plot reading",
        bodies={
            "t3": """
p = np.log(n / n1) / np.log(q) + 1
search = p * np.log(n1) + C * p * (p - 1) / 2 * np.log(q)
add = n1 * np.log(n1) + m * q * p * np.log(n1) + m * q / 2 * p * (p - 1) * np.log(q)
return add + C * search
""",
            "e1": "return 3500.0",
        },
        lost=("t3", "e1")),
]
