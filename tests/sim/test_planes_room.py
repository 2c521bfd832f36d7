"""Room of planes, vertical line scanner, yawing flight (002; ours): ray casting against exact geometry."""

import numpy as np
import pytest

from slamlab.sim import (
    PlaneScanner,
    build_plane_room,
    cast_rays_planes,
    quad_flight,
    scanner_beam_directions,
    simulate_flight,
    simulate_odometry_3d,
)


@pytest.fixture(scope="module")
def room():
    return build_plane_room()


def test_room_is_200_m2_with_parallel_faces(room):
    floor = room.names.index("room z-")
    assert (2 * room.half_u[floor]) * (2 * room.half_v[floor]) == pytest.approx(200.0)
    # pillar and box faces are parallel to the walls (002: "some of them parallel")
    n = room.normals
    assert np.sum(np.abs(n @ [1.0, 0, 0]) > 1 - 1e-12) >= 4


@pytest.mark.parametrize(("d", "expected_r", "name"), [
    ([0, 0, -1], 1.0, "room z-"), ([0, 0, 1], 2.0, "room z+"), ([-1, 0, 0], 5.0, "room x-"),
    ([0, -1, 0], 5.0, "room y-"), ([0, 1, 0], 5.0, "room y+"),
])
def test_axis_rays_hit_the_walls_at_exact_distances(room, d, expected_r, name):
    r, k, c = cast_rays_planes(room, [5.0, 5.0, 1.0], [d])
    assert r[0] == pytest.approx(expected_r, abs=1e-12)
    assert room.names[k[0]] == name
    assert c[0] == pytest.approx(1.0)


def test_ray_hits_the_near_face_of_the_box_and_misses_beside_it(room):
    # box spans x in [6, 8], y in [1.5, 2.7], z in [0, 1]
    r, k, _ = cast_rays_planes(room, [[2.0, 2.0, 0.5], [2.0, 2.0, 1.5]], [[1.0, 0, 0], [1.0, 0, 0]])
    assert r[0] == pytest.approx(4.0, abs=1e-12)
    assert room.names[k[0]] == "box x-"
    assert r[1] == pytest.approx(18.0, abs=1e-12)        # above the box: the far wall
    assert room.names[k[1]] == "room x+"


def _brute_force(room, o, d):
    best, arg = np.inf, -1
    for i in range(len(room)):
        nd = room.normals[i] @ d
        if abs(nd) < 1e-15:
            continue
        t = (room.offsets[i] - room.normals[i] @ o) / nd
        if t <= 1e-9:
            continue
        x = o + t * d - room.centres[i]
        if abs(x @ room.axes_u[i]) <= room.half_u[i] + 1e-9 and abs(x @ room.axes_v[i]) <= room.half_v[i] + 1e-9 \
                and t < best:
            best, arg = t, i
    return best, arg


