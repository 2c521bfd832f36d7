"""Lab 02's submissions for the autograde test (issue 43): written here, not copied from the instructor's cells.

The explorations have no seed: the questions fix the image, the sizes, the detectors' settings, the tolerance
and the grids. "other_seed" therefore answers them with another allowed reading or route (another detector
implementation, another reading of "inside the other image").
"""

from __future__ import annotations

from . import Submission

# --- correct, by other methods ---------------------------------------------------------------------------------

T1_ROWS = '''
H, W = image.shape
II = np.zeros((H + 1, W + 1))
for r in range(H):  # a running sum along each row, added to the row above
    II[r + 1, 1:] = II[r, 1:] + np.cumsum(image[r])
return II
'''

T2_MINMAX = '''
H, W = II.shape[0] - 1, II.shape[1] - 1


def clamp(x, top):
    return min(max(int(x), 0), top)


a0, a1, b0, b1 = clamp(r0, H), clamp(r1, H), clamp(c0, W), clamp(c1, W)
if a1 <= a0 or b1 <= b0:
    return 0.0
return float(II[a1, b1] - II[a0, b1] - II[a1, b0] + II[a0, b0])
'''

T3_WEIGHTED_BOXES = '''
l = L // 3
b = (L - 1) // 2
h = l // 2
# each filter as a list of (weight, rows a0..a1, cols b0..b1) relative to the pixel
filters = {
    "xx": [(1, -l + 1, l, -b, b + 1), (-3, -l + 1, l, -h, -h + l)],
    "yy": [(1, -b, b + 1, -l + 1, l), (-3, -h, -h + l, -l + 1, l)],
    "xy": [(1, -l, 0, 1, l + 1), (1, 1, l + 1, -l, 0), (-1, -l, 0, -l, 0), (-1, 1, l + 1, 1, l + 1)],
}
D = {}
for name, boxes in filters.items():
    D[name] = sum(w * box_sum(II, row + a0, row + a1, col + c0, col + c1) for w, a0, a1, c0, c1 in boxes) / L**2
return D["xx"] * D["yy"] - 0.81 * D["xy"] ** 2, D["xx"] + D["yy"]
'''

T4_VECTORISED = '''
img = image.astype(np.int32)
H, W = img.shape
out = np.zeros((H, W), dtype=bool)
if H < 7 or W < 7:
    return out
centre = img[3:H - 3, 3:W - 3]
ring = np.stack([img[3 + dv:H - 3 + dv, 3 + du:W - 3 + du] for du, dv in CIRCLE])  # (16, H-6, W-6)
for flags in (ring > centre + t, ring < centre - t):
    hit = np.zeros(centre.shape, dtype=bool)
    for start in range(16):  # an arc of n from every start, indices taken modulo 16
        hit |= np.all(flags[[(start + k) % 16 for k in range(n)]], axis=0)
    out[3:H - 3, 3:W - 3] |= hit
return out
'''

E1_OPENCV_BISECTION = '''
import cv2

img = np.ascontiguousarray(sl.features.load_oxford_image("graf", 1, size=(768, 576)), dtype=np.uint8)
grid = list(range(5, 105, 5))


def count(t):
    fd = cv2.FastFeatureDetector_create(threshold=t, nonmaxSuppression=True, type=cv2.FAST_FEATURE_DETECTOR_TYPE_9_16)
    return len(fd.detect(img))


lo, hi = 0, len(grid) - 1  # the count falls with t: bisect for the first threshold within budget
while lo < hi:
    mid = (lo + hi) // 2
    if count(grid[mid]) <= 1000:
        hi = mid
    else:
        lo = mid + 1
return grid[lo]
'''


