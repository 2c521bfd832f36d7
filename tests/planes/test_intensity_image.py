"""002 Fig. 3: the intensity image of the scan lines and the model's rendering beside it (ours: the rendering)."""

import matplotlib.pyplot as plt
import numpy as np
import pytest

from slamlab.sim import PlaneScanner, simulate_flight
from slamlab.sim.planes_room import scanner_beam_directions
from slamlab.studies.planes import plot_intensity_image, scan_intensity_image


@pytest.fixture(scope="module")
def hover():
    """A noise-free scanner on a vehicle that only turns: every line's scanner stands where the rendering's does."""
    sc = PlaneScanner(sigma_intensity=0.0, sigma_range_m=0.0)
    wp = [[5.0, 3.0, 1.5], [6.0, 3.0, 1.5]]
    return simulate_flight(2.0, scanner=sc, speed_m_s=0.0, waypoints_m=wp, odometry_noise=0.0, rng=3)


def test_image_is_the_lines_intensities(hover):
    r = scan_intensity_image(hover, start_s=0.5, duration_s=1.0, angles_deg=(45.0, 135.0))
    assert r.image.shape == r.render.shape == (40, 361)          # 1 s at 40 lines/s; 90 deg / 0.25 deg + 1 beams
    assert (r.lines[0], r.lines[-1]) == (20, 59)
    assert (r.beam_deg[0], r.beam_deg[-1]) == pytest.approx((45.0, 135.0))
    np.testing.assert_array_equal(r.image, hover.intensities[20:60][:, r.beams])
    assert r.deg_per_line == pytest.approx(45.0 / 40, rel=1e-6)   # 45 deg/s at 40 lines/s
    assert "40 scan lines x 361 beams" in str(r)


def test_rendering_times_the_incidence_factor_is_the_image(hover):
    # noise-free: I = I0 * rho * |cos theta|, with cos theta computed here from the room's normal of the plane the
    # simulator says each beam hit; exact on the middle line (the rendering's viewpoint is its scanner), and
    # wherever the hover's millimetre sway leaves the beam on the same panel
    r = scan_intensity_image(hover, start_s=0.5, duration_s=1.0)
    origins = hover.poses[r.lines, :3, :3] @ np.asarray(hover.scanner.mount_m) + hover.poses[r.lines, :3, 3]
    np.testing.assert_allclose(origins[len(r.lines) // 2], r.origin_m, atol=1e-12)
    assert np.ptp(origins, axis=0).max() < 0.005
    d = np.einsum("nij,bj->nbi", hover.poses[r.lines, :3, :3], scanner_beam_directions(hover.scanner)[r.beams])
    k = hover.plane_ids[np.ix_(r.lines, r.beams)]
    assert (k >= 0).all()
    cos = np.abs(np.einsum("nbi,nbi->nb", d, hover.room.normals[k]))
    model = np.maximum(r.gain * r.render * cos, 0.0)
    mid = len(r.lines) // 2
    np.testing.assert_allclose(r.image[mid], model[mid], rtol=1e-9, atol=1e-9)
    assert np.mean(np.isclose(r.image, model, rtol=1e-6)) > 0.98
    names = np.array(r.planes)[r.render_plane]
    np.testing.assert_array_equal(names[mid], np.array(hover.room.names)[k[mid]])
    assert r.correlation() > 0.3
    # the medians of I / (I0 rho) per plane: those of |cos theta| (the few shifted pixels do not move a median far)
    med = [np.median(cos[r.render_plane == j]) for j in range(len(r.planes))]
    np.testing.assert_allclose(r.attenuation(), med, atol=0.02)
    assert np.all(r.attenuation() <= 1.0 + 1e-9)
    assert "median I / (I0 rho)" in str(r)


def test_bad_arguments(hover):
    with pytest.raises(TypeError, match="flight"):
        scan_intensity_image(np.zeros(3))
    with pytest.raises(ValueError, match="start_s"):
        scan_intensity_image(hover, start_s=1.5, duration_s=1.0)
    with pytest.raises(ValueError, match="duration_s"):
        scan_intensity_image(hover, duration_s=-1.0)
    with pytest.raises(ValueError, match="angles_deg"):
        scan_intensity_image(hover, start_s=0.0, angles_deg=(100.0, 50.0))
    with pytest.raises(ValueError, match="angles_deg"):
        scan_intensity_image(hover, start_s=0.0, angles_deg=(140.0, 150.0))


def test_plot_draws_both_images(hover):
    fig = plot_intensity_image(scan_intensity_image(hover, start_s=0.0, duration_s=0.5))
    assert sum(len(ax.images) for ax in fig.axes) == 2
    plt.close(fig)
