"""Lab 10 (plane-based 3-D particle-filter SLAM): what students hand in (issue 43).

The independent submission solves every task and exploration by another route than the instructor's: the rigid
inverse written out (R^T, -R^T t) in a loop, the rotation applied with einsum, the normal as the smallest
eigenvector of the scatter matrix, the weights through a rank-free masked array; Exploration 1 with eigenvectors on
a tilted plane and the angle by arccos, Exploration 2 in closed form from Cramer's rule.
"""

from __future__ import annotations

from . import Submission

T1_RIGID_INVERSE = """
R_N, t_N = odometry[-1][:3, :3], odometry[-1][:3, 3]
inv_N = np.eye(4)
inv_N[:3, :3] = R_N.T
inv_N[:3, 3] = -R_N.T @ t_N
out = np.empty_like(odometry, dtype=float)
for j, T in enumerate(odometry):
    out[j] = inv_N @ T
return out
"""

T2_EINSUM = """
n_m, p_m = np.atleast_2d(np.asarray(n_m, float)), np.asarray(p_m, float)
n_b = np.einsum("ji,kj->ki", R, n_m)  # R^T n for every row
p_b = p_m - np.einsum("kj,j->k", n_m, t)
return np.column_stack([n_b, p_b])
"""

T3_EIGH = """
X = np.asarray(points, float)
c = X.mean(axis=0)
Xc = X - c
vals, vecs = np.linalg.eigh(Xc.T @ Xc)
n = vecs[:, np.argmin(vals)]
p = float(n @ c)
if p < 0:
    n, p = -n, -p
return np.array([n[0], n[1], n[2], p])
"""

T4_MASKED = """
sad = np.asarray(sad, float)
ok = ~np.isnan(sad)
w = np.zeros(len(sad))
if ok.any():
    w[ok] = sad[ok].max() - sad[ok]
total = w.sum()
if total == 0:
    return np.ones(len(sad)) / len(sad)
return w / total
"""

E1_EIGH_TILTED = """
rng = np.random.default_rng(99)
n_true = np.array([1.0, 2.0, 2.0]) / 3.0
u = np.cross(n_true, [0.0, 0.0, 1.0])
u /= np.linalg.norm(u)
v = np.cross(n_true, u)
sq = []
for _ in range(3000):
    ab = rng.uniform(-2.0, 2.0, (200, 2))
    X = 5.0 * n_true + ab[:, :1] * u + ab[:, 1:] * v + rng.normal(0.0, 0.02, (200, 1)) * n_true
    Xc = X - X.mean(axis=0)
    n = np.linalg.eigh(Xc.T @ Xc)[1][:, 0]
    sq.append(np.arccos(min(1.0, abs(n @ n_true))) ** 2)
return float(np.degrees(np.sqrt(np.mean(sq))))
"""

E2_CRAMER = """
# walls n1 = (1, 0), n2 = (cos a, sin a): an error d in p2 moves the solution by d / sin a along wall 1
return float(np.degrees(np.arcsin(0.03 / 0.5)))
"""

E1_OTHER_SEED_MORE_DRAWS = """
rng = np.random.default_rng(31415)
angles = []
for _ in range(5000):
    X = np.column_stack([rng.uniform(-2.0, 2.0, (200, 2)), rng.normal(0.0, 0.02, 200)])
    n = fit_plane(X)[:3]
    angles.append(np.arctan2(np.hypot(n[0], n[1]), abs(n[2])))
return float(np.degrees(np.sqrt(np.mean(np.square(angles)))))
"""

E2_BISECTION_ROUNDED = """
def shift(alpha_deg):
    a = np.radians(alpha_deg)
    N = np.array([[1.0, 0.0], [np.cos(a), np.sin(a)]])
    return abs(np.linalg.solve(N, [0.0, 0.03])[1])

lo, hi = 0.5, 20.0
for _ in range(50):
    mid = 0.5 * (lo + hi)
    lo, hi = (mid, hi) if shift(mid) > 0.5 else (lo, mid)
return round(hi, 1)  # to 0.1°, as asked
"""

T3_LARGEST_SPREAD = """
c = points.mean(axis=0)
n = np.linalg.svd(points - c, full_matrices=False)[2][0]  # the direction of most spread
p = n @ c
return np.r_[-n, -p] if p < 0 else np.r_[n, p]
"""

E1_MEAN_ANGLE = """
rng = np.random.default_rng(SEED)
angles = []
for _ in range(2000):
    X = np.column_stack([rng.uniform(-2.0, 2.0, (200, 2)), rng.normal(0.0, 0.02, 200)])
    c = X.mean(axis=0)
    n = np.linalg.svd(X - c, full_matrices=False)[2][2]
    angles.append(np.arctan2(np.hypot(n[0], n[1]), abs(n[2])))
return float(np.degrees(np.mean(angles)))  # the mean angle, not the RMS
"""

T2_NO_TRANSPOSE = """
return np.c_[n_m @ R.T, p_m - n_m @ t]  # R n instead of R^T n
"""

E2_RADIANS = """
return float(np.arcsin(0.03 / 0.5))  # in radians
"""

SUBMISSIONS = [
    Submission("independent", "every task and exploration by another method than the instructor's",
               bodies={"t1": T1_RIGID_INVERSE, "t2": T2_EINSUM, "t3": T3_EIGH, "t4": T4_MASKED,
                       "e1": E1_EIGH_TILTED, "e2": E2_CRAMER}),
    Submission("other_seed", "Exploration 1 on another seed with 5000 draws, Exploration 2 by bisection rounded "
               "to 0.1°", bodies={"e1": E1_OTHER_SEED_MORE_DRAWS, "e2": E2_BISECTION_ROUNDED}),
    Submission("mistake_mean_angle", "Task 3 with the direction of most spread; Exploration 1 as the mean angle",
               bodies={"t3": T3_LARGEST_SPREAD, "e1": E1_MEAN_ANGLE}, lost=("t3", "e1")),
    Submission("mistake_radians", "Task 2 rotates by R instead of R^T; Exploration 2 answered in radians",
               bodies={"t2": T2_NO_TRANSPOSE, "e2": E2_RADIANS}, lost=("t2", "e2")),
]
