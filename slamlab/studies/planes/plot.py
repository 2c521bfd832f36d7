"""Plots of Ch. 10's study results (002): Fig. 2 (one, two, three plane pairs), Fig. 3 (the intensity image),
Fig. 4 (intensity weights), Fig. 8 (a flight's errors), Fig. 9 (a flight's plane map and paths)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...planes.plot import axes_3d, thin_points
from ...plotting import new_axes
from ...sim.planes_room import PlaneScanner, scanner_beam_directions

__all__ = ["plot_flight_errors", "plot_intensity_figure", "plot_intensity_image", "plot_pairs_figure",
           "plot_plane_map", "plot_room", "scanner_geometry_figure"]


def plot_pairs_figure(result):
    """002 Fig. 2: the predicted particles (grey) and the LM solutions for one, two, three pairs (colour).

    Parameters
    ----------
    result : PairsResult
        From :func:`~slamlab.studies.planes.run_pairs_figure`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig = plt.figure(figsize=(13, 4.2))
    for k in range(3):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        axes_3d(ax, title=f"{k + 1} pair{'s' if k else ''}: a {('plane', 'line', 'point')[k]}")
        ax.scatter(*result.before[k].T, s=2, c="0.7", label="predicted")
        ax.scatter(*result.after[k].T, s=4, c="tab:blue", label="solved")
        ax.scatter(*result.true_t, s=40, c="tab:red", marker="*", label="truth")
        if k == 0:
            ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_intensity_figure(result, *, ax=None):
    """002 Fig. 4: solved particles along the corridor (x) with their intensity weights, and the particles after
    resampling; the truth and the odometry's guess marked.

    Parameters
    ----------
    result : IntensityResult
        From :func:`~slamlab.studies.planes.run_intensity_figure`.
    ax : matplotlib.axes.Axes, optional
        Axes to draw into.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = new_axes(ax, figsize=(8, 4), title="002 Fig. 4: weights along the line of uncertainty (first cycle)",
                  xlabel="x along the corridor [m]", ylabel="weight × number of particles")
    P = len(result.weights)
    ax.scatter(result.solved[:, 0], result.weights * P, s=6, c="tab:blue", label="solved particles: weight")
    ax2 = ax.twinx()
    ax2.hist(result.resampled[:, 0], bins=30, color="tab:green", alpha=0.35, label="after resampling")
    ax2.set_ylabel("particles after resampling")
    ax.axvline(result.true_t[0], color="tab:red", label="truth")
    ax.axvline(np.mean(result.predicted[:, 0]), color="0.4", ls="--", label="odometry (prediction mean)")
    ax.legend(loc="upper left", fontsize=8)
    return ax


def plot_intensity_image(result):
    """002 Fig. 3: left, the intensities of the scan lines as an image (rows: lines, columns: beams); right, in
    place of 002's photo, the room model's reflectance panels seen along the same beams (ours).

    Pixels are drawn with the angles they span (a line's yaw step by a beam's step), so the room keeps its shape.

    Parameters
    ----------
    result : IntensityImage
        From :func:`~slamlab.studies.planes.scan_intensity_image`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 5.2), sharey=True)
    b, ln = result.beams, result.lines
    extent = (b[0] - 0.5, b[-1] + 0.5, ln[-1] + 0.5, ln[0] - 0.5)
    aspect = result.deg_per_line / result.step_deg if np.isfinite(result.deg_per_line) else "auto"
    im = a1.imshow(result.image, cmap="gray", extent=extent, aspect=aspect, interpolation="nearest")
    fig.colorbar(im, ax=a1, shrink=0.8, label="intensity")
    a1.set_title("002 Fig. 3 left: intensities of the scan lines\n(simulated scanner)")
    a1.set_ylabel(f"scan line ({result.deg_per_line:.3g}° of yaw each)")
    im = a2.imshow(result.render, cmap="gray", extent=extent, aspect=aspect, interpolation="nearest",
                   vmin=0.0, vmax=1.0)
    fig.colorbar(im, ax=a2, shrink=0.8, label="reflectance ρ")
    a2.set_title("ours, in place of 002's photo: the room model's\npanels seen from one point along the same beams")
    for ax in (a1, a2):
        ax.grid(False)
        ax.set_xlabel(f"beam index ({result.beam_deg[0]:.0f}°..{result.beam_deg[-1]:.0f}° from up; 90°: forward)")
    fig.tight_layout()
    return fig


