"""Soft bodies, proximity sensors and constraint actuators (Bullet behind the scene API)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.rays import pixel_rays

import ambfplus

G = 9.8
EDGE = 0.05  # the test cube's edge, m
# A cube that keeps its shape (AMBF's defaults, one position iteration, make a floppy one).
FIRM = {"piterations": 10, "kDP": 0.01, "bending constraint": 2}


def cube_triangles(size: float = EDGE, n: int = 4) -> np.ndarray:
    """(T, 3, 3) triangles of a cube's surface centred on the origin, each face an n x n grid,
    wound outwards."""
    h = size / 2
    u = np.linspace(-h, h, n + 1)
    tris = []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            for i in range(n):
                for j in range(n):
                    quad = []
                    for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
                        p = np.zeros(3)
                        p[axis] = sign * h
                        p[(axis + 1) % 3] = u[a]
                        p[(axis + 2) % 3] = u[b]
                        quad.append(p)
                    for t in ([quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]):
                        if np.dot(np.cross(t[1] - t[0], t[2] - t[0]), t[0]) < 0:
                            t = [t[0], t[2], t[1]]
                        tris.append(t)
    return np.array(tris)


def write_stl(path, tris: np.ndarray) -> None:
    """ASCII STL: every facet repeats its vertices, as STL files do."""
    lines = ["solid cube"]
    for t in tris:
        normal = np.cross(t[1] - t[0], t[2] - t[0])
        normal /= np.linalg.norm(normal)
        lines.append("facet normal {:.9g} {:.9g} {:.9g}".format(*normal))
        lines.append(" outer loop")
        lines += ["  vertex {:.9g} {:.9g} {:.9g}".format(*p) for p in t]
        lines += [" endloop", "endfacet"]
    lines.append("endsolid cube")
    path.write_text("\n".join(lines) + "\n")


def write_obj(path, tris: np.ndarray) -> None:
    """OBJ with shared vertices."""
    points, index = [], {}
    faces = []
    for t in tris:
        face = []
        for p in t:
            key = tuple(np.round(p, 9))
            if key not in index:
                index[key] = len(points)
                points.append(key)
            face.append(index[key] + 1)
        faces.append(face)
    text = "".join("v {:.9g} {:.9g} {:.9g}\n".format(*p) for p in points)
    text += "".join("f {} {} {}\n".format(*f) for f in faces)
    path.write_text(text)


def ray_mesh_distance(origin, direction, triangles) -> float:
    """Distance along direction (any length, measured in its units) to the nearest of
    (T, 3, 3) triangles (Moller-Trumbore), inf on a miss."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-15
    inv = np.where(ok, 1 / np.where(ok, det, 1), 0)
    s = origin - a
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ direction) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return float(t[hit].min() * np.linalg.norm(direction)) if hit.any() else math.inf


@pytest.fixture
def cube_stl(tmp_path):
    path = tmp_path / "cube.stl"
    write_stl(path, cube_triangles())
    return path


def floor(world, kind: str) -> None:
    if kind == "plane":
        world.add_body("floor", "plane", mass=0)
    else:  # a box whose top face is z = 0
        world.add_body(
            "floor", "box", size=(1, 1, 0.1), mass=0, pose=ambfplus.make_pose((0, 0, -0.05))
        )


# ---------------------------------------------------------------------------------------------
# Soft bodies


@pytest.mark.parametrize("floor_kind", ["plane", "box"])
def test_a_soft_cube_falls_onto_the_floor_and_rests_on_it(cube_stl, floor_kind):
    world = ambfplus.World()
    floor(world, floor_kind)
    start = ambfplus.make_pose((0, 0, 0.1), rpy=(0.3, 0.2, 0.0))
    cube = world.add_soft_body("jelly", cube_stl, pose=start, mass=0.1, config=FIRM)
    assert cube.kind == "soft body" and isinstance(world["jelly"], ambfplus.SoftBody)
    rest = cube.nodes.copy()
    world.step(2000)
    nodes = cube.nodes
    assert np.isfinite(nodes).all()
    margin = cube.margin
    # It fell 7 cm and rests on the floor, nodes a collision margin above it, none through it.
    assert nodes[:, 2].min() == pytest.approx(margin, abs=0.002)
    assert cube.pose[2, 3] == pytest.approx(EDGE / 2 + margin, abs=0.003)
    speed = np.linalg.norm(cube.node_velocities, axis=1)
    assert speed.max() < 0.01, f"still moving at {speed.max():.3g} m/s"

    # Kept its shape (every distance between two nodes within 5 % of the edge of what it was)
    # and landed flat, a face down.
    def distances(p):
        return np.linalg.norm(p[:, None] - p[None], axis=-1)

    change = np.abs(distances(nodes) - distances(rest)).max()
    assert change < 0.05 * EDGE, f"deformed by {change * 1000:.2f} mm"
    assert np.ptp(nodes[:, 2]) == pytest.approx(EDGE, rel=0.05)


