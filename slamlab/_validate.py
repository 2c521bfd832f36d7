"""Argument checks shared by every slamlab module (one place).

Every public function validates its inputs here and raises ``TypeError`` (wrong
type) or ``ValueError`` (wrong shape or value) with a message that names the
argument, says what was expected and what came.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "as_covariance",
    "as_finite_array",
    "as_image",
    "as_matrix",
    "as_measurement",
    "as_path",
    "as_rng",
    "as_vector",
    "check_callable",
    "check_choice",
    "check_int",
    "check_positive",
    "check_probability",
    "parse_numbers",
]


def _describe_shape(shape: tuple[int | None, ...]) -> str:
    return "(" + ", ".join("any" if s is None else str(s) for s in shape) + (",)" if len(shape) == 1 else ")")


def as_finite_array(value: Any, name: str, *, ndim: int | None = None, dtype=np.float64) -> np.ndarray:
    """Convert ``value`` to a finite numeric array, or raise naming ``name``.

    >>> as_finite_array([1, 2], "x")
    array([1., 2.])
    """
    if value is None:
        raise TypeError(f"`{name}` must be a numeric array; got None")
    arr = np.asarray(value)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_):
        raise TypeError(f"`{name}` must be a numeric array; got dtype {arr.dtype}")
    if np.iscomplexobj(arr):
        raise TypeError(f"`{name}` must be real; got complex dtype {arr.dtype}")
    arr = arr.astype(dtype, copy=False)
    if ndim is not None and arr.ndim != ndim:
        raise ValueError(f"`{name}` must be {ndim}-dimensional; got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.size(arr) - np.count_nonzero(np.isfinite(arr)))
        raise ValueError(f"`{name}` must be finite; got {bad} NaN/inf value(s)")
    return arr


def as_vector(value: Any, name: str, n: int | None = None) -> np.ndarray:
    """A finite float vector of length ``n`` (a scalar counts as length 1).

    >>> as_vector(3.0, "z")
    array([3.])
    """
    arr = as_finite_array(value, name)
    if arr.ndim == 0:
        arr = arr.reshape(1)
    if arr.ndim == 2 and 1 in arr.shape:  # column or row vector
        arr = arr.ravel()
    if arr.ndim != 1:
        raise ValueError(f"`{name}` must be a vector of shape {_describe_shape((n,))}; got shape {arr.shape}")
    if n is not None and arr.shape[0] != n:
        raise ValueError(f"`{name}` must have length {n}; got shape {arr.shape}")
    return arr


def as_measurement(value: Any, name: str, n: int) -> np.ndarray:
    """:func:`as_vector` with a fast path for a float64 ``(n,)`` array (per-step filter input).

    >>> as_measurement(np.array([1.0, 2.0]), "z", 2)
    array([1., 2.])
    """
    if type(value) is np.ndarray and value.dtype == np.float64 and value.shape == (n,):
        # short vectors: a Python-level check is ~6x cheaper than np.isfinite(...).all()
        ok = all(map(math.isfinite, value.tolist())) if n <= 32 else bool(np.isfinite(value).all())
        if ok:
            return value
        raise ValueError(f"`{name}` must be finite; got {int(n - np.isfinite(value).sum())} NaN/inf value(s)")
    return as_vector(value, name, n)


def as_matrix(value: Any, name: str, shape: tuple[int | None, int | None] | None = None) -> np.ndarray:
    """A finite float 2-D array of the given shape (``None`` = any size).

    A scalar is accepted where the expected shape is ``(1, 1)``.
    """
    arr = as_finite_array(value, name)
    if arr.ndim == 0 and shape is not None and shape == (1, 1):
        arr = arr.reshape(1, 1)
    if arr.ndim != 2:
        want = _describe_shape(shape) if shape else "(rows, cols)"
        raise ValueError(f"`{name}` must be a 2-D matrix of shape {want}; got shape {arr.shape}")
    if shape is not None:
        for got, want in zip(arr.shape, shape, strict=True):
            if want is not None and got != want:
                raise ValueError(f"`{name}` must have shape {_describe_shape(shape)}; got shape {arr.shape}")
    return arr


def as_covariance(value: Any, name: str, n: int | None = None, *, rtol: float = 1e-9) -> np.ndarray:
    """A symmetric positive semi-definite ``(n, n)`` matrix (returned symmetrised).

    A scalar is accepted for ``n == 1``. Symmetry is checked to ``rtol`` of the
    largest entry; the smallest eigenvalue must be ``>= -rtol * max|eig|``.

    >>> as_covariance([[2.0, 0.0], [0.0, 1.0]], "P", 2)
    array([[2., 0.],
           [0., 1.]])
    """
    arr = as_finite_array(value, name)
    if arr.ndim == 0:
        arr = arr.reshape(1, 1)
    arr = as_matrix(arr, name, (n, n))
    if arr.shape[0] != arr.shape[1]:
        raise ValueError(f"`{name}` must be a square matrix; got shape {arr.shape}")
    scale = float(np.max(np.abs(arr))) if arr.size else 0.0
    asym = float(np.max(np.abs(arr - arr.T))) if arr.size else 0.0
    if asym > rtol * max(scale, np.finfo(float).tiny) and asym > 0:
        raise ValueError(f"`{name}` must be symmetric; largest |{name} - {name}^T| entry is {asym:.2e}")
    sym = 0.5 * (arr + arr.T)
    if sym.size:
        eig = np.linalg.eigvalsh(sym)
        if eig[0] < -rtol * max(abs(eig[-1]), np.finfo(float).tiny):
            raise ValueError(f"`{name}` must be symmetric positive semi-definite; smallest eigenvalue {eig[0]:.2e}")
    return sym


def as_image(value: Any, name: str = "image", *, allow_color: bool = False) -> np.ndarray:
    """A non-empty 2-D (or ``H×W×3`` when ``allow_color``) numeric image, as given."""
    arr = np.asarray(value)
    if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number) or arr.dtype == np.bool_):
        raise TypeError(f"`{name}` must be a numeric image array; got dtype {arr.dtype}")
    ok_ndim = arr.ndim == 2 or (allow_color and arr.ndim == 3 and arr.shape[2] in (3, 4))
    if not ok_ndim:
        want = "(H, W) or (H, W, 3)" if allow_color else "(H, W)"
        raise ValueError(f"`{name}` must have shape {want}; got shape {arr.shape}")
    if arr.size == 0:
        raise ValueError(f"`{name}` must not be empty; got shape {arr.shape}")
    if np.issubdtype(arr.dtype, np.floating) and not np.all(np.isfinite(arr)):
        raise ValueError(f"`{name}` must be finite; got NaN/inf pixels")
    return arr


def as_rng(rng: Any, name: str = "rng") -> np.random.Generator:
    """Normalise ``rng`` (Generator, int seed, SeedSequence or None) to a Generator.

    >>> bool(as_rng(7).integers(100) == as_rng(7).integers(100))
    True
    """
    if isinstance(rng, np.random.Generator):
        return rng
    if rng is None or isinstance(rng, np.random.SeedSequence):
        return np.random.default_rng(rng)
    if isinstance(rng, numbers.Integral) and not isinstance(rng, bool):
        if rng < 0:
            raise ValueError(f"`{name}` seed must be non-negative; got {rng}")
        return np.random.default_rng(int(rng))
    raise TypeError(f"`{name}` must be a numpy Generator, an int seed, a SeedSequence or None; "
                    f"got {type(rng).__name__}")


def check_int(value: Any, name: str, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """An integer within ``[minimum, maximum]``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"`{name}` must be an integer; got {type(value).__name__}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise ValueError(f"`{name}` must be >= {minimum}; got {value}")
    if maximum is not None and value > maximum:
        raise ValueError(f"`{name}` must be <= {maximum}; got {value}")
    return value


