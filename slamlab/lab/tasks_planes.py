"""Lab 10 (plane-based 3-D particle-filter SLAM, 002): the tasks and the library functions they are checked against."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from ..planes import fit_plane_lsq, frame_transforms, intensity_weights, planes_to_body
from .core import Case, ExplorationTask, Task, allclose, register

#: the lab's seed (the notebook's SEED)
LAB_SEED = 2017


def _pose(rng, scale=3.0):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rng.normal(0, 0.8, 3)).as_matrix()
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
                       "R": Rotation.from_euler("z", 90, degrees=True).as_matrix(), "t": np.zeros(3)}))
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
              "T_j = inv(oT_N) @ oT_j for every j (the last pose is oT_N = odometry[-1]); the inverse of a rigid "
              "[R t; 0 1] is [R^T, -R^T t; 0 1].", compare=allclose(rtol=1e-9, atol=1e-9)))
register(Task("10.planes_to_body", "Task 2, a map plane seen from the body (002, reconstructed)",
              _body_reference, _body_cases,
              "n_b = R^T n_m and p_b = p_m - n_m . t for each plane (rows of n_m); return the (K, 4) array "
              "[n_b, p_b].", compare=allclose(rtol=1e-9, atol=1e-9)))
register(Task("10.fit_plane", "Task 3, a least-squares plane through points", _fit_reference, _fit_cases,
              "centre the points; n = the right singular vector of the smallest singular value (np.linalg.svd(..., "
              "full_matrices=False)); p = n . centroid; "
              "flip both signs when p < 0; return [nx, ny, nz, p].", compare=allclose(rtol=1e-9, atol=1e-9),
              points=2))
register(Task("10.intensity_weights", "Task 4, the intensity weights (002)", intensity_weights, _weights_cases,
              "SAD* = max SAD - SAD (NaN counts as the max), w = SAD* / sum SAD*; when every SAD* is 0 (all equal, "
              "or all NaN) return uniform weights.", compare=allclose(rtol=1e-12, atol=1e-12)))


def _fig4_without_weights() -> float:
    from ..planes import run_intensity_figure

    return run_intensity_figure(n_particles=200, rng=LAB_SEED).error_without_m


def _flight_ate() -> float:
    from ..planes import run_flight

    return run_flight(6.0, rng=LAB_SEED, n_particles=100, intensity_weights=False).ate_m


register(ExplorationTask(
    "10.explore.fig4",
    "Exploration 1: the along-corridor error [m] of Fig. 4 with 200 particles when the intensity weights are off",
    _fig4_without_weights, rtol=0.0, atol=5e-4,
    hint="sl.planes.run_intensity_figure(n_particles=200, rng=SEED) returns both runs; read error_without_m."))
register(ExplorationTask(
    "10.explore.flight",
    "Exploration 2: the map-frame ATE [m] of a 6 s flight with 100 particles and the intensity weights off",
    _flight_ate, rtol=0.0, atol=5e-4,
    hint="sl.planes.run_flight(6.0, rng=SEED, n_particles=100, intensity_weights=False).ate_m"))
