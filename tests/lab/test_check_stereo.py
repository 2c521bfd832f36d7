"""Lab 05 tasks: solutions written from 000 §3.3-3.5 and Umeyama (1991) pass, typical mistakes fail at the right case."""

from __future__ import annotations

import numpy as np
import pytest

from slamlab import lab

# --- independent solutions (what a student should write) --------------------------------------------


def triangulate(c1, d1, c2, d2, *, midpoint=True):
    w = c1 - c2
    a, b, c = (d1 * d1).sum(1), (d1 * d2).sum(1), (d2 * d2).sum(1)
    d, e = (d1 * w).sum(1), (d2 * w).sum(1)
    den = a * c - b * b
    ok = den > 1e-12 * a * c
    den = np.where(ok, den, 1.0)
    s = np.where(ok, (b * e - c * d) / den, 0.0)
    t = np.where(ok, (a * e - b * d) / den, 0.0)
    p1, p2 = c1 + s[:, None] * d1, c2 + t[:, None] * d2
    return ((p1 + p2) / 2 if midpoint else p1), np.linalg.norm(p1 - p2, axis=1)


def epipolar(uv_left, uv_right, F, tol_px, *, normalise=True, transpose=False):
    xl = np.column_stack([uv_left, np.ones(len(uv_left))])
    lines = xl @ (F if transpose else F.T)
    dist = np.abs((lines[:, :2] * uv_right).sum(1) + lines[:, 2])
    if normalise:
        dist /= np.hypot(lines[:, 0], lines[:, 1])
    return dist <= tol_px


def stereo_point(uv_left, uv_right, fx, fy, cx, cy, baseline_m, *, fy_is_fx=False):
    d = uv_left[:, 0] - uv_right[:, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        Z = np.where(d > 0, fx * baseline_m / np.where(d > 0, d, 1.0), np.nan)
    X = (uv_left[:, 0] - cx) * Z / fx
    Y = (uv_left[:, 1] - cy) * Z / (fx if fy_is_fx else fy)
    return np.column_stack([X, Y, Z])


def umeyama(src, dst, with_scale, *, fix_reflection=True, transpose=False):
    mu_s, mu_d = src.mean(0), dst.mean(0)
    xs, xd = src - mu_s, dst - mu_d
    Sigma = (xs.T @ xd if transpose else xd.T @ xs) / len(src)
    U, D, Vt = np.linalg.svd(Sigma)
    S = np.eye(src.shape[1])
    if fix_reflection and np.linalg.det(U) * np.linalg.det(Vt) < 0:
        S[-1, -1] = -1
    R = U @ S @ Vt
    c = np.trace(np.diag(D) @ S) / (xs**2).sum(1).mean() if with_scale else 1.0
    return R, mu_d - c * R @ mu_s, c


@pytest.mark.parametrize(("task_id", "fn"), [("05.triangulate", triangulate), ("05.epipolar", epipolar),
                                             ("05.stereo_point", stereo_point), ("05.umeyama", umeyama)])
def test_correct_solutions_pass(task_id, fn):
    res = lab.check(task_id, fn, quiet=True)
    assert res.passed, res.message


def test_triangulation_mistakes():
    def first_ray_point(c1, d1, c2, d2):  # the closest point on ray 1, not the midpoint
        return triangulate(c1, d1, c2, d2, midpoint=False)

    def no_parallel_case(c1, d1, c2, d2):
        w = c1 - c2
        a, b, c = (d1 * d1).sum(1), (d1 * d2).sum(1), (d2 * d2).sum(1)
        d, e = (d1 * w).sum(1), (d2 * w).sum(1)
        s, t = (b * e - c * d) / (a * c - b * b), (a * e - b * d) / (a * c - b * b)
        p1, p2 = c1 + s[:, None] * d1, c2 + t[:, None] * d2
        return (p1 + p2) / 2, np.linalg.norm(p1 - p2, axis=1)

    assert "case 1 of 4" in lab.check("05.triangulate", first_ray_point, quiet=True).message
    assert "(parallel and anti-parallel" in lab.check("05.triangulate", no_parallel_case, quiet=True).message


def test_epipolar_mistakes():
    def unnormalised(uv_left, uv_right, F, tol_px):  # the algebraic distance x_r^T F x_l is not in pixels
        return epipolar(uv_left, uv_right, F, tol_px, normalise=False)

    def transposed(uv_left, uv_right, F, tol_px):  # the line in the LEFT image, l = F^T x_r mixed up
        return epipolar(uv_left, uv_right, F, tol_px, transpose=True)

    assert "case 1 of 4" in lab.check("05.epipolar", unnormalised, quiet=True).message
    assert lab.check("05.epipolar", transposed, quiet=True).status == "failed"


def test_stereo_point_mistakes():
    def reversed_disparity(uv_left, uv_right, fx, fy, cx, cy, baseline_m):
        return stereo_point(uv_right, uv_left, fx, fy, cx, cy, baseline_m)

    def fx_for_y(uv_left, uv_right, fx, fy, cx, cy, baseline_m):
        return stereo_point(uv_left, uv_right, fx, fy, cx, cy, baseline_m, fy_is_fx=True)

    def keeps_negative(uv_left, uv_right, fx, fy, cx, cy, baseline_m):  # only d = 0 treated
        d = uv_left[:, 0] - uv_right[:, 0]
        P = stereo_point(uv_left, uv_right, fx, fy, cx, cy, baseline_m)
        neg = d < 0
        Z = fx * baseline_m / d[neg]
        P[neg] = np.column_stack([(uv_left[neg, 0] - cx) * Z / fx, (uv_left[neg, 1] - cy) * Z / fy, Z])
        return P

    assert "case 1 of 3" in lab.check("05.stereo_point", reversed_disparity, quiet=True).message
    assert "case 2 of 3" in lab.check("05.stereo_point", fx_for_y, quiet=True).message
    assert "(zero and negative disparity" in lab.check("05.stereo_point", keeps_negative, quiet=True).message


def test_umeyama_mistakes():
    def no_reflection_fix(src, dst, with_scale):
        return umeyama(src, dst, with_scale, fix_reflection=False)

    def transposed_sigma(src, dst, with_scale):  # src^T dst gives R^T
        return umeyama(src, dst, with_scale, transpose=True)

    def dst_variance(src, dst, with_scale):  # scale from the spread of dst instead of src
        R, _, c = umeyama(src, dst, with_scale)
        if with_scale:
            c = c * ((src - src.mean(0)) ** 2).sum(1).mean() / ((dst - dst.mean(0)) ** 2).sum(1).mean()
        return R, dst.mean(0) - c * R @ src.mean(0), c

    res = lab.check("05.umeyama", no_reflection_fix, quiet=True)
    assert "(a mirror image" in res.message
    assert "reflection" in res.message
    assert "case 1 of 6" in lab.check("05.umeyama", transposed_sigma, quiet=True).message
    assert "case 2 of 6" in lab.check("05.umeyama", dst_variance, quiet=True).message


def test_depth_error_exploration():
    import slamlab as sl

    rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=2010).rig
    f, B = rig.left.fx, rig.baseline_m
    d = f * B / 8.0
    err = f * B / (d - 0.5) - 8.0  # Z = f B / d with half a pixel less disparity
    assert lab.answer("05.explore.depth_error", err, quiet=True).passed
    assert lab.answer("05.explore.depth_error", 8.0 * 0.5 / d, quiet=True).passed  # first order Z^2/(f B) dd, 2 % low
    assert lab.answer("05.explore.depth_error", 2 * err, quiet=True).status == "failed"


