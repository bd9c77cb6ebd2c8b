"""The Python package keeps its shape (DESIGN.md, Layout; STYLE.md, a package grouped by
concept): concepts are packages, the top level holds only the public facade and small
single-concept modules, no module imports another's private names, and the modules import
each other without a cycle. Imports are read from the source with ``ast`` (inside functions
too), so a failure names the module and line without importing anything."""

from __future__ import annotations

import ast
import textwrap
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "ambfplus"
ENGINE = f"{PACKAGE}._core"

# The top level: the facade (__init__, __main__) and single-concept modules. A new concept
# that needs more than one module is a package.
TOP_LEVEL_MODULES = {
    "__init__",
    "__main__",
    "config",  # checked YAML configuration: the rules every YAML file is checked by
    "ambf_client",  # AMBF's Python client, for scripts written against it
    "doctor",  # what the engine finds on this machine
    "fileio",  # writing files whole
    "labels",  # the id legend and segmentation colours
    "stereo",  # stereo rigs, stereo frames, disparity
    "transforms",  # poses and rotations
    "volumes",  # loading and converting anatomy volumes
}


@dataclass(frozen=True)
class Import:
    importer: str  # module name
    line: int
    target: str  # module name
    name: str | None  # the imported name (from X import name), else None


def module_names(root: Path, package: str = PACKAGE) -> dict[str, Path]:
    """Every module of the package under `root` by dotted name (a package by its own name)."""
    names = {}
    for path in sorted((root / package).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        names[".".join(parts)] = path
    return names


def _is_package(name: str, modules: dict[str, Path]) -> bool:
    return modules[name].name == "__init__.py"


def imports(root: Path, package: str = PACKAGE) -> list[Import]:
    """Every import of one module of the package by another, resolved to module names: `from
    X import y` is an import of X.y when that is a module, else of X's name y."""
    modules = module_names(root, package)
    known = set(modules) | {f"{package}._core"}
    found = []
    for importer, path in modules.items():
        base = importer if _is_package(importer, modules) else importer.rpartition(".")[0]
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                for alias in node.names:
                    target = alias.name
                    while target and target not in known:
                        target = target.rpartition(".")[0]
                    if target:
                        found.append(Import(importer, node.lineno, target, None))
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    anchor = base.split(".")[: len(base.split(".")) - (node.level - 1)]
                    source = ".".join(anchor + ([node.module] if node.module else []))
                else:
                    source = node.module or ""
                if source.split(".")[0] != package:
                    continue
                for alias in node.names:
                    submodule = f"{source}.{alias.name}"
                    if submodule in known:
                        found.append(Import(importer, node.lineno, submodule, None))
                    else:
                        found.append(Import(importer, node.lineno, source, alias.name))
    return found


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def private_imports(root: Path, package: str = PACKAGE) -> list[str]:
    """Imports of another module's private names, or of a private module from outside its
    package. The engine (``_core``) is everyone's; a package's __init__ may gather its own
    submodules' names."""
    modules = module_names(root, package)
    bad = []
    for i in imports(root, package):
        where = f"{modules[i.importer].relative_to(root)}:{i.line}"
        if i.target == f"{package}._core" or i.target == i.importer:
            continue
        own_package = _is_package(i.importer, modules) and i.target.startswith(i.importer + ".")
        if i.name is not None and _private(i.name) and not own_package:
            bad.append(f"{where}: imports {i.name} from {i.target}")
        # A private module (export._common) serves its own package only.
        parts = i.target.split(".")
        for depth, part in enumerate(parts):
            if _private(part) and i.target != f"{package}._core":
                owner = ".".join(parts[:depth])
                if not (i.importer == owner or i.importer.startswith(owner + ".")):
                    bad.append(f"{where}: imports the private module {i.target}")
                break
    return bad


def import_cycles(root: Path, package: str = PACKAGE) -> list[list[str]]:
    """The cycles of the import graph, one per strongly connected group of modules, each
    named as a path a -> b -> ... -> a."""
    graph: dict[str, set[str]] = {m: set() for m in module_names(root, package)}
    for i in imports(root, package):
        if i.target in graph and i.target != i.importer:
            graph[i.importer].add(i.target)
    # Tarjan's strongly connected components.
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    groups: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                groups.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return [_a_cycle(graph, set(group)) for group in groups]


def _a_cycle(graph: dict[str, set[str]], group: set[str]) -> list[str]:
    """One cycle through the group's first module (a shortest one, by breadth-first search)."""
    start = min(group)
    paths = {start: [start]}
    frontier = [start]
    while frontier:
        following = []
        for v in frontier:
            for w in sorted(graph[v] & group):
                if w == start:
                    return paths[v] + [start]
                if w not in paths:
                    paths[w] = paths[v] + [w]
                    following.append(w)
        frontier = following
    raise AssertionError(f"no cycle through {start} in {sorted(group)}")


def require_checkout():
    if not (ROOT / PACKAGE / "__init__.py").is_file():
        pytest.skip("needs the source checkout (ambfplus/), not an installed package alone")


def test_the_top_level_holds_the_facade_and_single_concept_modules_only():
    require_checkout()
    top = {p.stem for p in (ROOT / PACKAGE).glob("*.py")}
    assert top - TOP_LEVEL_MODULES == set(), (
        f"modules at the top level of {PACKAGE}/ that belong in a package: "
        f"{sorted(top - TOP_LEVEL_MODULES)}"
    )
    assert TOP_LEVEL_MODULES - top == set(), f"gone: {sorted(TOP_LEVEL_MODULES - top)}"


def test_every_folder_of_modules_is_a_package():
    require_checkout()
    bare = sorted(
        str(folder.relative_to(ROOT))
        for folder in {p.parent for p in (ROOT / PACKAGE).rglob("*.py")}
        if not (folder / "__init__.py").is_file()
    )
    assert not bare, f"folders without __init__.py (implicit namespace packages): {bare}"


def test_no_module_imports_another_modules_private_names():
    require_checkout()
    bad = private_imports(ROOT)
    assert not bad, "private names imported across modules:\n" + "\n".join(bad)


def test_the_modules_import_each_other_without_a_cycle():
    require_checkout()
    cycles = import_cycles(ROOT)
    assert not cycles, "import cycles:\n" + "\n".join(" -> ".join(c) for c in cycles)


def write_package(root: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        path = root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    return root


def test_the_checks_find_a_cycle_through_a_function_and_a_private_import(tmp_path):
    """The checks can fail: a cycle closed by an import inside a function, and private names
    taken from a sibling, are both found and named."""
    root = write_package(
        tmp_path,
        {
            "ambfplus/__init__.py": "from . import _core\nfrom .a import run\n",
            "ambfplus/a.py": "from .pkg.b import helper\n\ndef run():\n    return helper()\n",
            "ambfplus/pkg/__init__.py": "from .b import _shared, helper\n",
            "ambfplus/pkg/b.py": "def helper():\n    from ..a import run\n    return run\n",
            "ambfplus/pkg/c.py": "from .b import _shared\nfrom .._core import _engine\n",
            "ambfplus/d.py": "from .pkg._hidden import x\n",
            "ambfplus/pkg/_hidden.py": "x = 1\n",
        },
    )
    assert import_cycles(root) == [["ambfplus.a", "ambfplus.pkg.b", "ambfplus.a"]]
    bad = private_imports(root)
    assert any("pkg/c.py:1: imports _shared from ambfplus.pkg.b" in b for b in bad), bad
    assert any("d.py:1: imports the private module ambfplus.pkg._hidden" in b for b in bad), bad
    # The package's own __init__ gathering _shared, and the engine's names, are fine.
    assert not any("pkg/__init__.py" in b or "_engine" in b for b in bad), bad
    assert len(bad) == 2, bad


def test_test_files_have_unique_names():
    """Test folders have no __init__.py: pytest imports a test file by its name (its default
    "prepend" import mode), so two test files of one name in two folders would collide."""
    seen: dict[str, list[str]] = {}
    for path in sorted((ROOT / "tests").rglob("test_*.py")):
        seen.setdefault(path.name, []).append(str(path.relative_to(ROOT)))
    twice = {name: paths for name, paths in seen.items() if len(paths) > 1}
    assert not twice, f"test files sharing a name: {twice}"
