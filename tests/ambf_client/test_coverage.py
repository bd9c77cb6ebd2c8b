"""The audit of AMBF's client: every public method of every handle class is in the coverage
table and every entry of the table is a method of its handle; the docs page carries the same
table; not-applied methods raise saying why; `import ambf_client` finds ambfplus's client."""

from __future__ import annotations

import importlib.util
import inspect
import re
import sys
from pathlib import Path

import pytest

import ambfplus
from ambfplus import ambf_client
from ambfplus.ambf_client import AMBF_BASES, COVERAGE, HANDLES, expected_methods, public_methods

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs" / "reference" / "ambf-client.md"
ALIAS = ROOT / "ambfplus" / "aliases" / "ambf_client.py"
STATUSES = {"implemented", "no-op", "not applied", "extension"}


def checkout(path: Path) -> Path:
    if not path.is_file():
        pytest.skip(f"needs the source checkout ({path.relative_to(ROOT)})")
    return path


@pytest.mark.parametrize("ambf_type", sorted(HANDLES))
def test_each_handle_has_exactly_the_methods_the_table_lists(ambf_type):
    handle = HANDLES[ambf_type]
    methods, listed = public_methods(handle), expected_methods(ambf_type)
    assert methods - listed == set(), f"{handle.__name__}: methods missing from COVERAGE"
    assert listed - methods == set(), f"{handle.__name__}: COVERAGE entries with no method"


def test_the_table_is_well_formed():
    types = set(HANDLES) | {"WatchDog"}
    for key, (status, note) in COVERAGE.items():
        ambf_type, _, method = key.partition(".")
        assert ambf_type in types and method, key
        assert status in STATUSES, key
        # Anything short of implemented says why.
        assert status == "implemented" or note, key
    assert set(AMBF_BASES) == set(HANDLES)


def test_the_audit_found_what_ambf_defines():
    """Counts of AMBF's own methods per type, as audited (extensions left out): a change here
    is a change to the audit, not an accident."""
    counts: dict = {}
    for key, (status, _) in COVERAGE.items():
        if status != "extension":
            ambf_type = key.split(".")[0]
            counts[ambf_type] = counts.get(ambf_type, 0) + 1
    assert counts == {
        "Client": 18,
        "WatchDog": 3,
        "World": 12,
        "BaseObject": 25,
        "RigidBody": 40,  # and 7 of BaseObject's names it redefines
        "Sensor": 8,
        "Actuator": 3,
        "Vehicle": 12,
    }


def test_the_docs_page_carries_the_table():
    text = checkout(DOCS).read_text(encoding="utf-8")
    match = re.search(
        r"<!-- begin: coverage \(ambfplus\.ambf_client\.coverage_markdown\) -->\n(.*)"
        r"<!-- end: coverage -->",
        text,
        flags=re.DOTALL,
    )
    assert match, f"{DOCS.name} has no coverage section"
    assert match.group(1) == ambf_client.coverage_markdown(), (
        f"{DOCS.name} is out of date: replace its coverage section with "
        "ambfplus.ambf_client.coverage_markdown()"
    )


def test_not_applied_methods_raise_saying_why():
    world = ambfplus.World()
    body = world.add_body("car", "box", size=(0.1, 0.1, 0.1))
    client = ambf_client.Client(simulator=world.simulator)
    vehicle = ambf_client.VehicleHandle(client, body)
    handles = {"Client": client, "Vehicle": vehicle}
    for key, (status, _) in COVERAGE.items():
        if status != "not applied":
            continue
        ambf_type, _, name = key.partition(".")
        method = getattr(handles[ambf_type], name)
        arguments = [0] * len(inspect.signature(method).parameters)
        with pytest.raises(NotImplementedError, match=re.escape(name)):
            method(*arguments)


def test_no_op_ros_plumbing_runs():
    world = ambfplus.World()
    world.add_body("b", "box", size=(0.1, 0.1, 0.1))
    client = ambf_client.Client(simulator=world.simulator)
    client.create_objs_from_rostopics()
    client.set_publish_rate(100)
    handle = client.get_obj_handle("b")
    handle.set_active()
    handle.ros_cb(None)
    handle.run_publisher()
    handle.acknowledge_wd()
    assert handle.is_active() and not handle.is_wd_expired()
    assert handle.resize_joint_cmd_array(0) and not handle.resize_joint_cmd_array(1)
    handle.set_publish_joint_names_flag(False)
    assert handle.get_joint_names() == []


def test_the_alias_module_is_ambfplus_client(monkeypatch):
    monkeypatch.delitem(sys.modules, "ambf_client", raising=False)
    spec = importlib.util.spec_from_file_location("ambf_client", checkout(ALIAS))
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "ambf_client", module)
    spec.loader.exec_module(module)
    assert sys.modules["ambf_client"] is ambf_client
    from ambf_client import Client  # the import a script written for AMBF makes

    assert Client is ambf_client.Client


def test_the_wheel_installs_the_alias_at_its_top_level():
    cmake = checkout(ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    assert "install(FILES ambfplus/aliases/ambf_client.py DESTINATION .)" in cmake


def test_install_alias_registers_the_name(monkeypatch):
    monkeypatch.delitem(sys.modules, "ambf_client", raising=False)
    assert ambf_client.install_alias() is ambf_client
    import ambf_client as alias

    assert alias is ambf_client


def test_client_without_a_simulator_says_how_to_give_one():
    ambf_client.use_simulator(None)
    with pytest.raises(ValueError, match="use_simulator"):
        ambf_client.Client()