@pytest.mark.parametrize("floor_kind", ["plane", "box"])
def test_ambf_default_coefficients_land_without_exploding(cube_stl, floor_kind):
    world = ambfplus.World()
    floor(world, floor_kind)
    cube = world.add_soft_body("jelly", cube_stl, pose=ambfplus.make_pose((0, 0, 0.1)), mass=0.1)
    world.step(1500)
    nodes = cube.nodes
    assert np.isfinite(nodes).all()
    assert nodes[:, 2].min() > -0.003, "not through the floor"
    assert nodes[:, 2].max() < 0.06, "fell"
    assert (np.ptp(nodes, axis=0) < 2 * EDGE).all(), "no explosion"


def test_duplicate_vertices_merge_into_nodes_and_views_follow_the_simulation(tmp_path, cube_stl):
    tris = cube_triangles()
    obj = tmp_path / "cube.obj"
    write_obj(obj, tris)
    world = ambfplus.World()
    a = world.add_soft_body("from_stl", cube_stl, pose=ambfplus.make_pose((0, 0, 1)))
    b = world.add_soft_body("from_obj", obj, pose=ambfplus.make_pose((1, 0, 1)))
    # 6 faces of a 5 x 5 vertex grid, edges and corners shared: 6*25 - 12*5 + 8 = 98 nodes.
    assert a.node_count == b.node_count == 98
    assert a.triangles.shape == b.triangles.shape == (192, 3)
    # Every triangle's nodes are a triangle of the mesh, placed by the pose.
    placed = np.sort((a.nodes - (0, 0, 1))[a.triangles].reshape(-1, 9), axis=0)
    assert np.allclose(placed, np.sort(tris.reshape(-1, 9), axis=0), atol=1e-6)

    nodes = a.nodes
    assert nodes.dtype == np.float64 and nodes.shape == (98, 3) and nodes.strides == (24, 8)
    assert not nodes.flags.owndata and not nodes.flags.writeable
    triangles = a.triangles
    assert triangles.dtype == np.uint32 and not triangles.flags.writeable
    z0 = nodes[:, 2].copy()
    world.step(100)  # free fall, 0.1 s
    drop = z0 - nodes[:, 2]  # the same view, refreshed by the step
    assert drop.mean() == pytest.approx(0.5 * G * 0.1**2, rel=0.05)
    del world, a, b
    assert np.isfinite(nodes).all() and (nodes[:, 2] < 1).all(), "the view keeps its owner alive"


def test_fixed_nodes_hold_and_released_nodes_fall(cube_stl):
    world = ambfplus.World()
    probe = world.add_soft_body("probe", cube_stl, pose=ambfplus.make_pose((0, 0, 1)))
    top = [int(i) for i in np.flatnonzero(probe.nodes[:, 2] > 1 + EDGE / 2 - 1e-6)]
    assert len(top) == 25
    # No damping (kDP takes that share of the node velocities every step: a drag).
    config = {"piterations": 10, "bending constraint": 2, "fixed nodes": top}
    cube = world.add_soft_body(
        "hanging", cube_stl, pose=ambfplus.make_pose((0.5, 0, 1)), config=config
    )
    assert cube.fixed_nodes == top
    held = cube.nodes[top].copy()
    world.step(500)
    assert np.array_equal(cube.nodes[top], held), "pinned nodes do not move"
    assert cube.nodes[:, 2].min() > 1 - EDGE, "hangs from its top face (some sag)"
    cube.release_nodes(top[:5])
    assert cube.fixed_nodes == top[5:]
    cube.release_nodes(top[5:])
    world.step(300)
    assert 1 - cube.pose[2, 3] == pytest.approx(0.5 * G * 0.3**2, rel=0.05), "falls once released"
    cube.fix_nodes([0])
    assert cube.fixed_nodes == [0]
    before = cube.nodes[0].copy()
    cube.set_node_positions([0], [before + (0, 0, 0.01)])
    assert cube.nodes[0] == pytest.approx(before + (0, 0, 0.01))


