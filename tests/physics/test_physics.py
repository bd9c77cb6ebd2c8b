"""Bullet physics behind the scene API: bodies, contacts, joints and their controllers."""

from __future__ import annotations

import math
import struct

import numpy as np
import pytest

import ambfplus

G = 9.8


def floor_world(**gravity):
    world = ambfplus.World()
    world.add_body("floor", "plane", mass=0)
    return world


def test_a_dropped_body_meets_the_floor_at_the_free_fall_time():
    world = floor_world()
    r, h = 0.05, 1.0
    ball = world.add_body(
        "ball", "sphere", radius=r, pose=ambfplus.make_pose((0, 0, h + r)), restitution=0.0
    )
    hit = None
    while world.time < 0.6:
        world.step()
        if hit is None and ball.pose[2, 3] <= r + 0.001:  # within the collision margin
            hit = world.time
    assert hit == pytest.approx(math.sqrt(2 * h / G), abs=0.002)
    assert ball.pose[2, 3] == pytest.approx(r, abs=0.002), "resting on the floor"


def test_a_box_comes_to_rest_flat_and_a_ball_bounces_by_its_restitution():
    world = floor_world()
    box = world.add_body(
        "box",
        "box",
        size=(0.2, 0.1, 0.06),
        pose=ambfplus.make_pose((0, 0, 0.3), rpy=(0.3, 0.2, 0.5)),
    )
    world.step(3000)
    assert np.linalg.norm(box.linear_velocity) < 1e-3
    assert box.pose[2, 3] == pytest.approx(0.03, abs=0.002), "on its largest face"
    assert abs(box.pose[2, 2]) > 0.999

    # Floor and ball restitution 0.8: Bullet multiplies them, so e = 0.64 and the rebound
    # reaches e^2 of the drop.
    world = ambfplus.World()
    world.add_body("floor", "plane", mass=0, restitution=0.8)
    ball = world.add_body(
        "ball",
        "sphere",
        radius=0.02,
        pose=ambfplus.make_pose((0, 0, 0.52)),
        restitution=0.8,
        linear_damping=0.0,
    )
    bounced, peak = False, 0.0
    while world.time < 1.2:
        world.step()
        v = ball.linear_velocity[2]
        bounced |= v > 0
        if bounced:
            peak = max(peak, ball.pose[2, 3] - 0.02)
    assert peak == pytest.approx(0.5 * 0.64**2, rel=0.08)


def test_friction_holds_a_box_on_a_gentle_slope_and_not_on_a_steep_one():
    def slide(angle, mu):
        world = ambfplus.World()
        tilt = ambfplus.make_pose((0, 0, 0), rpy=(0, angle, 0))
        world.add_body("slope", "box", size=(2, 1, 0.1), mass=0, pose=tilt, friction=mu)
        start = tilt @ ambfplus.make_pose((0, 0, 0.05 + 0.05))
        box = world.add_body(
            "box", "box", size=(0.1, 0.1, 0.1), pose=start, friction=mu, rolling_friction=0.0
        )
        world.step(1000)
        return np.linalg.norm(box.pose[:3, 3] - start[:3, 3])

    assert slide(math.radians(15), mu=0.6) < 0.002, "tan 15 deg = 0.27 < 0.6: sticks"
    assert slide(math.radians(40), mu=0.6) > 0.1, "tan 40 deg = 0.84 > 0.6: slides"


def test_forces_and_torques_act_every_step():
    world = ambfplus.World()
    body = world.add_body("b", "box", size=(0.1, 0.2, 0.3), mass=2.0, linear_damping=0.0)
    body.force = (0, 0, 2.0 * G)  # holds it up against gravity
    world.step(500)
    assert np.allclose(body.linear_velocity, 0, atol=1e-6)
    # A box's principal moment about x: m (y^2 + z^2) / 12.
    assert body.inertia[0] == pytest.approx(2.0 * (0.2**2 + 0.3**2) / 12, rel=1e-4)
    body.damping = (0.0, 0.0)
    body.torque = (0.13, 0, 0)
    world.step(100)
    assert body.angular_velocity[0] == pytest.approx(0.13 / body.inertia[0] * 0.1, rel=0.01)


