"""Lab 05: solutions written from 000 §3.3-3.5 and Umeyama (1991) pass, typical mistakes fail at the right case on the
student's feedback cases (seed 0) and the grading's, the library's own functions are refused, and the explorations'
ranges hold for independent methods while every named misconception is rejected on 30 seeds."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
import pytest

import slamlab_grading as lab
from slamlab_grading import core
from slamlab_grading import tasks_stereo as tst

RNGS = (0, core.GRADING_RNG)  # the feedback file's cases and the grading's

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


def _fails(task_id, fn, where=""):
    """``fn`` fails on both the feedback and the grading cases, at the case labelled ``where`` (if given)."""
    for rng in RNGS:
        res = lab.check(task_id, fn, rng=rng, quiet=True)
        assert res.status in ("failed", "error"), (rng, res.message)
        assert where in res.message, (rng, res.message)


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

    _fails("05.triangulate", first_ray_point, "case 1 of 4")
    _fails("05.triangulate", no_parallel_case, "(parallel and anti-parallel")


def test_epipolar_mistakes():
    def unnormalised(uv_left, uv_right, F, tol_px):  # the algebraic distance x_r^T F x_l is not in pixels
        return epipolar(uv_left, uv_right, F, tol_px, normalise=False)

    def transposed(uv_left, uv_right, F, tol_px):  # the line in the LEFT image, l = F^T x_r mixed up
        return epipolar(uv_left, uv_right, F, tol_px, transpose=True)

    _fails("05.epipolar", unnormalised, "case 1 of 4")
    _fails("05.epipolar", transposed, "rig rotated up to 3 deg")  # a rotated rig's F is not skew-symmetric


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

    _fails("05.stereo_point", reversed_disparity, "case 1 of 3")
    _fails("05.stereo_point", fx_for_y, "fy=720")  # the case with fx != fy
    _fails("05.stereo_point", keeps_negative, "(zero and negative disparity")


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

    _fails("05.umeyama", no_reflection_fix, "(a mirror image")
    assert "reflection" in lab.check("05.umeyama", no_reflection_fix, quiet=True).message
    _fails("05.umeyama", transposed_sigma, "case 1 of 6")
    _fails("05.umeyama", dst_variance, "with_scale=True")


def test_the_librarys_own_functions_are_refused():
    import slamlab as sl

    def tri(c1, d1, c2, d2):
        r = sl.geometry.triangulate_midpoint(c1, d1, c2, d2)
        return r.points, r.gap_m

    def epi(uv_left, uv_right, F, tol_px):
        ok = np.zeros(len(uv_left), bool)
        for i in range(len(uv_left)):
            ok[i] = sl.stereo.stages.epipolar_pairs(uv_left[i:i + 1], uv_right[i:i + 1], F, tol_px)[0].size > 0
        return ok

    def point(uv_left, uv_right, fx, fy, cx, cy, baseline_m):
        cam = sl.geometry.PinholeCamera(768, 576, fx, fy, cx, cy)
        rig = sl.geometry.StereoRig(cam, cam, np.eye(3), np.array([-baseline_m, 0.0, 0.0]))
        P = sl.geometry.triangulate_stereo(rig, uv_left, uv_right).points
        P[uv_left[:, 0] - uv_right[:, 0] <= 0] = np.nan
        return P

    def ume(src, dst, with_scale):
        T = sl.geometry.umeyama(src, dst, with_scale=with_scale)
        return T.R, T.t, T.c

    for task_id, fn in (("05.triangulate", tri), ("05.epipolar", epi), ("05.stereo_point", point),
                        ("05.umeyama", ume)):
        for rng in RNGS:
            res = lab.check(task_id, fn, rng=rng, quiet=True)
            assert res.status == "failed"
            assert "called the library's" in res.message, res.message


# --- the explorations ----------------------------------------------------------------------------------------

SEEDS = range(2010, 2040)  # simulator seeds: the calibrated rig is the same for each (an arena takes 2.6 s to build)


@lru_cache(maxsize=1)
def _rigs():
    import slamlab as sl

    arena = sl.sim.StereoArena(texture_seed=0)
    return [sl.sim.StereoSim(arena, rng=s).rig for s in SEEDS]


def _turned_errors(rig, Z=8.0, turn=2e-3, *, about_own_centre=False):
    """Both directions' depth errors [m], by projecting with the turned camera and Z = f B / d, written here."""
    f, B = rig.left.fx, rig.baseline_m
    out = []
    for a in (turn, -turn):
        c, s = np.cos(a), np.sin(a)
        x_l = np.array([0.0, 0.0, Z])
        t = np.array([-B, 0.0, 0.0])
        x_r = (np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ (x_l + t) if about_own_centre
               else np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]) @ x_l + t)
        d = -f * x_r[0] / x_r[2]  # u_l - u_r with u_l = c_x (the point is straight ahead)
        out.append(f * B / d - Z)
    return out


