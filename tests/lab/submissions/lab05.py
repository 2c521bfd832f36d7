"""Lab 05 (stereo SLAM): what students hand in. Bodies replace the code between the solution markers."""

from __future__ import annotations

from . import Submission

# --- correct, by methods other than the instructor's -----------------------------------------------------------

T1_LSTSQ = '''
# each pair of rays: the 2x2 normal equations of min |c1 + s d1 - c2 - t d2|, solved row by row
points, gaps = [], []
for a1, a2 in zip(np.atleast_2d(d1), np.atleast_2d(d2)):
    A = np.array([[a1 @ a1, -a1 @ a2], [a1 @ a2, -a2 @ a2]])
    rhs = np.array([a1 @ (c2 - c1), a2 @ (c2 - c1)])
    if abs(np.linalg.det(A)) <= 1e-12 * (a1 @ a1) * (a2 @ a2):
        s = t = 0.0  # parallel rays: the midpoint of the centres
    else:
        s, t = np.linalg.solve(A, rhs)
    q1, q2 = c1 + s * a1, c2 + t * a2
    points.append((q1 + q2) / 2)
    gaps.append(np.sqrt(np.sum((q1 - q2) ** 2)))
return np.array(points).reshape(-1, 3), np.array(gaps)
'''

T2_EINSUM = '''
ones = np.ones((len(uv_left), 1))
xl, xr = np.hstack([uv_left, ones]), np.hstack([uv_right, ones])
lines = np.einsum("ij,nj->ni", F, xl)  # l = F x_l, a line in the right image
algebraic = np.einsum("ni,ni->n", xr, lines)
return np.abs(algebraic) <= tol_px * np.sqrt(lines[:, 0] ** 2 + lines[:, 1] ** 2)
'''

T3_LOOP = '''
out = np.full((len(uv_left), 3), np.nan)
for i, ((ul, vl), (ur, _)) in enumerate(zip(uv_left, uv_right)):
    disparity = ul - ur
    if disparity > 0:
        Z = fx * baseline_m / disparity
        out[i] = [(ul - cx) / fx * Z, (vl - cy) / fy * Z, Z]
return out
'''

T4_KABSCH = '''
n, dim = src.shape
ms, md = src.mean(axis=0), dst.mean(axis=0)
A, B = src - ms, dst - md
H = A.T @ B  # Kabsch: the cross-covariance the other way round, so R = V S U^T
U, sv, Vt = np.linalg.svd(H)
S = np.ones(dim)
S[-1] = np.sign(np.linalg.det(Vt.T @ U.T)) or 1.0
R = Vt.T @ np.diag(S) @ U.T
c = float((sv * S).sum() / (A ** 2).sum()) if with_scale else 1.0
return R, md - c * R @ ms, c
'''

# Exploration 1 by hand: where the turned right camera sees the point, and Z = f B / d (no triangulation call)
E1_BY_HAND = '''
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=SEED).rig
f, B, Z = rig.left.fx, rig.baseline_m, 8.0
errors = []
for delta in (2e-3, -2e-3):
    x_r = Z * np.sin(delta) - B  # R_y(delta) (0, 0, Z) + (-B, 0, 0)
    z_r = Z * np.cos(delta)
    d = 0.0 - f * x_r / z_r  # u_l - u_r relative to the principal point
    errors.append(f * B / d - Z)
return max(abs(e) for e in errors)
'''

# Exploration 2 with the student's own Task 3 on the rig's projected pixels
E2_TASK3 = '''
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=SEED).rig
uvl, uvr = rig.project(np.array([[0.0, 0.0, 8.0]]))
cam = rig.left
P = stereo_point(uvl, uvr + np.array([0.5, 0.0]), cam.fx, cam.fy, cam.cx, cam.cy, rig.baseline_m)
return float(P[0, 2] - 8.0)
'''

# --- correct, with another seed or setting ----------------------------------------------------------------------

