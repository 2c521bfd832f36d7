"""Ch. 10's studies, plane-based 3-D SLAM (002): the flight, Figs. 2, 3 and 4, the map's storage against the raw
clouds, the ablations, tables, plots, widgets."""

from ..._lazy import lazy_exports
from .ablations import (
    PAIR_VARIANTS,
    FlightComparison,
    IncidenceResult,
    map_normal_error_deg,
    run_frame_source_ablation,
    run_incidence_ablation,
    run_pairs_ablation,
)
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
    scan_intensity_image,
    setup_table,
    three_plane_room,
    timing_goal,
    timing_table,
)
from .figures import (
    FIG4_PARAMS,
    IntensityResult,
    IntensitySpread,
    IntensityStudy,
    PairsResult,
    run_intensity_figure,
    run_intensity_spread,
    run_intensity_study,
    run_pairs_figure,
)
from .intensity_image import IntensityImage
from .storage import StorageResult, flight_storage, map_storage

_PLOT = ("plot_flight_errors", "plot_intensity_figure", "plot_intensity_image", "plot_pairs_figure", "plot_plane_map",
         "plot_room", "scanner_geometry_figure")
_WIDGETS = ("explore_flight", "explore_intensity_figure")
# plots (pyplot) and widgets (ipywidgets) load on first use: `import slamlab.studies.planes` stays light
__getattr__, __dir__ = lazy_exports(__name__, {**dict.fromkeys(_PLOT, ".plot"), **dict.fromkeys(_WIDGETS, ".widgets")})

__all__ = [
    "FIG4_PARAMS",
    "GOAL_S",
    "PAIR_VARIANTS",
    "POSE_SOURCES",
    "SOURCE_TIMES_S",
    "FlightComparison",
    "FlightResult",
    "IncidenceResult",
    "IntensityImage",
    "IntensityResult",
    "IntensitySpread",
    "IntensityStudy",
    "PairsResult",
    "StorageResult",
    "euler_errors",
    "flight_frames",
    "flight_head",
    "flight_storage",
    "in_frame_rotation_error_deg",
    "map_normal_error_deg",
    "map_storage",
    "ours_vs_source",
    "plot_room",
    "run_flight",
    "run_frame_source_ablation",
    "run_incidence_ablation",
    "run_intensity_figure",
    "run_intensity_spread",
    "run_intensity_study",
    "run_pairs_ablation",
    "run_pairs_figure",
    "scan_intensity_image",
    "scanner_geometry_figure",
    "setup_table",
    "three_plane_room",
    "timing_goal",
    "timing_table",
]
__all__ += list(_PLOT + _WIDGETS)  # loaded on first use