def test_kinematic_bodies_push_dynamic_ones_and_gravity_can_change():
    world = floor_world()
    pusher = world.add_body("pusher", "box", size=(0.1, 0.3, 0.1), kinematic=True)
    pusher.pose = ambfplus.make_pose((-0.2, 0, 0.05))
    ball = world.add_body("ball", "sphere", radius=0.05, pose=ambfplus.make_pose((0, 0, 0.05)))
    for k in range(300):
        pusher.pose = ambfplus.make_pose((-0.2 + 0.001 * k, 0, 0.05))
        world.step()
    assert ball.pose[0, 3] > 0.05, "pushed along +x"
    assert pusher.dynamic is False and ball.dynamic is True
    world.gravity = (0, 0, 0)
    assert np.allclose(world.gravity, 0)


def test_collision_groups_decide_who_meets_whom():
    def fall_onto_shelf(shelf_groups, ball_groups):
        world = ambfplus.World()
        world.add_body("shelf", "box", size=(1, 1, 0.1), mass=0, groups=shelf_groups)
        ball = world.add_body(
            "ball", "sphere", radius=0.05, pose=ambfplus.make_pose((0, 0, 0.3)), groups=ball_groups
        )
        world.step(500)
        return ball.pose[2, 3] > 0.0

    assert fall_onto_shelf([1], [1]), "same group: collide"
    assert not fall_onto_shelf([1], [2]), "different groups: pass through"
    assert fall_onto_shelf([], [2]) and fall_onto_shelf([3], []), "no group: collides with all"


def write_box_stl(path, size):
    """A binary STL of a box of the given full extents centred on (0, 0, size_z / 2)."""
    sx, sy, sz = (s / 2 for s in size)
    corners = np.array([[x, y, z + sz] for x in (-sx, sx) for y in (-sy, sy) for z in (-sz, sz)])
    faces = [
        (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
        (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),
    ]  # fmt: skip
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(faces)))
        for a, b, c in faces:
            n = np.cross(corners[b] - corners[a], corners[c] - corners[a])
            f.write(struct.pack("<12fH", *n, *corners[a], *corners[b], *corners[c], 0))


@pytest.mark.parametrize("kind", ["concave", "convex_hull", "convex_mesh"])
def test_mesh_bodies_collide_with_their_mesh(tmp_path, kind):
    stl = tmp_path / "box.stl"
    write_box_stl(stl, (0.2, 0.2, 0.1))
    world = floor_world()
    body = world.add_body(
        "crate", mesh=str(stl), pose=ambfplus.make_pose((0, 0, 0.2)), collision_type=kind
    )
    # The centre of mass defaults to the vertex mean: the box's centre, 5 cm above its origin.
    assert np.allclose(body.inertial_offset[:3, 3], (0, 0, 0.05), atol=1e-6)
    world.step(1500)
    assert body.pose[2, 3] == pytest.approx(0.0, abs=0.003), "its bottom face on the floor"
    assert np.linalg.norm(body.linear_velocity) < 1e-2


def test_compound_shapes_rest_on_their_lowest_part():
    world = floor_world()
    body = world.add_body(
        "dumbbell",
        "box",
        size=(0.02, 0.02, 0.3),
        pose=ambfplus.make_pose((0, 0, 0.4)),
        collision_shapes=[
            {"shape": "sphere", "radius": 0.05, "pose": ambfplus.make_pose((0, 0, -0.15))},
            {"shape": "sphere", "radius": 0.05, "pose": ambfplus.make_pose((0.1, 0, -0.15))},
            {"shape": "cylinder", "radius": 0.01, "height": 0.3, "axis": "z"},
        ],
    )
    world.step(2000)
    assert body.pose[2, 3] == pytest.approx(0.15 + 0.05, abs=0.003), "standing on its spheres"


def arm_world(type="revolute", **joint_options):
    """A static base and a 0.4 m, 1 kg arm hinged at its end about y (so gravity loads it)."""
    world = ambfplus.World()
    base = world.add_body("base", "box", size=(0.05, 0.05, 0.05), mass=0)
    arm = world.add_body(
        "arm", "box", size=(0.4, 0.04, 0.04), mass=1.0, pose=ambfplus.make_pose((0.2, 0, 0))
    )
    joint_options.setdefault("parent_axis", (0, 1, 0))
    joint_options.setdefault("child_axis", (0, 1, 0))
    joint = world.add_joint(
        "hinge", base, arm, type, parent_pivot=(0, 0, 0), child_pivot=(-0.2, 0, 0), **joint_options
    )
    return world, base, arm, joint


