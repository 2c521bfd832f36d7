"""The student's feedback files: each lab's implementation tasks with fixed cases and the values they expect,
and its explorations with the form of their answer (``slamlab/lab/feedback/NN.json``).

They are written by the instructor's grading package (``slamlab_grading.export_feedback``, in
``grading/`` beside the library, not part of it) and hold no reference implementation, accepted
range or model answer: a student's function is compared with the stored values of a few fixed cases;
the grading runs the references on other cases. JSON holds the arrays as ``{"array": [...], "dtype": ..., "shape": [...]}`` (the shape keeps an empty array's)
tuples as ``{"tuple": [...]}`` and a :class:`~slamlab.kdtree.KDTree` (lab 03's input) by its points, ids and
leaf size.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["FEEDBACK_DIR", "decode", "encode", "load"]

#: Where the feedback files live (shipped with the library).
FEEDBACK_DIR = Path(__file__).resolve().parent / "feedback"


def encode(value: Any) -> Any:
    """A JSON-ready copy of ``value`` (numbers, strings, None, arrays, tuples, lists and dicts of them).

    Parameters
    ----------
    value : object
        The value.

    Returns
    -------
    object
        Plain JSON types; :func:`decode` gives ``value`` back.
    """
    if isinstance(value, np.ndarray):
        return {"array": value.tolist(), "dtype": value.dtype.str, "shape": list(value.shape)}
    if isinstance(value, tuple):
        return {"tuple": [encode(v) for v in value]}
    if isinstance(value, list):
        return [encode(v) for v in value]
    if isinstance(value, dict):
        return {"dict": {str(k): encode(v) for k, v in value.items()}}
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if np.isfinite(v) else {"float": repr(v)}
    if value is None or isinstance(value, str):
        return value
    if type(value).__name__ == "KDTree" and type(value).__module__.startswith("slamlab.kdtree"):
        return {"kdtree": {"points": encode(value.points), "ids": encode(value.ids), "leaf_size": value.leaf_size}}
    raise TypeError(f"cannot store a {type(value).__name__} in a feedback file")


def decode(value: Any) -> Any:
    """The value :func:`encode` stored.

    Parameters
    ----------
    value : object
        What :func:`encode` returned (after a JSON round trip).

    Returns
    -------
    object
        The original value.
    """
    if isinstance(value, list):
        return [decode(v) for v in value]
    if isinstance(value, dict):
        if "array" in value:
            return np.array(value["array"], dtype=np.dtype(value["dtype"])).reshape(value["shape"])
        if "tuple" in value:
            return tuple(decode(v) for v in value["tuple"])
        if "float" in value:
            return float(value["float"])
        if "kdtree" in value:
            from ..kdtree import KDTree

            t = value["kdtree"]
            return KDTree(decode(t["points"]), decode(t["ids"]), leaf_size=t["leaf_size"])
        return {k: decode(v) for k, v in value["dict"].items()}
    return value


@functools.cache
def load(chapter: str) -> dict[str, Any]:
    """The feedback of one lab: ``{"tasks": {task_id: {...}}}`` (empty when the lab has none).

    Parameters
    ----------
    chapter : str
        Two digits ("08").

    Returns
    -------
    dict
        The decoded file.
    """
    path = FEEDBACK_DIR / f"{chapter}.json"
    if not path.is_file():
        return {"tasks": {}}
    return decode(json.loads(path.read_text(encoding="utf-8")))
