"""Lab 09 (monocular mapping): what students hand in (issue 43).

The independent submission solves every task and exploration by another route than the instructor's: the Beta
moments solved for a + b, a band with np.where, the convergence test as one product, tau by intersecting the
rotated ray with the reference ray in the plane of the two cameras; Exploration 1 by the student's own Task 1
function in a scalar loop (not the library's study), Exploration 2 from a rectified pair's disparity.
"""

from __future__ import annotations

from . import Submission

T1_BETA_BY_MOMENTS = """
from scipy.stats import norm

c_in = a / (a + b) * norm.pdf(x, loc=mu, scale=math.sqrt(sigma2 + tau2))
c_out = b / (a + b) / rho_range
w_in, w_out = c_in / (c_in + c_out), c_out / (c_in + c_out)
post_var = sigma2 * tau2 / (sigma2 + tau2)
post_mean = (mu * tau2 + x * sigma2) / (sigma2 + tau2)
mu_new = w_in * post_mean + w_out * mu
var_new = w_in * (post_var + post_mean ** 2) + w_out * (sigma2 + mu ** 2) - mu_new ** 2
# first two moments of the inlier ratio, then the Beta with those moments: s = a + b from the variance
m1 = w_in * (a + 1) / (a + b + 1) + w_out * a / (a + b + 1)
m2 = (w_in * (a + 1) * (a + 2) + w_out * a * (a + 1)) / ((a + b + 1) * (a + b + 2))
s = (m1 - m2) / (m2 - m1 * m1)
return float(mu_new), float(var_new), float(m1 * s), float((1 - m1) * s)
"""

T2_WHERE = """
near_rho = mu + 2 * sigma
far_rho = mu - 2 * sigma
far_rho = np.where(far_rho <= 0, 1e-10, far_rho)
return float(1.0 / near_rho), float(1.0 / far_rho)
"""

T3_ONE_PRODUCT = """
sigma_depth = np.sqrt(sigma2) / (mu * mu)
return float(4.0 * sigma_depth * np.abs(cos_alpha) / d_m)
"""

T4_RAY_INTERSECTION = """
t, f = np.asarray(t, float), np.asarray(f, float)
# 2-D coordinates in the plane of the baseline and the ray
e1 = t / np.linalg.norm(t)
e2 = f - (f @ e1) * e1
e2 = e2 / np.linalg.norm(e2)
f2 = np.array([f @ e1, f @ e2])
t2 = np.array([np.linalg.norm(t), 0.0])
a2 = f2 * z - t2
c, s = np.cos(px_error_angle), np.sin(px_error_angle)
d = np.array([c * a2[0] + s * a2[1], -s * a2[0] + c * a2[1]])  # turned away from the reference camera
# f2 * z_plus = t2 + d * u
z_plus, _ = np.linalg.solve(np.column_stack([f2, -d]), t2)
return float(z_plus - z)
"""

E1_SCALAR_LOOP = """
def count(rate, rng, n=500, n_obs=40):
    rho = rng.uniform(0.2, 2.0, n)
    seeds = [(float(rho.mean()), 4.0 / 36, 10.0, 10.0)] * n
    for k in range(n_obs + 1):
        if sum(math.sqrt(s[1]) < 0.01 for s in seeds) >= n / 2:
            return k
        bad = rng.random(n) < rate
        x = np.where(bad, rng.uniform(0.0, 2.0, n), rho + rng.normal(0.0, 0.01, n))
        seeds = [update_seed(*s, float(xi), 1e-4, 2.0) for s, xi in zip(seeds, x)]
    return n_obs + 1

rng = np.random.default_rng(7)
base = count(0.0, rng)
r = 0.0
while count(r, rng) < 3 * base:
    r = round(r + 0.05, 2)
print(f"outlier-free: {base} observations; three times that from outlier rate {r}")
return r
"""

E2_DISPARITY = """
# a rectified pair: disparity d = f b / z; one pixel less, z' = f b / (d - 1); z' / z - 1 = 1 / (d - 1) > 0.1
f_px, b = 500.0, 0.2
d_limit = 1 + 1 / 0.1
return f_px * b / d_limit
"""