def test_drift_range_accepts_every_exact_method_and_rejects_first_order_and_the_mean():
    lo, hi = lab.task("05.explore.drift").accepted_range()
    rigs = _rigs()
    assert all(np.allclose(r.F, rigs[0].F) and r.baseline_m == rigs[0].baseline_m for r in rigs)
    Z, turn, B = 8.0, 2e-3, rigs[0].baseline_m
    for rig in rigs:
        kept, own = _turned_errors(rig), _turned_errors(rig, about_own_centre=True)
        worst = max(kept, key=abs)
        assert worst > 0 > min(kept, key=abs)  # the shrinking disparity pushes the point away, further
        answers = {"projected, R_rl turned": worst, "projected, turned about its own centre": max(own, key=abs),
                   "pixel shift f δ": Z**2 * turn / (B - Z * turn),
                   "second order": Z**2 * turn / B * (1 + Z * turn / B),
                   "the library's": lab.task("05.explore.drift").expected()}
        for name, v in answers.items():
            assert lo <= v <= hi, name
            assert lab.answer("05.explore.drift", v, quiet=True).passed, name
        wrong = {"first order": (Z**2 * turn / B, "first-order"),
                 "mean of both sizes": ((abs(kept[0]) + abs(kept[1])) / 2, "mean of the two"),
                 "the other direction": (abs(min(kept, key=abs)), "disparity larger"),
                 "the other, signed": (min(kept, key=abs), "disparity larger"),
                 "millimetres": (1000 * worst, "unit"), "pixels": (rig.left.fx * turn, "pixels"),
                 "relative": (worst / Z, "divided by the depth"), "the depth": (Z + worst, "depth itself")}
        for name, (v, hint) in wrong.items():
            assert not lo <= v <= hi, name
            res = lab.answer("05.explore.drift", v, quiet=True)
            assert res.status == "failed"
            assert hint in res.message, (name, res.message)


def test_depth_error_range_accepts_both_methods_and_rejects_each_misconception_on_30_seeds():
    lo, hi = lab.task("05.explore.depth_error").accepted_range()
    for rig in _rigs():
        f, B = rig.left.fx, rig.baseline_m
        d = f * B / 8.0
        exact = f * B / (d - 0.5) - 8.0  # Z = f B / d with half a pixel less disparity
        first = 8.0 * 0.5 / d  # first order Z^2/(f B) dd, 2 % low
        uvl, uvr = rig.project(np.array([[0.0, 0.0, 8.0]]))  # Task 3 on the projected pixels
        cam = rig.left
        by_task3 = stereo_point(uvl, uvr + np.array([0.5, 0.0]), cam.fx, cam.fy, cam.cx, cam.cy, B)[0, 2] - 8.0
        for v in (exact, first, by_task3):
            assert lab.answer("05.explore.depth_error", v, quiet=True).passed
        for v, hint in ((-exact, "closer"), (1000 * exact, "unit"), (exact / 8.0, "divided by the depth"),
                        (8.0 + exact, "depth itself"), (2 * exact, "")):
            assert not lo <= v <= hi
            res = lab.answer("05.explore.depth_error", v, quiet=True)
            assert res.status == "failed"
            assert hint in res.message


def test_exploration_answers_have_a_form_and_name_their_tools():
    for task_id in ("05.explore.drift", "05.explore.depth_error"):
        t = lab.task(task_id)
        assert t.unit.startswith("metres")
        assert t.answered_by == ("slamlab.geometry.triangulate_stereo",)
    assert lab.task("05.explore.drift").bounds[0] == 0.0
    assert tst.turned_about_centre_error() > tst.turned_depth_formulas()[1]
