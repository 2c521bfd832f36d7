"""How a lab check compares the value a student's function returned with the expected one.

A :class:`Compare` is plain data (a kind and two tolerances), so the student's feedback files
(:mod:`slamlab.lab.feedback`) can name it and the instructor's grading can use the same one.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["KINDS", "Compare", "allclose"]


@dataclass(frozen=True)
class Compare:
    """A comparison of an expected and a received value: ``compare(expected, received, kwargs)``.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`: "allclose" (arrays, scalars or tuples of them, elementwise), "bbf" (distances
        and ids of nearest neighbours: a tied distance may name any of the tied ids) or "umeyama" (a
        similarity ``(R, t, c)``: a proper rotation, the same scale, and ``c R src + t`` where the expected
        one maps ``src``, the case's ``src`` argument).
    rtol, atol : float
        Relative and absolute tolerance (as :func:`numpy.allclose`).
    """

    kind: str = "allclose"
    rtol: float = 1e-7
    atol: float = 1e-9

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"`kind` must be one of {sorted(KINDS)}; got {self.kind!r}")
        if not (self.rtol >= 0 and self.atol >= 0):
            raise ValueError(f"`rtol` and `atol` must be >= 0; got {self.rtol}, {self.atol}")

    def __call__(self, expected: Any, received: Any, kwargs: Mapping[str, Any] | None = None) -> str | None:
        """None when ``received`` agrees with ``expected``, else a short description of the difference.

        Parameters
        ----------
        expected, received : object
            The expected value and the student's.
        kwargs : mapping, optional
            The case's arguments (the "umeyama" kind maps their ``src``).

        Returns
        -------
        str or None
            The difference, or None.
        """
        return KINDS[self.kind](self, expected, received, kwargs or {})


def allclose(rtol: float = 1e-7, atol: float = 1e-9) -> Compare:
    """An elementwise comparison with ``rtol``/``atol`` (arrays, scalars, tuples of them).

    Parameters
    ----------
    rtol, atol : float
        Relative and absolute tolerance (as :func:`numpy.allclose`).

    Returns
    -------
    Compare
        The comparison.
    """
    return Compare("allclose", float(rtol), float(atol))


def _allclose(c: Compare, expected, received, kwargs) -> str | None:
    if isinstance(expected, tuple):
        if not isinstance(received, (tuple, list)) or len(received) != len(expected):
            got = f"a {type(received).__name__}" + (f" of {len(received)}" if hasattr(received, "__len__") else "")
            return f"expected a tuple of {len(expected)} values; got {got}"
        for i, (e, r) in enumerate(zip(expected, received, strict=True)):
            diff = _allclose(c, e, r, kwargs)
            if diff is not None:
                return f"item {i} of the returned tuple: {diff}"
        return None
    e = np.asarray(expected, dtype=float)
    try:
        r = np.asarray(received, dtype=float)
    except (TypeError, ValueError):
        return f"expected numbers; got {type(received).__name__}"
    if r.shape != e.shape:
        return f"expected shape {e.shape}; got shape {r.shape}"
    if not np.allclose(r, e, rtol=c.rtol, atol=c.atol, equal_nan=True):
        k = np.unravel_index(np.argmax(np.abs(r - e)), e.shape) if e.shape else ()
        return f"largest difference at index {tuple(int(i) for i in k)}: expected {float(e[k]):.6g}, got {float(r[k]):.6g}"
    return None


def _bbf(c: Compare, expected, received, kwargs) -> str | None:
    if not isinstance(received, (tuple, list)) or len(received) != 2:
        return _allclose(c, expected, received, kwargs)
    diff = _allclose(c, expected[0], received[0], kwargs)
    if diff is not None:
        return f"item 0 of the returned tuple (distances): {diff}"
    e_ids = np.asarray(expected[1], dtype=float)
    try:
        r_ids = np.asarray(received[1], dtype=float)
    except (TypeError, ValueError):
        return f"expected integer ids; got {type(received[1]).__name__}"
    if r_ids.shape != e_ids.shape:
        return f"item 1 of the returned tuple (ids): expected shape {e_ids.shape}; got shape {r_ids.shape}"
    d = np.asarray(expected[0])
    unique = np.array([np.count_nonzero(d == x) == 1 for x in d])  # tied distances: any of the tied ids
    bad = np.flatnonzero(unique & (r_ids != e_ids))
    if bad.size:
        i = int(bad[0])
        return f"item 1 of the returned tuple (ids): at index {i} expected {int(e_ids[i])}, got {r_ids[i]:g}"
    return None


def _umeyama(c: Compare, expected, received, kwargs) -> str | None:
    """Comparing the mapped points rather than R itself accepts any of the equally good rotations of a
    collinear set (a rotation about the line moves none of its points)."""
    if not isinstance(received, (tuple, list)) or len(received) != 3:
        return f"expected a tuple (R, t, c); got {type(received).__name__}"
    try:
        R, t, s = np.asarray(received[0], float), np.asarray(received[1], float), float(received[2])
    except (TypeError, ValueError):
        return "expected numbers in (R, t, c)"
    R0, t0, s0 = (np.asarray(expected[0], float), np.asarray(expected[1], float), float(expected[2]))
    if R.shape != R0.shape or t.shape != t0.shape:
        return f"expected R of shape {R0.shape} and t of shape {t0.shape}; got {R.shape} and {t.shape}"
    if not np.allclose(R.T @ R, np.eye(len(R)), atol=1e-8):
        return "R is not orthonormal (R^T R != I)"
    if np.linalg.det(R) < 0:
        return "R is a reflection (det R = -1): flip the sign of the last singular direction"
    if not np.isclose(s, s0, rtol=1e-8, atol=1e-10):
        return f"scale c: expected {s0:.6g}, got {s:.6g}"
    src = np.asarray(kwargs["src"], float)
    mine, ref = s * src @ R.T + t, s0 * src @ R0.T + t0
    if not np.allclose(mine, ref, rtol=1e-7, atol=1e-8):
        k = int(np.argmax(np.abs(mine - ref).max(axis=1)))
        return f"c R src + t differs at point {k}: expected {ref[k]}, got {mine[k]}"
    return None


#: The comparisons by name.
KINDS = {"allclose": _allclose, "bbf": _bbf, "umeyama": _umeyama}
