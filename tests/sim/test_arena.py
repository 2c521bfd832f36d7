"""The stereo arena renderer, textures and trajectories (000 §3.2, §3.7)."""

import numpy as np
import pytest

from slamlab.geometry import PinholeCamera, StereoRig, se3_from_planar, wrap_angle
from slamlab.sim import textures
from slamlab.sim.arena import R_BODY_CAM, StereoArena, StereoSim
from slamlab.sim.stereo_paths import long_path, rectangular_loop, turn_in_place, waypoint_path
from slamlab.sim.textures import crater_heightfield, fractal_noise, lunar_texture


@pytest.fixture(scope="module")
def arena():
    return StereoArena(texture_seed=3)


@pytest.fixture(scope="module")
def sim(arena):
    return StereoSim(arena, rng=0)


def test_cast_points_project_back_to_their_pixels(arena, sim):
    cam = sim.rig.left
    T = se3_from_planar(2.0, 3.0, 0.7) @ sim.T_body_left
    surface, t, pts = arena.cast(cam, T)
    hit = surface > 0
    rows, cols = np.nonzero(hit)
    sel = np.random.default_rng(0).choice(rows.size, 2000, replace=False)
    P = pts[rows[sel], cols[sel]]
    Pc = (P - T[:3, 3]) @ T[:3, :3]  # world -> camera
    uv = cam.project(Pc)
    np.testing.assert_allclose(uv, np.column_stack([cols[sel], rows[sel]]), atol=1e-3)
    np.testing.assert_allclose(Pc[:, 2], t[rows[sel], cols[sel]], rtol=1e-5)


def test_hits_lie_on_the_planes(arena, sim):
    T = se3_from_planar(1.0, 1.5, 0.2) @ sim.T_body_left
    surface, _, pts = arena.cast(sim.rig.left, T)
    floor = pts[surface == 1]
    wall = pts[surface == 2]
    assert np.abs(floor[:, 2]).max() < 1e-4
    assert np.all(arena.contains(floor[:, :2]) | (np.abs(floor[:, 0]) < 1e-4))
    d_wall = np.minimum.reduce([wall[:, 0], arena.width_m - wall[:, 0], wall[:, 1], arena.length_m - wall[:, 1]])
    assert np.abs(d_wall).max() < 1e-4
    assert wall[:, 2].min() >= -1e-6
    assert wall[:, 2].max() <= arena.fence_height_m + 1e-6
    assert np.all(np.isnan(pts[surface == 0]))


def test_horizon_row_sees_the_fence_at_the_known_distance(arena, sim):
    # facing +x from x = 1 m: the optical axis hits the x = W fence at distance W - 1
    T = se3_from_planar(1.0, 4.0, 0.0) @ sim.T_body_left
    surface, t, _ = arena.cast(sim.rig.left, T)
    cam = sim.rig.left
    r, c = round(cam.cy), round(cam.cx)
    assert surface[r, c] == 2
    assert t[r, c] == pytest.approx(arena.width_m - 1.0, rel=1e-4)
    # the floor-fence edge lies at angle atan(h / d) below the axis: v = cy + f h / d
    v_edge = cam.cy + cam.fy * sim.camera_height_m / (arena.width_m - 1.0)
    col = surface[:, c]
    first_floor = np.argmax(col == 1)
    assert abs(first_floor - v_edge) <= 1.0


def test_left_and_right_images_agree_at_corresponding_points(arena):
    sim = StereoSim(arena, rng=1)
    pose = [3.0, 4.0, 1.0]
    left, right = sim.render_pair(pose)
    T = se3_from_planar(*pose) @ sim.T_body_left
    surface, _, pts = arena.cast(sim.rig.left, T)
    rows, cols = np.nonzero(surface == 2)
    sel = np.random.default_rng(0).choice(rows.size, 3000, replace=False)
    Pc = (pts[rows[sel], cols[sel]] - T[:3, 3]) @ T[:3, :3]
    _, uvr = sim.rig.project(Pc)
    inside = (uvr[:, 0] > 1) & (uvr[:, 0] < 766)
    ur = np.rint(uvr[inside]).astype(int)
    a = left[rows[sel][inside], cols[sel][inside]].astype(float)
    b = right[ur[:, 1], ur[:, 0]].astype(float)
    # the texture is view-independent: same brightness up to sub-pixel resampling
    assert np.median(np.abs(a - b)) < 0.25 * np.median(np.abs(a - a.mean()))