def test_revolute_controller_settles_at_its_set_point_under_gravity():
    for controller in (None, {"p": 100.0, "i": 200.0, "d": 10.0}):
        world, base, arm, joint = arm_world(controller=controller, damping=0.0)
        joint.set_position(-0.4)  # about +y: lifts the arm's tip above the base
        world.step(4000)
        assert joint.position == pytest.approx(-0.4, abs=1e-3), controller
        assert arm.pose[2, 3] == pytest.approx(0.2 * math.sin(0.4), abs=2e-3)
        assert abs(joint.velocity) < 1e-3
    assert joint.controller["output"] == "effort"
    # Gravity turns the arm about +y with m g l cos(q); the joint holds it with the opposite.
    assert joint.effort == pytest.approx(-1.0 * G * 0.2 * math.cos(0.4), rel=0.02)


def test_joint_velocity_is_the_rate_of_its_position_and_commands_drive_it():
    world, base, arm, joint = arm_world()
    world.gravity = (0, 0, 0)
    joint.set_velocity(0.7)
    world.step(10)
    before = joint.position
    world.step(100)
    assert (joint.position - before) / 0.1 == pytest.approx(0.7, rel=1e-3)
    assert joint.velocity == pytest.approx(0.7, rel=1e-3)
    # Through a full turn the position keeps counting.
    world.step(10000)
    assert joint.position == pytest.approx(0.7 * world.time, rel=0.01)
    assert joint.position > 2 * math.pi
    # An effort accelerates the arm by effort / its inertia about the pivot.
    joint.release()
    arm.angular_velocity = (0, 0, 0)
    arm.linear_velocity = (0, 0, 0)
    joint.set_effort(0.2)
    world.step(100)
    inertia_about_pivot = 1.0 * (0.4**2 + 0.04**2) / 12 + 1.0 * 0.2**2
    assert joint.velocity == pytest.approx(0.2 / inertia_about_pivot * 0.1, rel=0.02)


def test_limits_stop_revolute_and_prismatic_joints():
    world, base, arm, joint = arm_world(lower=-0.3, upper=0.5)
    joint.set_velocity(-2.0)
    world.step(1000)
    assert joint.position == pytest.approx(-0.3, abs=0.01)
    joint.set_velocity(2.0)
    world.step(1000)
    assert joint.position == pytest.approx(0.5, abs=0.01)

    world = ambfplus.World()
    world.gravity = (0, 0, 0)
    rail = world.add_body("rail", "box", size=(1, 0.05, 0.05), mass=0)
    cart = world.add_body("cart", "box", size=(0.1, 0.1, 0.1), mass=0.5)
    slider = world.add_joint(
        "slider", rail, cart, "prismatic", parent_axis=(1, 0, 0), child_axis=(1, 0, 0), upper=0.2
    )
    slider.set_velocity(0.5)
    world.step(200)
    assert slider.position == pytest.approx(0.1, abs=1e-3)
    assert cart.pose[0, 3] == pytest.approx(0.1, abs=1e-3)
    world.step(1000)
    assert slider.position == pytest.approx(0.2, abs=0.005)
    assert abs(cart.pose[1, 3]) < 1e-6 and abs(cart.pose[2, 3]) < 1e-6, "only along its axis"


def test_springs_sag_by_weight_over_stiffness_and_ring_at_their_frequency():
    world = ambfplus.World()
    ceiling = world.add_body("ceiling", "box", size=(0.1, 0.1, 0.1), mass=0)
    weight = world.add_body(
        "weight",
        "sphere",
        radius=0.02,
        mass=0.5,
        pose=ambfplus.make_pose((0, 0, -0.3)),
        linear_damping=0.0,
        angular_damping=0.0,
    )
    k = 200.0
    spring = world.add_joint(
        "spring",
        ceiling,
        weight,
        "linear spring",
        parent_pivot=(0, 0, -0.3),
        parent_axis=(0, 0, 1),
        child_axis=(0, 0, 1),
        stiffness=k,
        damping=0.0,
    )
    heights = []
    for _ in range(2000):
        world.step()
        heights.append(weight.pose[2, 3])
    heights = np.array(heights)
    sag = 0.5 * G / k
    assert heights.mean() == pytest.approx(-0.3 - sag, abs=sag * 0.05)
    # Period from the upward crossings of the mean.
    centred = heights - heights.mean()
    ups = np.nonzero((centred[:-1] < 0) & (centred[1:] >= 0))[0]
    period = np.diff(ups).mean() * world.time_step
    assert period == pytest.approx(2 * math.pi * math.sqrt(0.5 / k), rel=0.03)
    assert spring.position == pytest.approx(heights[-1] + 0.3, abs=1e-6)