def check_real(value: Any, name: str) -> float:
    """A finite real number (not a bool); a ``TypeError`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value):
        raise TypeError(f"`{name}` must be a finite real number; got {value!r}")
    return float(value)


def check_positive(value: Any, name: str, *, allow_zero: bool = False) -> float:
    """A finite real number > 0 (or >= 0 with ``allow_zero``)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"`{name}` must be a real number; got {type(value).__name__}")
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"`{name}` must be finite; got {value}")
    if value < 0 or (value == 0 and not allow_zero):
        raise ValueError(f"`{name}` must be {'>= 0' if allow_zero else '> 0'}; got {value}")
    return value


def check_probability(value: Any, name: str) -> float:
    """A number strictly between 0 and 1."""
    value = check_positive(value, name)
    if not value < 1:
        raise ValueError(f"`{name}` must be in (0, 1); got {value}")
    return value


def check_choice(value: Any, name: str, choices: Iterable[str]) -> str:
    """One of ``choices``."""
    choices = tuple(choices)
    if value not in choices:
        raise ValueError(f"`{name}` must be one of {', '.join(map(repr, choices))}; got {value!r}")
    return value


def check_callable(value: Any, name: str) -> Callable:
    """A callable."""
    if not callable(value):
        raise TypeError(f"`{name}` must be callable; got {type(value).__name__}")
    return value


def as_path(value: Any, name: str = "path", *, kind: str = "any") -> Path:
    """A ``str`` or ``os.PathLike`` as a :class:`pathlib.Path` that exists (``kind``: "file", "dir" or "any").

    >>> as_path(".", kind="dir").is_dir()
    True
    """
    if isinstance(value, bool) or not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"`{name}` must be a str or os.PathLike path; got {type(value).__name__}")
    p = Path(value)
    exists = {"file": p.is_file, "dir": p.is_dir, "any": p.exists}[check_choice(kind, "kind", ("file", "dir", "any"))]
    if not exists():
        what = {"file": "file", "dir": "folder", "any": "file or folder"}[kind]
        raise FileNotFoundError(f"`{name}`: no {what} at {p}")
    return p


def parse_numbers(fields: Iterable[str], where: str) -> np.ndarray:
    """Text fields of one line of a data file as floats; a field that is not a number names ``where`` and itself.

    ``where`` says the file and line ("exp2.dat line 12"); "nan" and "inf" are numbers.

    >>> parse_numbers(["1", "2.5", "nan"], "log.txt line 3").tolist()
    [1.0, 2.5, nan]
    """
    fields = list(fields)
    try:
        return np.array(fields, dtype=float)
    except ValueError:
        for i, tok in enumerate(fields):
            try:
                float(tok)
            except ValueError:
                raise ValueError(f"{where}: field {i} is not a number: {tok!r}") from None
        raise