def test_soft_body_pose_moves_it_rigidly(cube_stl):
    world = ambfplus.World()
    cube = world.add_soft_body("c", cube_stl, pose=ambfplus.make_pose((0, 0, 1)))
    assert cube.pose[:3, 3] == pytest.approx((0, 0, 1))  # the nodes' centroid
    before = cube.nodes.copy()
    target = ambfplus.make_pose((0.2, -0.1, 0.5), rpy=(0, 0, 0.5))
    cube.pose = target
    assert np.allclose(cube.pose, target)
    assert np.allclose(cube.nodes, (before - (0, 0, 1)) @ target[:3, :3].T + target[:3, 3])


def test_soft_body_config_follows_ambf_and_bad_input_is_refused(tmp_path, cube_stl):
    world = ambfplus.World()
    cube = world.add_soft_body("c", cube_stl, config={"kLST": 0.4, "kMT": 0.2, "clusters": 4})
    c = cube.config
    assert (c["kLST"], c["kMT"], c["clusters"]) == (0.4, 0.2, 4)
    # AMBF's defaults for the rest.
    assert (c["kDF"], c["kAHR"], c["kKHR"], c["kCHR"], c["kVCF"]) == (0.2, 0.7, 0.1, 1.0, 1.0)
    assert (c["piterations"], c["citerations"], c["flags"], c["bending constraint"]) == (
        1,
        4,
        1,
        None,
    )
    assert cube.margin == 0.001 and cube.mass == 1.0

    with pytest.raises(ambfplus.AssetNotFound, match="nowhere.stl"):
        world.add_soft_body("missing", tmp_path / "nowhere.stl")
    with pytest.raises(FileNotFoundError):
        world.add_soft_body("missing", tmp_path / "nowhere.obj")
    with pytest.raises(ValueError, match="unknown soft body config key 'kXYZ'"):
        world.add_soft_body("bad", cube_stl, config={"kXYZ": 1})
    with pytest.raises(ValueError, match="kLST"):
        world.add_soft_body("bad", cube_stl, config={"kLST": 2})
    with pytest.raises(ValueError, match="piterations"):
        world.add_soft_body("bad", cube_stl, config={"piterations": 2.5})
    with pytest.raises(ValueError, match="fixed node 98 is not a node"):
        world.add_soft_body("bad", cube_stl, fixed_nodes=[98])
    with pytest.raises(ValueError, match="mass must be > 0"):
        world.add_soft_body("bad", cube_stl, mass=0)
    with pytest.raises(ValueError, match="already has a soft body"):
        world.add_soft_body("c", cube_stl)
    with pytest.raises(TypeError, match="frobnicate"):
        world.add_soft_body("bad", cube_stl, frobnicate=1)
    with pytest.raises(IndexError):
        cube.fix_nodes([1000])
    points = tmp_path / "points.obj"
    points.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n")
    with pytest.raises((ambfplus.ConfigError, ValueError)):
        world.add_soft_body("flat", points)
    assert "bad" not in world and "flat" not in world


