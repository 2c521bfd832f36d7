"""Simulated worlds: motion and sensor models, trajectories (shared by the chapters)."""

from .robot import (
    RangeBearingSensor,
    UnicycleModel,
    simulate_unicycle,
)
from .targets import constant_velocity_model, simulate_linear

__all__ = [
    "RangeBearingSensor",
    "UnicycleModel",
    "constant_velocity_model",
    "simulate_linear",
    "simulate_unicycle",
]
