"""Virtual fixtures: forbidden regions around a drill's structures (force law, hard stop,
passivity), their configuration from Python and from a DRILL block, and the critical-distance
report that reads the same distance fields."""

from __future__ import annotations

import gc
import math
import os
import signal
import textwrap
import time

import numpy as np
import pytest

import ambfplus
from ambfplus.scenes import drilling_phantom

UP = ambfplus.rotation_between((1, 0, 0), (0, 0, 1))  # shaft straight up, burr at the bottom
VOXEL = 0.0002


def nerve_data(bone: bool, wide: bool = True) -> ambfplus.VolumeData:
    """A 20 mm cube at 0.2 mm voxels with a nerve (label 2, critical) whose top voxel centres
    are at z = -2.1 mm; with bone (label 1) below z = 0 when asked, else in air."""
    grid = np.zeros((100, 100, 100), np.uint8)
    if bone:
        grid[:, :, :50] = 1
    span = slice(20, 80) if wide else slice(45, 55)
    grid[span, span, 30:40] = 2
    table = [ambfplus.Label(1, "Bone"), ambfplus.Label(2, "Nerve", critical=True)]
    return ambfplus.VolumeData(grid, voxel_size=(VOXEL,) * 3, label_table=table)


def nerve_world(bone: bool, wide: bool = True, **options):
    world = ambfplus.World()
    volume = world.add_volume("bone", nerve_data(bone, wide))
    options.setdefault("pose", ambfplus.make_pose((0, 0, 0.01), rotation=UP))
    drill = world.add_drill("drill", volume, burr=1, **options)
    return world, drill


def surface_distance(z: float) -> float:
    """The 2 mm burr's surface distance to the nerve with its centre at height z above the
    nerve's middle: to the top voxel centres, less the radius and half a voxel."""
    return z + 0.0021 - 0.001 - VOXEL / 2


def test_the_fixture_pushes_away_with_the_force_law_and_only_below_start():
    world, drill = nerve_world(bone=False, cursors=1)
    drill.set_fixture("Nerve", start=0.002, max_force=3.0)
    for z in (0.002, 0.0005, 0.0, -0.0005, -0.0009):
        drill.pose = ambfplus.make_pose((0.0003, -0.0002, z), rotation=UP)  # at rest there
        world.step()
        d = surface_distance(z)
        expected = 3.0 * (1 - d / 0.002) if d < 0.002 else 0.0
        np.testing.assert_allclose(drill.fixture_force, (0, 0, expected), atol=1e-6)
        np.testing.assert_allclose(drill.force, drill.fixture_force, atol=1e-12)
        assert drill.critical_distances["Nerve"] == pytest.approx(d, abs=1e-9)
    drill.set_fixture("Nerve", start=0.002, max_force=3.0, enabled=False)
    world.step()
    assert not drill.fixture_force.any()


def test_the_fixture_force_is_a_step_log_column():
    world, drill = nerve_world(bone=False, cursors=1)
    drill.set_fixtures([{"structure": 2, "start": 0.002, "max_force": 3.0}])
    drill.pose = ambfplus.make_pose((0, 0, 0.0), rotation=UP)
    world.start_step_log([drill])
    world.step(3)
    log = world.take_step_log()
    world.stop_step_log()
    column = log["drill.fixture_force"]
    np.testing.assert_allclose(column[-1], drill.fixture_force)
    assert column[-1][2] == pytest.approx(1.5, abs=1e-6)


def plunge_slab(stop: float | None):
    """A plunge from 8 mm above the bone to 3 mm beneath the nerve's top, on for 1.3 s."""
    world, drill = nerve_world(bone=True, wide=False, cutting_rate=2e-6, stiffness=2000.0)
    if stop is not None:
        drill.set_fixture("Nerve", start=0.002, max_force=1.0, stop=stop)
    r = drill.burr_radius
    drill.set_waypoints(
        [
            {"time": 0.0, "pose": ambfplus.make_pose((0, 0, 0.008), rotation=UP), "on": True},
            {"time": 1.0, "pose": ambfplus.make_pose((0, 0, r - 0.0051), rotation=UP), "on": True},
            {"time": 1.3, "pose": ambfplus.make_pose((0, 0, r - 0.0051), rotation=UP), "on": True},
        ]
    )
    closest = np.inf
    for _ in range(130):
        world.step(10)
        closest = min(closest, drill.critical_distances["Nerve"])
    return drill, closest


