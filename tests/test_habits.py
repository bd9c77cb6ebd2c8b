"""The project's habits are pinned in one place and used everywhere: the formatters and type
checker of pyproject.toml's `lint` extra are the versions pre-commit installs, and CI runs exactly
the README's test command, which runs the lint."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def require_checkout():
    if not (ROOT / ".ci" / "run").is_file():
        pytest.skip("needs the source checkout (.ci/run), not an installed package alone")


def lint_pins() -> dict[str, str]:
    tomllib = pytest.importorskip("tomllib", reason="Python 3.11 reads pyproject.toml")
    extra = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    pins = dict(requirement.split("==") for requirement in extra["lint"])
    assert all(pins.values()), f"every lint tool is pinned with ==: {extra['lint']}"
    return pins


def readme_commands() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = re.search(r"^```(?:bash|sh|console)?\n(.*?)^```", text, re.M | re.S)
    assert block, "README.md has no fenced code block"
    return [line for line in block.group(1).splitlines() if line.strip()]


def test_pre_commit_installs_the_pinned_versions():
    require_checkout()
    pins = lint_pins()
    config = (ROOT / ".pre-commit-config.yaml").read_text()
    named = dict(re.findall(r'"([A-Za-z0-9_.-]+)==([^"]+)"', config))
    assert named, ".pre-commit-config.yaml pins no tool"
    for tool, version in named.items():
        assert pins.get(tool) == version, (
            f".pre-commit-config.yaml pins {tool}=={version}, pyproject.toml's lint extra "
            f"{tool}=={pins.get(tool)}"
        )
    assert {"ruff", "clang-format", "mypy"} <= pins.keys()


def test_ci_runs_exactly_the_readme_test_command_which_lints():
    require_checkout()
    commands = readme_commands()
    assert len(commands) == 2, f"the README's first code block holds two commands: {commands}"
    ci = (ROOT / ".ci" / "run").read_text().strip().splitlines()[-1]
    assert ci == commands[1], f".ci/run runs\n  {ci}\nthe README says\n  {commands[1]}"
    assert ".ci/lint" in ci and "lint" in re.search(r'"\.\[([^\]]*)\]"', ci).group(1)
