"""Ghost objects: shapes with no collision response whose overlaps Bullet's narrow phase reports
after every step (not their bounding boxes), that exert no force, are drawn unless hidden, and
come from Python, AMBF files (`ghost objects`) and plugins."""

from __future__ import annotations

import textwrap

import numpy as np
import pytest

import ambfplus

HALF = 0.1  # the ghost box's half size
R = 0.03  # the spheres' radius


def scene(with_ghost: bool = True):
    world = ambfplus.World()
    world.gravity = (0.0, 0.0, -9.8)
    ghost = None
    if with_ghost:
        ghost = world.add_ghost("zone", "box", size=(2 * HALF, 2 * HALF, 2 * HALF))
    world.add_body("inside", "sphere", radius=R, mass=0.0, pose=ambfplus.make_pose((0.065, 0, 0)))
    world.add_body("far", "sphere", radius=R, mass=0.0, pose=ambfplus.make_pose((0.5, 0, 0)))
    # Near a vertical edge of the box: the bounding boxes overlap, the shapes do not (the
    # sphere's centre is 7 mm further from the edge than its radius).
    d = HALF + (R + 0.007) / np.sqrt(2)
    world.add_body("corner", "sphere", radius=R, mass=0.0, pose=ambfplus.make_pose((d, d, 0)))
    falling = world.add_body(
        "falling",
        "sphere",
        radius=R,
        mass=0.1,
        pose=ambfplus.make_pose((0.0, -0.02, 0.4)),
        linear_damping=0.0,
        angular_damping=0.0,
    )
    return world, ghost, falling


def test_ghost_reports_exactly_the_overlapping_bodies_and_exerts_no_force():
    world, ghost, falling = scene()
    assert ghost.is_ghost and not world.get("inside").is_ghost
    reference, _, reference_falling = scene(with_ghost=False)
    seen_falling = []
    for _ in range(500):
        world.step(1)
        reference.step(1)
        names = [b.name for b in ghost.overlapping]
        z = falling.pose[2, 3]
        # Free fall through the ghost: the same trajectory, bit for bit, as without it.
        assert z == reference_falling.pose[2, 3]
        assert "inside" in names and "far" not in names and "corner" not in names
        gap = abs(z) - (HALF + R)  # < 0: the sphere's and the box's shapes overlap
        if gap < -0.005:
            assert "falling" in names, z
        elif gap > 0.005:
            assert "falling" not in names, z
        seen_falling.append("falling" in names)
    assert any(seen_falling) and not seen_falling[-1]
    # Free fall: z = z0 - g t^2 / 2 (to Bullet's semi-implicit step).
    t = world.time
    assert falling.pose[2, 3] == pytest.approx(0.4 - 9.8 * t * t / 2, abs=0.01)
    # Overlaps come in creation order, as objects.
    assert [b.name for b in ghost.overlapping] == ["inside"]
    assert ghost.overlapping[0].id == world.get("inside").id


def test_ghost_moves_and_rides_on_a_parent():
    world, ghost, _ = scene()
    ghost.pose = ambfplus.make_pose((0.5, 0.0, 0.0))
    world.step(1)
    assert [b.name for b in ghost.overlapping] == ["far"]
    carrier = world.add_body("carrier", "box", size=(0.01, 0.01, 0.01), mass=0.0)
    carrier.kinematic = True
    ghost.attach_to(carrier, ambfplus.make_pose((0.0, 0.0, 0.0)))
    carrier.pose = ambfplus.make_pose((0.02, 0.0, 0.0))
    world.step(1)
    assert "inside" in [b.name for b in ghost.overlapping]


def test_ghost_is_drawn_unless_hidden_and_rays_pass_through_it():
    world, ghost, _ = scene()
    camera = world.add_camera("top", 64, 64, fov_y=0.8, near=0.05, far=5.0)
    camera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    frame = camera.capture(passes=["instance"])
    assert (frame.instance == ghost.id).sum() > 100
    hidden = world.add_ghost(
        "hidden", "sphere", radius=0.05, pose=ambfplus.make_pose((0, 0, 0.3)), visible=False
    )
    frame = camera.capture(passes=["instance"])
    assert (frame.instance == hidden.id).sum() == 0
    # A proximity sensor's ray goes through ghosts to the body inside.
    holder = world.add_body(
        "holder", "sphere", radius=0.005, mass=0.0, pose=ambfplus.make_pose((0.065, 0.0, 0.8))
    )
    sensor = world.add_sensor(
        "beam", holder, range=2.0, rays=[{"offset": (0, 0, 0), "direction": (0, 0, -1)}]
    )
    world.step(1)
    (hit,) = sensor.hits
    assert hit["body"].name == "inside"


def test_ghost_objects_from_an_adf_file(tmp_path):
    (tmp_path / "phantom.yaml").write_text(
        textwrap.dedent(
            """
            bodies: [BODY phantom, BODY needle]
            ghost objects: [GHOST entry]
            BODY phantom:
              name: phantom
              mass: 0.0
              shape: box
              geometry: {x: 0.2, y: 0.2, z: 0.02}
              location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0, p: 0, y: 0}}
            BODY needle:
              name: needle
              mass: 0.0
              shape: cylinder
              geometry: {radius: 0.002, height: 0.05, axis: z}
              location: {position: {x: 0.05, y: 0.0, z: 0.03}, orientation: {r: 0, p: 0, y: 0}}
            GHOST entry:
              name: Entry1
              parent: BODY phantom
              shape: sphere
              geometry: {radius: 0.01}
              location: {position: {x: 0.05, y: 0.0, z: 0.025}, orientation: {r: 0, p: 0, y: 0}}
              color: red
            """
        )
    )
    world = ambfplus.World()
    world.load_adf(tmp_path / "phantom.yaml")
    entry = world.get("Entry1")
    assert entry.is_ghost
    assert entry.attached_to.name == "phantom"
    world.step(1)
    assert [b.name for b in entry.overlapping] == ["needle"]
    # It rides on the phantom: moved away, it leaves the needle.
    phantom = world.get("phantom")
    phantom.kinematic = True
    phantom.pose = ambfplus.make_pose((0.0, 0.1, 0.0))
    world.step(1)
    assert entry.pose[1, 3] == pytest.approx(0.1)
    assert entry.overlapping == []
