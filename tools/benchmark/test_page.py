"""The page of `streaks benchmark` in a real headless browser (Debian's chromium).

    BENCHMARK_PAGE=OUT/index.html BENCHMARK_METHODS=sgm,sgm-streaks,lk \\
        python -m pytest -q tools/benchmark

starts chromedriver (/usr/bin/chromedriver, or $CHROMEDRIVER) and talks WebDriver to it over
plain HTTP (the W3C protocol, no Selenium): it opens the page from file://, waits for it to
load, and checks that every <img> resolved (complete, naturalWidth > 0), that the methods
table, the summary table and the breakdown tables (by condition, streak length and distance,
where the page has them) hold every method, that an empty bin reads n/a, and that the bar
charts are there.
"""

from __future__ import annotations

import json
import os
import shutil
import socket
import subprocess
import tempfile
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1400,2000",
]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class WebDriver:
    """The few W3C WebDriver commands the test needs, over HTTP."""

    def __init__(self, base: str) -> None:
        self.base = base
        self.session: str | None = None

    def call(self, method: str, path: str, body: dict[str, Any] | None = None) -> Any:
        data = None if body is None else json.dumps(body).encode()
        req = urllib.request.Request(
            self.base + path,
            data=data,
            method=method,
            headers={"Content-Type": "application/json"},
        )
        try:
            with urllib.request.urlopen(req, timeout=60) as r:
                return json.loads(r.read())["value"]
        except urllib.error.HTTPError as e:
            raise AssertionError(f"WebDriver {method} {path}: {e.read().decode()}") from e

    def start(self, binary: str, profile: str) -> None:
        caps = {
            "capabilities": {
                "alwaysMatch": {
                    "browserName": "chrome",
                    "goog:chromeOptions": {
                        "binary": binary,
                        "args": [*CHROMIUM_ARGS, f"--user-data-dir={profile}"],
                    },
                }
            }
        }
        self.session = self.call("POST", "/session", caps)["sessionId"]

    def run(self, script: str) -> Any:
        return self.call(
            "POST", f"/session/{self.session}/execute/sync", {"script": script, "args": []}
        )

    def quit(self) -> None:
        if self.session:
            try:
                self.call("DELETE", f"/session/{self.session}")
            finally:
                self.session = None


@pytest.fixture
def browser() -> Iterator[WebDriver]:
    driver_bin = os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver")
    chromium = os.environ.get("CHROMIUM", "/usr/bin/chromium")
    for b in (driver_bin, chromium):
        if not shutil.which(b):
            pytest.fail(f"{b} not found: install Debian's chromium and chromium-driver")
    port = free_port()
    proc = subprocess.Popen(
        [driver_bin, f"--port={port}", "--allowed-ips=127.0.0.1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    wd = WebDriver(f"http://127.0.0.1:{port}")
    try:
        deadline = time.monotonic() + 20
        while True:
            try:
                if wd.call("GET", "/status").get("ready"):
                    break
            except (urllib.error.URLError, ConnectionError, AssertionError):
                pass
            if time.monotonic() > deadline:
                pytest.fail("chromedriver did not become ready in 20 s")
            time.sleep(0.1)
        with tempfile.TemporaryDirectory(prefix="streaks-chromium-") as profile:
            wd.start(chromium, profile)
            try:
                yield wd
            finally:
                wd.quit()
    finally:
        proc.terminate()
        proc.wait(timeout=10)


def page_and_methods() -> tuple[Path, list[str]]:
    page = os.environ.get("BENCHMARK_PAGE")
    methods = os.environ.get("BENCHMARK_METHODS")
    if not page or not methods:
        pytest.skip("set BENCHMARK_PAGE (an index.html) and BENCHMARK_METHODS (a,b,...)")
    return Path(page).resolve(), [m for m in methods.split(",") if m]


def test_page_loads_with_every_image_and_method(browser: WebDriver) -> None:
    page, methods = page_and_methods()
    assert page.is_file(), page
    browser.call("POST", f"/session/{browser.session}/url", {"url": page.as_uri()})
    deadline = time.monotonic() + 30
    while browser.run("return document.readyState") != "complete":
        assert time.monotonic() < deadline, "the page did not finish loading"
        time.sleep(0.1)
    assert "streaks benchmark" in browser.run("return document.title")
    images = browser.run(
        "return Array.from(document.images).map(i => [i.alt, i.complete, i.naturalWidth])"
    )
    assert images, "the page has no images"
    broken = [alt for alt, complete, width in images if not (complete and width > 0)]
    assert not broken, f"images that did not resolve: {broken}"
    # A left image and one error map per method for each sample with thumbnails.
    assert len(images) % (1 + len(methods)) == 0, len(images)
    for table in ("methods", "summary", "region-all", "samples"):
        text = browser.run(f"return document.getElementById('{table}').innerText")
        for m in methods:
            assert m in text, f"table {table} lacks method {m}: {text}"
    # The breakdown tables, where the report has them (a dataset's: all three; KITTI: none):
    # every method, and n/a (never 0) in a bin or condition without pixels.
    for table in ("condition", "streak-length", "distance"):
        text = browser.run(
            f"const t = document.getElementById('{table}'); return t ? t.innerText : null"
        )
        if text is None:
            continue
        for m in methods:
            assert m in text, f"table {table} lacks method {m}: {text}"
    empty = browser.run(
        "return Array.from(document.querySelectorAll('td.none[title^=\"not available: no\"]'))"
        ".map(td => td.innerText)"
    )
    assert all(t == "n/a" for t in empty), empty
    charts = browser.run("return document.querySelectorAll('svg rect').length")
    assert charts >= len(methods), charts