def test_soft_bodies_are_drawn_with_their_deformed_nodes(cube_stl):
    world = ambfplus.World()
    cube = world.add_soft_body("c", cube_stl, color=(0.9, 0.1, 0.1))
    height = 0.3
    camera = world.add_camera("top", 64, 48, 0.5, 0.01, 2.0)
    camera.look_at((0, 0, height), (0, 0, 0), (0, 1, 0))
    centre = (24, 32)
    depth = camera.capture().depth
    assert depth[centre] == pytest.approx(height - EDGE / 2, abs=1e-4)
    # Press the middle of the top face down 1 cm: the rendered surface follows the nodes.
    top = cube.nodes[:, 2] > EDGE / 2 - 1e-6
    middle = np.flatnonzero(top & (np.abs(cube.nodes[:, :2]).max(axis=1) < 1e-6))
    assert len(middle) == 1
    pressed = cube.nodes[middle] - (0, 0, 0.01)
    cube.set_node_positions(middle, pressed)
    frame = camera.capture()
    # Each pixel's depth is where its ray meets the deformed triangles.
    rows, cols = slice(centre[0] - 4, centre[0] + 4), slice(centre[1] - 4, centre[1] + 4)
    rays = pixel_rays(frame.intrinsics, frame.height, frame.width)[rows, cols].reshape(-1, 3)
    world_rays = rays @ frame.pose[:3, :3].T
    expected = [
        ray_mesh_distance(frame.pose[:3, 3], d, cube.nodes[cube.triangles]) for d in world_rays
    ]
    expected = np.array(expected) / np.linalg.norm(rays, axis=1)  # along the ray -> depth (z)
    assert frame.depth[rows, cols].ravel() == pytest.approx(expected, abs=2e-4)
    assert frame.depth[centre] > height - EDGE / 2 + 0.005, "the dent is drawn"
    red, green, _ = frame.rgb[centre[0], centre[1] - 8].astype(int)
    assert red > green + 80, "drawn in its colour"


# ---------------------------------------------------------------------------------------------
# Proximity sensors


def sensor_world():
    world = ambfplus.World()
    base = world.add_body(
        "base", "box", size=(0.02, 0.02, 0.02), mass=0, pose=ambfplus.make_pose((0, 0, 0.5))
    )
    return world, base


def test_a_proximity_sensor_measures_the_distance_to_the_nearest_box():
    world, base = sensor_world()
    # The sensor 1 cm in front of the base, looking along the base's +x turned 0.2 rad about z.
    yaw = 0.2
    location = ambfplus.make_pose((0.01, 0, 0), rpy=(0, 0, yaw))
    sensor = world.add_sensor("prox", base, location=location, range=0.5)
    assert sensor.kind == "sensor" and isinstance(world["prox"], ambfplus.ProximitySensor)
    origin = np.array([0.01, 0, 0.5])
    ray = np.array([math.cos(yaw), math.sin(yaw), 0])
    # A box turned 0.5 rad about z whose -x face the ray meets, and another behind it.
    centre, turn, half = np.array([0.3, 0.05, 0.5]), 0.5, 0.05
    box = world.add_body(
        "box",
        "box",
        size=(0.1, 0.1, 0.1),
        mass=0,
        pose=ambfplus.make_pose(centre, rpy=(0, 0, turn)),
    )
    world.add_body(
        "behind", "box", size=(0.1, 0.4, 0.4), mass=0, pose=ambfplus.make_pose((0.45, 0, 0.5))
    )
    world.step()
    normal = -np.array([math.cos(turn), math.sin(turn), 0])  # of the -x face, outwards
    face_point = centre + normal * half
    expected = np.dot(face_point - origin, normal) / np.dot(ray, normal)
    hit = sensor.hits[0]
    assert hit["triggered"] and sensor.triggered
    assert hit["distance"] == pytest.approx(expected, abs=0.001)
    assert sensor.distances[0] == pytest.approx(expected, abs=0.001)
    assert hit["point"] == pytest.approx(origin + expected * ray, abs=0.001)
    assert hit["normal"] == pytest.approx(normal, abs=1e-3)
    assert hit["body"].name == "box", "the nearest body, not the one behind nor the parent"
    assert hit["fraction"] == pytest.approx(expected / 0.5, abs=0.002)

    # Out of range: the ray's far end reports "nothing closer than its range".
    box.pose = ambfplus.make_pose((0.3, 0.05, 2.0))
    world["behind"].pose = ambfplus.make_pose((0.8, 0, 0.5))
    world.step()
    hit = sensor.hits[0]
    assert not hit["triggered"] and not sensor.triggered
    assert hit["body"] is None and hit["distance"] == pytest.approx(0.5)
    assert hit["point"] == pytest.approx(origin + 0.5 * ray)
    # Back in range, nearer: the sensor sees it at the next step.
    box.pose = ambfplus.make_pose(centre - (0.1, 0, 0), rpy=(0, 0, turn))
    world.step()
    assert sensor.hits[0]["distance"] == pytest.approx(
        np.dot(face_point - (0.1, 0, 0) - origin, normal) / np.dot(ray, normal), abs=0.001
    )


