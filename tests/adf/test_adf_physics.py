"""The original system's models under Bullet: puzzle pieces settle on the floor, the closed-loop
parallel structure stays closed, joint controllers reach their set-points, and an AMBF-client
script drives a fixture model."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import ambfplus
from ambfplus.ambf_client import Client

DESCRIPTIONS = Path("ambf") / "ambf_models" / "descriptions"
FLOOR_Z = -1.5  # checkered_floor's plane


def launch(fixtures: Path, models: list[int]) -> ambfplus.Simulator:
    sim = ambfplus.Simulator.from_launch(
        fixtures / DESCRIPTIONS / "launch.yaml", models=models, strict=True
    )
    assert sim.load_report.errors == []
    return sim


def test_puzzle_pieces_come_to_rest_on_the_floor(fixtures):
    sim = launch(fixtures, [12])
    world = sim.world
    start = {b.name: b.pose[:3, 3].copy() for b in world.bodies}
    sim.step(6000)
    moving = [b for b in world.bodies if b.dynamic]
    assert len(moving) == 18
    for b in moving:
        p = b.pose[:3, 3]
        assert np.all(np.isfinite(p)), b.name
        assert np.linalg.norm(b.linear_velocity) < 0.01, b.name
        assert np.linalg.norm(b.angular_velocity) < 0.05, b.name
        assert FLOOR_Z < p[2] < start[b.name][2] + 0.05, b.name  # above the floor, not thrown
        assert np.linalg.norm(p[:2] - start[b.name][:2]) < 1.0, b.name
    # The balls are spheres: at rest on the floor their centres are one radius above it.
    for name, radius in (("Ball_A", 0.149), ("Ball_B", 0.1995)):
        assert world.get(name).pose[2, 3] == pytest.approx(FLOOR_Z + radius, abs=3e-3)
    # The hanging lights (a chain of point-to-point joints under a static anchor) hang still.
    for j in ("LightCylinder-LightSphere", "LightSphere-LightCube", "LightCube-LightCone"):
        a, b = world.get(j).anchors
        assert np.linalg.norm(a - b) < 1e-3, j


def test_closed_loop_parallel_structure_stays_closed(fixtures):
    sim = launch(fixtures, [10])
    world = sim.world
    loop = world.get("l1-l4")  # closes l1-l2-l3-l4 back onto l1
    sim.step(10000)
    a, b = loop.anchors
    assert np.linalg.norm(a - b) < 1e-3
    for j in world.joints:
        a, b = j.anchors
        assert np.linalg.norm(a - b) < 1e-3, j.name
    # It moved (under gravity, within its limits), and the loop's angles agree.
    assert abs(world.get("l1-l2").position) > 0.1
    for name in ("l1-l2", "l2-l3", "l3-l4"):
        assert abs(world.get(name).position) <= 1.047 + 5e-3, name


def test_revolute_joint_under_its_controller_settles_at_the_set_point(fixtures):
    path = fixtures / DESCRIPTIONS / "multi-bodies" / "grippers" / "single joint1.yaml"
    world = ambfplus.World()
    world.gravity = (0, 0, 0)
    world.load_adf(path)
    joint = world.get("gripperR1-gripperL1")
    assert joint.controller["output"] == "effort"  # declared in the file: P 100, D 1
    assert (joint.controller["p"], joint.controller["d"]) == (100.0, 1.0)
    for target in (0.4, 0.1):
        joint.set_position(target)
        world.step(3000)
        assert abs(joint.position - target) < 1e-3, target


def test_ambf_client_script_moves_a_fixture_joint(fixtures):
    sim = launch(fixtures, [12])
    client = Client(simulator=sim)
    assert client.connect()
    assert "Mold_A" in client.get_obj_names()  # AMBF client keys: no /ambf/env/ prefix
    mold = client.get_obj_handle("Mold_A")
    assert mold.get_num_joints() == 6
    assert mold.get_joint_names()[4] == "Mold_A-MoldHinge"
    assert client.get_obj_handle("NoSuchBody") is None
    # The top plate's hinge opens to 1 rad under the joint's controller (P 101000, D 202).
    mold.set_joint_pos(4, 1.0)
    client.step(3000)
    assert mold.get_joint_pos("Mold_A-MoldHinge") == pytest.approx(1.0, abs=2e-2)
    assert mold.get_all_joint_pos()[4] == pytest.approx(1.0, abs=2e-2)
    # Bodies are placed directly.
    ball = client.get_obj_handle("Ball_A")
    ball.set_pos(0.5, 1.0, 0.0)
    ball.set_rpy(0.0, 0.0, 0.3)
    p = ball.get_pos()
    assert (p.x, p.y, p.z) == pytest.approx((0.5, 1.0, 0.0))
    assert ball.get_rpy() == pytest.approx([0.0, 0.0, 0.3])
    world = client.get_world_handle()
    t = world.get_sim_time()
    world.set_num_step_skips(10)
    world.update()
    assert world.get_sim_time() == pytest.approx(t + 0.01)
    assert ball.get_pos().z < 0.0  # it fell for 10 ms


def sphere_obj(path: Path, radius: float, rings: int = 6, segments: int = 10) -> None:
    """A closed UV sphere as OBJ (poles shared), written here so the test needs no asset."""
    vertices = [(0.0, 0.0, radius)]
    for i in range(1, rings):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            vertices.append(
                (
                    radius * np.sin(theta) * np.cos(phi),
                    radius * np.sin(theta) * np.sin(phi),
                    radius * np.cos(theta),
                )
            )
    vertices.append((0.0, 0.0, -radius))
    faces = []
    ring = lambda i, j: 2 + (i - 1) * segments + j % segments  # noqa: E731 (1-based)
    for j in range(segments):
        faces.append((1, ring(1, j), ring(1, j + 1)))
        faces.append((len(vertices), ring(rings - 1, j + 1), ring(rings - 1, j)))
        for i in range(1, rings - 1):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)
            faces += [(a, d, c), (a, c, b)]
    lines = [f"v {x:.6f} {y:.6f} {z:.6f}" for x, y, z in vertices]
    lines += [f"f {a} {b} {c}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def test_soft_body_sensor_and_actuator_from_a_model_file(tmp_path):
    sphere_obj(tmp_path / "blob.obj", 0.1)
    model = tmp_path / "lab.yaml"
    model.write_text(
        """