def _e2_count(region: str, one_to_one: bool = False) -> str:
    """Exploration 2 counted with SciPy's cKDTree (or a one-to-one assignment), ``region`` the inside test."""
    pairing = ('''
        from scipy.optimize import linear_sum_assignment
        near = np.linalg.norm(a[:, None] - b[None], axis=2) < 2.5
        rr, cc = linear_sum_assignment(~near)
        repeated = near[rr, cc].sum()
''' if one_to_one else '''
        from scipy.spatial import cKDTree
        repeated = min(np.sum(cKDTree(b).query(a)[0] < 2.5), np.sum(cKDTree(a).query(b)[0] < 2.5))
''')
    return f'''
settings = {{"sift": {{}}, "surf": {{"threshold": 1e-4}}, "orb": {{"n_features": 3000}}, "fast": {{"threshold": 20}}}}


def mapped(H, uv):
    x = np.c_[uv, np.ones(len(uv))] @ H.T
    return x[:, :2] / x[:, 2:]


def inside(p, shape):
    h, w = shape[:2]
    return {region}


means = {{}}
for method, params in settings.items():
    scores = []
    for j in range(2, 7):
        im1, im2, H = sl.features.load_oxford_pair("wall", j, scale=0.5)
        k1 = sl.features.detect(im1, method, max_points=500, **params).uv
        k2 = sl.features.detect(im2, method, max_points=500, **params).uv
        p1, p2 = mapped(H, k1), mapped(np.linalg.inv(H), k2)
        a, b = p1[inside(p1, im2.shape)], k2[inside(p2, im1.shape)]
{pairing}
        scores.append(repeated / min(len(a), len(b)))
    means[method] = np.mean(scores)
print(means)
return round(max(means.values()), 2)
'''


E2_PIXEL_CENTRES = _e2_count("(p[:, 0] >= 0) & (p[:, 1] >= 0) & (p[:, 0] <= w - 1) & (p[:, 1] <= h - 1)")
E2_HALF_OPEN = _e2_count("(p[:, 0] >= 0) & (p[:, 1] >= 0) & (p[:, 0] < w) & (p[:, 1] < h)")
E2_ONE_TO_ONE = _e2_count("(p[:, 0] >= 0) & (p[:, 1] >= 0) & (p[:, 0] <= w - 1) & (p[:, 1] <= h - 1)",
                          one_to_one=True)

E1_LIBRARY_DOWNWARDS = '''
img = sl.features.load_oxford_image("graf", 1, size=(768, 576))
best = None
for t in range(100, 0, -5):  # from the top of the grid down: the last threshold still within budget
    if len(sl.features.fast_detect(img, t)) > 1000:
        break
    best = t
return best
'''

# --- mistakes --------------------------------------------------------------------------------------------------

T1_NO_BORDER = '''
return np.cumsum(np.cumsum(image, axis=0), axis=1)  # shape (H, W): the zero row and column forgotten
'''

T4_UINT8 = '''
H, W = image.shape
out = np.zeros((H, W), dtype=bool)
for r in range(3, H - 3):
    for c in range(3, W - 3):
        p = image[r, c]
        ring = np.array([image[r + dv, c + du] for du, dv in CIRCLE], dtype=np.uint8)
        with np.errstate(over="ignore"):
            brighter, darker = ring > p + np.uint8(t), ring < p - np.uint8(t)  # wraps around in uint8
        for flags in (brighter, darker):
            twice = np.concatenate([flags, flags])
            run = 0
            for f in twice:
                run = run + 1 if f else 0
                if run >= n:
                    out[r, c] = True
                    break
return out
'''

E1_NO_NMS = '''
import cv2

img = np.ascontiguousarray(sl.features.load_oxford_image("graf", 1, size=(768, 576)), dtype=np.uint8)
for t in range(5, 105, 5):
    fd = cv2.FastFeatureDetector_create(threshold=t, nonmaxSuppression=False)  # every corner pixel counted
    if len(fd.detect(img)) <= 1000:
        return t
'''

SUBMISSIONS = [
    Submission("independent", "every task by another method (row sums, min/max clamping, weighted box lists, a "
                              "vectorised segment test); E1 by OpenCV and bisection, E2 by a cKDTree count",
               bodies={"t1": T1_ROWS, "t2": T2_MINMAX, "t3": T3_WEIGHTED_BOXES, "t4": T4_VECTORISED,
                       "e1": E1_OPENCV_BISECTION, "e2": E2_PIXEL_CENTRES}, lost=()),
    Submission("other_seed", "no seed to change: E1 by the library's detector searched downwards, E2 with the "
                             "other reading of 'inside the image' (0 <= u < W)",
               bodies={"e1": E1_LIBRARY_DOWNWARDS, "e2": E2_HALF_OPEN}, lost=()),
    Submission("mistake_no_border_no_nms", "the integral image without its zero row and column; E1 counted "
                                           "before non-maximum suppression",
               bodies={"t1": T1_NO_BORDER, "e1": E1_NO_NMS}, lost=("t1", "e1")),
    Submission("mistake_uint8_one_to_one", "the segment test in uint8 arithmetic; E2 counted as one-to-one pairs",
               bodies={"t4": T4_UINT8, "e2": E2_ONE_TO_ONE}, lost=("t4", "e2")),
]