def test_rendering_is_deterministic_from_the_seed():
    a1, a2, a3 = StereoArena(3.0, 4.0, texture_seed=5), StereoArena(3.0, 4.0, texture_seed=5), StereoArena(3.0, 4.0, texture_seed=6)
    # the textures are kept between arenas of the same parameters: a fresh generation gives the same bits
    from slamlab.sim.arena import _arena_textures

    fresh = _arena_textures.__wrapped__(3.0, 4.0, 0.5, 0.004, 0.01, 0.6, 5)
    assert np.array_equal(a1.wall_texture, fresh[0])
    assert np.array_equal(a2.floor_texture, fresh[1])
    assert all(np.array_equal(a, b) for a, b in zip(a1._wall_mips, fresh[2], strict=True))
    assert not a1.wall_texture.flags.writeable
    assert not a1._floor_mips[-1].flags.writeable
    assert not np.array_equal(a1.wall_texture, a3.wall_texture)
    s1 = StereoSim(a1, noise_std=3.0, drift_std_rad=1e-3, rng=9)
    s2 = StereoSim(a2, noise_std=3.0, drift_std_rad=1e-3, rng=9)
    for pose in ([1.0, 1.0, 0.3], [1.5, 2.0, 1.3]):
        la, ra = s1.render_pair(pose)
        lb, rb = s2.render_pair(pose)
        assert np.array_equal(la, lb)
        assert np.array_equal(ra, rb)


def test_noise_and_drift():
    arena = StereoArena(3.0, 4.0, texture_seed=5)
    clean = StereoSim(arena, rng=0).render_pair([1.5, 2.0, 0.5])
    noisy = StereoSim(arena, noise_std=4.0, rng=0).render_pair([1.5, 2.0, 0.5])
    diff = noisy[0].astype(float) - clean[0]
    assert np.std(diff) == pytest.approx(4.0, rel=0.1)
    drift = StereoSim(arena, drift_std_rad=0.01, rng=0)
    for _ in range(5):
        drift.render_pair([1.5, 2.0, 0.5])
    # a random walk: each render adds N(0, σ²) to each of the 3 angles, drawn first from the sim's stream
    # (no image noise here), so the drift after 5 renders is the sum of the stream's first 5 draws
    steps = np.random.default_rng(0).normal(0.0, 0.01, (5, 3))
    np.testing.assert_allclose(drift.drift_rad, steps.sum(axis=0), rtol=0, atol=1e-15)
    assert not np.allclose(drift.render_pair([1.5, 2.0, 0.5])[1], clean[1])  # the right camera drifts
    assert np.array_equal(drift.render_pair([1.5, 2.0, 0.5])[0], clean[0])  # the left camera does not drift


def test_textures():
    z = fractal_noise((256, 256), beta=2.0, rng=0)
    # radially averaged power spectrum falls as f^-beta
    F = np.abs(np.fft.fft2(z)) ** 2
    f = np.hypot(*np.meshgrid(np.fft.fftfreq(256), np.fft.fftfreq(256)))
    bins = np.geomspace(0.01, 0.4, 12)
    idx = np.digitize(f, bins)
    p = [F[idx == i].mean() for i in range(1, 12)]
    fc = np.sqrt(bins[:-1] * bins[1:])
    slope = np.polyfit(np.log(fc), np.log(p), 1)[0]
    assert slope == pytest.approx(-2.0, abs=0.2)
    # periodic: the wrap-around step is as small as an ordinary neighbour step
    step = np.abs(np.diff(z, axis=1)).mean()
    assert np.abs(z[:, 0] - z[:, -1]).mean() < 2 * step
    h = crater_heightfield((100, 100), n_craters=1, radius_px=(20.0, 20.0), rng=1)
    assert h.min() == pytest.approx(-0.2 * 20, rel=0.05)  # bowl depth 0.2 R at the centre
    t = lunar_texture((80, 120), rng=2)
    assert t.min() >= 0.0
    assert t.max() <= 1.0
    assert t.std() > 0.05



