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

# --- the 2-D layer lives in slamlab.scans; sim re-exports its grid codes and Scan for convenience ---
from ..scans import Scan

__all__ += ["Scan"]

# --- occupancy grids, scanning rangefinder, odometry and paths (004; Ch. 5-6) ---
from .grid import (
    FREE,
    OBSTACLE,
    TEST_ROOM_CLUTTER,
    UNEXPLORED,
    add_clutter,
    build_test_room_200,
    cell_to_world,
    check_grid,
    free_cells,
    grid_from_text,
    grid_to_text,
    grid_to_values,
    make_grid,
    measurement_room_200,
    test_room_200,
    world_to_cell,
)
from .paths import PATH_004_SEGMENTS, PATH_004_START, path_004, piecewise_path, random_free_poses
from .rangefinder import (
    Odometry,
    Rangefinder,
    beam_angles,
    cast_rays,
    simulate_odometry,
    simulate_scans,
)

__all__ += [
    "FREE",
    "OBSTACLE",
    "PATH_004_SEGMENTS",
    "PATH_004_START",
    "TEST_ROOM_CLUTTER",
    "UNEXPLORED",
    "Odometry",
    "Rangefinder",
    "Scan",
    "add_clutter",
    "beam_angles",
    "build_test_room_200",
    "cast_rays",
    "cell_to_world",
    "check_grid",
    "free_cells",
    "grid_from_text",
    "grid_to_text",
    "grid_to_values",
    "make_grid",
    "measurement_room_200",
    "path_004",
    "piecewise_path",
    "random_free_poses",
    "simulate_odometry",
    "simulate_scans",
    "test_room_200",
    "world_to_cell",
]

# --- stereo arena, procedural lunar textures, stereo trajectories (000 §3.2, §3.7; Ch. 4) ---
from .arena import R_BODY_CAM, StereoArena, StereoSim
from .highway import HighwayScene, highway_path
from .stereo_paths import (
    LONG_PATH_WAYPOINTS,
    LOOP_WAYPOINTS,
    long_path,
    rectangular_loop,
    turn_in_place,
    waypoint_path,
)
from .textures import crater_heightfield, fractal_noise, lunar_texture

__all__ += [
    "LONG_PATH_WAYPOINTS",
    "LOOP_WAYPOINTS",
    "R_BODY_CAM",
    "HighwayScene",
    "StereoArena",
    "StereoSim",
    "crater_heightfield",
    "fractal_noise",
    "highway_path",
    "long_path",
    "lunar_texture",
    "rectangular_loop",
    "turn_in_place",
    "waypoint_path",
]

# --- a room of planes, a vertical line scanner on a yawing quadcopter, inertial odometry (002; Ch. 10) ---
from .planes_room import (
    Flight,
    PlaneRoom,
    PlaneScanner,
    build_corridor,
    build_plane_room,
    cast_rays_planes,
    quad_flight,
    scanner_beam_directions,
    simulate_flight,
    simulate_odometry_3d,
)

__all__ += [
    "Flight",
    "PlaneRoom",
    "PlaneScanner",
    "build_corridor",
    "build_plane_room",
    "cast_rays_planes",
    "quad_flight",
    "scanner_beam_directions",
    "simulate_flight",
    "simulate_odometry_3d",
]
