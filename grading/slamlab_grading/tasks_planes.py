"""Lab 10 (plane-based 3-D particle-filter SLAM, 002): the tasks and the library functions they are checked against."""

from __future__ import annotations

import numpy as np

from slamlab._validate import check_int, check_positive
from slamlab.geometry.so3 import so3_exp
from slamlab.lab.compare import allclose
from slamlab.planes import fit_plane_lsq, frame_transforms, intensity_weights, planes_to_body

from .core import Case, ExplorationTask, Task, WrongAnswer, register


def _pose(rng, scale=3.0):
    T = np.eye(4)
    T[:3, :3] = so3_exp(rng.normal(0, 0.8, 3))
    T[:3, 3] = rng.normal(0, scale, 3)
    return T


def _frame_cases(rng):
    cases = [Case(f"{n} random poses", {"odometry": np.stack([_pose(rng) for _ in range(n)])}) for n in (3, 7)]
    cases.append(Case("a single line: T_1 = identity", {"odometry": _pose(rng)[None]}))
    T = np.stack([_pose(rng) for _ in range(4)])
    T[-1] = np.eye(4)
    cases.append(Case("the last pose is the odom origin: T_j = oT_j", {"odometry": T}))
    return cases


def _body_cases(rng):
    cases = []
    for k in (1, 4):
        n = rng.normal(size=(k, 3))
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        T = _pose(rng)
        cases.append(Case(f"{k} random plane(s), random pose", {"n_m": n, "p_m": rng.uniform(-5, 5, k),
                                                                "R": T[:3, :3], "t": T[:3, 3]}))
    cases.append(Case("a wall x = 5 seen from x = 2: p_b = 3", {"n_m": np.array([[1.0, 0, 0]]), "p_m": np.array([5.0]),
                                                                "R": np.eye(3), "t": np.array([2.0, 0, 0])}))
    cases.append(Case("the vehicle turned 90° about z: the wall's normal turns the other way",
                      {"n_m": np.array([[1.0, 0, 0]]), "p_m": np.array([5.0]),
                       "R": so3_exp([0.0, 0.0, np.pi / 2]), "t": np.zeros(3)}))
    return cases


def _body_reference(n_m, p_m, R, t):
    n_b, p_b = planes_to_body(n_m, p_m, R, t)
    return np.c_[n_b, p_b]


def _fit_cases(rng):
    cases = []
    for k, noise in ((20, 0.0), (200, 0.01)):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        u = np.cross(n, [0.3, -0.2, 0.9])
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        ab = rng.uniform(-2, 2, (k, 2))
        X = 2.5 * n + ab[:, :1] * u + ab[:, 1:] * w + rng.normal(0, noise, (k, 1)) * n
        cases.append(Case(f"{k} points on a plane, noise {noise} m", {"points": X}))
    cases.append(Case("the plane z = -2: n = (0, 0, -1), p = 2 (p >= 0)",
                      {"points": np.array([[0, 0, -2.0], [1, 0, -2], [0, 1, -2], [3, 2, -2]])}))
    cases.append(Case("three points only", {"points": np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])}))
    return cases


def _fit_reference(points):
    n, p = fit_plane_lsq(points)
    return np.r_[n, p]


def _weights_cases(rng):
    return [Case("random SADs", {"sad": rng.uniform(10, 90, 12)}),
            Case("one particle without overlap (NaN): weight 0", {"sad": np.array([30.0, np.nan, 10.0, 20.0])}),
            Case("all equal: uniform weights", {"sad": np.full(5, 7.0)}),
            Case("nobody overlaps: uniform weights", {"sad": np.full(3, np.nan)})]


register(Task("10.frame_transforms", "Task 1, moving the lines of a frame into the last line's pose",
              frame_transforms, _frame_cases,
              "each line's pose is re-expressed relative to the last line's pose: undo the last pose, then apply the "
              "line's (the order matters). The last line itself must come out as the identity.",
              compare=allclose(rtol=1e-9, atol=1e-9)))
register(Task("10.planes_to_body", "Task 2, a map plane seen from the body (002, reconstructed)",
              _body_reference, _body_cases,
              "the normal only turns, into the body frame, so with the inverse of the body's rotation; the offset "
              "shrinks by how far the body has moved along the normal. Try the wall case by hand.",
              compare=allclose(rtol=1e-9, atol=1e-9)))
