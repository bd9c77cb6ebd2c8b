"""The source tree keeps its layering (DESIGN.md, Layout): the engine knows nothing of Python,
each area of the engine reaches another only through its public headers, and bindings and
plugins include public headers only. A file that breaks a rule is named with its line."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')

# Private headers an area may use from another area, each with its reason. Everything else
# crosses areas through cpp/include/ambfplus/<area>/.
ALLOWED_PRIVATE = {
    # The voxel collider reads the grid through the volume's inlined accessors (1 kHz path).
    ("haptics", "volume/grid_access.h"),
}


def includes(path: Path):
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        match = INCLUDE.match(line)
        if match:
            yield number, match.group(1), match.group(2)


def sources(folder: Path):
    return sorted(p for p in folder.rglob("*") if p.suffix in {".h", ".hpp", ".cpp", ".cc"})


def require_checkout():
    if not (ROOT / "cpp" / "src").is_dir():
        pytest.skip("needs the source checkout (cpp/src), not an installed package alone")


def test_the_engine_includes_no_python():
    require_checkout()
    bad = [
        f"{p.relative_to(ROOT)}:{n}: {h}"
        for p in sources(ROOT / "cpp")
        for n, _, h in includes(p)
        if h.startswith("pybind11") or h == "Python.h"
    ]
    assert not bad, "the engine must not include pybind11 or Python:\n" + "\n".join(bad)


def test_engine_areas_reach_each_other_through_public_headers():
    require_checkout()
    src = ROOT / "cpp" / "src"
    areas = {p.name for p in src.iterdir() if p.is_dir()}
    bad = []
    for area in sorted(areas):
        for path in sources(src / area):
            for number, _, header in includes(path):
                first = header.split("/", 1)[0]
                if "/" not in header or first == "ambfplus" or first not in areas:
                    continue
                if first in {area, "util"} or (area, header) in ALLOWED_PRIVATE:
                    continue
                bad.append(f"{path.relative_to(ROOT)}:{number}: {header}")
    assert not bad, "private headers of another area:\n" + "\n".join(bad)


def test_scene_owns_no_render_or_physics_internals():
    require_checkout()
    bad = [
        f"{p.relative_to(ROOT)}:{n}: {h}"
        for p in sources(ROOT / "cpp" / "src" / "scene")
        for n, _, h in includes(p)
        if h.split("/", 1)[0] in {"render", "physics"}
    ]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("folder", ["bindings", "plugins"])
def test_bindings_and_plugins_include_public_headers_only(folder):
    require_checkout()
    root = ROOT / folder
    own = {p.name for p in sources(root)}
    bad = [
        f"{p.relative_to(ROOT)}:{n}: {h}"
        for p in sources(root)
        for n, quote, h in includes(p)
        if quote == '"' and not h.startswith("ambfplus/") and Path(h).name not in own
    ]
    assert not bad, f"{folder} may include only cpp/include/ambfplus/... :\n" + "\n".join(bad)
