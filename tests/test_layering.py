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


# The areas built on the scene: the scene names none of their headers, public or private; it
# forward-declares what it must name (DESIGN.md: scene is the ground floor).
ABOVE_SCENE = {"adf", "audio", "engine", "haptics", "physics", "plugin", "render"}


def area_of(header: str) -> str:
    """The engine area an include names: "ambfplus/render/x.h" and "render/x.h" are render's."""
    parts = header.split("/")
    if parts[0] == "ambfplus" and len(parts) > 2:
        return parts[1]
    return parts[0] if len(parts) > 1 else ""


def test_scene_is_the_ground_floor():
    require_checkout()
    scene = sources(ROOT / "cpp" / "include" / "ambfplus" / "scene") + sources(
        ROOT / "cpp" / "src" / "scene"
    )
    assert scene, "no scene sources found"
    bad = [
        f"{p.relative_to(ROOT)}:{n}: {h}"
        for p in scene
        for n, quote, h in includes(p)
        if quote == '"' and area_of(h) in ABOVE_SCENE
    ]
    assert not bad, "scene includes the headers of areas built on it:\n" + "\n".join(bad)


def resolve_include(path: Path, header: str) -> Path | None:
    """The engine file an include names: public headers under cpp/include, private ones under
    cpp/src, else beside the including file; None for anything outside the engine."""
    for base in (ROOT / "cpp" / "include", ROOT / "cpp" / "src", path.parent):
        candidate = base / header
        if candidate.is_file():
            return candidate.resolve()
    return None


def include_cycle(files: list[Path]) -> list[Path] | None:
    """The first include cycle among these files (a path that ends where it began), or None."""
    graph = {}
    for path in files:
        targets = (resolve_include(path, h) for _, quote, h in includes(path) if quote == '"')
        graph[path.resolve()] = [t for t in targets if t is not None]
    state = {}  # 1: on the current path, 2: finished
    path_stack: list[Path] = []

    def visit(node: Path) -> list[Path] | None:
        state[node] = 1
        path_stack.append(node)
        for target in graph.get(node, []):
            if state.get(target) == 1:
                return path_stack[path_stack.index(target) :] + [target]
            if target not in state:
                found = visit(target)
                if found:
                    return found
        path_stack.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


def test_engine_headers_include_no_cycle():
    require_checkout()
    files = sources(ROOT / "cpp" / "include") + sources(ROOT / "cpp" / "src")
    cycle = include_cycle(files)
    assert cycle is None, "include cycle:\n  " + "\n  -> ".join(
        str(p.relative_to(ROOT.resolve())) for p in cycle
    )


# A bound class's methods come from the binding file of its header's area (bindings mirror the
# public headers: py_scene.cpp binds what cpp/include/ambfplus/scene declares).
BINDS = re.compile(r"(?:\bbound|py::class_)<\s*([A-Za-z_]\w*)")


def declaring_area(name: str) -> str | None:
    # An exported definition at namespace scope (nested classes are indented; plugin.h's
    # header-only wrappers are not the engine's classes).
    declaration = re.compile(rf"^(?:class|struct)\s+AMBFPLUS_API\s+{name}\b[^;\n]*\{{", re.M)
    for header in sources(ROOT / "cpp" / "include" / "ambfplus"):
        if declaration.search(header.read_text(encoding="utf-8")):
            return header.parent.name
    return None


def test_bindings_mirror_the_public_headers():
    require_checkout()
    bad, seen = [], {}
    for path in sources(ROOT / "bindings"):
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            for name in BINDS.findall(line):
                area = seen.setdefault(name, declaring_area(name))
                if area is not None and path.name != f"py_{area}.cpp":
                    bad.append(f"{path.relative_to(ROOT)}:{number}: {name} ({area}/)")
    assert not bad, "classes bound outside their area's py_<area>.cpp:\n" + "\n".join(bad)


def test_benchmarks_are_not_in_the_shipped_module():
    core = pytest.importorskip("ambfplus._core")
    leaked = [name for name in dir(core) if name.startswith("_benchmark_")]
    assert not leaked, f"benchmark entry points in ambfplus._core: {leaked}"