def test_a_hard_stop_holds_the_burr_at_its_distance_and_cuts_no_nerve():
    drill, closest = plunge_slab(stop=0.001)
    removed = drill.take_removed()
    assert len(removed["label"]) > 200, "it drilled the bone down to the stop"
    assert not (removed["label"] == 2).any()
    assert drill.take_events() == []
    assert closest == pytest.approx(0.001, abs=0.0002)
    assert drill.critical_distances["Nerve"] == pytest.approx(0.001, abs=0.0002)
    # The hand is 3 mm further down: the stop's spring pushes it back up.
    assert drill.fixture_force[2] > 1.0


def test_without_the_fixture_the_same_plunge_cuts_the_nerve():
    drill, closest = plunge_slab(stop=None)
    assert (drill.take_removed()["label"] == 2).any()
    assert closest == 0.0


FACIAL_NERVE = 10  # the phantom's label id (the original system's)


def phantom_plunge(fixture: bool):
    """The 4 mm burr driven straight down onto the facial nerve's descending segment of the
    built-in phantom (x = 1 mm, y = -11 mm; its top at z = -2.8 mm), 5 mm past its top, through
    17 mm of mastoid over 6 s."""
    scene = drilling_phantom(resolution=128)
    world, drill = scene.world, scene.drill
    drill.burr = 2
    if fixture:
        drill.set_fixtures(
            [{"structure": "Facial_Nerve", "start": 0.002, "max_force": 1.5, "stop": 0.001}]
        )
    above = ambfplus.make_pose((0.001, -0.011, 0.017), rotation=UP)
    below = ambfplus.make_pose((0.001, -0.011, -0.008), rotation=UP)
    drill.set_waypoints(
        [
            {"time": 0.3, "pose": above, "on": False},
            {"time": 0.4, "pose": above, "on": True},
            {"time": 6.4, "pose": below, "on": True},
            {"time": 6.8, "pose": below, "on": True},
        ]
    )
    closest = np.inf
    for _ in range(680):
        world.step(10)
        closest = min(closest, drill.critical_distances["Facial_Nerve"])
    return drill, closest


@pytest.mark.parametrize("fixture", [True, False], ids=["fixture-on", "fixture-off"])
def test_a_scripted_drill_pushed_toward_the_facial_nerve(fixture):
    drill, closest = phantom_plunge(fixture)
    labels = drill.take_removed()["label"]
    assert (labels == 1).sum() > 300, "it drilled through the bone above the nerve"
    if fixture:
        assert closest == pytest.approx(0.001, abs=0.0002)
        assert drill.critical_distances["Facial_Nerve"] == pytest.approx(0.001, abs=0.0002)
        assert not (labels == FACIAL_NERVE).any(), "no nerve voxel is removed"
    else:
        assert closest == 0.0
        assert (labels == FACIAL_NERVE).any(), (
            "without the fixture the same script reaches the nerve"
        )


def push_into_fixture(speed: float, passive: bool):
    """A hand (50 g on a 1000 N/m spring to a reference, no damping anywhere) moved at `speed`
    into a stiff fixture (4 N over 1 mm), held there, and moved back out. The device's force is
    held over each 1 ms tick while the hand moves exactly (the spring and mass in closed form).
    Returns the hand's mechanical energy (kinetic, spring, the fixture's potential) over the
    hold's first and last 150 ms, its positions over the same windows, and the net work the
    drill did on the hand over the whole push and return."""
    world, drill = nerve_world(bone=False, cursors=1)
    drill.fixture_passivity = passive
    drill.set_fixture("Nerve", start=0.001, max_force=4.0)
    mass, k_user, dt = 0.05, 1000.0, world.time_step
    omega = math.sqrt(k_user / mass)
    cos, sin = math.cos(omega * dt), math.sin(omega * dt)
    top, deep = 0.003, -0.002  # the reference's ends: 4 mm and -1 mm from the nerve
    ramp = int(round((top - deep) / speed / dt))
    hold = 600
    refs = np.concatenate(
        [
            np.linspace(top, deep, ramp),
            np.full(hold, deep),
            np.linspace(deep, top, ramp),
            np.full(300, top),
        ]
    )
    x, v = top, 0.0
    drill.pose = ambfplus.make_pose((0, 0, x), rotation=UP)
    work, xs, energy = 0.0, [], []
    for ref in refs:
        drill.goal = ambfplus.make_pose((0, 0, x), rotation=UP)
        world.step()
        force = float(drill.force[2])
        rest = ref + force / k_user  # where the spring and the held force balance
        x_next = rest + (x - rest) * cos + v / omega * sin
        v = -(x - rest) * omega * sin + v * cos
        work += force * (x_next - x)
        x = x_next
        xs.append(x)
        d = min(max(surface_distance(x), 0.0), 0.001)
        stored = 4.0 * (0.001 - d) ** 2 / (2 * 0.001)
        energy.append(0.5 * mass * v * v + 0.5 * k_user * (ref - x) ** 2 + stored)
    early, late = slice(ramp + 50, ramp + 200), slice(ramp + hold - 150, ramp + hold)
    xs, energy = np.asarray(xs), np.asarray(energy)
    return energy[early], energy[late], xs[early], xs[late], work


