"""Plane-based 3-D particle-filter SLAM from a yawing line scanner (002; Ch. 10).

Its own package, not ``slamlab.localisation`` (where CONVENTIONS first placed 002): it is a
3-D system with its own types — frames of 40 000 points, planes ``Π = {n, p, T, A}`` with
cell grids, particles in SE(3), a plane database — and shares nothing with the 2-D
grid localisation of Ch. 8 except the idea of a particle filter.
"""

from .._lazy import lazy_exports
from .ablations import (
    PAIR_VARIANTS,
    FlightComparison,
    IncidenceResult,
    map_normal_error_deg,
    run_frame_source_ablation,
    run_incidence_ablation,
    run_pairs_ablation,
)
from .description import Plane, cell_keys, describe_plane, lookup_mean_intensity, plane_frame
from .experiments import (
    GOAL_S,
    POSE_SOURCES,
    SOURCE_TIMES_S,
    FlightResult,
    euler_errors,
    flight_frames,
    flight_head,
    in_frame_rotation_error_deg,
    ours_vs_source,
    run_flight,
    setup_table,
    three_plane_room,
    timing_goal,
    timing_table,
)
from .extraction import Frame, build_frame, extract_planes, fit_plane_lsq, frame_transforms, plane_distances
from .figures import (
    IntensityResult,
    IntensitySpread,
    IntensityStudy,
    PairsResult,
    run_intensity_figure,
    run_intensity_spread,
    run_intensity_study,
    run_pairs_figure,
)
from .filter import (
    STAGES,
    CycleReport,
    PlaneSLAM,
    PlaneSLAMParams,
    intensity_weights,
    mean_pose,
    pair_planes,
    predict_particles,
    systematic_resample,
)
from .mapping import PlaneMap, VoxelStore, merge_planes, planes_touch
from .transform import (
    LMResult,
    lm_pose,
    plane_pair_jacobian,
    plane_pair_residuals,
    planes_to_body,
    planes_to_map,
)

_PLOT = (
    "plot_flight_errors",
    "plot_plane_description",
    "plot_room",
    "plot_frame_planes",
    "plot_frame_points",
    "plot_intensity_figure",
    "plot_pairs_figure",
    "plot_plane_map",
    "scanner_geometry_figure",
)
_WIDGETS = ("explore_flight", "explore_intensity_figure")
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ = [
    "GOAL_S",
    "PAIR_VARIANTS",
    "POSE_SOURCES",
    "SOURCE_TIMES_S",
    "STAGES",
    "CycleReport",
    "FlightComparison",
    "FlightResult",
    "Frame",
    "IncidenceResult",
    "IntensityResult",
    "IntensitySpread",
    "IntensityStudy",
    "LMResult",
    "PairsResult",
    "Plane",
    "PlaneMap",
    "PlaneSLAM",
    "PlaneSLAMParams",
    "VoxelStore",
    "build_frame",
    "cell_keys",
    "describe_plane",
    "euler_errors",
    "extract_planes",
    "fit_plane_lsq",
    "flight_frames",
    "flight_head",
    "frame_transforms",
    "in_frame_rotation_error_deg",
    "intensity_weights",
    "lm_pose",
    "lookup_mean_intensity",
    "map_normal_error_deg",
    "mean_pose",
    "merge_planes",
    "ours_vs_source",
    "pair_planes",
    "plane_distances",
    "plane_frame",
    "plane_pair_jacobian",
    "plane_pair_residuals",
    "planes_to_body",
    "planes_to_map",
    "planes_touch",
    "predict_particles",
    "run_flight",
    "run_frame_source_ablation",
    "run_incidence_ablation",
    "run_intensity_figure",
    "run_intensity_spread",
    "run_intensity_study",
    "run_pairs_ablation",
    "run_pairs_figure",
    "setup_table",
    "systematic_resample",
    "three_plane_room",
    "timing_goal",
    "timing_table",
]
__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
