"""Trajectories and their files: TUM and KITTI pose formats (Ch. 9; 003 §5.2).

A :class:`Trajectory` is a sequence of poses ``T_world_body``: positions
``(N, 3)`` in metres, rotation matrices ``(N, 3, 3)``, and timestamps in seconds
(optional: KITTI files have none and are associated by line number).

* **TUM** (one pose per line): ``timestamp tx ty tz qx qy qz qw`` — unit
  quaternion with the scalar *last*; ``#`` starts a comment.
* **KITTI** (one pose per line): the first three rows of the 4×4 pose matrix,
  row-major, 12 numbers; a variant (the KITTI devkit's example results)
  prefixes each line with the 0-based frame index (13 numbers), kept in
  ``frame_ids`` and used to associate with a full ground truth.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._validate import as_finite_array, as_vector, parse_numbers

__all__ = ["Trajectory", "read_kitti", "read_tum", "write_kitti", "write_tum"]


@dataclass(frozen=True)
class Trajectory:
    """Poses ``T_world_body``: ``positions_m (N, 3)``, ``rotations (N, 3, 3)``, ``timestamps_s (N,)`` or None.

    ``frame_ids (N,)``: frame numbers of the poses when a file lists them (else None).

    Attributes
    ----------
    positions_m : ndarray, shape (N, 3)
        Positions [m].
    rotations : ndarray, shape (N, 3, 3)
        Rotation matrices (body to world).
    timestamps_s : ndarray, shape (N,), optional
        Timestamps [s], ``None`` when the file has none.
    name : str
        Label (the file name for read trajectories).
    frame_ids : ndarray of int, shape (N,), optional
        Frame numbers of the poses, ``None`` when the file lists none.
    """

    positions_m: np.ndarray
    rotations: np.ndarray
    timestamps_s: np.ndarray | None = None
    name: str = ""
    frame_ids: np.ndarray | None = None

    def __post_init__(self):
        p = as_finite_array(self.positions_m, "positions_m", ndim=2)
        if p.shape[1] != 3 or p.shape[0] < 1:
            raise ValueError(f"`positions_m` must have shape (N, 3) with N >= 1; got {p.shape}")
        R = as_finite_array(self.rotations, "rotations", ndim=3)
        if R.shape != (p.shape[0], 3, 3):
            raise ValueError(f"`rotations` must have shape ({p.shape[0]}, 3, 3); got {R.shape}")
        object.__setattr__(self, "positions_m", p)
        object.__setattr__(self, "rotations", R)
        if self.timestamps_s is not None:
            object.__setattr__(self, "timestamps_s", as_vector(self.timestamps_s, "timestamps_s", p.shape[0]))
        if self.frame_ids is not None:
            ids = np.asarray(self.frame_ids)
            if ids.shape != (p.shape[0],) or not np.issubdtype(ids.dtype, np.integer):
                raise ValueError(f"`frame_ids` must be {p.shape[0]} integers; got dtype {ids.dtype}, shape {ids.shape}")

    def __len__(self) -> int:
        return self.positions_m.shape[0]

    @property
    def poses(self) -> np.ndarray:
        """Homogeneous ``(N, 4, 4)`` pose matrices."""
        T = np.zeros((len(self), 4, 4))
        T[:, :3, :3] = self.rotations
        T[:, :3, 3] = self.positions_m
        T[:, 3, 3] = 1.0
        return T

    @classmethod
    def from_poses(cls, poses, timestamps_s=None, name: str = "", frame_ids=None) -> Trajectory:
        """From ``(N, 4, 4)`` or ``(N, 3, 4)`` pose matrices.

        Parameters
        ----------
        poses : array_like, shape (N, 4, 4) or (N, 3, 4)
            Pose matrices (rotation and position of each pose in the trajectory's frame).
        timestamps_s : array_like of float, optional
            One time per pose, seconds.
        name : str
            Label in tables and plots.
        frame_ids : array_like of int, optional
            One frame index per pose.

        Returns
        -------
        Trajectory
        """
        P = as_finite_array(poses, "poses", ndim=3)
        if P.shape[1:] not in ((4, 4), (3, 4)):
            raise ValueError(f"`poses` must have shape (N, 4, 4) or (N, 3, 4); got {P.shape}")
        return cls(P[:, :3, 3].copy(), P[:, :3, :3].copy(), timestamps_s, name, frame_ids)

    def subset(self, idx) -> Trajectory:
        """The poses at integer indices ``idx``.

        Parameters
        ----------
        idx : array_like of int
            Indices of the poses to keep.

        Returns
        -------
        Trajectory
            The selected poses with their timestamps and frame ids.
        """
        idx = np.asarray(idx, dtype=int)
        ts = None if self.timestamps_s is None else self.timestamps_s[idx]
        ids = None if self.frame_ids is None else self.frame_ids[idx]
        return Trajectory(self.positions_m[idx], self.rotations[idx], ts, self.name, ids)

    def path_length_m(self) -> float:
        """Length of the polyline through the positions."""
        return float(np.sum(np.linalg.norm(np.diff(self.positions_m, axis=0), axis=1)))


def _load_rows(path, n_cols, what: str) -> np.ndarray:
    path = os.fspath(path)
    rows = []
    with open(path, encoding="utf-8") as fh:
        for line_no, line in enumerate(fh, start=1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.replace(",", " ").split()
            allowed = (n_cols,) if isinstance(n_cols, int) else tuple(n_cols)
            if len(parts) not in allowed or (rows and len(parts) != len(rows[0])):
                want = " or ".join(map(str, allowed))
                raise ValueError(f"{path}:{line_no}: a {what} line needs {want} numbers (the same on every "
                                 f"line); got {len(parts)}")
            rows.append(parse_numbers(parts, f"{path}:{line_no} ({what} line)"))
    if not rows:
        raise ValueError(f"{path}: no poses found")
    arr = np.asarray(rows, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{path}: non-finite numbers in the {what} file")
    return arr


def read_tum(path) -> Trajectory:
    """Read a TUM trajectory (``timestamp tx ty tz qx qy qz qw`` per line).

    Quaternions are normalised before conversion (files round them).

    Parameters
    ----------
    path : str or Path
        The TUM file.

    Returns
    -------
    Trajectory
        With ``timestamps_s``; ``name`` is the file name.
    """
    arr = _load_rows(path, 8, "TUM")
    q = arr[:, 4:8]
    norms = np.linalg.norm(q, axis=1)
    if np.any(norms < 1e-6):
        raise ValueError(f"{os.fspath(path)}: a quaternion has zero norm")
    R = Rotation.from_quat(q / norms[:, None]).as_matrix()  # scipy: scalar-last, like TUM
    return Trajectory(arr[:, 1:4], R, arr[:, 0], os.path.basename(os.fspath(path)))


def read_kitti(path, timestamps_s=None) -> Trajectory:
    """Read a KITTI pose file: 12 numbers per line (rows of the 3×4 pose matrix), or 13 with a leading frame index.

    Parameters
    ----------
    path : str or Path
        The KITTI pose file.
    timestamps_s : array_like, shape (N,), optional
        Timestamps [s] of the poses (KITTI files have none).

    Returns
    -------
    Trajectory
        ``frame_ids`` set when the file has 13 columns; ``name`` is the file name.
    """
    arr = _load_rows(path, (12, 13), "KITTI")
    ids = None
    if arr.shape[1] == 13:
        ids = arr[:, 0].astype(np.int64)
        if np.any(ids != arr[:, 0]) or np.any(ids < 0):
            raise ValueError(f"{os.fspath(path)}: the first of 13 columns must be a non-negative frame index")
        arr = arr[:, 1:]
    P = arr.reshape(-1, 3, 4)
    return Trajectory.from_poses(P, timestamps_s, os.path.basename(os.fspath(path)), ids)


def write_tum(path, traj: Trajectory) -> None:
    """Write ``traj`` in TUM format (needs timestamps).

    Parameters
    ----------
    path : str or Path
        File to write.
    traj : Trajectory
        Trajectory with timestamps.
    """
    if traj.timestamps_s is None:
        raise ValueError("`traj` needs timestamps to be written in TUM format")
    q = Rotation.from_matrix(traj.rotations).as_quat()
    data = np.column_stack([traj.timestamps_s, traj.positions_m, q])
    np.savetxt(os.fspath(path), data, fmt="%.9f", header="timestamp tx ty tz qx qy qz qw")


def write_kitti(path, traj: Trajectory) -> None:
    """Write ``traj`` in KITTI format (12 numbers per line).

    Parameters
    ----------
    path : str or Path
        File to write.
    traj : Trajectory
        Trajectory to write (timestamps and frame ids are not written).
    """
    np.savetxt(os.fspath(path), traj.poses[:, :3, :].reshape(len(traj), 12), fmt="%.9e")
