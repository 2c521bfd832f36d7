"""The simulated scenes of the labs' exploration tasks (the lab's experiments: the one lab module that runs the simulator).

Task modules (``tasks_*.py``) check a student's work; the scans and maps their explorations need
come from here, so that no task module imports :mod:`slamlab.sim` (CONVENTIONS: the simulator
produces scans and grids, everything else consumes them).
"""

from __future__ import annotations

import numpy as np

from slamlab.sim import (
    Rangefinder,
    StereoArena,
    StereoSim,
    add_clutter,
    free_cells,
    measurement_room_200,
    path_004,
    random_free_poses,
    simulate_scans,
    test_room_200,
)

__all__ = ["hough_run_scans", "hough_scene_scan", "localisation_scene", "monte_carlo_scene", "stereo_rig"]


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


def hough_run_scans(n_poses: int = 121, *, range_std_cells: float = 0.1, rng=2010) -> list:
    """Lab 07: the scans of :func:`slamlab.studies.hough.run_sim_slam` (the room without clutter), drawn as it draws them.

    The run spawns two streams from ``SeedSequence(rng)``: the first casts the scans along 004's
    path (the second is the odometry's); these are the same scans, so an independent line count
    can be set beside the run's lost steps.

    Parameters
    ----------
    n_poses : int
        Poses along 004's path.
    range_std_cells : float
        Standard deviation of the range noise, in cells.
    rng : int
        The run's seed.

    Returns
    -------
    list of Scan
        One 360-beam scan per pose.
    """
    seeds = np.random.SeedSequence(rng).spawn(2)
    rf = Rangefinder(n_beams=360, max_range_cells=100.0, range_std_cells=range_std_cells, quantum_cells=0.1)
    return simulate_scans(test_room_200(), path_004(n_poses), rf, rng=np.random.default_rng(seeds[0]))


def monte_carlo_scene(n_poses: int = 12, *, range_std_cells: float = 2.0, extra_clutter: int = 120, rng=2010):
    """Lab 06: the map, poses and scans of :func:`slamlab.studies.correlation.run_monte_carlo`, drawn as it draws them.

    From one stream, in the run's order: ``extra_clutter`` discs of radius 1.5 cells on free cells
    (3 cells from obstacles) added to the measurement room, ``n_poses`` free whole-cell poses with
    uniform headings, then one 360-beam scan per pose (0.1-cell quantum).

    Parameters
    ----------
    n_poses : int
        Random poses.
    range_std_cells : float
        Standard deviation of the range noise, in cells.
    extra_clutter : int
        Unmapped discs added.
    rng : int
        The run's seed.

    Returns
    -------
    tuple
        ``(room, poses, scans)``: the mapped room's grid, the ``(n, 3)`` true poses and the scans.
    """
    rng = np.random.default_rng(rng)
    world = measurement_room_200()
    if extra_clutter:
        cells = free_cells(world, 3)
        pick = cells[rng.integers(0, cells.shape[0], extra_clutter)]
        world = add_clutter(world, [("disc", int(c), int(r), 1.5) for r, c in pick])
    poses = random_free_poses(world, n_poses, margin_cells=2, rng=rng)
    rf = Rangefinder(n_beams=360, fov_rad=2 * np.pi, max_range_cells=100.0, range_std_cells=range_std_cells,
                     quantum_cells=0.1)
    return test_room_200(), poses, [rf.scan(world, pose, rng) for pose in poses]


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
    return StereoSim(StereoArena(texture_seed=arena_seed), rng=rng).rig
