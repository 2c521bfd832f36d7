"""Lab 06 (correlation localisation): what students hand in. Bodies replace the code between the solution markers."""

from __future__ import annotations

from . import Submission

# --- correct, by methods other than the instructor's -----------------------------------------------------------

T1_COMPLEX = '''
z = ranges[valid] * np.exp(1j * (bearings_rad[valid] + pose[2])) + (pose[0] + 1j * pose[1])  # rotate, then shift
return np.stack([z.real, z.imag], axis=-1).reshape(-1, 2)
'''

T2_VECTORISED = '''
o = l_max + 2
T = np.full((2 * o, 2 * o), float(a_n))
a, r = heading_rad + bearings_rad[valid], ranges[valid]
steps = np.arange(0.0, r.max() if r.size else 0.0, 0.5)
beam, k = np.nonzero(steps[None, :] < r[:, None])  # every free mark of every beam at once
t_free, a_free = steps[k], a[beam]
t_hit = np.concatenate([r + 0.01, r + 0.5])
a_hit = np.concatenate([a, a])
for t, ang, value in ((t_free, a_free, a_c), (t_hit, a_hit, a_p)):  # all free marks, then all obstacle marks
    rows = o + np.floor(t * np.sin(ang) + 0.5).astype(int)
    cols = o + np.floor(t * np.cos(ang) + 0.5).astype(int)
    T[rows, cols] = value
return T
'''

T3_PADDED = '''
S = T.shape[0]
H, W = M_values.shape
padded = np.zeros((H + 2 * S, W + 2 * S))  # zeros outside the map, no wrap-around
padded[S:S + H, S:S + W] = M_values
r0, c0 = S + row - o, S + col - o
return float(np.sum(T * padded[r0:r0 + S, c0:c0 + S]))
'''

T4_WINDOWS = '''
S = T.shape[0]
H, W = M_values.shape
padded = np.pad(M_values, ((o, S - o), (o, S - o)))  # M = 0 outside the map
windows = np.lib.stride_tricks.sliding_window_view(padded, (S, S))[:H, :W]
return np.einsum("rcij,ij->rc", windows, T)
'''

# Exploration 1 by the student's own localiser: Task 2's template at every 1° heading, every cell scored by FFT
E1_OWN_LOCALISER = '''
from scipy.signal import fftconvolve

pose = np.array([60.0, 40.0, np.radians(37.0)])
rf = sl.sim.Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=0.3, quantum_cells=0.1)
scan = rf.scan(sl.sim.measurement_room_200(), pose, rng=SEED)
grid = sl.sim.test_room_200()
M = np.where(grid == 1, 1.0, np.where(grid == 0, -1.0, 0.0))  # the stored map in Task 2's values
l_max = int(np.ceil(scan.ranges[scan.valid].max() + 0.5))
o = l_max + 2
H, W = M.shape
best, cells = np.empty(360), np.empty((360, 2), int)
for h in range(360):  # every 1° heading once; a step d then picks among the multiples of d
    T = stamp(scan.bearings_rad, scan.ranges, scan.valid, np.radians(h), l_max, -1.0, 1.0, 0.0)
    # C(row, col) = sum T[i, j] M[row + i - o, col + j - o]: a convolution with T flipped
    C = np.rint(fftconvolve(M, T[::-1, ::-1], mode="full"))[T.shape[0] - 1 - o:, T.shape[1] - 1 - o:][:H, :W]
    k = int(np.argmax(C))
    best[h], cells[h] = C.flat[k], divmod(k, W)
for d in range(1, 31):
    hs = np.arange(0, 360, d)
    row, col = cells[hs[np.argmax(best[hs])]]
    if np.hypot(col - pose[0], row - pose[1]) > 2.0:
        return d
'''

# Exploration 2 counted from each pose's errors with the question's rule (not the study's own failure flags)
E2_FROM_ERRORS = '''
failed = 0
for seed in (2010, 2011, 2012):
    res = sl.studies.correlation.run_monte_carlo(12, range_std_cells=2.0, extra_clutter=120,
                                                 delta_alpha_rad=np.radians(2.0), rng=seed, progress=False)
    heading_off = np.degrees(np.abs(np.angle(np.exp(1j * res.err_heading_rad))))
    failed += int(np.count_nonzero((res.err_pos_cells > 2.0) | (heading_off > 5.0)))
return failed
'''

# --- correct, with another seed or setting ----------------------------------------------------------------------

E1_OTHER_SEED = '''
pose = np.array([60.0, 40.0, np.radians(37.0)])
rf = sl.sim.Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=0.3, quantum_cells=0.1)
scan = rf.scan(sl.sim.measurement_room_200(), pose, rng=2033)  # any seed from 2010 to 2039
for d in range(1, 31):
    loc = sl.correlation.localise(sl.sim.test_room_200(), scan, delta_alpha_rad=np.radians(d))
    if np.hypot(loc.pose[0] - pose[0], loc.pose[1] - pose[1]) > 2.0:
        return d
'''

