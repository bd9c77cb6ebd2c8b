"""Multi-axis joints from AMBF files: six dof spring joints with stiffness, damping, equilibrium
point and limits per axis (Bullet's generic six-dof spring constraint) against an analytic
spring-damper, a chain of ten that sags to its analytic equilibrium and settles with the damping
given, six dof and cone twist limits, and revolute limits with low > high (free, as Bullet
reads them, with a warning)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import ambfplus

G = 9.8


def xyz(x=0.0, y=0.0, z=0.0) -> str:
    return f"{{x: {x}, y: {y}, z: {z}}}"


def linear_angular(linear, angular) -> str:
    return f"{{linear: {xyz(*linear)}, angular: {xyz(*angular)}}}"


def six_dof_limits(linear_low, linear_high, angular_low, angular_high) -> str:
    return (
        f"{{linear: {{low: {xyz(*linear_low)}, high: {xyz(*linear_high)}}}, "
        f"angular: {{low: {xyz(*angular_low)}, high: {xyz(*angular_high)}}}}}"
    )


def sphere(name: str, z: float, mass: float) -> str:
    return (
        f"BODY {name}:\n  name: {name}\n  mass: {mass}\n  shape: sphere\n"
        f"  geometry: {{radius: 0.005}}\n  inertia: {{ix: 1e-5, iy: 1e-5, iz: 1e-5}}\n"
        f"  damping: {{linear: 0.0, angular: 0.0}}\n"
        f"  location: {{position: {xyz(0, 0, z)}, orientation: {{r: 0, p: 0, y: 0}}}}\n"
    )


def spring_joint(name: str, parent: str, child: str, pivot_z: float, k, c, limits: str) -> str:
    return (
        f"JOINT {name}:\n  name: {name}\n  parent: BODY {parent}\n  child: BODY {child}\n"
        f"  parent pivot: {xyz(0, 0, pivot_z)}\n  child pivot: {xyz()}\n"
        f"  parent axis: {xyz(0, 0, 1)}\n  child axis: {xyz(0, 0, 1)}\n"
        f"  type: six dof spring\n  joint limits: {limits}\n"
        f"  stiffness: {linear_angular(k[:3], k[3:])}\n"
        f"  damping: {linear_angular(c[:3], c[3:])}\n"
        f"  equilibrium point: {linear_angular((0, 0, 0), (0, 0, 0))}\n"
    )


def write_chain(folder: Path, count: int, mass: float, k: float, c: float, spacing=0.05) -> Path:
    """count bodies hanging below a static anchor, each on a six dof spring whose z spring
    carries it (stiffness k, damping c); the other axes have stiff springs too, and the lateral
    ones are limited."""
    names = ["anchor"] + [f"link{i}" for i in range(1, count + 1)]
    text = "bodies: [" + ", ".join(f"BODY {n}" for n in names) + "]\n"
    text += "joints: [" + ", ".join(f"JOINT j{i}" for i in range(1, count + 1)) + "]\n"
    text += sphere("anchor", 0.0, 0.0)
    for i in range(1, count + 1):
        text += sphere(names[i], -spacing * i, mass)
    stiffness = (50 * k, 50 * k, k, 0.5, 0.5, 0.5)
    damping = (c, c, c, 0.01, 0.01, 0.01)
    # z free (low > high, as Bullet reads it), x and y within 1 cm, rotations within 0.5 rad.
    limits = six_dof_limits((-0.01, -0.01, 1), (0.01, 0.01, -1), (-0.5,) * 3, (0.5,) * 3)
    for i in range(1, count + 1):
        text += spring_joint(f"j{i}", names[i - 1], names[i], -spacing, stiffness, damping, limits)
    path = folder / "chain.yaml"
    path.write_text(text)
    return path


def load(path: Path):
    world = ambfplus.World()
    world.load_adf(path)
    return world


def test_one_body_on_a_vertical_spring_matches_the_analytic_spring_damper(tmp_path):
    m, k, c = 0.5, 50.0, 1.0
    world = load(write_chain(tmp_path, 1, m, k, c))
    body = world.get("link1")
    z0 = body.pose[2, 3]
    dt = world.time_step
    steps = 3000
    z = np.empty(steps)
    for i in range(steps):
        world.step(1)
        z[i] = body.pose[2, 3] - z0
    t = dt * np.arange(1, steps + 1)
    w0 = math.sqrt(k / m)
    zeta = c / (2 * math.sqrt(k * m))
    wd = w0 * math.sqrt(1 - zeta**2)
    sag = m * G / k
    analytic = -sag + sag * np.exp(-zeta * w0 * t) * (
        np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t)
    )
    # The trajectory follows the analytic one within 3 % of the sag at every step.
    assert np.max(np.abs(z - analytic)) < 0.03 * sag
    # Period from the minima (downward peaks), and decay from their depths.
    minima = [i for i in range(1, steps - 1) if z[i] < z[i - 1] and z[i] <= z[i + 1]]
    assert len(minima) >= 4
    period = np.mean(np.diff(t[minima]))
    assert period == pytest.approx(2 * math.pi / wd, rel=0.01)
    depth = -(z[minima] + sag)
    decay = np.log(depth[0] / depth[3]) / (t[minima[3]] - t[minima[0]])
    assert decay == pytest.approx(zeta * w0, rel=0.05)
    # It ends at rest at the static sag m g / k; the locked-ish axes stayed put.
    world.step(7000)
    assert body.pose[2, 3] - z0 == pytest.approx(-sag, rel=0.005)
    assert np.linalg.norm(body.pose[:2, 3]) < 1e-4


def test_chain_of_ten_sags_to_its_analytic_equilibrium_and_settles(tmp_path):
    count, m, k, c = 10, 0.02, 20.0, 4.0
    world = load(write_chain(tmp_path, count, m, k, c))
    links = [world.get(f"link{i}") for i in range(1, count + 1)]
    rest = np.array([b.pose[2, 3] for b in links])
    # Spring i carries the links below it: its extension is (count - i + 1) m g / k.
    extension = np.array([(count - i) * m * G / k for i in range(count)])
    sag = np.cumsum(extension)
    world.step(500)
    early = rest - np.array([b.pose[2, 3] for b in links])
    assert early[-1] > 0.2 * sag[-1]  # sagging
    world.step(7500)
    z = np.array([b.pose[2, 3] for b in links])
    np.testing.assert_allclose(rest - z, sag, rtol=0.01)
    # Settled (the damping given took the motion out) and straight.
    assert max(np.linalg.norm(b.linear_velocity) for b in links) < 1e-3
    assert max(np.linalg.norm(b.pose[:2, 3]) for b in links) < 1e-4


def test_chain_without_damping_still_oscillates(tmp_path):
    """The same chain with zero damping does not settle: the damping in the file is what
    settles the other."""
    world = load(write_chain(tmp_path, 10, 0.02, 20.0, 0.0))
    world.step(8000)
    bottom = world.get("link10")
    assert np.linalg.norm(bottom.linear_velocity) > 0.05


def test_six_dof_limits_hold_each_axis(tmp_path):
    """A six dof joint (no springs) lets the body fall only as far as its z limit, while a
    sideways push is stopped by the x limit."""
    text = "bodies: [BODY anchor, BODY b]\njoints: [JOINT j]\n"
    text += sphere("anchor", 0.0, 0.0) + sphere("b", -0.05, 0.1)
    limits = six_dof_limits((-0.01, -0.02, -0.03), (0.01, 0.02, 0.03), (-0.1,) * 3, (0.1,) * 3)
    text += (
        f"JOINT j:\n  name: j\n  parent: BODY anchor\n  child: BODY b\n"
        f"  parent pivot: {xyz(0, 0, -0.05)}\n  child pivot: {xyz()}\n"
        f"  parent axis: {xyz(0, 0, 1)}\n  child axis: {xyz(0, 0, 1)}\n"
        f"  type: six dof\n  joint limits: {limits}\n"
    )
    (tmp_path / "six.yaml").write_text(text)
    world = load(tmp_path / "six.yaml")
    body = world.get("b")
    body.force = (0.5, 0.0, 0.0)
    world.step(2000)
    p = body.pose[:3, 3]
    assert p[2] == pytest.approx(-0.05 - 0.03, abs=1e-3)
    assert p[0] == pytest.approx(0.01, abs=1e-3)
    assert abs(p[1]) < 1e-3


def test_cone_twist_limits_stop_the_swing(tmp_path):
    """A pendulum on a cone twist joint (axis along x, swing spans 0.3 rad) pushed sideways
    stops at the span instead of swinging up."""
    text = "bodies: [BODY anchor, BODY bob]\njoints: [JOINT j]\n"
    text += sphere("anchor", 0.0, 0.0) + sphere("bob", -0.1, 0.1)
    text += (
        f"JOINT j:\n  name: j\n  parent: BODY anchor\n  child: BODY bob\n"
        f"  parent pivot: {xyz()}\n  child pivot: {xyz(0, 0, 0.1)}\n"
        f"  parent axis: {xyz(0, 0, -1)}\n  child axis: {xyz(0, 0, -1)}\n"
        f"  type: cone twist\n  joint limits: {{x: 0.2, y: 0.3, z: 0.3}}\n"
    )
    (tmp_path / "cone.yaml").write_text(text)
    world = load(tmp_path / "cone.yaml")
    world.gravity = (0, 0, 0)
    bob = world.get("bob")
    bob.force = (1.0, 0.0, 0.0)
    world.step(3000)
    p = bob.pose[:3, 3]
    swing = math.atan2(p[0], -p[2])
    assert swing == pytest.approx(0.3, abs=0.03)


def test_revolute_limits_low_above_high_turn_freely_with_a_warning(tmp_path, caplog):
    text = "bodies: [BODY base, BODY arm]\njoints: [JOINT hinge]\n"
    text += sphere("base", 0.0, 0.0) + sphere("arm", 0.0, 0.1)
    text += (
        "JOINT hinge:\n  name: hinge\n  parent: BODY base\n  child: BODY arm\n"
        f"  parent pivot: {xyz()}\n  child pivot: {xyz()}\n"
        f"  parent axis: {xyz(0, 0, 1)}\n  child axis: {xyz(0, 0, 1)}\n"
        "  type: revolute\n  joint limits: {low: 1.0, high: -1.0}\n"
    )
    (tmp_path / "hinge.yaml").write_text(text)
    with caplog.at_level("WARNING"):
        world = load(tmp_path / "hinge.yaml")
    assert any("low > high" in r.getMessage() for r in caplog.records)
    world.gravity = (0, 0, 0)
    hinge = world.get("hinge")
    hinge.set_effort(1e-4)
    world.step(4000)
    # Past both of the values given, and still turning.
    assert hinge.position > 2 * math.pi
    assert hinge.velocity > 0.1
