"""Lab 07 (Hough SLAM): the submissions the autograde test hands in (see the package's docstring)."""

from __future__ import annotations

from . import Submission

# --- written independently of the instructor solution --------------------------------------------------------

_T1 = '''
n_theta = int(round(np.pi / delta_theta_rad))
n_half = int(np.ceil(r_max / delta_rho - 1e-9))
H = np.zeros((2 * n_half + 1, n_theta), dtype=int)
ok = (ranges > 0) & (ranges <= r_max)
for k in range(n_theta):  # one θ column at a time, counted with bincount
    th = -np.pi / 2 + k * delta_theta_rad
    rows = np.floor(ranges[ok] * np.cos(th - bearings_rad[ok]) / delta_rho + n_half + 0.5).astype(int)
    H[:, k] = np.bincount(rows, minlength=2 * n_half + 1)
return H
'''

_T2 = '''
H = np.asarray(H)
n_rho, n_theta = H.shape
# pad: a row of -1 above and below (no neighbour), and θ wrapped with rho flipped on both sides
P = np.full((n_rho + 2, n_theta + 2), -1, dtype=np.int64)
P[1:-1, 1:-1] = H
P[1:-1, 0] = H[::-1, -1]
P[1:-1, -1] = H[::-1, 0]
is_peak = H >= H_min
for di in (-1, 0, 1):
    for dk in (-1, 0, 1):
        if di or dk:
            is_peak &= H >= P[1 + di:1 + di + n_rho, 1 + dk:1 + dk + n_theta]
i, k = np.nonzero(is_peak)
order = np.argsort(-H[i, k], kind="stable")
i, k = i[order], k[order]
return np.asarray(rho)[i], np.asarray(theta_rad)[k], H[i, k].astype(float)
'''

_T3 = '''
normals = np.stack([np.cos(theta_rad), np.sin(theta_rad)], axis=-1)
shift = normals @ np.asarray(pose[:2], dtype=float)
return np.asarray(rho) - shift, np.asarray(theta_rad) - pose[2]
'''

_T4 = '''
ti1, ti2, tj1, tj2 = line_i1[1], line_i2[1], line_j1[1], line_j2[1]
between = ti2 - ti1
changed = np.angle(np.exp(1j * (between - (tj2 - tj1))))  # wrapped into (-π, π]
if abs(np.sin(between)) < np.sin(np.radians(20)) or abs(changed) > np.radians(2):
    return np.array([np.nan, np.nan, np.nan])
A = np.array([[np.cos(ti1), np.sin(ti1)], [np.cos(ti2), np.sin(ti2)]])
d = np.array([line_i1[0] - line_j1[0], line_i2[0] - line_j2[0]])
dx, dy = np.linalg.solve(A, d)
return np.array([dx, dy, ti1 - tj1])
'''

# Exploration 1 with the student's own Tasks 1-2 (phi, r: the demo scan of Task 1's look cell) and a merging loop
_E1 = '''
H = hough_votes(phi, r, 1.0, np.radians(1.0), float(r.max()))
n_half = (H.shape[0] - 1) // 2
pr, pt, pv = find_peaks(H, np.arange(-n_half, n_half + 1.0), np.radians(np.arange(-90.0, 90.0)), 1)
lines = []
for p, t, v in zip(pr, np.degrees(pt), pv):
    same = [abs(t - u) <= 3 + 1e-9 and abs(p - q) <= 3 or abs(abs(t - u) - 180) <= 3 + 1e-9 and abs(p + q) <= 3
            for q, u, _ in lines]
    if not any(same):
        lines.append((p, t, v))
    if len(lines) == 3:
        break
print("three strongest lines:", lines)
return int(lines[2][2]) + 1
'''

# Exploration 2: the run's per-step record (a step with a pose from lines has cause 0), not its lost flags
_E2 = '''
res = sl.studies.hough.run_sim_slam(121, range_std_cells=0.1, with_icp=False, H_min=40, rng=SEED, progress=False)
return int(np.count_nonzero(res.slam.cause[1:] != 0))
'''

# --- the same questions with another allowed setting ---------------------------------------------------------