def plot_flight_errors(result):
    """002 Fig. 8: x, y, z [m] and roll, pitch, yaw [deg] errors against time, SLAM and odometry.

    Parameters
    ----------
    result : FlightResult
        From :func:`~slamlab.studies.planes.run_flight`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axs = plt.subplots(2, 3, figsize=(12, 5.5), sharex=True)
    names = ("x [m]", "y [m]", "z [m]", "roll [deg]", "pitch [deg]", "yaw [deg]")
    for i, ax in enumerate(axs.ravel()):
        ax.plot(result.times_s, result.errors[:, i], color="tab:blue", label="SLAM")
        ax.plot(result.times_s, result.errors_odo[:, i], color="0.5", ls="--", label="odometry")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_title(names[i])
        if i >= 3:
            ax.set_xlabel("time [s]")
    axs[0, 0].legend(fontsize=8)
    fig.tight_layout()
    return fig


def plot_plane_map(result, *, ax=None, max_cells: int = 20000):
    """002 Fig. 9: the plane map (cell centres coloured by mean intensity) with the true and estimated paths.

    Parameters
    ----------
    result : FlightResult
        From :func:`~slamlab.studies.planes.run_flight`.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        3-D axes to draw into.
    max_cells : int
        At most this many cells, a fixed random subset.

    Returns
    -------
    mpl_toolkits.mplot3d.Axes3D
    """
    ax = axes_3d(ax, figsize=(8, 6), title=f"plane map: {len(result.map)} planes")
    c = np.concatenate([pl.cell_centres() for pl in result.map.planes])
    I = np.concatenate([pl.mean_intensity for pl in result.map.planes])
    k = thin_points(len(c), max_cells)
    ax.scatter(*c[k].T, c=I[k], s=1, cmap="gray")
    ax.plot(*result.poses_true[:, :3, 3].T, color="tab:red", label="truth")
    ax.plot(*result.poses_est[:, :3, 3].T, color="tab:blue", label="SLAM")
    ax.legend(fontsize=8)
    return ax


def scanner_geometry_figure(scanner: PlaneScanner | None = None, *, yaw_rate_deg_s: float = 45.0,
                            frame_s: float = 1.0):
    """Left: the vertical 270° fan in the body x-z plane (gap down). Right: seen from above, the fan's trace
    swept by the yaw over one frame: two sectors of ``yaw_rate · frame_s`` degrees, 180° apart (002 Fig. 5).

    Parameters
    ----------
    scanner : slamlab.sim.PlaneScanner, optional
        The scanner (defaults when None).
    yaw_rate_deg_s : float
        Yaw rate in degrees per second.
    frame_s : float
        Frame length in seconds.

    Returns
    -------
    matplotlib.figure.Figure
    """
    s = PlaneScanner.resolve(scanner)
    d = scanner_beam_directions(s)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4.5))
    for k in range(0, len(d), 20):
        a1.plot([0, d[k, 0]], [0, d[k, 2]], color="tab:orange", lw=0.6)
    a1.plot(0, 0, "ks")
    a1.set_aspect("equal")
    a1.set_title(f"scan plane (body x-z): {s.fov_deg:.0f}°, {s.step_deg}° steps, {s.n_beams} beams")
    a1.set_xlabel("body x [m]")
    a1.set_ylabel("body z [m]")
    sweep = np.deg2rad(yaw_rate_deg_s * frame_s)
    for base, lab in ((0.0, "front sector"), (np.pi, "back sector")):
        a = base + np.linspace(0, sweep, 30)
        a2.fill(np.r_[0, np.cos(a), 0], np.r_[0, np.sin(a), 0], alpha=0.4, label=lab)
    a2.plot(0, 0, "ks")
    a2.set_xlim(-1.2, 1.2)
    a2.set_ylim(-1.2, 1.2)
    a2.set_aspect("equal")
    a2.legend(loc="lower right")
    a2.set_title(f"from above: {yaw_rate_deg_s:.0f}°/s × {frame_s:g} s of lines = one frame")
    a2.set_xlabel("x [m]")
    a2.set_ylabel("y [m]")
    fig.tight_layout()
    return fig


def plot_room(room, *, ax=None, path=None, hide=("room z+",)):
    """002 Fig. 7: the model of the room — every bounded plane drawn with its reflectance panels (grey levels);
    ``path (N, 3)`` optional, e.g. a flight's true positions; ``hide`` names of planes left out (the ceiling, so
    that the inside shows).

    Parameters
    ----------
    room : slamlab.sim.PlaneRoom
        The room.
    ax : mpl_toolkits.mplot3d.Axes3D, optional
        3-D axes to draw into.
    path : (N, 3) float, optional
        A path to draw, metres.
    hide : tuple of str
        Names of planes left out.

    Returns
    -------
    mpl_toolkits.mplot3d.Axes3D
    """
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax = axes_3d(ax, figsize=(8, 6), title=f"the room: {len(room)} planes, {room.panel_m} m reflectance panels")
    polys, shades = [], []
    for i in range(len(room)):
        if room.names[i] in hide:
            continue
        nu = int(np.ceil(2 * room.half_u[i] / room.panel_m - 1e-9))
        nv = int(np.ceil(2 * room.half_v[i] / room.panel_m - 1e-9))
        corner = room.centres[i] - room.half_u[i] * room.axes_u[i] - room.half_v[i] * room.axes_v[i]
        su = np.minimum(np.arange(nu + 1) * room.panel_m, 2 * room.half_u[i])
        sv = np.minimum(np.arange(nv + 1) * room.panel_m, 2 * room.half_v[i])
        for a in range(nu):
            for b in range(nv):   # a few hundred panels in all: drawing, not a hot path
                q = [corner + su[x] * room.axes_u[i] + sv[y] * room.axes_v[i]
                     for x, y in ((a, b), (a + 1, b), (a + 1, b + 1), (a, b + 1))]
                polys.append(q)
                shades.append(room.panels[i, a, b])
    coll = Poly3DCollection(polys, facecolors=plt.cm.gray(np.asarray(shades)), edgecolors="none", alpha=0.55)
    ax.add_collection3d(coll)
    lo = (room.centres - np.abs(room.axes_u) * room.half_u[:, None] - np.abs(room.axes_v) * room.half_v[:, None]).min(0)
    hi = (room.centres + np.abs(room.axes_u) * room.half_u[:, None] + np.abs(room.axes_v) * room.half_v[:, None]).max(0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(np.maximum(hi - lo, 1e-9)))
    if path is not None:
        ax.plot(*np.asarray(path, dtype=float).T, color="tab:red", label="flight path")
        ax.legend(fontsize=8)
    return ax
