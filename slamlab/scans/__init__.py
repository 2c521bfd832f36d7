"""The 2-D layer: one Scan type, scan → points, occupancy grids, a map from a log, the likelihood field and the
grid ray caster (004 §7).

Produced alike by the simulator (:mod:`slamlab.sim`) and the log readers
(:mod:`slamlab.io`); used by correlation localisation, Hough SLAM and
localisation. Nothing here imports :mod:`slamlab.sim`.
"""

from .grid import (
    FREE,
    OBSTACLE,
    UNEXPLORED,
    GridFrame,
    cell_to_world,
    check_grid,
    grid_to_values,
    make_grid,
    world_to_cell,
)
from .logmap import leave_out_grid, log_counts, log_grid, map_coverage
from .occupancy import RULES, OccupancyGrid, free_space_samples, likelihood_field, occupancy_grid
from .raycast import cast_rays
from .scan import UNITS, Scan, scan_to_points

__all__ = [
    "FREE",
    "OBSTACLE",
    "RULES",
    "UNEXPLORED",
    "UNITS",
    "GridFrame",
    "OccupancyGrid",
    "Scan",
    "cast_rays",
    "cell_to_world",
    "check_grid",
    "free_space_samples",
    "grid_to_values",
    "leave_out_grid",
    "likelihood_field",
    "log_counts",
    "log_grid",
    "make_grid",
    "map_coverage",
    "occupancy_grid",
    "scan_to_points",
    "world_to_cell",
]
