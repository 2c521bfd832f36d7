"""Lab 08 (probabilistic localisation): the submissions the autograde test hands in (see the package's docstring)."""

from __future__ import annotations

from . import Submission

# --- written independently of the instructor solution --------------------------------------------------------

_T1 = '''
w = np.asarray(weights, dtype=float)
c = np.cumsum(w) / np.sum(w)
out = np.empty(n, dtype=int)
i = 0
for m in range(n):  # PR Table 4.4: walk the cumulative weights with one pointer
    u = r + m / n
    while i < len(c) - 1 and u >= c[i]:
        i += 1
    out[m] = i
return out
'''

_T2 = '''
import math

def wrap(a):
    return math.atan2(math.sin(a), math.cos(a))

a1, a2, a3, a4 = (float(a) for a in alpha)
dx, dy = float(odom_now[0] - odom_prev[0]), float(odom_now[1] - odom_prev[1])
trans = math.hypot(dx, dy)
rot1 = wrap(math.atan2(dy, dx) - odom_prev[2]) if trans >= 1e-6 else 0.0
rot2 = wrap(odom_now[2] - odom_prev[2] - rot1)
s1 = math.sqrt(a1 * rot1 * rot1 + a2 * trans * trans)
st = math.sqrt(a3 * trans * trans + a4 * (rot1 * rot1 + rot2 * rot2))
s2 = math.sqrt(a1 * rot2 * rot2 + a2 * trans * trans)
out = np.empty((len(poses), 3))
for m, (x, y, th) in enumerate(np.asarray(poses, dtype=float)):  # one particle at a time
    r1 = rot1 - s1 * noise[0][m]
    t = trans - st * noise[1][m]
    r2 = rot2 - s2 * noise[2][m]
    out[m] = (x + t * math.cos(th + r1), y + t * math.sin(th + r1), wrap(th + r1 + r2))
return out
'''

_T3 = '''
import math

field = np.minimum(ndimage.distance_transform_edt(np.asarray(grid) != 1), max_dist)
norm = 1.0 / (math.sqrt(2 * math.pi) * sigma_hit)
log_p = 0.0
for a, z in zip(bearings_rad, ranges):  # beam by beam
    if z >= z_max:
        continue
    col = math.floor(pose[0] + z * math.cos(pose[2] + a) + 0.5)
    row = math.floor(pose[1] + z * math.sin(pose[2] + a) + 0.5)
    on_map = 0 <= row < field.shape[0] and 0 <= col < field.shape[1]
    d = field[row, col] if on_map else max_dist
    log_p += math.log(z_hit * norm * math.exp(-d * d / (2 * sigma_hit**2)) + z_rand / z_max)
return log_p
'''

_T4 = '''
slow = (1 - alpha_slow) * w_slow + alpha_slow * w_avg
fast = (1 - alpha_fast) * w_fast + alpha_fast * w_avg
p = 1.0 - fast / slow if slow > 0 and fast < slow else 0.0
return np.array([slow, fast, p])
'''

_E1 = '''
M = 1000
return 1.0 - (1.0 - 1.0 / M) ** M  # each particle is missed by all M draws with probability (1 - 1/M)^M
'''

_E2 = '''
# the averages after T steady steps of score 1 in closed form, 1 - (1 - α)^T; then the kidnap step at 0.5
a_s, a_f = 0.001, 0.1
T = np.arange(1, 100000)
s = 1 - (1 - a_s) ** T
f = 1 - (1 - a_f) ** T
s_next, f_next = s + a_s * (0.5 - s), f + a_f * (0.5 - f)
return int(T[np.argmax(f_next < s_next)])
'''

# --- the same questions with another allowed seed or setting ---------------------------------------------------

_E1_OTHER = '''
rng = np.random.default_rng(7)  # one multinomial resampling with another seed
return np.unique(rng.integers(0, 1000, 1000)).size / 1000
'''

_E2_OTHER = '''
# another steady score (0.3): the answer is a ratio, so it does not change; counted with the student's Task 4
w_slow = w_fast = 0.0
for T in range(1, 20000):
    w_slow, w_fast, _ = augmented(0.3, w_slow, w_fast, 0.001, 0.1)
    if augmented(0.15, w_slow, w_fast, 0.001, 0.1)[2] > 0:
        return T
'''

# --- named mistakes ---------------------------------------------------------------------------------------------

_T1_MULTINOMIAL = '''
w = np.asarray(weights, dtype=float)
return np.random.default_rng(SEED).choice(len(w), n, p=w / w.sum())  # i.i.d. draws: r ignored
'''

_E1_LOST = '''
rng = np.random.default_rng(SEED)
return 1.0 - np.unique(rng.choice(1000, 1000)).size / 1000  # the share never drawn
'''

_T2_NO_SQUARES = '''
def wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi

a1, a2, a3, a4 = alpha
dx, dy = odom_now[0] - odom_prev[0], odom_now[1] - odom_prev[1]
trans = np.hypot(dx, dy)
rot1 = 0.0 if trans < 1e-6 else wrap(np.arctan2(dy, dx) - odom_prev[2])
rot2 = wrap(odom_now[2] - odom_prev[2] - rot1)
# PR Table 5.6 as printed in some editions: variances from |δ|, not δ²
r1 = rot1 - np.sqrt(a1 * abs(rot1) + a2 * trans) * noise[0]
t = trans - np.sqrt(a3 * trans + a4 * (abs(rot1) + abs(rot2))) * noise[1]
r2 = rot2 - np.sqrt(a1 * abs(rot2) + a2 * trans) * noise[2]
x, y, th = poses[:, 0], poses[:, 1], poses[:, 2]
return np.column_stack([x + t * np.cos(th + r1), y + t * np.sin(th + r1), wrap(th + r1 + r2)])
'''

_E2_TIME_CONSTANT = '''
return round(1 / 0.001)  # the slow average's time constant
'''

SUBMISSIONS = [
    Submission("independent", "every task and both explorations by methods other than the instructor's: the "
               "pointer loop of PR Table 4.4, a per-particle motion loop, a per-beam likelihood loop, the averages "
               "as convex combinations; E1 from the closed form, E2 from the averages' closed form over all T",
               bodies={"t1": _T1, "t2": _T2, "t3": _T3, "t4": _T4, "e1": _E1, "e2": _E2}, lost=()),
    Submission("other_seed", "E1 from one multinomial resampling with seed 7 (integers, not choice); E2 with a "
               "steady score of 0.3 instead of 1",
               bodies={"e1": _E1_OTHER, "e2": _E2_OTHER}, lost=()),
    Submission("mistake_multinomial_and_lost", "Task 1 draws i.i.d. (multinomial) instead of the low-variance "
               "sampler; E1 answers the share lost instead of the share surviving",
               bodies={"t1": _T1_MULTINOMIAL, "e1": _E1_LOST}, lost=("t1", "e1")),
    Submission("mistake_no_squares_and_time_constant", "Task 2's variances from |δ| instead of δ²; E2 answers the "
               "slow average's time constant 1/α_slow",
               bodies={"t2": _T2_NO_SQUARES, "e2": _E2_TIME_CONSTANT}, lost=("t2", "e2")),
]