register(Task("10.fit_plane", "Task 3, a least-squares plane through points", _fit_reference, _fit_cases,
              "the plane passes through the centroid; its normal is the direction in which the centred points spread "
              "least (not most); finally choose the sign that makes the offset non-negative.",
              compare=allclose(rtol=1e-9, atol=1e-9),
              points=2))
register(Task("10.intensity_weights", "Task 4, the intensity weights (002)", intensity_weights, _weights_cases,
              "the best particle (smallest SAD) gets the largest weight and the worst gets none; a particle without "
              "overlap counts as the worst; when no particle is better than another, all weights are equal.",
              compare=allclose(rtol=1e-12, atol=1e-12)))


# --- explorations -----------------------------------------------------------------------------------------

#: Exploration 1: points on a square patch (side, m), their count and the noise along the normal (m).
EXPLORE_PATCH_M = 4.0
EXPLORE_N_POINTS = 200
EXPLORE_NOISE_M = 0.02
#: The fewest independent draws Exploration 1 asks for, and the accepted relative half-width around the true RMS.
EXPLORE_MIN_DRAWS = 2000
EXPLORE_RMS_TOL = 0.05
#: The RMS angle relative to the first-order formula, by Monte Carlo (200 000 draws of this setting; the formula
#: leaves out that the spread of 200 uniform points varies from draw to draw, E[1/S] > 1/E[S]).
EXPLORE_RMS_OVER_FIRST_ORDER = 1.005
#: Exploration 2: the error of one wall's measured offset (m) and the largest along-wall error allowed (m).
EXPLORE_OFFSET_ERROR_M = 0.03
EXPLORE_ALONG_LIMIT_M = 0.5
#: The resolution Exploration 2 asks for, degrees.
EXPLORE_ANGLE_RESOLUTION_DEG = 0.1


def normal_rms_error_deg(n_points: int = EXPLORE_N_POINTS, noise_m: float = EXPLORE_NOISE_M,
                         side_m: float = EXPLORE_PATCH_M) -> float:
    """RMS angle (deg) between a least-squares plane's normal and the true one, to first order in the noise.

    Points uniform on a square of side L have a variance L²/12 along each in-plane axis; the normal tilts about
    each axis by noise / sqrt(N · L²/12) (a line fit's slope error), and the angle combines both tilts.

    Parameters
    ----------
    n_points : int
        Points on the patch.
    noise_m : float
        Noise std along the normal, m.
    side_m : float
        Side of the square patch, m.

    Returns
    -------
    float
        The RMS angle, degrees.
    """
    n_points = check_int(n_points, "n_points", minimum=3)
    noise_m, side_m = check_positive(noise_m, "noise_m", allow_zero=True), check_positive(side_m, "side_m")
    return float(np.degrees(noise_m * np.sqrt(2.0 / (n_points * side_m**2 / 12.0))))


def smallest_safe_angle_deg(offset_error_m: float = EXPLORE_OFFSET_ERROR_M,
                            limit_m: float = EXPLORE_ALONG_LIMIT_M) -> float:
    """The smallest angle (deg) between two walls at which one wall's offset error moves the position ≤ the limit.

    Two walls n1 · t = p1, n2 · t = p2 with normals α apart: an error δ in p2 moves the solution by δ / sin α along
    the walls (Cramer's rule on the 2 × 2 system), so α = asin(δ / limit).

    Parameters
    ----------
    offset_error_m, limit_m : float
        The offset error δ and the along-wall error allowed, m.

    Returns
    -------
    float
        The angle, degrees.
    """
    offset_error_m, limit_m = check_positive(offset_error_m, "offset_error_m"), check_positive(limit_m, "limit_m")
    if not offset_error_m < limit_m:
        raise ValueError(f"`offset_error_m` must be smaller than `limit_m`; got {offset_error_m} and {limit_m}")
    return float(np.degrees(np.arcsin(offset_error_m / limit_m)))


def _rms_range() -> tuple[float, float]:
    centre = EXPLORE_RMS_OVER_FIRST_ORDER * normal_rms_error_deg()
    return (1.0 - EXPLORE_RMS_TOL) * centre, (1.0 + EXPLORE_RMS_TOL) * centre


