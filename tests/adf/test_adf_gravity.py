"""A body's `gravity` and a model's `gravity` (AMBF 2.0 reads both) are applied: the body falls
with its own gravity, the model's bodies without one with the model's, and the world's gravity,
now or set later, moves only the others. From Python it is add_body's `gravity`."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus


def body(name: str, z: float, extra: str = "") -> str:
    text = f"""
BODY {name}:
  name: {name}
  mass: 1.0
  shape: sphere
  geometry: {{radius: 0.05}}
  damping: {{linear: 0, angular: 0}}
  location: {{position: {{x: {z}, y: 0, z: {z}}}}}
"""
    return text + (f"  {extra}\n" if extra else "")


def load(tmp_path, name: str, text: str) -> ambfplus.World:
    path = tmp_path / name
    path.write_text(text)
    world = ambfplus.World()
    world.load_adf(path)
    return world


def dropped(world: ambfplus.World, name: str, seconds: float = 0.5) -> np.ndarray:
    """How far name moved (x, y, z) while the world stepped seconds."""
    start = world.get(name).pose[:3, 3].copy()
    world.step(round(seconds / 0.001))
    return world.get(name).pose[:3, 3] - start


def test_a_body_gravity_and_a_model_gravity_are_applied(tmp_path):
    text = "bodies: [BODY own, BODY plain]\ngravity: {x: 0, y: 0, z: 0}\n"
    text += body("own", 1.0, "gravity: {x: 0, y: 0, z: 2.0}") + body("plain", 3.0)
    world = load(tmp_path, "model.yaml", text)
    own, plain = world.get("own"), world.get("plain")
    start_own, start_plain = own.pose[:3, 3].copy(), plain.pose[:3, 3].copy()
    world.step(500)
    # Up at 2 m/s^2 for 0.5 s: 0.25 m; the model's zero gravity keeps the other still.
    assert own.pose[:3, 3] - start_own == pytest.approx([0, 0, 0.25], abs=2e-3)
    assert plain.pose[:3, 3] - start_plain == pytest.approx([0, 0, 0], abs=1e-6)
    world.gravity = (0, 0, -20)  # leaves both alone
    start_own, start_plain = own.pose[:3, 3].copy(), plain.pose[:3, 3].copy()
    v = 2.0 * 0.5
    world.step(500)
    assert own.pose[2, 3] - start_own[2] == pytest.approx(v * 0.5 + 0.25, abs=3e-3)
    assert plain.pose[:3, 3] - start_plain == pytest.approx([0, 0, 0], abs=1e-6)


def test_a_model_without_gravity_falls_with_the_world(tmp_path):
    world = load(tmp_path, "model.yaml", "bodies: [BODY plain]\n" + body("plain", 3.0))
    assert dropped(world, "plain") == pytest.approx([0, 0, -0.5 * 9.8 * 0.25], abs=5e-3)


def test_python_add_body_takes_its_own_gravity():
    world = ambfplus.World()
    world.add_body("b", shape="sphere", radius=0.05, linear_damping=0, gravity=(1.0, 0, 0))
    assert dropped(world, "b") == pytest.approx([0.5 * 1.0 * 0.25, 0, 0], abs=2e-3)
    with pytest.raises(ambfplus.ArgumentError, match="gravity"):
        world.add_body("c", shape="sphere", radius=0.05, gravity=(0, 0, float("nan")))


def test_body_gravity_must_be_finite_in_a_file(tmp_path):
    text = "bodies: [BODY own]\n" + body("own", 1.0, "gravity: {x: 0, y: 0, z: .nan}")
    path = tmp_path / "model.yaml"
    path.write_text(text)
    with pytest.raises(ambfplus.ConfigError, match="gravity"):
        ambfplus.World().load_adf(path)
