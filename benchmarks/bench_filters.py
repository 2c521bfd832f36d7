"""Benchmark: slamlab's KF / EKF / UKF step (predict + update) against filterpy on the same models.

Run: ``.venv/bin/python benchmarks/bench_filters.py`` (or ``make bench``). Prints,
per case, the median time of one predict+update step for ours and filterpy,
measured in the same process, and the ratio filterpy / ours (> 1: ours faster).
"""

from __future__ import annotations

import platform
import timeit

import filterpy
import numpy as np
from filterpy.kalman import ExtendedKalmanFilter as FPExtendedKalmanFilter
from filterpy.kalman import KalmanFilter as FPKalmanFilter
from filterpy.kalman import MerweScaledSigmaPoints
from filterpy.kalman import UnscentedKalmanFilter as FPUnscentedKalmanFilter

import slamlab
from slamlab.filters import ExtendedKalmanFilter, KalmanFilter, UnscentedKalmanFilter
from slamlab.sim import RangeBearingSensor, UnicycleModel, constant_velocity_model, simulate_unicycle


def _median_step_us(step, n_steps: int, repeat: int = 7) -> float:
    t = timeit.repeat(step, number=n_steps, repeat=repeat)
    return 1e6 * float(np.median(t)) / n_steps


def bench_kf(n=2000):
    F, Q, H, R = constant_velocity_model(1.0, 0.2, 1.0, dims=2)
    z = np.array([1.0, 2.0])
    ours = KalmanFilter(np.zeros(4), np.eye(4), F, Q, H, R)
    ref = FPKalmanFilter(dim_x=4, dim_z=2)
    ref.x, ref.P, ref.F, ref.Q, ref.H, ref.R = np.zeros(4), np.eye(4), F, Q, H, R

    def s_ours():
        ours.predict()
        ours.update(z)

    def s_ref():
        ref.predict()
        ref.update(z)

    return _median_step_us(s_ours, n), _median_step_us(s_ref, n)


def _robot():
    model = UnicycleModel(0.5, 0.2, np.deg2rad(10))
    sensor = RangeBearingSensor(np.array([[0.0, 5.0], [4.0, 8.0], [-4.0, 2.0]]), 0.5, np.deg2rad(10))
    u = np.array([1.0, 0.2])
    _, Z = simulate_unicycle(model, sensor, np.zeros(3), np.tile(u, (1, 1)), rng=1)
    return model, sensor, u, Z[0]


def bench_ekf(n=2000):
    model, sensor, u, z = _robot()
    x0, P0 = np.zeros(3), 0.1 * np.eye(3)
    Q = model.Q(x0, u)
    ours = ExtendedKalmanFilter(x0, P0, model.f, model.F_jac, Q, sensor.h, sensor.H_jac, sensor.R,
                                residual=sensor.residual)

    class Ref(FPExtendedKalmanFilter):
        def predict_x(self, u=0):
            self.x = model.f(self.x, u)

    ref = Ref(dim_x=3, dim_z=sensor.dim_z)
    ref.x, ref.P, ref.Q, ref.R = x0.copy(), P0.copy(), Q, sensor.R

    def s_ours():
        ours.x, ours.P = x0.copy(), P0.copy()
        ours.predict(u)
        ours.update(z)

    def s_ref():
        ref.x, ref.P = x0.copy(), P0.copy()
        ref.F = model.F_jac(ref.x, u)
        ref.predict(u=u)
        ref.update(z, sensor.H_jac, sensor.h, residual=sensor.residual)

    return _median_step_us(s_ours, n), _median_step_us(s_ref, n)


def bench_ukf(n=1000, vectorized=True):
    model, sensor, u, z = _robot()
    x0, P0 = np.zeros(3), 0.1 * np.eye(3)
    Q = model.Q(x0, u)
    ours = UnscentedKalmanFilter(x0, P0, model.f, Q, sensor.h, sensor.R, form="additive", alpha=0.5,
                                 x_mean_fn=model.mean, x_residual_fn=model.residual, z_mean_fn=sensor.mean,
                                 z_residual_fn=sensor.residual, vectorized=vectorized)
    pts = MerweScaledSigmaPoints(3, alpha=0.5, beta=2.0, kappa=0.0)
    ref = FPUnscentedKalmanFilter(3, sensor.dim_z, 0.5, hx=sensor.h, fx=lambda x, dt, u: model.f(x, u), points=pts,
                                  x_mean_fn=model.mean, z_mean_fn=sensor.mean, residual_x=model.residual,
                                  residual_z=sensor.residual)
    ref.Q, ref.R = Q, sensor.R

    def s_ours():
        ours.x, ours.P = x0.copy(), P0.copy()
        ours.predict(u)
        ours.update(z)

    def s_ref():
        ref.x, ref.P = x0.copy(), P0.copy()
        ref.predict(u=u)
        ref.update(z)

    return _median_step_us(s_ours, n), _median_step_us(s_ref, n)


def bench_ukf_augmented(n=1000):
    """000's augmented UKF (no filterpy counterpart): ours only, for the record."""
    model, sensor, u, z = _robot()
    x0, P0 = np.zeros(3), 0.1 * np.eye(3)
    ours = UnscentedKalmanFilter(x0, P0, model.f, model.M, sensor.h, sensor.R, form="augmented", alpha=0.5,
                                 x_mean_fn=model.mean, x_residual_fn=model.residual, z_mean_fn=sensor.mean,
                                 z_residual_fn=sensor.residual, vectorized=True)

    def s_ours():
        ours.x, ours.P = x0.copy(), P0.copy()
        ours.predict(u)
        ours.update(z)

    return _median_step_us(s_ours, n)


def main():
    print(f"slamlab {slamlab.__version__}, filterpy {filterpy.__version__}, numpy {np.__version__}, "
          f"Python {platform.python_version()}, {platform.machine()}")
    rows = [
        ("KF, CV target (n=4, m=2)", *bench_kf()),
        ("EKF, unicycle + 3 landmarks (n=3, m=6)", *bench_ekf()),
        ("UKF additive, vectorised models", *bench_ukf(vectorized=True)),
        ("UKF additive, per-point model calls", *bench_ukf(vectorized=False)),
    ]
    print(f"{'case':42s} {'ours [us]':>10s} {'filterpy [us]':>14s} {'filterpy/ours':>14s}")
    for name, ours, ref in rows:
        print(f"{name:42s} {ours:10.1f} {ref:14.1f} {ref / ours:14.2f}")
    print(f"{'UKF augmented (000), vectorised':42s} {bench_ukf_augmented():10.1f} {'-':>14s} {'-':>14s}")


if __name__ == "__main__":
    main()