@pytest.mark.parametrize("speed", [0.01, 0.05])
def test_pushing_into_a_fixture_gains_no_energy(speed):
    e_early, e_late, x_early, x_late, work = push_into_fixture(speed, passive=True)
    assert e_late.max() <= e_early.max() * 1.01, "the held hand's energy does not grow"
    assert np.ptp(x_late) <= np.ptp(x_early) * 1.01 + 1e-7, "its oscillation does not grow"
    assert x_late.min() > -0.0011, "the hand stays out of the nerve"
    assert work <= 1e-5, "over the push and the return the drill gave the hand no energy"


def test_without_passivity_control_the_sampled_fixture_pumps_energy():
    # The same push with the controller off: the checks above can fail.
    e_early, e_late, x_early, x_late, work = push_into_fixture(0.05, passive=False)
    assert e_late.max() > 2 * e_early.max()
    assert np.ptp(x_late) > 2 * np.ptp(x_early)


def test_fixtures_from_python_round_trip_and_bad_values_are_refused():
    world, drill = nerve_world(bone=False)
    assert drill.fixtures == []
    drill.set_fixtures(
        [
            {"structure": "Nerve", "start": 0.002, "max_force": 1.5, "stop": 0.0005},
            {"structure": 1, "start": 0.001, "enabled": False},
        ]
    )
    assert drill.fixtures == [
        {"structure": "Nerve", "start": 0.002, "max_force": 1.5, "stop": 0.0005, "enabled": True},
        {"structure": "Bone", "start": 0.001, "max_force": 1.0, "stop": None, "enabled": False},
    ]
    drill.set_fixture("Nerve", start=0.003, max_force=2.0)  # replaces the nerve's
    assert drill.fixtures[0] == {
        "structure": "Nerve",
        "start": 0.003,
        "max_force": 2.0,
        "stop": None,
        "enabled": True,
    }
    with pytest.raises(ValueError, match="start must be > 0"):
        drill.set_fixture("Nerve", start=-0.001)
    with pytest.raises(KeyError, match="Nerf"):
        drill.set_fixture("Nerf", start=0.001)
    with pytest.raises(TypeError, match=r"fixtures\[0\].*'force'"):
        drill.set_fixtures([{"structure": "Nerve", "start": 0.001, "force": 2.0}])
    with pytest.raises(ValueError, match=r"fixtures\[0\].*needs a start"):
        drill.set_fixtures([{"structure": "Nerve"}])
    with pytest.raises(ValueError, match="two fixtures"):
        drill.set_fixtures([{"structure": "Nerve", "start": 0.001}, {"structure": 2, "start": 1}])
    assert len(drill.fixtures) == 2, "a refused list changes nothing"
    drill.set_fixtures([])
    assert drill.fixtures == []


def adf_world(tmp_path, fixtures: str):
    data = nerve_data(bone=True)
    data.save_slice_stack(tmp_path / "slab")
    ambfplus.write_label_table(tmp_path / "slab" / "labels.csv", data.label_table)
    path = tmp_path / "drill.yaml"
    path.write_text(
        textwrap.dedent(
            """
            volumes: [VOLUME slab]
            VOLUME slab:
              name: slab
              location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0.0, p: 0.0, y: 0.0}}
              dimensions: {x: 0.02, y: 0.02, z: 0.02}
              images: {path: slab/, prefix: plane, format: png, count: 100}
              labels: slab/labels.csv
            drills: [DRILL burr]
            DRILL burr:
              name: burr
              volume: VOLUME slab
              burr: 1
            """
        )
        + textwrap.indent(fixtures, "  ")
    )
    world = ambfplus.World()
    world.load_adf(path)
    return world


def test_a_drill_block_sets_fixtures(tmp_path):
    world = adf_world(
        tmp_path,
        "fixtures:\n"
        "  - {structure: Nerve, start: 0.002, max force: 1.5, stop: 0.0005}\n"
        "  - {structure: 1, start: 0.001, enabled: false}\n",
    )
    (drill,) = world.drills
    assert drill.fixtures == [
        {"structure": "Nerve", "start": 0.002, "max_force": 1.5, "stop": 0.0005, "enabled": True},
        {"structure": "Bone", "start": 0.001, "max_force": 1.0, "stop": None, "enabled": False},
    ]
    # What drill.fixtures gives, set_fixtures takes back unchanged.
    drill.set_fixtures(drill.fixtures)
    assert drill.fixtures[0]["stop"] == 0.0005