def test_drift_exploration():
    """The drifted right camera's pixel and the depth from the disparity, written here: the range's ends are the
    first-order and exact errors of the turn that shrinks the disparity; the library's answer and the typical
    wrong ones fall where they should."""
    import slamlab as sl

    rig = sl.sim.StereoSim(sl.sim.StereoArena(texture_seed=0), rng=2010).rig
    f, cx, B, Z, turn = rig.left.fx, rig.left.cx, rig.baseline_m, 8.0, 2e-3
    errors = []
    for a in (turn, -turn):  # the right camera turned about its vertical axis, x_r = R_y(a) x_l + (-B, 0, 0)
        x, z = Z * np.sin(a) - B, Z * np.cos(a)
        d = cx - (f * x / z + cx)  # the left pixel is cx: the point is straight ahead
        errors.append(f * B / d - Z)  # the calibrated rig's depth from the disparity
    worst, other = max(errors, key=abs), min(errors, key=abs)
    assert worst > 0 > other  # the shrinking disparity pushes the point away, and further than the other pulls it
    lo, hi = lab.task("05.explore.drift").accepted_range()
    assert (lo, hi) == pytest.approx((0.97 * Z**2 * turn / B, 1.03 * worst), rel=1e-9)
    assert lo < Z**2 * turn / B < worst < hi  # first order and exact both pass
    assert lab.answer("05.explore.drift", lab.task("05.explore.drift").expected(), quiet=True).passed
    assert lab.task("05.explore.drift").expected() == pytest.approx(worst, rel=1e-6)
    for wrong, hint in ((abs(other), "disparity larger"), (other, "disparity larger"), (1000 * worst, "unit"),
                        (f * turn, "pixels"), (worst / Z, "divided by the depth"), (Z + worst, "depth itself")):
        r = lab.answer("05.explore.drift", wrong, quiet=True)
        assert r.status == "failed"
        assert hint in r.message