_E1_OTHER = '''
# the library's accumulator and peak finder, r_max the rangefinder's 100 cells instead of the largest range
acc = sl.hough.hough_polar(phi, r, delta_rho=1.0, delta_theta_rad=np.radians(1.0), r_max=100.0)
votes = sl.hough.find_peaks(acc, H_min=1, max_lines=3).votes
return int(votes[2]) + 1
'''

_E2_OTHER = '''
# every setting the question names spelt out (they are the defaults)
res = sl.studies.hough.run_sim_slam(121, range_std_cells=0.1, clutter=False, n_beams=360, max_range_cells=100.0,
                                    with_icp=False, start="truth", H_min=40, rng=2010, progress=False)
return int(res.slam.lost[1:].sum())
'''

# --- named mistakes ---------------------------------------------------------------------------------------------

_T1_TRUNCATES = '''
n_theta = int(round(np.pi / delta_theta_rad))
theta = -np.pi / 2 + delta_theta_rad * np.arange(n_theta)
n_half = int(np.ceil(r_max / delta_rho - 1e-9))
H = np.zeros((2 * n_half + 1, n_theta), dtype=int)
keep = (ranges > 0) & (ranges <= r_max)
rho = ranges[keep][:, None] * np.cos(theta[None, :] - bearings_rad[keep][:, None])
rows = (rho / delta_rho).astype(int) + n_half  # int() truncates towards zero: not the nearest cell
np.add.at(H, (rows, np.broadcast_to(np.arange(n_theta), rows.shape)), 1)
return H
'''

_E2_TRACKED = '''
res = sl.studies.hough.run_sim_slam(121, range_std_cells=0.1, with_icp=False, H_min=40, rng=SEED, progress=False)
return int(120 - res.slam.lost.sum())  # the steps with a pose from lines, not the lost ones
'''

_T2_NO_WRAP = '''
n_rho, n_theta = H.shape
found = []
for i in range(n_rho):
    for k in range(n_theta):
        if H[i, k] < H_min:
            continue
        window = H[max(i - 1, 0):i + 2, max(k - 1, 0):k + 2]  # θ = ±90° not neighbours: no wrap
        if H[i, k] >= window.max():
            found.append((H[i, k], rho[i], theta_rad[k]))
found.sort(key=lambda f: -f[0])
return (np.array([f[1] for f in found]), np.array([f[2] for f in found]),
        np.array([f[0] for f in found], dtype=float))
'''

_E1_NO_MERGE = '''
acc = sl.hough.hough_polar(phi, r, delta_rho=1.0, delta_theta_rad=np.radians(1.0))
lines = sl.hough.find_peaks(acc, H_min=1, suppress_rho=0.0, suppress_theta_rad=0.0)  # raw maxima, not merged
return int(lines.votes[2]) + 1
'''

SUBMISSIONS = [
    Submission("independent", "every task and both explorations by methods other than the instructor's: a column "
               "loop with bincount, padded-array peaks, a matrix product, a 2x2 solve; E1 from the student's own "
               "Tasks 1-2 and a merging loop, E2 from the run's per-step causes",
               bodies={"t1": _T1, "t2": _T2, "t3": _T3, "t4": _T4, "e1": _E1, "e2": _E2}, lost=()),
    Submission("other_seed", "the explorations with another allowed setting: E1 by the library with r_max = 100 "
               "cells, E2 with every setting of the run spelt out (the question fixes the seed)",
               bodies={"e1": _E1_OTHER, "e2": _E2_OTHER}, lost=()),
    Submission("mistake_truncates_and_tracked", "Task 1 truncates rho to a cell instead of rounding; E2 answers "
               "the tracked steps instead of the lost ones",
               bodies={"t1": _T1_TRUNCATES, "e2": _E2_TRACKED}, lost=("t1", "e2")),
    Submission("mistake_no_wrap_and_no_merge", "Task 2 does not wrap θ at ±90°; E1 counts a wall's two raw maxima "
               "as two lines (no merging)",
               bodies={"t2": _T2_NO_WRAP, "e1": _E1_NO_MERGE}, lost=("t2", "e1")),
]
