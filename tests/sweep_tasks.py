"""Task functions for tests/test_sweep.py: importable by name in worker processes (loky, Dask)."""

from __future__ import annotations


def noisy(scale, rng, fail_at=None, label=""):
    """A draw scaled by ``scale`` (``label`` is a parameter that changes nothing); raises at ``scale == fail_at``."""
    if fail_at is not None and scale == fail_at:
        raise ValueError(f"scale {scale} is not allowed")
    return {"draw": float(scale * rng.standard_normal()), "n": int(rng.integers(1000))}