@pytest.mark.parametrize(
    ("fixtures", "message"),
    [
        (
            "fixtures:\n  - {structure: Nerve, start: 0.002, force: 1.5}\n",
            r"fixtures\[0\].*'force'",
        ),
        ("fixtures:\n  - {structure: Nerve, start: -1}\n", r"fixtures\[0\].*start must be > 0"),
        ("fixtures:\n  - {structure: Nerf, start: 0.001}\n", "Nerf"),
        ("fixtures: {structure: Nerve}\n", "fixtures"),
    ],
)
def test_a_bad_fixture_in_a_drill_block_names_the_key(tmp_path, fixtures, message):
    with pytest.raises(ambfplus.ConfigError, match=message) as error:
        adf_world(tmp_path, fixtures)
    assert "drill.yaml" in str(error.value)


def test_critical_distances_follow_the_drilling():
    """The report against a brute-force distance to the nerve voxels left: never more (a field
    rebuilt after a cut into the nerve is taken 50 ticks later, the old one a lower bound till
    then), and equal once the burr has rested for longer than that."""
    world, drill = nerve_world(bone=True, wide=False, cutting_rate=2e-6, stiffness=2000.0)
    data = drill.volume.data
    r = drill.burr_radius
    bottom = ambfplus.make_pose((0, 0, r - 0.0035), rotation=UP)
    drill.set_waypoints(
        [
            {"time": 0.0, "pose": ambfplus.make_pose((0, 0, 0.008), rotation=UP), "on": True},
            {"time": 1.0, "pose": bottom, "on": True},
            {"time": 1.2, "pose": bottom, "on": False},
        ]
    )
    c = (np.arange(100) + 0.5 - 50) * VOXEL

    def brute_force():
        nerve = np.argwhere(np.asarray(data.labels) == 2)
        centre = drill.cursor_proxies[0]
        return max(0.0, np.sqrt(((c[nerve] - centre) ** 2).sum(axis=1)).min() - r - VOXEL / 2)

    checked = 0
    for _ in range(24):
        world.step(50)
        expected, got = brute_force(), drill.critical_distances["Nerve"]
        # Trilinear between exact voxel-centre values: within a tenth of a voxel, and within
        # half a voxel where the burr's centre is a voxel from the nerve's face (the signed
        # field's zero is there, halfway between the last voxel centres).
        tolerance = VOXEL / 10 if expected > VOXEL else VOXEL / 2
        assert got <= expected + tolerance
        if expected < 0.005:
            checked += 1
        else:
            assert got >= 0.005, "beyond the exact reach: a lower bound of at least 5 mm"
    assert checked >= 5
    assert (drill.take_removed()["label"] == 2).any(), "the check went on as the nerve was cut"
    world.step(60)  # the burr off and still for longer than a rebuild takes to be due
    assert drill.critical_distances["Nerve"] == pytest.approx(brute_force(), abs=VOXEL / 2)
    drill.goal = ambfplus.make_pose((0, 0, 0.004), rotation=UP)  # lifted out of the hole
    world.step(5)
    assert drill.critical_distances["Nerve"] == pytest.approx(brute_force(), abs=VOXEL / 10)


def test_a_forked_child_follows_its_cuts_and_exits():
    """A process forked after its drill's fields were built (a DataLoader's or a pool's worker)
    drills a structure, waits for its fields' updates and exits: the background worker of the
    parent does not run in the child, which must neither wait for it nor join it."""
    world, drill = nerve_world(bone=True, wide=False, cutting_rate=2e-6, stiffness=2000.0)
    r = drill.burr_radius
    pid = os.fork()
    if pid == 0:  # the child: only os._exit, never pytest's teardown
        code = 1
        try:
            drill.set_waypoints([
                {"time": 0.0, "pose": ambfplus.make_pose((0, 0, 0.008), rotation=UP), "on": True},
                {"time": 1.0, "pose": ambfplus.make_pose((0, 0, r - 0.0051), rotation=UP),
                 "on": True},
            ])  # fmt: skip
            world.step(1300)
            labels = drill.removed["label"]
            code = 0 if (labels == 2).sum() > 0 and drill.critical_distances["Nerve"] == 0 else 2
            del drill, world
            gc.collect()
        finally:
            os._exit(code)
    deadline = time.monotonic() + 120
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            pytest.fail("the forked child hung")
        time.sleep(0.05)
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0, status
