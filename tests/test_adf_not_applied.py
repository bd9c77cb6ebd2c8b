"""Keys AMBF reads that ambfplus does not apply are named in one warning per key and file,
with the blocks that have them; a file without them gets no such warning."""

from __future__ import annotations

import ambfplus

JOINT = """
JOINT ab:
  name: ab
  parent: BODY a
  child: BODY b
  type: revolute
  parent axis: {x: 0, y: 0, z: 1}
  child axis: {x: 0, y: 0, z: 1}
"""


def body(name: str, extra: str) -> str:
    text = f"""
BODY {name}:
  name: {name}
  mass: 1.0
  shape: box
  geometry: {{x: 0.1, y: 0.1, z: 0.1}}
"""
    return text + "".join(f"  {line}\n" for line in extra.splitlines())


def load(tmp_path, caplog, body_extra: dict[str, str], joint_extra: str = ""):
    text = "bodies: [BODY a, BODY b, BODY c, BODY d, BODY e]\njoints: [JOINT ab]\n"
    text += "".join(body(n, body_extra.get(n, "")) for n in "abcde")
    text += JOINT + (f"  {joint_extra}\n" if joint_extra else "")
    path = tmp_path / "model.yaml"
    path.write_text(text)
    world = ambfplus.World()
    with caplog.at_level("WARNING"):
        world.load_adf(path)
    return world, [r.getMessage() for r in caplog.records]


def test_keys_read_but_not_applied_are_one_warning_each_naming_the_blocks(tmp_path, caplog):
    extra = {n: "use material: false" for n in "abcde"}
    extra["a"] += "\ncontroller: {linear: {P: 10, I: 0, D: 1}}"
    world, warnings = load(tmp_path, caplog, extra, joint_extra="enable feedback: true")
    assert len([b for b in "abcde" if world.get(b)]) == 5, "the file still loads whole"
    material = [w for w in warnings if "'use material'" in w]
    assert len(material) == 1, warnings
    assert "BODY a, BODY b, BODY c and 2 more" in material[0] and "not applied" in material[0]
    controller = [w for w in warnings if "'controller'" in w]
    assert len(controller) == 1 and "BODY a is read" in controller[0], warnings
    feedback = [w for w in warnings if "'enable feedback'" in w]
    assert len(feedback) == 1 and "JOINT ab" in feedback[0], warnings


def test_a_file_without_such_keys_has_no_such_warning(tmp_path, caplog):
    _, warnings = load(tmp_path, caplog, {})
    assert not [w for w in warnings if "not applied" in w], warnings
