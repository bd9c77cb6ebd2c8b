"""Packaging: one version source, a typed public API."""

from __future__ import annotations

import ast
import importlib.metadata
import re
from pathlib import Path

from helpers import REPO

import ambfplus
from ambfplus import _core

ROOT = REPO


def test_version_comes_from_pyproject():
    text = (ROOT / "pyproject.toml").read_text()
    declared = re.search(r'^version = "([^"]+)"', text, re.M).group(1)
    assert ambfplus.__version__ == declared
    assert importlib.metadata.version("ambfplus") == declared


def test_public_names_exist_and_are_documented():
    for name in ambfplus.__all__:
        assert hasattr(ambfplus, name), name
    for cls in (ambfplus.World, ambfplus.Camera, ambfplus.Frame):
        assert cls.__doc__


def test_stubs_cover_the_extension_module():
    stub = Path(ambfplus.__file__).parent / "_core.pyi"
    assert (Path(ambfplus.__file__).parent / "py.typed").exists()
    tree = ast.parse(stub.read_text())
    declared = {n.name for n in tree.body if isinstance(n, (ast.ClassDef, ast.FunctionDef))}
    declared |= {t.id for n in tree.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    public = {n for n in dir(_core) if not n.startswith("_")} | {"__version__"}
    assert public <= declared | {"__version__"}, public - declared
    # Every method and property of the bound classes appears in its stub class.
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}

    def members(node):  # with those of stub base classes; a plain property may be a field
        own = {m.name for m in node.body if isinstance(m, ast.FunctionDef)}
        own |= {m.target.id for m in node.body if isinstance(m, ast.AnnAssign)}
        for base in node.bases:
            if isinstance(base, ast.Name) and base.id in classes:
                own |= members(classes[base.id])
        return own

    for name, node in classes.items():
        if not hasattr(_core, name):
            continue  # a stub-only helper
        declared_members = members(node)
        for attr, value in vars(getattr(_core, name)).items():
            if attr.startswith("_") and attr not in ("__getitem__", "__contains__", "__len__"):
                continue
            if callable(value) or isinstance(value, property):
                assert attr in declared_members, f"{name}.{attr} missing from _core.pyi"