def _whole_array_noise(shape, beta, rng):
    """fractal_noise as one whole-array expression (before the block passes)."""
    rows, cols = shape
    fy = np.fft.fftfreq(rows)[:, None]
    fx = np.fft.rfftfreq(cols)[None, :]
    f = np.hypot(fx, fy)
    f[0, 0] = 1.0
    amp = f ** (-beta / 2.0)
    amp[0, 0] = 0.0
    spec = amp * (rng.standard_normal(amp.shape) + 1j * rng.standard_normal(amp.shape))
    z = np.fft.irfft2(spec, s=(rows, cols))
    z -= z.mean()
    return z / z.std()


def _whole_array_lunar(shape, rng, n_craters, radius_px, noise_amp_px, contrast):
    """lunar_texture as whole-array expressions (before the block passes)."""
    r_noise, r_crater, r_albedo = rng.spawn(3)
    h = noise_amp_px * _whole_array_noise(shape, 2.4, r_noise)
    h += crater_heightfield(shape, n_craters, radius_px, rng=r_crater)
    hx = 0.5 * (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1))
    hy = 0.5 * (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0))
    sun = np.array([np.cos(0.5) * np.cos(0.6), np.cos(0.5) * np.sin(0.6), np.sin(0.5)])
    shade = np.clip((-hx * sun[0] - hy * sun[1] + sun[2]) / np.sqrt(hx**2 + hy**2 + 1.0), 0.0, None)
    img = (0.75 + 0.2 * np.tanh(_whole_array_noise(shape, 3.0, r_albedo))) * shade
    img = 0.5 + contrast * (img - img.mean()) / (4.0 * img.std() + 1e-12)
    return np.clip(img, 0.0, 1.0)


@pytest.mark.parametrize("shape", [(2, 2), (7, 37), (40, 64), (33, 250)])
def test_textures_in_blocks_equal_whole_array(monkeypatch, shape):
    # the block passes that keep a long fence's peak memory down give the whole-array values bit for
    # bit: blocks of 64 texels here cut every pass (draws, spectrum, both FFT axes, shading) many times
    monkeypatch.setattr(textures, "BLOCK_ELEMENTS", 64)
    for seed in (0, 5):
        z = fractal_noise(shape, 2.4, np.random.default_rng(seed))
        assert np.array_equal(z, _whole_array_noise(shape, 2.4, np.random.default_rng(seed)))
        kw = {"n_craters": 4, "radius_px": (1.5, 6.0), "noise_amp_px": 1.0, "contrast": 0.6 + 0.4 * (seed == 0)}
        t = lunar_texture(shape, rng=np.random.default_rng(seed), **kw)
        assert np.array_equal(t, _whole_array_lunar(shape, np.random.default_rng(seed), **kw))

def test_trajectories():
    turn = turn_in_place(np.deg2rad(5.0))
    assert len(turn) == 73
    assert turn[-1, 2] - turn[0, 2] == pytest.approx(2 * np.pi)
    assert np.ptp(turn[:, :2], axis=0).max() == 0
    loop = rectangular_loop()
    np.testing.assert_allclose(loop[-1, :2], loop[0, :2])
    assert float(wrap_angle(loop[-1, 2] - loop[0, 2])) == pytest.approx(0.0, abs=1e-12)
    length = np.hypot(*np.diff(loop[:, :2], axis=0).T)
    assert length.sum() == pytest.approx(18.0)
    assert length.max() <= 0.25 + 1e-12
    assert np.abs(np.diff(loop[:, 2])).max() <= np.deg2rad(15.0) + 1e-12
    arena = StereoArena(6.0, 8.0, texel_m=0.02)
    assert arena.contains(loop[:, :2]).all()
    lp = long_path()
    assert np.hypot(*np.diff(lp[:, :2], axis=0).T).sum() == pytest.approx(79.0)
    assert lp[:, 0].min() > 0
    assert lp[:, 0].max() < 10
    assert lp[:, 1].max() < 12
    # both turning directions occur (000 §3.7.2: one-way turning accumulates error)
    dyaw = np.diff(lp[:, 2])
    assert (dyaw > 0).any()
    assert (dyaw < 0).any()