E1_OTHER = '''
# another simulator seed, and the right camera turned about its own centre (the baseline turns with it)
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=2031).rig
B, Z = rig.baseline_m, 8.0
worst = 0.0
for delta in (2e-3, -2e-3):
    c, s = np.cos(delta), np.sin(delta)
    x_r = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ np.array([-B, 0.0, Z])
    Zhat = B * x_r[2] / -x_r[0]  # f cancels in Z = f B / d
    worst = max(worst, abs(Zhat - Z))
return worst
'''

E2_OTHER = '''
# the first-order formula, with the rig of another simulator seed
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=2024).rig
return 8.0 ** 2 * 0.5 / (rig.left.fx * rig.baseline_m)
'''

# --- mistakes -------------------------------------------------------------------------------------------------

T1_FIRST_RAY = '''
w = c1 - c2
a, b, c = (d1 * d1).sum(axis=1), (d1 * d2).sum(axis=1), (d2 * d2).sum(axis=1)
d, e = (d1 * w).sum(axis=1), (d2 * w).sum(axis=1)
den = a * c - b * b
ok = den > 1e-12 * a * c
den = np.where(ok, den, 1.0)
s = np.where(ok, (b * e - c * d) / den, 0.0)
t = np.where(ok, (a * e - b * d) / den, 0.0)
p1, p2 = c1 + s[:, None] * d1, c2 + t[:, None] * d2
return p1, np.linalg.norm(p1 - p2, axis=1)  # the point on the first ray, not the midpoint
'''

E1_FIRST_ORDER = '''
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=SEED).rig
return 8.0 ** 2 * 2e-3 / rig.baseline_m  # Z^2 delta / B: first order, the same both ways
'''

T4_NO_REFLECTION_FIX = '''
mu_s, mu_d = src.mean(axis=0), dst.mean(axis=0)
xs, xd = src - mu_s, dst - mu_d
U, D, Vt = np.linalg.svd(xd.T @ xs / len(src))
R = U @ Vt  # may be a reflection
c = float(D.sum() / np.mean(np.sum(xs**2, axis=1))) if with_scale else 1.0
return R, mu_d - c * R @ mu_s, c
'''

E1_MEAN = '''
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=SEED).rig
errors = []
for turn in (2e-3, -2e-3):
    drifted = sl.geometry.StereoRig(rig.left, rig.right, sl.geometry.rotation_xyz(0.0, turn, 0.0) @ rig.R_rl,
                                    rig.t_rl)
    uvl, uvr = drifted.project([[0.0, 0.0, 8.0]])
    errors.append(abs(sl.geometry.triangulate_stereo(rig, uvl, uvr).points[0, 2] - 8.0))
return float(np.mean(errors))  # the two directions averaged
'''

E2_LARGER_DISPARITY = '''
rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=SEED).rig
uvl, uvr = rig.project([[0.0, 0.0, 8.0]])
return sl.geometry.triangulate_stereo(rig, uvl, uvr - np.array([0.5, 0.0])).points[0, 2] - 8.0  # wrong way
'''

SUBMISSIONS = [
    Submission("independent", "every task and exploration by a method other than the instructor's: normal "
               "equations row by row, einsum lines, a loop over matches, Kabsch; the drift by hand, the depth "
               "error with the student's own Task 3",
               bodies={"t1": T1_LSTSQ, "t2": T2_EINSUM, "t3": T3_LOOP, "t4": T4_KABSCH, "e1": E1_BY_HAND,
                       "e2": E2_TASK3}, lost=()),
    Submission("other_seed", "the explorations with other simulator seeds (the rig is the same), the drift with "
               "the camera turned about its own centre, the depth error to first order",
               bodies={"e1": E1_OTHER, "e2": E2_OTHER}, lost=()),
    Submission("mistake_first_order", "the point on the first ray instead of the midpoint; the drift to first "
               "order (the question asks for the exact error of the worse direction)",
               bodies={"t1": T1_FIRST_RAY, "e1": E1_FIRST_ORDER}, lost=("t1", "e1")),
    Submission("mistake_mean_of_directions", "Umeyama without the reflection fix; the drift as the mean of both "
               "directions; the depth error with a larger disparity",
               bodies={"t4": T4_NO_REFLECTION_FIX, "e1": E1_MEAN, "e2": E2_LARGER_DISPARITY},
               lost=("t4", "e1", "e2")),
]
