"""The handles' behaviour over the engine: stepping in lock-step and in real time, poses and
quaternions, sensors, actuators, ghosts and reset."""

from __future__ import annotations

import time

import numpy as np
import pytest
from conftest import BASES, forward_kinematics

import ambfplus
from ambfplus import ambf_client
from ambfplus.ambf_client import Client


def falling_ball() -> ambfplus.World:
    world = ambfplus.World()
    world.add_body("ball", "sphere", radius=0.05, pose=ambfplus.make_pose((0, 0, 1)))
    return world


def test_lock_step_time_passes_only_when_stepped():
    world = falling_ball()
    client = Client(simulator=world.simulator)
    client.connect()
    handle = client.get_world_handle()
    time.sleep(0.2)
    assert world.time == 0.0  # sleeping does not step a lock-stepped world
    handle.set_num_step_skips(5)
    handle.update()
    assert world.step_index == 5
    client.step(3)
    assert world.step_index == 8
    client.create_rate(100).sleep()  # one period of 10 ms
    assert world.step_index == 18
    assert handle.get_sim_step() == 18 and handle.get_sim_time() == pytest.approx(0.018)
    with pytest.raises(ValueError):
        handle.set_num_step_skips(0)
    client.clean_up()


def test_real_time_time_passes_while_the_script_sleeps():
    world = falling_ball()
    client = Client(simulator=world.simulator, realtime=True)
    client.connect()
    start = time.perf_counter()
    time.sleep(0.2)
    advanced = world.time
    elapsed = time.perf_counter() - start
    assert 0.05 < advanced <= elapsed + 0.01
    # Throttled, the clock belongs to update().
    handle = client.get_world_handle()
    handle.enable_throttling(True)
    time.sleep(0.02)
    held = world.step_index
    time.sleep(0.05)
    assert world.step_index == held
    handle.set_num_step_skips(7)
    handle.update()
    assert world.step_index == held + 7
    handle.enable_throttling(False)
    time.sleep(0.1)
    assert world.step_index > held + 7 + 20
    client.clean_up()
    stopped = world.time
    time.sleep(0.05)
    assert world.time == stopped
    assert client.is_shutdown()


def test_poses_quaternions_and_placing(two_arms):
    client = Client(simulator=two_arms)
    arm = client.get_obj_handle("arm2_base")
    assert arm.get_num_joints() == 2 and arm.get_num_of_children() == 2
    assert arm.get_children_names() == ["arm2_link1", "arm2_link2"]
    assert arm.get_joint_idx_from_name("arm2_link1-link2") == 1
    assert arm.get_joint_idx_from_name("nope") is None
    assert arm.get_joint_name_from_idx(5) is None
    with pytest.raises(IndexError):
        arm.get_joint_pos(2)
    with pytest.raises(KeyError):
        arm.set_joint_pos("nope", 0.1)
    arm.set_multiple_joint_pos([0.3, -0.2], [0, 1])
    client.step(2000)
    q = arm.get_all_joint_pos()
    assert q == pytest.approx([0.3, -0.2], abs=2e-3)
    link2 = client.get_obj_handle("arm2_link2")
    fk = forward_kinematics(BASES["arm2"], *q)
    assert tuple(link2.get_pos()) == pytest.approx(tuple(fk["link2"]), abs=2e-3)
    quat = link2.get_rot()
    yaw = fk["yaw2"]
    assert (quat.z, quat.w) == pytest.approx((np.sin(yaw / 2), np.cos(yaw / 2)), abs=2e-3)
    assert link2.get_parent_name() == "arm2_link1"
    assert link2.get_identifier() == "BODY arm2_link2"
    assert client.get_obj_pose("arm2_link2") == pytest.approx(link2.get_pose())
    # Placing: set_rot takes (x, y, z, w); the command is remembered.
    needle = client.get_obj_handle("needle")
    needle.set_pos(2.0, 0.0, 0.5)
    needle.set_rot([0.0, 0.0, np.sin(0.25), np.cos(0.25)])
    assert needle.get_rpy() == pytest.approx([0.0, 0.0, 0.5])
    assert tuple(needle.get_pos_command()) == pytest.approx((2.0, 0.0, 0.5))
    pose = ambf_client.Pose(ambf_client.Point(2.0, 1.0, 0.5), ambf_client.Quaternion())
    needle.set_pose(pose)
    assert needle.get_pose() == pytest.approx([2.0, 1.0, 0.5, 0.0, 0.0, 0.0])
    needle.set_linear_vel(0.0, 0.1, 0.0)
    client.step(100)
    assert needle.get_pos().y == pytest.approx(1.01, abs=1e-4)
    assert needle.get_msg_header().seq == two_arms.world.step_index
    # reset_bodies puts the bodies back where they were when the client was made.
    client.get_world_handle().reset_bodies()
    assert arm.get_all_joint_pos() == pytest.approx([0.0, 0.0], abs=1e-6)
    assert needle.get_pos().x < 1.0


def test_sensor_and_actuator_handles():
    world = ambfplus.World()
    post = world.add_body("post", "box", size=(0.1, 0.1, 1.0), mass=0.0)
    at = ambfplus.make_pose
    world.add_body("target", "box", size=(0.2, 0.2, 0.2), mass=0.0, pose=at((1, 0, 0)))
    part = world.add_body("part", "sphere", radius=0.03, mass=0.2, pose=at((0, 2, 0.9)))
    gripper = world.add_body("gripper", "box", size=(0.1, 0.1, 0.1), mass=0.0, pose=at((0, 2, 1)))
    world.add_sensor("range", post, range=2.0)
    world.add_actuator("grasp", gripper)
    world.step(1)
    client = Client(simulator=world.simulator)
    sensor = client.get_obj_handle("range")
    assert isinstance(sensor, ambf_client.SensorHandle)
    assert sensor.get_count() == 1 and sensor.is_triggered(0)
    assert sensor.get_sensed_object(0) == "target"
    assert sensor.get_range(0) == 2.0
    assert sensor.get_measurement(0) == pytest.approx(1 - 0.9 / 2.0, abs=1e-3)
    assert sensor.get_parent() == "post"
    assert sensor.get_pose().position.x == pytest.approx(0.0)
    grasp = client.get_obj_handle("grasp")
    grasp.actuate("part")
    client.step(500)
    assert part.pose[2, 3] == pytest.approx(0.9, abs=3e-3)  # held against gravity
    grasp.deactuate()
    client.step(300)
    assert part.pose[2, 3] < 0.6


def test_ghost_handle_senses_and_the_actuator_grasps_from_it(two_arms):
    client = Client(simulator=two_arms)
    arm, jaw = client.get_obj_handle("arm1_base"), client.get_obj_handle("arm1_jaw")
    assert isinstance(jaw, ambf_client.GhostHandle)
    client.step(1)
    assert jaw.get_sensed_objects() == ["arm1_link2"]  # the link it rides on
    arm.set_joint_pos(0, 0.5)
    arm.set_joint_pos(1, -0.7)
    client.step(2000)
    assert jaw.get_sensed_objects() == ["arm1_link2", "needle"]
    client.get_obj_handle("arm1_grip").actuate_from_sensor_data("arm1_jaw")
    assert two_arms.world.get("arm1_grip").actuated_body.name == "needle"