bodies: [BODY floor, BODY post, BODY target, BODY gripper, BODY part]
soft bodies: [SOFTBODY blob]
sensors: [SENSOR range, SENSOR lidar]
actuators: [ACTUATOR grasp]
BODY floor:
  name: floor
  mesh: ''
  mass: 0
  collision shape: PLANE
  collision geometry: {normal: {x: 0, y: 0, z: 1}, offset: 0}
BODY post: {name: post, mass: 0, shape: BOX, geometry: {x: 0.1, y: 0.1, z: 1.0},
            location: {position: {x: 0, y: 0, z: 0.5}}}
BODY target: {name: target, mass: 0, shape: BOX, geometry: {x: 0.2, y: 0.2, z: 0.2},
              location: {position: {x: 1.0, y: 0, z: 0.5}}}
BODY gripper: {name: gripper, mass: 0, shape: BOX, geometry: {x: 0.1, y: 0.1, z: 0.1},
               location: {position: {x: 0, y: 2, z: 1.0}}}
BODY part: {name: part, mass: 0.2, shape: SPHERE, geometry: {radius: 0.03},
            location: {position: {x: 0, y: 2, z: 0.87}}}
SOFTBODY blob:
  name: blob
  mesh: blob.obj
  mass: 0.2
  location: {position: {x: -1.0, y: 0.0, z: 0.3}}
  config: {kLST: 0.6, kDP: 0.01, kDF: 0.5, piterations: 8, kCHR: 1.0}
SENSOR range:
  name: range
  type: Proximity
  parent: BODY post
  location: {position: {x: 0, y: 0, z: 0.0}}
  range: 2.0
  array: [{offset: {x: 0, y: 0, z: 0}, direction: {x: 1, y: 0, z: 0}}]
SENSOR lidar:
  type: Resistance
  parent: BODY post
ACTUATOR grasp:
  name: grasp
  type: Constraint
  parent: BODY gripper
  location: {position: {x: 0, y: 0, z: -0.1}}
  max impulse: 5
"""
    )
    world = ambfplus.World()
    world.load_adf(model)
    assert "lidar" not in world  # a resistance sensor is not supported yet: left out, warned
    blob, sensor, grasp = world.get("blob"), world.get("range"), world.get("grasp")
    assert blob.config["kLST"] == 0.6 and blob.config["piterations"] == 8
    assert blob.node_count == 2 + 5 * 10
    assert grasp.parent.name == "gripper" and grasp.max_impulse == 5
    part = world.get("part")
    grasp.actuate(part)
    world.step(1500)
    # The sensor (at the post's centre, z = 0.5) sees the target's near face at x = 0.9.
    assert sensor.parent.name == "post"
    assert sensor.hits[0]["body"].name == "target"
    assert sensor.distances[0] == pytest.approx(0.9, abs=1e-3)
    # The actuator held the part; the soft body fell onto the floor and rests there whole.
    assert part.pose[:3, 3] == pytest.approx([0, 2, 0.87], abs=3e-3)
    nodes = blob.nodes
    assert np.all(np.isfinite(nodes))
    assert -0.01 < nodes[:, 2].min() < 0.02
    assert nodes[:, 2].max() < 0.25
    extent = nodes.max(axis=0) - nodes.min(axis=0)
    assert np.all(extent < 0.4)
    grasp.deactuate()
    world.step(300)
    assert part.pose[2, 3] < 0.6  # free again, it falls


def test_ambf_client_real_time_mode_steps_in_step_with_the_clock():
    import time

    world = ambfplus.World()
    world.add_body("ball", "sphere", radius=0.05, pose=ambfplus.make_pose((0, 0, 1)))
    client = Client(simulator=world.simulator, realtime=True)
    client.connect()
    ball = client.get_obj_handle("ball")
    start = time.perf_counter()
    time.sleep(0.4)  # as an AMBF client script waits for the simulator
    z = ball.get_pos().z
    client.clean_up()
    elapsed = time.perf_counter() - start
    assert 0.8 * elapsed - 0.05 <= world.time <= elapsed + 0.01
    # It fell for (about) that long: z = 1 - g t^2 / 2 at the time read.
    assert z < 1.0 - 9.8 * (0.8 * 0.4 - 0.05) ** 2 / 2
    stopped = world.time
    time.sleep(0.05)
    assert world.time == stopped  # clean_up stops the thread