def test_an_array_of_rays_reports_each_ray():
    world, base = sensor_world()
    rays = [{"offset": (0, y, 0), "direction": (1, 0, 0)} for y in (-0.04, 0.0, 0.04, 0.08)]
    sensor = world.add_sensor(
        "array", base, location=ambfplus.make_pose((0.01, 0, 0)), range=0.4, rays=rays
    )
    world.add_body(
        "wall", "box", size=(0.02, 0.1, 0.1), mass=0, pose=ambfplus.make_pose((0.21, 0.0, 0.5))
    )
    world.step()
    assert sensor.ray_count == 4
    assert list(sensor.triggered_rays) == [True, True, True, False]
    assert np.allclose(sensor.distances, [0.19, 0.19, 0.19, 0.4], atol=0.001)
    assert np.allclose(sensor.ray_starts[:, 1], [-0.04, 0, 0.04, 0.08])
    assert np.allclose(sensor.ray_ends[:, 0], 0.41)
    # AMBF's parametric fan: resolution^2 rays about +x.
    fan = world.add_sensor(
        "fan",
        base,
        range=0.3,
        parametric={"resolution": 3, "horizontal angle": 0.4, "vertical angle": 0.2},
    )
    assert fan.ray_count == 9
    directions = fan.ray_ends - fan.ray_starts
    assert np.allclose(np.linalg.norm(directions, axis=1), 0.3)
    assert np.allclose(directions[4], (0.3, 0, 0)), "the middle ray looks straight ahead"


def test_a_sensor_moves_with_its_parent_body():
    world = ambfplus.World()
    arm = world.add_body(
        "arm", "box", size=(0.02, 0.02, 0.02), kinematic=True, pose=ambfplus.make_pose((0, 0, 0.5))
    )
    world.add_body("wall", "box", size=(0.02, 1, 1), mass=0, pose=ambfplus.make_pose((0.5, 0, 0.5)))
    sensor = world.add_sensor("prox", arm, range=1.0)
    world.step()
    assert sensor.distances[0] == pytest.approx(0.49, abs=0.001)
    arm.pose = ambfplus.make_pose((0.2, 0, 0.5))
    world.step()
    assert sensor.pose[:3, 3] == pytest.approx((0.2, 0, 0.5))
    assert sensor.distances[0] == pytest.approx(0.29, abs=0.001)
    arm.pose = ambfplus.make_pose((0.2, 0, 0.5), rpy=(0, 0, math.pi))  # turned away
    world.step()
    assert not sensor.triggered


def test_a_sensor_sees_soft_bodies(cube_stl):
    world = ambfplus.World()
    floor(world, "plane")
    cube = world.add_soft_body(
        "jelly", cube_stl, pose=ambfplus.make_pose((0, 0, 0.1)), mass=0.1, config=FIRM
    )
    eye = world.add_body(
        "eye", "sphere", radius=0.005, mass=0, pose=ambfplus.make_pose((0.003, 0.002, 0.3))
    )
    sensor = world.add_sensor("down", eye, direction=(0, 0, -1), range=0.5)
    world.step(1000)
    hit = sensor.hits[0]
    assert hit["body"].name == "jelly"
    top = cube.nodes[:, 2].max()
    assert hit["distance"] == pytest.approx(0.3 - top, abs=0.003)
    assert cube.nodes[hit["node"], 2] == pytest.approx(top, abs=0.003), "a node of the top face"


def test_sensor_bad_input_is_refused():
    world, base = sensor_world()
    with pytest.raises(ValueError, match="range must be > 0"):
        world.add_sensor("s", base, range=0)
    with pytest.raises(ValueError, match="non-zero direction"):
        world.add_sensor("s", base, direction=(0, 0, 0))
    with pytest.raises(ValueError, match="not both"):
        world.add_sensor("s", base, direction=(0, 0, 1), rays=[((0, 0, 0), (1, 0, 0))])
    with pytest.raises(ValueError, match="resolution of at least 2"):
        world.add_sensor(
            "s", base, parametric={"resolution": 1, "horizontal angle": 1, "vertical angle": 1}
        )
    with pytest.raises(ValueError, match="rigid transform"):
        world.add_sensor("s", base, location=np.diag([2.0, 1, 1, 1]))
    assert "s" not in world


