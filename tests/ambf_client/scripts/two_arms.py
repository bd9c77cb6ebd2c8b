"""A script written for AMBF's Python client, using AMBF's names only: it poses two arms by
joint index and by joint name, reads their links' poses, grasps the needle once the ghost on the
first arm's jaw senses it, and carries it away. It runs unchanged in lock-step and in real time:
update() steps the world when the client is lock-stepped, and time passes while it sleeps when
the simulator runs by itself."""

import time

from ambf_client import Client

client = Client("two_arms")
client.connect()
world = client.get_world_handle()
world.set_num_step_skips(10)
arm1 = client.get_obj_handle("arm1_base")
arm2 = client.get_obj_handle("arm2_base")
jaw = client.get_obj_handle("arm1_jaw")
grip = client.get_obj_handle("arm1_grip")


def wait_for(targets, timeout=20.0):
    """Until every arm's joints are at their targets (arm handle -> positions)."""
    start = time.time()
    while True:
        errors = [
            abs(q - t)
            for arm, goal in targets.items()
            for q, t in zip(arm.get_all_joint_pos(), goal)
        ]
        if max(errors) < 2e-3:
            return
        if time.time() - start > timeout:
            raise RuntimeError(f"the joints did not reach their targets: {errors}")
        world.update()
        time.sleep(0.005)


# The first arm by index, the second by name.
arm1.set_joint_pos(0, 0.5)
arm1.set_joint_pos(1, -0.7)
names = arm2.get_joint_names()
arm2.set_joint_pos(names[0], -0.4)
arm2.set_joint_pos("arm2_link1-link2", 0.9)
wait_for({arm1: [0.5, -0.7], arm2: [-0.4, 0.9]})

joints = {"arm1": arm1.get_all_joint_pos(), "arm2": arm2.get_all_joint_pos()}
links = {}
for arm in ("arm1", "arm2"):
    for link in ("link1", "link2"):
        links[f"{arm}_{link}"] = client.get_obj_handle(f"{arm}_{link}").get_pose()

sensed = jaw.get_sensed_objects()
if "needle" in sensed:
    grip.actuate("needle")

# Carry it: swing the first arm's base joint back, by name.
arm1.set_joint_pos(arm1.get_joint_name_from_idx(0), 0.0)
wait_for({arm1: [0.0, -0.7]})
needle = client.get_obj_handle("needle").get_pos()
jaw_pos = jaw.get_pos()
carried = {"needle": (needle.x, needle.y, needle.z), "jaw": (jaw_pos.x, jaw_pos.y, jaw_pos.z)}
sim_step = jaw.get_sim_step()
client.clean_up()
