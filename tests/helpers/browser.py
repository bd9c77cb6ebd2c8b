"""Headless Chromium driven over its DevTools protocol: opens pages, collects console errors,
uncaught exceptions and failed loads, counts rendered images and takes screenshots (the docs
site's test and the training report's)."""

from __future__ import annotations

import base64
import contextlib
import json
import os
import shutil
import subprocess
import time
import urllib.request
from pathlib import Path

import pytest


def skip_or_fail(reason: str):
    if os.environ.get("CI"):
        pytest.fail(f"{reason} (CI must run the docs test)")
    pytest.skip(reason)


def chromium_path() -> str:
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    skip_or_fail("needs Debian's chromium (.ci/install-system-deps installs it)")


class Browser:
    """Headless Chromium over the DevTools protocol (one page target, flat sessions)."""

    def __init__(self, profile: Path):
        from websockets.sync.client import connect

        args = [
            chromium_path(),
            "--headless",
            "--no-sandbox",  # root in containers; the pages are our own
            "--disable-gpu",
            "--disable-dev-shm-usage",
            "--no-first-run",
            "--no-default-browser-check",
            "--disable-extensions",
            "--disable-background-networking",
            "--remote-debugging-port=0",
            f"--user-data-dir={profile}",
            "about:blank",
        ]
        self.process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        port_file = profile / "DevToolsActivePort"
        deadline = time.monotonic() + 60
        while not (port_file.is_file() and port_file.read_text().strip()):
            if self.process.poll() is not None or time.monotonic() > deadline:
                self.close()
                raise RuntimeError(f"chromium did not start: {self.process.stderr.read()!r}")
            time.sleep(0.1)
        port = port_file.read_text().split()[0]
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/version", timeout=10) as r:
            endpoint = json.load(r)["webSocketDebuggerUrl"]
        self.stack = contextlib.ExitStack()
        self.socket = self.stack.enter_context(connect(endpoint, max_size=None, open_timeout=30))
        self.next_id = 0
        self.events: list[dict] = []
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target, flatten=True)[
            "sessionId"
        ]
        for domain in ("Page", "Runtime", "Log"):
            self.call(f"{domain}.enable", session=True)

    def call(self, method: str, session: bool = False, timeout: float = 60, **params) -> dict:
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = self.session
        self.socket.send(json.dumps(message))
        deadline = time.monotonic() + timeout
        while True:
            reply = json.loads(self.socket.recv(timeout=max(0.1, deadline - time.monotonic())))
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method: str, timeout: float = 60) -> None:
        deadline = time.monotonic() + timeout
        while not any(e.get("method") == method for e in self.events):
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(f"no {method} within {timeout} s")
            try:
                self.events.append(json.loads(self.socket.recv(timeout=remaining)))
            except TimeoutError:
                pass

    def settle(self, seconds: float) -> None:
        """Collects events for a while (late scripts, the search index's worker)."""
        deadline = time.monotonic() + seconds
        while (remaining := deadline - time.monotonic()) > 0:
            try:
                self.events.append(json.loads(self.socket.recv(timeout=remaining)))
            except TimeoutError:
                break

    def open(self, url: str) -> dict:
        """Loads url; returns its errors (console errors, uncaught exceptions, failed loads) and
        how many of its images rendered."""
        self.events.clear()
        self.call("Page.navigate", session=True, url=url)
        self.wait_for("Page.loadEventFired")
        self.settle(1.5)
        errors = []
        for event in self.events:
            method, params = event.get("method"), event.get("params", {})
            if method == "Runtime.exceptionThrown":
                details = params["exceptionDetails"]
                text = details.get("exception", {}).get("description") or details.get("text")
                errors.append(f"uncaught: {text}")
            elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
                args = [a.get("value", a.get("description", "")) for a in params.get("args", [])]
                errors.append(f"console.error: {' '.join(map(str, args))}")
            elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
                entry = params["entry"]
                errors.append(f"{entry['source']}: {entry['text']} {entry.get('url', '')}")
        rendered = self.call(
            "Runtime.evaluate",
            session=True,
            returnByValue=True,
            expression="Array.from(document.images).filter(i => i.complete && i.naturalWidth > 0)"
            ".length",
        )["result"]["value"]
        title = self.call(
            "Runtime.evaluate", session=True, returnByValue=True, expression="document.title"
        )["result"]["value"]
        return {"errors": errors, "images": rendered, "title": title}

    def close(self) -> None:
        if getattr(self, "stack", None) is not None:
            self.stack.close()
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()

    def screenshot(self, path: Path, width: int = 1000, height: int = 1400) -> Path:
        """The current page as a PNG of the whole page's width and `height` pixels."""
        self.call("Emulation.setDeviceMetricsOverride", session=True, width=width,
                  height=height, deviceScaleFactor=1, mobile=False)  # fmt: skip
        data = self.call("Page.captureScreenshot", session=True, format="png")["data"]
        path.write_bytes(base64.b64decode(data))
        return path


@contextlib.contextmanager
def chromium(profile: Path):
    """A Browser for a with-block: skips (or fails under CI) without Chromium or websockets."""
    chromium_path()
    pytest.importorskip("websockets", reason="the DevTools client is websockets (test extra)")
    b = Browser(profile)
    try:
        yield b
    finally:
        b.close()
