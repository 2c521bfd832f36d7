"""How well a built map matches a reference grid (004 §Hough SLAM, Fig. 11; our measure).

"Using the displacement data it is easy to re-project the rangefinder data and build
the map" (004). The map itself is built by the one occupancy builder of the 2-D
layer, :func:`slamlab.scans.occupancy_grid`; this module scores it.
"""

from __future__ import annotations

from .._validate import as_image, check_int
from ..scans import FREE, OBSTACLE, OccupancyGrid

__all__ = ["map_agreement"]


def map_agreement(built: OccupancyGrid, reference, *, tolerance_cells: int = 1) -> dict[str, float]:
    """How well a built map matches a reference grid of the same size and origin (our measure).

    ``precision``: share of built obstacle cells within ``tolerance_cells`` of a reference
    obstacle; ``recall``: share of reference obstacle cells that the built map saw (within
    the tolerance), counted over reference obstacles next to built free space.

    Parameters
    ----------
    built : OccupancyGrid
        The built map.
    reference : array_like of int, shape (H, W)
        Reference cell codes, same size and origin.
    tolerance_cells : int, default 1
        Distance within which an obstacle counts as matched [cells].

    Returns
    -------
    dict
        ``{"precision": float, "recall": float}``.

    Examples
    --------
    >>> import numpy as np
    >>> ref = np.zeros((5, 5), np.int8); ref[:, 4] = 1
    >>> b = OccupancyGrid(ref.copy(), ref.astype(int), np.zeros((5, 5), int))
    >>> map_agreement(b, ref)["precision"]
    1.0
    """
    from scipy import ndimage

    if not isinstance(built, OccupancyGrid):
        raise TypeError(f"`built` must be an OccupancyGrid; got {type(built).__name__}")
    ref = as_image(reference, "reference")
    if ref.shape != built.grid.shape:
        raise ValueError(f"`reference` must have the built map's shape {built.grid.shape}; got {ref.shape}")
    tol = check_int(tolerance_cells, "tolerance_cells", minimum=0)
    size = 2 * tol + 1
    ref_obs = ref == OBSTACLE
    b_obs = built.grid == OBSTACLE
    near_ref = ndimage.maximum_filter(ref_obs, size=size) if tol else ref_obs
    near_b = ndimage.maximum_filter(b_obs, size=size) if tol else b_obs
    seen = ndimage.maximum_filter(built.grid == FREE, size=3) & ref_obs
    precision = float((b_obs & near_ref).sum() / max(1, b_obs.sum()))
    recall = float((seen & near_b).sum() / max(1, seen.sum()))
    return {"precision": precision, "recall": recall}