E2_OTHER_ORDER = '''
# the three runs in another order, the failure rate times the pose count
rates = [sl.studies.correlation.run_monte_carlo(12, range_std_cells=2.0, extra_clutter=120,
                                                delta_alpha_rad=np.radians(2.0), rng=seed,
                                                progress=False).failure_rate for seed in (2012, 2010, 2011)]
return int(round(12 * sum(rates)))
'''

# --- mistakes -------------------------------------------------------------------------------------------------

T1_TRANSPOSED = '''
a, r = bearings_rad[valid], ranges[valid]
x, y, th = pose
c, s = np.cos(th), np.sin(th)
px, py = r * np.cos(a), r * np.sin(a)
return np.column_stack([x + c * px + s * py, y - s * px + c * py])  # R(theta) transposed
'''

E1_COARSE_TEMPLATE = '''
from scipy.signal import fftconvolve

pose = np.array([60.0, 40.0, np.radians(37.0)])
rf = sl.sim.Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=0.3, quantum_cells=0.1)
scan = rf.scan(sl.sim.measurement_room_200(), pose, rng=SEED)
grid = sl.sim.test_room_200()
M = np.where(grid == 1, 1.0, np.where(grid == 0, -1.0, 0.0))
a0, r = scan.bearings_rad[scan.valid], scan.ranges[scan.valid]
o = int(np.ceil(r.max())) + 3
H, W = M.shape
best, cells = np.empty(360), np.empty((360, 2), int)
for h in range(360):
    T = np.zeros((2 * o, 2 * o))
    a = np.radians(h) + a0
    for ang, l in zip(a, r):  # a coarser template: a free mark every cell, one obstacle mark
        t = np.arange(0.0, l, 1.0)
        T[o + np.floor(t * np.sin(ang) + 0.5).astype(int), o + np.floor(t * np.cos(ang) + 0.5).astype(int)] = -1.0
    for ang, l in zip(a, r):
        T[o + int(np.floor((l + 0.5) * np.sin(ang) + 0.5)), o + int(np.floor((l + 0.5) * np.cos(ang) + 0.5))] = 1.0
    C = np.rint(fftconvolve(M, T[::-1, ::-1], mode="full"))[T.shape[0] - 1 - o:, T.shape[1] - 1 - o:][:H, :W]
    k = int(np.argmax(C))
    best[h], cells[h] = C.flat[k], divmod(k, W)
for d in range(1, 31):
    hs = np.arange(0, 360, d)
    row, col = cells[hs[np.argmax(best[hs])]]
    if np.hypot(col - pose[0], row - pose[1]) > 2.0:
        return d
'''

T3_WRAPS = '''
total = 0.0
for i in range(T.shape[0]):
    for j in range(T.shape[1]):
        r, c = row + i - o, col + j - o
        if r < M_values.shape[0] and c < M_values.shape[1]:  # negative indices wrap around
            total += T[i, j] * M_values[r, c]
return total
'''

E2_NO_CLUTTER = '''
return sum(int(sl.studies.correlation.run_monte_carlo(12, range_std_cells=2.0, delta_alpha_rad=np.radians(2.0),
                                                      rng=seed, progress=False).failed.sum())
           for seed in (2010, 2011, 2012))  # the 120 clutter discs forgotten
'''

E2_ONE_RUN = '''
res = sl.studies.correlation.run_monte_carlo(12, range_std_cells=2.0, extra_clutter=120,
                                             delta_alpha_rad=np.radians(2.0), rng=SEED, progress=False)
return int(res.failed.sum())  # one run, not the three
'''

SUBMISSIONS = [
    Submission("independent", "every task and exploration by a method other than the instructor's: complex "
               "numbers, vectorised marks, a padded map, sliding windows; Exploration 1 with the student's own "
               "localiser (Task 2's template, FFT scores), Exploration 2 counted from each pose's errors",
               bodies={"t1": T1_COMPLEX, "t2": T2_VECTORISED, "t3": T3_PADDED, "t4": T4_WINDOWS,
                       "e1": E1_OWN_LOCALISER, "e2": E2_FROM_ERRORS}, lost=()),
    Submission("other_seed", "Exploration 1 with another allowed seed (2033), Exploration 2 from the failure "
               "rates of the three runs in another order",
               bodies={"e1": E1_OTHER_SEED, "e2": E2_OTHER_ORDER}, lost=()),
    Submission("mistake_no_clutter", "R(θ) transposed in Task 1; Exploration 2 without the unmapped clutter",
               bodies={"t1": T1_TRANSPOSED, "e2": E2_NO_CLUTTER}, lost=("t1", "e2")),
    Submission("mistake_coarse_template", "negative indices wrap around in Task 3; Exploration 1 with a coarser "
               "template than Task 2's; Exploration 2 from one run",
               bodies={"t3": T3_WRAPS, "e1": E1_COARSE_TEMPLATE, "e2": E2_ONE_RUN}, lost=("t3", "e1", "e2")),
]
