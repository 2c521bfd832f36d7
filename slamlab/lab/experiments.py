"""The simulated scenes of the labs' exploration tasks (the lab's experiments: the one lab module that runs the simulator).

Task modules (``tasks_*.py``) check a student's work; the scans and maps their explorations need
come from here, so that no task module imports :mod:`slamlab.sim` (CONVENTIONS: the simulator
produces scans and grids, everything else consumes them).
"""

from __future__ import annotations

import numpy as np

from ..sim import Rangefinder, StereoArena, StereoSim, measurement_room_200, path_004, test_room_200

__all__ = ["hough_scene_scan", "localisation_scene", "stereo_rig"]


def localisation_scene(pose, *, range_std_cells: float = 0.3, rng=2010):
    """Lab 06: 004's stored test room and a 360-beam scan cast at ``pose`` in its measurement version.

    Parameters
    ----------
    pose : array_like, shape (3,)
        ``(x, y, theta)`` of the sensor in cells and radians.
    range_std_cells : float
        Standard deviation of the range noise, in cells.
    rng : Generator, int or None
        The scan's random stream.

    Returns
    -------
    tuple
        ``(room, scan)``: the test room's grid and the :class:`~slamlab.scans.Scan`.
    """
    rf = Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=range_std_cells, quantum_cells=0.1)
    return test_room_200(), rf.scan(measurement_room_200(), np.asarray(pose, dtype=float), rng=rng)


def hough_scene_scan(pose_index: int, *, range_std_cells: float = 0.1, rng=2010):
    """Lab 07: the scan at pose ``pose_index`` of 004's path in the test room (the chapter's scene).

    Parameters
    ----------
    pose_index : int
        Index of the pose on 004's path.
    range_std_cells : float
        Standard deviation of the range noise, in cells.
    rng : Generator, int or None
        The scan's random stream.

    Returns
    -------
    Scan
        The 360-beam scan.
    """
    rf = Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=range_std_cells)
    return rf.scan(test_room_200(), path_004()[pose_index], rng=rng)


def stereo_rig(*, arena_seed: int = 0, rng=2010):
    """Lab 05: the stereo rig of the simulated lunar arena (the chapter's camera pair).

    Parameters
    ----------
    arena_seed : int
        Seed of the arena's texture and layout.
    rng : Generator, int or None
        The simulator's random stream.

    Returns
    -------
    StereoRig
        The simulator's camera pair.
    """
    return StereoSim(StereoArena(seed=arena_seed), rng=rng).rig
