"""What a :class:`~slamlab.stereo.slam.StereoSLAM` run reports, per frame and in total (000 §3.1: trajectory, counts, timings)."""

from __future__ import annotations

import numpy as np

from ..geometry.se3 import planar_from_se3
from ._frame import STAGES

__all__ = ["RunResults"]


class RunResults:
    """The results of a run (the base of :class:`~slamlab.stereo.slam.StereoSLAM`): trajectory, counts, stage times.

    Reads the run's state, which :class:`~slamlab.stereo.slam.StereoSLAM` fills frame by frame.

    Attributes
    ----------
    poses : list of ndarray, shape (4, 4)
        Estimated body poses in the map frame, one per processed frame.
    records : list of FrameRecord
        One record per processed frame (matches, inliers, status).
    times, cpu_times : list of dict
        Wall-clock and CPU seconds per stage, one dict per frame.
    """

    @property
    def trajectory(self) -> np.ndarray:
        """(N, 4, 4) estimated body poses in the map frame, one per processed frame."""
        return np.array(self.poses) if self.poses else np.empty((0, 4, 4))

    @property
    def planar_trajectory(self) -> np.ndarray:
        """(N, 3) ``(x_m, y_m, yaw_rad)`` with the yaw unwrapped."""
        if not self.poses:
            return np.empty((0, 3))
        p = np.array([planar_from_se3(T) for T in self.poses])
        p[:, 2] = np.unwrap(p[:, 2])
        return p

    def counts(self) -> dict:
        """Per-frame counts as arrays: points, matches, inliers, landmarks.

        Returns
        -------
        dict
            Count name -> numpy.ndarray over the frames.
        """
        keys = [k for k in self.records[0] if k not in ("status", "trail")] if self.records else []
        return {k: np.array([r[k] for r in self.records]) for k in keys}

    def stage_times(self, cpu: bool = False) -> dict:
        """Per-frame time of each stage in seconds, as arrays: wall clock, or with ``cpu`` the process's
        CPU time (all its threads: detection runs the two images in two threads).

        Parameters
        ----------
        cpu : bool, default False
            CPU time of the process instead of wall clock.

        Returns
        -------
        dict
            Stage name -> per-frame times [s].
        """
        times = self.cpu_times if cpu else self.times
        return {s: np.array([t[s] for t in times]) for s in STAGES}

    @property
    def degenerate_frames(self) -> np.ndarray:
        """Indices of frames that kept the last pose (too few points / matches, RANSAC failure, ill-conditioned pose)."""
        return np.array([r["frame"] for r in self.records if r["status"] not in ("ok", "init")], dtype=np.int64)