E1_LIBRARY_OTHER_SEED = """
rates = np.round(np.arange(0.0, 0.81, 0.05), 2)
c = sl.studies.mono.run_depth_filter_convergence(tuple(rates), n_obs=40, rng=11)
k = np.array([41 if n is None else n for n in c.first_half()])
return float(rates[np.flatnonzero(k >= 3 * k[0])[0]])
"""

E2_COARSE_LAST_BELOW = """
z = np.round(np.arange(1.0, 20.0, 0.1), 1)
rel = np.array([tau(np.array([0.2, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]), zi, 2 * np.arctan(0.5 / 500)) for zi in z]) / z
return float(z[np.flatnonzero(rel <= 0.1)[-1]])  # the last depth of a 0.1 m scan still within 10 %
"""

T1_NO_UNIFORM_DENSITY = """
s_tot2 = sigma2 + tau2
C1 = a / (a + b) * math.exp(-0.5 * (x - mu) ** 2 / s_tot2) / math.sqrt(2 * math.pi * s_tot2)
C2 = b / (a + b)  # the outlier's uniform density 1 / rho_range forgotten
C1, C2 = C1 / (C1 + C2), C2 / (C1 + C2)
s2 = 1 / (1 / sigma2 + 1 / tau2)
m = s2 * (mu / sigma2 + x / tau2)
mu_new = C1 * m + C2 * mu
var = C1 * (s2 + m * m) + C2 * (sigma2 + mu * mu) - mu_new ** 2
f = C1 * (a + 1) / (a + b + 1) + C2 * a / (a + b + 1)
e = (C1 * (a + 1) * (a + 2) + C2 * a * (a + 1)) / ((a + b + 1) * (a + b + 2))
a_new = (e - f) / (f - e / f)
return mu_new, var, a_new, a_new * (1 - f) / f
"""

E1_INLIER_RATE = """
rates = np.round(np.arange(0.0, 0.81, 0.05), 2)
c = sl.studies.mono.run_depth_filter_convergence(tuple(rates), n_obs=40, rng=SEED)
k = np.array([41 if n is None else n for n in c.first_half()])
r = float(rates[np.flatnonzero(k >= 3 * k[0])[0]])
return 1.0 - r  # the share of inliers at that rate
"""

T4_NO_MINUS_Z = """
t, f = np.asarray(t, float), np.asarray(f, float)
a = f * z - t
alpha = math.acos(f @ t / np.linalg.norm(t))
beta = math.acos(a @ -t / (np.linalg.norm(t) * np.linalg.norm(a)))
bp = beta + px_error_angle
return np.linalg.norm(t) * math.sin(bp) / math.sin(math.pi - alpha - bp)  # z+, not tau = z+ - z
"""

E2_FIRST_ORDER = """
# small angles: tau ~ z^2 delta / b, so tau / z = 0.1 at z = 0.1 b / delta
return 0.1 * 0.2 / (2 * np.arctan(0.5 / 500))
"""

SUBMISSIONS = [
    Submission("independent", "every task and exploration by another method than the instructor's",
               bodies={"t1": T1_BETA_BY_MOMENTS, "t2": T2_WHERE, "t3": T3_ONE_PRODUCT, "t4": T4_RAY_INTERSECTION,
                       "e1": E1_SCALAR_LOOP, "e2": E2_DISPARITY}),
    Submission("other_seed", "Exploration 1 on another run seed, Exploration 2 as the last depth of a 0.1 m scan",
               bodies={"e1": E1_LIBRARY_OTHER_SEED, "e2": E2_COARSE_LAST_BELOW}),
    Submission("mistake_inlier_rate", "Task 1 without the outliers' uniform density; Exploration 1 answered with "
               "the inlier rate", bodies={"t1": T1_NO_UNIFORM_DENSITY, "e1": E1_INLIER_RATE}, lost=("t1", "e1")),
    Submission("mistake_first_order", "Task 4 returns z+ instead of tau; Exploration 2 from the small-angle estimate",
               bodies={"t4": T4_NO_MINUS_Z, "e2": E2_FIRST_ORDER}, lost=("t4", "e2")),
]