# ---------------------------------------------------------------------------------------------
# Constraint actuators


def grip_world(mass_pose=(0.05, 0, 0.5)):
    world = ambfplus.World()
    hand = world.add_body(
        "hand", "box", size=(0.02, 0.02, 0.02), mass=0, pose=ambfplus.make_pose((0, 0, 0.5))
    )
    obj = world.add_body(
        "obj", "box", size=(0.04, 0.04, 0.04), mass=0.2, pose=ambfplus.make_pose(mass_pose)
    )
    return world, hand, obj


def test_a_constraint_actuator_holds_a_body_until_it_lets_go():
    world, hand, obj = grip_world()
    grip = world.add_actuator("grip", hand, location=ambfplus.make_pose((0.03, 0, 0)))
    assert grip.kind == "actuator" and isinstance(world["grip"], ambfplus.ConstraintActuator)
    assert not grip.is_actuated() and grip.actuated_body is None
    start = obj.pose.copy()
    grip.actuate(obj)
    assert grip.is_actuated() and grip.actuated_body.name == "obj"
    world.step(2000)
    assert np.linalg.norm(obj.pose[:3, 3] - start[:3, 3]) < 0.002, "held where it was grasped"
    assert np.abs(obj.pose[:3, :3] - start[:3, :3]).max() < 1e-3, "and as it was turned"
    grip.deactuate()
    assert not grip.is_actuated()
    world.step(300)
    fall = start[2, 3] - obj.pose[2, 3]
    assert fall == pytest.approx(0.5 * G * 0.3**2, rel=0.05), "falls freely once released"


def test_a_point_hold_keeps_the_point_and_lets_the_body_swing():
    world, hand, obj = grip_world()
    grip = world.add_actuator("grip", hand, location=ambfplus.make_pose((0.03, 0, 0)), hold="point")
    assert (grip.hold, grip.max_impulse, grip.tau) == ("point", 10.0, 1.0)
    grip.actuate(obj)  # held 2 cm to the side of its centre of mass
    world.step(1500)
    held_point = obj.pose @ np.array([-0.02, 0, 0, 1])
    assert held_point[:3] == pytest.approx((0.03, 0, 0.5), abs=0.002)
    assert np.arccos(np.clip(obj.pose[2, 2], -1, 1)) > 0.3, "it turned about the held point"


def test_an_actuator_pulls_a_body_to_an_offset_and_carries_it():
    world, hand, obj = grip_world(mass_pose=(0.1, 0.02, 0.45))
    hand.kinematic = True
    grip = world.add_actuator("grip", hand, location=ambfplus.make_pose((0.03, 0, 0)))
    grip.actuate(obj, offset=(-0.02, 0, 0))  # the actuator at the body's -x face centre
    world.step(500)
    assert obj.pose[:3, 3] == pytest.approx((0.05, 0, 0.5), abs=0.002)
    for k in range(500):
        hand.pose = ambfplus.make_pose((1e-4 * k, 0, 0.5))
        world.step()
    assert obj.pose[:3, 3] == pytest.approx((0.05 + 0.0499, 0, 0.5), abs=0.003), "carried along"
    assert grip.pose[:3, 3] == pytest.approx((0.03 + 0.0499, 0, 0.5), abs=1e-6)


def test_actuator_bad_input_is_refused():
    world, hand, obj = grip_world()
    grip = world.add_actuator("grip", hand)
    with pytest.raises(ValueError, match="its own parent"):
        grip.actuate(hand)
    wall = world.add_body(
        "wall", "box", size=(0.1, 0.1, 0.1), mass=0, pose=ambfplus.make_pose((1, 0, 0))
    )
    with pytest.raises(ValueError, match="static or kinematic"):
        grip.actuate(wall)
    with pytest.raises(ValueError, match="tau"):
        world.add_actuator("bad", hand, tau=0)
    with pytest.raises(ValueError, match="hold must be"):
        world.add_actuator("bad", hand, hold="glue")
    with pytest.raises(ValueError, match="not both"):
        world.add_actuator("bad", hand, location=np.eye(4), pose=np.eye(4))
    assert not grip.is_actuated() and "bad" not in world
