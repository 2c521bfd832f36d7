"""Correlation localisation on a known map from a scanning rangefinder (004 §7; Ch. 5)."""

from .._lazy import lazy_exports
from .algorithm import (
    Localisation,
    LocaliseParams,
    check_constants,
    heading_candidates,
    heading_error,
    localise,
    localise_joined,
    scan_stamps,
    score_maps,
)

_PLOT = (
    "localisation_figure",
    "plot_grid",
    "plot_grids",
    "plot_heading_profile",
    "plot_localisation",
    "plot_score_map",
    "plot_stamp",
    "plot_stamps",
)
__getattr__, __dir__ = lazy_exports(__name__, dict.fromkeys(_PLOT, ".plot"))

__all__ = [
    "Localisation",
    "LocaliseParams",
    "check_constants",
    "heading_candidates",
    "heading_error",
    "localise",
    "localise_joined",
    "scan_stamps",
    "score_maps",
]
__all__ += list(_PLOT)  # loaded on first use