def test_random_rays_match_a_per_ray_reference_and_land_on_their_plane(room):
    rng = np.random.default_rng(3)
    o = rng.uniform([1, 1, 0.2], [19, 9, 2.8], (300, 3))
    d = rng.normal(size=(300, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    r, k, c = cast_rays_planes(room, o, d)
    inside_obstacle = np.isnan(r)
    for i in np.flatnonzero(~inside_obstacle):
        t_ref, k_ref = _brute_force(room, o[i], d[i])
        assert r[i] == pytest.approx(t_ref, abs=1e-9)
        assert k[i] == k_ref
        x = o[i] + r[i] * d[i]
        assert room.normals[k[i]] @ x == pytest.approx(room.offsets[k[i]], abs=1e-9)
        assert c[i] == pytest.approx(abs(room.normals[k[i]] @ d[i]), abs=1e-12)


def test_beams_are_the_utm30lx_fan():
    d = scanner_beam_directions()
    assert d.shape == (1081, 3)
    ang = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", d[1:], d[:-1]), -1, 1)))
    np.testing.assert_allclose(ang, 0.25, atol=1e-9)
    np.testing.assert_allclose(d[:, 1], 0.0)                 # vertical scan plane (body x-z)


def test_noise_free_flight_intensity_and_odometry():
    sc = PlaneScanner(sigma_range_m=0.0, sigma_intensity=0.0)
    f = simulate_flight(1.0, scanner=sc, odometry_noise=0.0, rng=0)
    assert len(f) == 40
    assert f.ranges_m.shape == (40, 1081)
    np.testing.assert_allclose(f.odometry, f.poses, atol=1e-12)
    # the points in the map frame lie on the planes the simulator says they hit
    pts_b = f.body_points()
    pts_m = np.einsum("nij,nbj->nbi", f.poses[:, :3, :3], pts_b) + f.poses[:, None, :3, 3]
    ok = f.plane_ids >= 0
    k = f.plane_ids[ok]
    np.testing.assert_allclose(np.einsum("ij,ij->i", f.room.normals[k], pts_m[ok]), f.room.offsets[k], atol=1e-9)
    # intensity = I0 · rho · |cos theta|
    d_m = np.einsum("nij,bj->nbi", f.poses[:, :3, :3], scanner_beam_directions(sc))[ok]
    cos_t = np.abs(np.einsum("ij,ij->i", f.room.normals[k], d_m))
    expect = sc.intensity_gain * f.room.reflectance(k, pts_m[ok]) * cos_t
    np.testing.assert_allclose(f.intensities[ok], expect, rtol=1e-9)


def test_one_second_of_flight_yaws_45_degrees():
    _t, T = quad_flight(1.025)
    from scipy.spatial.transform import Rotation
    yaw = Rotation.from_matrix(T[:, :3, :3]).as_euler("xyz")[:, 2]
    assert np.degrees(yaw[-1] - yaw[0]) == pytest.approx(45.0)


def test_odometry_drifts():
    _, T = quad_flight(10.0)
    odo = simulate_odometry_3d(T, rng=0)
    assert np.linalg.norm(odo[-1, :3, 3] - T[-1, :3, 3]) > 0.05


def test_bad_arguments():
    room = build_plane_room()
    with pytest.raises(ValueError, match="directions"):
        cast_rays_planes(room, [0, 0, 0], [[1.0, 0.0]])
    with pytest.raises(ValueError, match="origins"):
        cast_rays_planes(room, [[0, 0, 0], [1, 1, 1]], [[1.0, 0, 0]])
    with pytest.raises(ValueError, match="fov_deg"):
        PlaneScanner(fov_deg=400.0)
    with pytest.raises(ValueError, match="waypoints_m"):
        quad_flight(1.0, waypoints_m=[[0, 0, 0]])
    with pytest.raises(TypeError, match="room"):
        simulate_flight(1.0, room="room")
    with pytest.raises(ValueError, match="poses"):
        simulate_odometry_3d(np.zeros((3, 3, 3)))


def test_ray_casting_in_chunks_equals_one_pass(monkeypatch):
    """The chunked caster (bounded temporaries, issue 16's kernel memory) gives exactly the one-pass result."""
    import slamlab.sim.planes_room as pr

    room = pr.build_plane_room()
    rng = np.random.default_rng(4)
    d = rng.standard_normal((5000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    o = np.array([5.0, 5.0, 1.2]) + 0.1 * rng.standard_normal((5000, 3))
    one = pr.cast_rays_planes(room, o, d, 30.0)
    import slamlab.sim.room_of_planes as rp  # the caster and its chunk size live there (re-exported by planes_room)

    monkeypatch.setattr(rp, "RAY_CHUNK", 333)
    chunked = pr.cast_rays_planes(room, o, d, 30.0)
    for a, b in zip(one, chunked, strict=True):
        np.testing.assert_array_equal(a, b)
    assert np.isfinite(one[0]).sum() > 4000  # most rays hit a plane


def test_odometry_rotation_noise_is_the_exponential_of_the_drawn_vectors():
    """The per-step rotation noise is Exp(ε) of the drawn rotation vectors (slamlab.geometry.so3, one place for
    every chapter), the same rotation as scipy's to the last bits."""
    from scipy.spatial.transform import Rotation

    from slamlab.geometry import so3_exp

    T = np.tile(np.eye(4), (4, 1, 1))
    odo = simulate_odometry_3d(T, sigma_trans_m=0.0, sigma_rot_deg=2.0, bias_m_per_step=(0, 0, 0),
                               bias_yaw_deg_per_step=0.0, rng=8)
    eps = np.random.default_rng(8).normal(0.0, np.deg2rad(2.0), (3, 3))
    expected = np.eye(3)
    for k in range(3):
        expected = expected @ so3_exp(eps[k])
        np.testing.assert_array_equal(odo[k + 1][:3, :3], expected)
        np.testing.assert_allclose(expected, np.linalg.multi_dot([Rotation.from_rotvec(e).as_matrix()
                                                                   for e in [np.zeros(3), *eps[:k + 1]]]),
                                   atol=1e-14)
