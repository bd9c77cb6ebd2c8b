"""MkDocs hook: fills the generated parts of pages at build time.

A page marks a generated part with an HTML comment on a line of its own:
`<!-- generated: cli -->` (the command-line reference, from the argument parsers) and
`<!-- generated: plugin-abi -->` (the plugin C ABI, from the public plugin headers).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import plugin_abi  # noqa: E402


def _cli_reference() -> str:
    # A separate interpreter started outside the checkout imports the installed package (the
    # source folder has no compiled engine).
    with tempfile.TemporaryDirectory() as neutral:
        result = subprocess.run(
            [sys.executable, str(HERE / "cli_reference.py")],
            cwd=neutral,
            env={**os.environ, "COLUMNS": "100"},  # usage lines wrap the same everywhere
            capture_output=True,
            text=True,
        )
    if result.returncode != 0:
        raise RuntimeError(f"the CLI reference could not be generated:\n{result.stderr}")
    return result.stdout


GENERATORS = {
    "<!-- generated: cli -->": _cli_reference,
    "<!-- generated: plugin-abi -->": lambda: plugin_abi.render(ROOT),
}


def on_page_markdown(markdown: str, page, config, files) -> str:
    for marker, generate in GENERATORS.items():
        if marker in markdown:
            markdown = markdown.replace(marker, generate())
    return markdown
