"""Lab 01's submissions (issue 43): independent methods, another seed, and two named mistakes."""

from __future__ import annotations

from . import Submission

_EKF_BY_HAND = '''
# an EKF written here (not the library's filters), one run per seed, the chapter's scenario
lm = np.array([[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]])
dt, v, om, sv, som = 0.5, 1.0, np.deg2rad(11.46), 0.2, np.deg2rad(10.0)
R = np.diag(np.tile([0.5**2, np.deg2rad(10.0) ** 2], 3))
P0 = np.diag([1.0, 1.0, np.deg2rad(90.0) ** 2])
wrap = lambda a: (a + np.pi) % (2 * np.pi) - np.pi

def h(x):
    d = lm - x[:2]
    return np.column_stack([np.hypot(d[:, 0], d[:, 1]), wrap(np.arctan2(d[:, 1], d[:, 0]) - x[2])]).ravel()

def run(seed, scale):
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])
    W = rng.normal(size=(60, 2)) * [sv, som]
    Vn = rng.normal(size=(60, 6)) * np.sqrt(np.diag(R))
    x, X, Z = np.zeros(3), [], []
    for k in range(60):
        x = np.array([x[0] + (v + W[k, 0]) * dt * np.cos(x[2]), x[1] + (v + W[k, 0]) * dt * np.sin(x[2]),
                      wrap(x[2] + (om + W[k, 1]) * dt)])
        X.append(x)
        z = h(x) + Vn[k]
        z[1::2] = wrap(z[1::2])
        Z.append(z)
    xe, P, out = rng.multivariate_normal(np.zeros(3), P0), P0.copy(), []
    for k in range(60):
        c, s = np.cos(xe[2]), np.sin(xe[2])
        F = np.array([[1, 0, -v * dt * s], [0, 1, v * dt * c], [0, 0, 1.0]])
        V = np.array([[dt * c, 0], [dt * s, 0], [0, dt]])
        xe = np.array([xe[0] + v * dt * c, xe[1] + v * dt * s, wrap(xe[2] + om * dt)])
        P = F @ P @ F.T + scale * V @ np.diag([sv**2, som**2]) @ V.T
        d = lm - xe[:2]
        q = (d**2).sum(axis=1)
        H = np.zeros((6, 3))
        H[0::2, 0], H[0::2, 1] = -d[:, 0] / np.sqrt(q), -d[:, 1] / np.sqrt(q)
        H[1::2, 0], H[1::2, 1], H[1::2, 2] = d[:, 1] / q, -d[:, 0] / q, -1.0
        y = Z[k] - h(xe)
        y[1::2] = wrap(y[1::2])
        S = H @ P @ H.T + R
        K = np.linalg.solve(S, H @ P).T
        xe = xe + K @ y
        xe[2] = wrap(xe[2])
        A = np.eye(3) - K @ H
        P = A @ P @ A.T + K @ R @ K.T
        e = X[k] - xe
        e[2] = wrap(e[2])
        out.append(e @ np.linalg.solve(P, e))
    return np.mean(out)
'''

SUBMISSIONS = [
    Submission(
        "independent", "every task by another formulation; both explorations by a simulation written here",
        bodies={
            "t1": "return np.einsum('ij,j->i', F, x), np.einsum('ij,jk,lk->il', F, P, F) + Q",
            "t2": """
S = H @ P @ H.T + R
K = P @ H.T @ np.linalg.inv(S)
return x + K @ (z - H @ x), P - K @ S @ K.T
""",
            "t3": "return P - K @ H @ P - P @ H.T @ K.T + K @ (H @ P @ H.T + R) @ K.T",
            "t4": """
s = alpha**2 * (L + kappa)
Ws = np.concatenate([[1.0 - L / s], np.full(2 * L, 0.5 / s)])
Wc = Ws.copy()
Wc[0] += 1.0 - alpha**2 + beta
return Ws, Wc, s - L
""",
            "t5": """
from scipy.linalg import cholesky
n = len(x)
A = cholesky(alpha**2 * (n + kappa) * P, lower=True)
return np.array([x] + [x + A[:, i] for i in range(n)] + [x - A[:, i] for i in range(n)])
""",
            "e1": _EKF_BY_HAND + "return float(np.median([run(s, 16.0) for s in range(SEED, SEED + 400)]))",
            "e2": """
rng = np.random.default_rng(SEED)
F1, Q1 = np.array([[1.0, 1.0], [0.0, 1.0]]), 0.2**2 * np.array([[1 / 3, 1 / 2], [1 / 2, 1.0]])
se, n_runs, n_steps = 0.0, 100, 60
for _axis in range(2):
    P = np.diag([0.25**2, 1.0])
    x = np.array([0.0, 1.0]) + rng.normal(size=(n_runs, 2)) * [0.25, 1.0]
    xe = np.tile([0.0, 1.0], (n_runs, 1))
    for _ in range(n_steps):
        x = x @ F1.T + rng.multivariate_normal(np.zeros(2), Q1, size=n_runs)
        z = x[:, 0] + 0.25 * rng.normal(size=n_runs)
        xe, P = xe @ F1.T, F1 @ P @ F1.T + Q1
        k = P[:, 0] / (P[0, 0] + 0.25**2)
        xe, P = xe + (z - xe[:, 0])[:, None] * k, P - np.outer(k, P[0])
        se += float(np.sum((xe[:, 0] - x[:, 0]) ** 2))
return float(np.sqrt(se / (n_runs * n_steps)))
""",
        }),
    Submission(
        "other_seed", "both explorations with other seeds and run counts (the library's studies)",
        bodies={
            "e1": """
runs = [sl.studies.filters.run_unicycle_comparison(1, 60, filters=("EKF",), stabilising_noise=16.0, rng=s)
        .mean_nees[0] for s in range(3000, 3400)]
return float(np.median(runs))
""",
            "e2": "return sl.studies.filters.run_cv_target(n_runs=100, n_steps=80, accel_std=0.2, pos_std_m=0.25,"
                  " rng=7).rmse_pos_m",
        }),
    Submission(
        "mistake_no_stabilising_noise",
        "Task 1 forgets the process noise; exploration 1 run with the true noise (scale 1)",
        bodies={
            "t1": "return F @ x, F @ P @ F.T",
            "e1": _EKF_BY_HAND + "return float(np.median([run(s, 1.0) for s in range(SEED, SEED + 400)]))",
        },
        lost=("t1", "e1")),
    Submission(
        "mistake_one_axis",
        "Task 3 with the short form (I - K H) P; exploration 2 reports one coordinate's RMSE",
        bodies={
            "t3": "return (np.eye(P.shape[0]) - K @ H) @ P",
            "e2": "return sl.studies.filters.run_cv_target(n_runs=50, n_steps=50, accel_std=0.2, pos_std_m=0.25,"
                  " rng=SEED).rmse_pos_m / np.sqrt(2)",
        },
        lost=("t3", "e2")),
]