def test_bad_input(arena, sim):
    with pytest.raises(ValueError, match="inside the arena"):
        arena.cast(sim.rig.left, se3_from_planar(-1.0, 1.0, 0.0) @ sim.T_body_left)
    with pytest.raises(TypeError, match="PinholeCamera"):
        arena.render("cam", np.eye(4))
    with pytest.raises(ValueError, match="T_world_cam"):
        arena.render(sim.rig.left, np.eye(3))
    with pytest.raises(ValueError, match="width_m"):
        StereoArena(0.0, 1.0)
    with pytest.raises(TypeError, match="arena"):
        StereoSim(None)
    with pytest.raises(ValueError, match="noise_std"):
        StereoSim(arena, noise_std=-1.0)
    with pytest.raises(ValueError, match="pose"):
        sim.render_pair([1.0, 2.0])
    with pytest.raises(ValueError, match="waypoints_m"):
        waypoint_path([[0.0, 0.0]])
    with pytest.raises(ValueError, match="repeat"):
        waypoint_path([[0.0, 0.0], [0.0, 0.0]])
    with pytest.raises(ValueError, match="step_rad"):
        turn_in_place(0.0)
    with pytest.raises(ValueError, match="shape"):
        fractal_noise((10,))
    with pytest.raises(ValueError, match="radius_px"):
        crater_heightfield((10, 10), radius_px=(5.0, 1.0))


def test_small_rig_renders_quickly_and_camera_axes():
    # body x forward maps to the camera's optical axis
    np.testing.assert_allclose(R_BODY_CAM @ [0, 0, 1], [1, 0, 0])
    np.testing.assert_allclose(R_BODY_CAM @ [1, 0, 0], [0, -1, 0])
    sim = StereoSim(StereoArena(2.0, 3.0, texel_m=0.01), StereoRig.parallel(0.1, 80, 60), rng=0)
    left, right = sim.render_pair([1.0, 1.5, 0.0])
    assert left.shape == (60, 80)
    assert isinstance(sim.rig.left, PinholeCamera)
    assert not np.array_equal(left, right)


def _stamp_by_stamp(shape, n_craters, radius_px, slope, rng):
    """crater_heightfield as it was first written: one stamp at a time (before the vectorised blocks)."""
    rows, cols = shape
    h = np.zeros((rows, cols))
    u = rng.random(n_craters)
    a = 1.0 - slope
    r_lo, r_hi = radius_px
    R = (r_lo**a + u * (r_hi**a - r_lo**a)) ** (1.0 / a) if r_hi > r_lo else np.full(n_craters, r_lo)
    cy = rng.uniform(0, rows, n_craters)
    cx = rng.uniform(0, cols, n_craters)
    for Ri, yi, xi in zip(R, cy, cx, strict=True):
        ext = int(np.ceil(2.0 * Ri)) + 1
        ys = np.arange(int(yi) - ext, int(yi) + ext + 1)
        xs = np.arange(int(xi) - ext, int(xi) + ext + 1)
        q = np.hypot((ys[:, None] - yi), (xs[None, :] - xi)) / Ri
        bowl = (q**2 - 1.0) * 0.2 * Ri
        rim = 0.06 * Ri * np.exp(-((q - 1.0) ** 2) / 0.04)
        prof = np.where(q < 1.0, bowl, 0.0) + rim * (q < 2.0)
        h[np.ix_(ys % rows, xs % cols)] += prof
    return h


@pytest.mark.parametrize("block", [64, 4096, textures.BLOCK_ELEMENTS])
@pytest.mark.parametrize(("shape", "n_craters", "radius_px"), [
    ((40, 300), 200, (1.5, 8.0)),    # many overlapping stamps, wrapped at both edges
    ((125, 700), 112, (2.5, 30.0)),  # a fence's proportions and crater sizes
    ((30, 30), 5, (6.0, 9.0)),       # stamps wider than the texture: the one-at-a-time path
    ((9, 500), 0, (1.0, 2.0)),
])
def test_crater_blocks_equal_stamp_by_stamp(monkeypatch, block, shape, n_craters, radius_px):
    # the vectorised crater field sums each texel's craters in the loop's order: the same bits
    monkeypatch.setattr(textures, "BLOCK_ELEMENTS", block)
    for seed in (0, 3):
        h = crater_heightfield(shape, n_craters, radius_px, rng=np.random.default_rng(seed))
        assert np.array_equal(h, _stamp_by_stamp(shape, n_craters, radius_px, 2.2, np.random.default_rng(seed)))
