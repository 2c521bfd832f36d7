"""Plane-based 3-D particle-filter SLAM from a yawing line scanner (002; Ch. 10).

Its own package, not part of ``slamlab.localisation``: it is a
3-D system with its own types — frames of 40 000 points, planes ``Π = {n, p, T, A}`` with
cell grids, particles in SE(3), a plane database — and shares nothing with the 2-D
grid localisation of Ch. 8 except the idea of a particle filter. The chapter's flights,
figure reproductions and ablations are in :mod:`slamlab.studies.planes`.
"""

from .._lazy import lazy_exports
from .description import Plane, cell_keys, describe_plane, lookup_mean_intensity, plane_frame
from .extraction import Frame, build_frame, extract_planes, fit_plane_lsq, frame_transforms, plane_distances
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
    "plot_plane_description",
    "plot_frame_planes",
    "plot_frame_points",
)
# the plots (pyplot) load on first use: `import slamlab.planes` stays light
__getattr__, __dir__ = lazy_exports(__name__, dict.fromkeys(_PLOT, ".plot"))

__all__ = [
    "STAGES",
    "CycleReport",
    "Frame",
    "LMResult",
    "Plane",
    "PlaneMap",
    "PlaneSLAM",
    "PlaneSLAMParams",
    "VoxelStore",
    "build_frame",
    "cell_keys",
    "describe_plane",
    "extract_planes",
    "fit_plane_lsq",
    "frame_transforms",
    "intensity_weights",
    "lm_pose",
    "lookup_mean_intensity",
    "mean_pose",
    "merge_planes",
    "pair_planes",
    "plane_distances",
    "plane_frame",
    "plane_pair_jacobian",
    "plane_pair_residuals",
    "planes_to_body",
    "planes_to_map",
    "planes_touch",
    "predict_particles",
    "systematic_resample",
]
__all__ += list(_PLOT)  # loaded on first use