def test_fixed_and_point_joints():
    world = ambfplus.World()
    anchor = world.add_body("anchor", "sphere", radius=0.01, mass=0)
    held = world.add_body("held", "box", size=(0.1, 0.1, 0.1), pose=ambfplus.make_pose((0.2, 0, 0)))
    world.add_joint("weld", anchor, held, "fixed", parent_pivot=(0.2, 0, 0))
    bob = world.add_body(
        "bob",
        "sphere",
        radius=0.01,
        mass=0.1,
        pose=ambfplus.make_pose((0, 0.5, 0)),
        linear_damping=0.0,
        angular_damping=0.0,
    )
    world.add_joint("pivot", anchor, bob, "p2p", child_pivot=(0, -0.5, 0))
    ys = []
    for _ in range(3000):
        world.step()
        ys.append(bob.pose[1, 3])
    assert np.allclose(held.pose[:3, 3], (0.2, 0, 0), atol=2e-3), "the weld holds it up"
    # The bob swings through the bottom: a pendulum of 0.5 m released horizontally.
    assert min(ys) < -0.45 and max(ys) > 0.45
    assert np.linalg.norm(bob.pose[:3, 3]) == pytest.approx(0.5, abs=2e-3), "stays on its rod"


def test_the_same_script_gives_the_same_motion():
    def run():
        world = floor_world()
        bodies = [
            world.add_body(
                f"b{i}",
                "box",
                size=(0.05, 0.05, 0.05),
                pose=ambfplus.make_pose((0.01 * i, 0.003 * i, 0.1 + 0.06 * i), rpy=(i, 0, 0)),
            )
            for i in range(6)
        ]
        world.step(800)
        return np.stack([b.pose for b in bodies])

    assert np.array_equal(run(), run())


def test_bad_physics_input_is_named():
    world = ambfplus.World()
    with pytest.raises(ValueError, match="plane is infinite"):
        world.add_body("floor", "plane", mass=1.0)
    a = world.add_body("a", "box", size=(0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match="parent and child are the same"):
        world.add_joint("j", a, a)
    b = world.add_body("b", "box", size=(0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match="unknown joint type 'hing'"):
        world.add_joint("j", a, b, "hing")
    with pytest.raises(ValueError, match="lower limit above upper"):
        world.add_joint("j", a, b, lower=1.0, upper=0.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'stifness'"):
        world.add_joint("j", a, b, stifness=1.0)
    with pytest.raises(ValueError, match="restitution"):
        world.add_body("c", "sphere", radius=0.1, restitution=2.0)
    with pytest.raises(ValueError, match="unknown collision mesh type"):
        world.add_body("d", "sphere", radius=0.1, collision_type="jelly")
    other = ambfplus.World().add_body("e", "box", size=(0.1, 0.1, 0.1))
    with pytest.raises(ValueError, match="in the joint's world"):
        world.add_joint("j", a, other)
    assert world.joints == [] and "j" not in world


def test_a_torsion_spring_turns_by_torque_over_stiffness():
    world = ambfplus.World()
    world.gravity = (0, 0, 0)
    post = world.add_body("post", "box", size=(0.05, 0.05, 0.05), mass=0)
    wheel = world.add_body("wheel", "cylinder", radius=0.1, height=0.02, mass=0.3)
    spring = world.add_joint("torsion", post, wheel, "torsion spring", stiffness=2.0, damping=0.05)
    wheel.torque = (0, 0, 0.3)
    world.step(5000)
    assert spring.position == pytest.approx(0.3 / 2.0, abs=2e-3)
    assert abs(spring.velocity) < 1e-3
