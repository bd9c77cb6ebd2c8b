"""The documentation site builds in strict mode and its pages render in a browser: headless
Chromium, driven over its DevTools protocol, opens the index, a guide page and an API page served
over HTTP, and every console error, uncaught exception or failed load fails the test.

The site is built once per run with `.ci/docs` (or taken from AMBFPLUS_DOCS_SITE, a folder built
before). Without the docs extra or Chromium the tests skip, except under CI (the environment
variable CI set), where CI installs both and a skip would hide a broken site.
"""

from __future__ import annotations

import functools
import http.server
import importlib.util
import os
import re
import subprocess
import threading
from pathlib import Path

import pytest
from helpers.browser import Browser, chromium_path, skip_or_fail

# Building the site executes the notebooks: minutes on two cores, so not in the fast loop.
pytestmark = pytest.mark.slow

# The checkout's root: the folder above this file that holds pyproject.toml (tests may be regrouped
# into subfolders).
HERE = Path(__file__).resolve()
ROOT = next((p for p in HERE.parents if (p / "pyproject.toml").is_file()), HERE.parents[1])
DOCS_MODULES = (
    "mkdocs",
    "material",
    "mkdocstrings",
    "mkdocstrings_handlers.python",
    "mkdocs_jupyter",
)


def _module_present(name: str) -> bool:
    try:
        return importlib.util.find_spec(name) is not None
    except ModuleNotFoundError:
        return False


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    prebuilt = os.environ.get("AMBFPLUS_DOCS_SITE")
    if prebuilt:
        return Path(prebuilt)
    missing = [m for m in DOCS_MODULES if not _module_present(m)]
    if missing:
        skip_or_fail(
            f'the docs test needs the docs extra: pip install ".[docs]" (missing {missing})'
        )
    if not (ROOT / "mkdocs.yml").is_file():
        pytest.skip("needs the source checkout (mkdocs.yml), not an installed package alone")
    out = tmp_path_factory.mktemp("site")
    build = subprocess.run(
        [str(ROOT / ".ci" / "docs"), str(out)], capture_output=True, text=True, timeout=1200
    )
    assert build.returncode == 0, f"the strict docs build failed:\n{build.stdout}\n{build.stderr}"
    return out


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format, *args):
        pass


@pytest.fixture(scope="module")
def serve():
    """serve(folder) -> base URL of that folder over HTTP on the loopback."""
    servers = []

    def start(folder: Path) -> str:
        handler = functools.partial(_QuietHandler, directory=str(folder))
        server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
        threading.Thread(target=server.serve_forever, daemon=True).start()
        servers.append(server)
        return f"http://127.0.0.1:{server.server_address[1]}/"

    yield start
    for server in servers:
        server.shutdown()
        server.server_close()


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    chromium_path()  # skips (or fails under CI) before anything starts
    pytest.importorskip("websockets", reason="the DevTools client is websockets (test extra)")
    b = Browser(tmp_path_factory.mktemp("chromium-profile"))
    yield b
    b.close()


def test_console_errors_are_detected(browser, serve, tmp_path):
    """The check itself: a page with a deliberate error and a missing image is caught."""
    (tmp_path / "broken.html").write_text(
        "<!doctype html><title>broken</title>"
        '<img src="missing.png">'
        "<script>console.error('deliberate console error');</script>"
        "<script>undefined_function_on_purpose();</script>",
        encoding="utf-8",
    )
    (tmp_path / "clean.html").write_text(
        "<!doctype html><title>clean</title><p>nothing wrong</p>", encoding="utf-8"
    )
    base = serve(tmp_path)
    broken = browser.open(base + "broken.html")
    text = "\n".join(broken["errors"])
    assert "deliberate console error" in text
    assert "undefined_function_on_purpose" in text
    assert "missing.png" in text
    assert broken["images"] == 0
    clean = browser.open(base + "clean.html")
    assert clean["errors"] == [] and clean["title"] == "clean"


@pytest.mark.parametrize(
    "page",
    ["index.html", "guide/recording-format/index.html", "reference/api/ambfplus/index.html"],
)
def test_page_renders_without_errors(site, serve, browser, page):
    assert (site / page).is_file(), f"the site has no {page}"
    result = browser.open(serve(site) + page)
    assert result["errors"] == [], f"{page}: " + "\n".join(result["errors"])
    assert result["title"], f"{page} has no title"
    if page == "index.html":
        assert result["images"] >= 1, "the index shows no rendered image"


def test_generated_references_are_filled(site):
    """The generated parts replaced their markers: the CLI, the plugin ABI, the engine's classes
    (from the stubs) and an executed notebook."""
    cli = (site / "reference/cli/index.html").read_text(encoding="utf-8")
    assert "ambfplus-launch" in cli and "--load_multibodies" in cli
    abi = (site / "reference/plugin-abi/index.html").read_text(encoding="utf-8")
    assert "ambfplus_world_add" in abi and "AMBFPLUS_PLUGIN_ABI_VERSION" in abi
    api = (site / "reference/api/ambfplus/index.html").read_text(encoding="utf-8")
    assert "ambfplus.World" in api and "capture" in api
    tutorial = (site / "tutorials/explore_anatomy/index.html").read_text(encoding="utf-8")
    assert "data:image/png;base64" in tutorial, "the notebook was not executed"


def test_plugin_abi_reference_lists_every_c_function():
    """The header extractor misses nothing: every exported C function and the entry table's
    hooks appear in the generated reference (plain Python: no docs extra needed)."""
    if not (ROOT / "cpp" / "include").is_dir():
        pytest.skip("needs the source checkout (cpp/include)")
    path = ROOT / "docs" / "hooks" / "plugin_abi.py"
    spec = importlib.util.spec_from_file_location("plugin_abi", path)
    plugin_abi = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(plugin_abi)
    page = plugin_abi.render(ROOT)
    api = (ROOT / "cpp" / "include" / "ambfplus" / "plugin" / "api.h").read_text(encoding="utf-8")
    functions = re.findall(r"AMBFPLUS_API\s+[\w\s\*]+?\b(ambfplus_\w+)\s*\(", api)
    assert len(functions) > 20
    missing = [f for f in functions if f"{f}(" not in page]
    assert not missing, f"not in the plugin ABI reference: {missing}"
    for hook in ("physics_update", "graphics_update", "object_removed", "on_object_added"):
        assert hook in page