def _wall_range() -> tuple[float, float]:
    a = smallest_safe_angle_deg()
    return a - EXPLORE_ANGLE_RESOLUTION_DEG, a + EXPLORE_ANGLE_RESOLUTION_DEG


register(ExplorationTask(
    "10.explore.normal_error",
    f"Exploration 1: the RMS angle [deg] between the fitted and the true normal ({EXPLORE_N_POINTS} points uniform "
    f"on a {EXPLORE_PATCH_M:.0f} m square, Gaussian noise of {100 * EXPLORE_NOISE_M:.0f} cm along the normal, at "
    f"least {EXPLORE_MIN_DRAWS} draws)",
    lambda: EXPLORE_RMS_OVER_FIRST_ORDER * normal_rms_error_deg(),
    accepted=_rms_range,
    why=f"first-order error propagation: each tilt of the normal has the std of a line fit's slope, noise / "
        f"sqrt(N L²/12), and the angle combines two tilts: {normal_rms_error_deg():.4f}°; 200 000 Monte Carlo draws "
        f"give {EXPLORE_RMS_OVER_FIRST_ORDER:.3f} times that. Accepted ± {100 * EXPLORE_RMS_TOL:.0f} % around the "
        f"Monte Carlo value: the RMS of {EXPLORE_MIN_DRAWS} draws scatters by 1.24 % (200 runs: 0.971-1.040 of the "
        f"formula), so ± 5 % is four standard errors; the mean angle (0.89 of the RMS, Rayleigh) of 2000 draws "
        f"stays below 0.93 of the formula on 200 runs, outside.",
    hint="repeat the fit on freshly drawn noisy points many times, measure the angle between the fitted and the "
         "true normal each time (either sign of the normal is the same plane), and take the root mean square.",
    more="The angle is small: compute it in a way that stays accurate for small angles, and report degrees.",
    unit="an angle in degrees",
    bounds=(0.0, 180.0),
    wrong=(WrongAnswer("radians", lambda: float(np.radians(normal_rms_error_deg())), rtol=0.2,
                       hint="that looks like radians; the question asks for degrees."),
           WrongAnswer("one axis only", lambda: normal_rms_error_deg() / np.sqrt(2.0), rtol=0.06,
                       hint="that matches the tilt about one in-plane axis only; the angle between the normals "
                            "combines the tilts about both axes."),
           WrongAnswer("the mean angle", lambda: np.sqrt(np.pi / 4) * EXPLORE_RMS_OVER_FIRST_ORDER
                       * normal_rms_error_deg(), rtol=0.05,
                       hint="that matches the mean of the angles; the question asks for their root mean square, "
                            "which weighs the large tilts more."))))
register(ExplorationTask(
    "10.explore.wall_angle",
    f"Exploration 2: the smallest angle [deg] between two walls at which a {100 * EXPLORE_OFFSET_ERROR_M:.0f} cm "
    f"offset error keeps the along-wall error within {EXPLORE_ALONG_LIMIT_M} m (to "
    f"{EXPLORE_ANGLE_RESOLUTION_DEG}°)",
    smallest_safe_angle_deg,
    accepted=_wall_range,
    why=f"Cramer's rule on the two wall equations: the error moves the solution by δ / sin α along the walls, so "
        f"α = asin(δ / 0.5 m) = {smallest_safe_angle_deg():.4f}°; accepted ± {EXPLORE_ANGLE_RESOLUTION_DEG}°, the "
        f"resolution the question asks for: rounding (3.4), a first safe value on a 0.1° grid (3.5), finer grids, "
        f"bisection and the small-angle δ / limit (3.4377°) all pass.",
    hint="put two walls at an angle, shift one wall's offset by the error, solve the walls' equations for the "
         "position before and after, and measure the shift along the walls; then find where it drops to the "
         "limit as the angle grows.",
    more="The shift along the walls falls as the angle between them grows; report the angle in degrees.",
    unit="an angle in degrees",
    bounds=(0.0, 90.0),
    wrong=(WrongAnswer("radians", lambda: float(np.radians(smallest_safe_angle_deg())), rtol=0.05,
                       hint="that looks like radians; the question asks for degrees."),
           WrongAnswer("the complement", lambda: 90.0 - smallest_safe_angle_deg(), atol=0.2,
                       hint="that is the angle between one wall and the other's normal; the question asks for the "
                            "angle between the walls (equal to the angle between their normals)."))))
