"""Fixtures of the view tests: query runs over the real dataset, and a headless Chromium."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import threading
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from scenegrep.dataset import open_dataset
from scenegrep.dataset.run import RunOptions
from tests.conftest import REPO

ARTIFACTS = REPO / "test-artifacts"
"""Screenshots the browser tests save (git ignores the folder)."""

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1400,900",
)


@pytest.fixture(scope="session")
def scenario_run(real_dataset: Path):
    """The s1 scenario (window 75, explained) over the real dataset and the sample traces."""
    program = REPO / "examples" / "queries" / "s1_lane_change_stationary_car.scenic"
    return open_dataset(real_dataset).scenario(program, 75, explain=True, run=RunOptions(jobs=2))


@pytest.fixture(scope="session")
def spre_run(real_dataset: Path):
    """A SpRE over the real dataset: pedestrians in every frame of a stretch."""
    return open_dataset(real_dataset).spre("[[:pedestrian:]]+", run=RunOptions(jobs=2))


@pytest.fixture
def server(real_dataset):
    """A dataset server in a thread of this process (its queries run in child processes, one job)."""
    from scenegrep.view.serve import DatasetServer

    with DatasetServer(real_dataset, 0, jobs=1) as httpd:
        thread = threading.Thread(target=httpd.serve_forever, daemon=True)
        thread.start()
        yield httpd
        httpd.shutdown()


def fetch(server, path: str, body: dict | None = None, headers: dict | None = None) -> tuple[int, bytes]:
    """Status and body of a request to ``server`` as its own page makes it (the token, and JSON
    for a ``body``); ``headers`` add to or (None) remove from those."""
    sent = {"X-Scenegrep-Token": server.token} | ({} if body is None else {"Content-Type": "application/json"})
    sent = {k: v for k, v in (sent | (headers or {})).items() if v is not None}
    data = None if body is None else json.dumps(body).encode()
    try:
        with urllib.request.urlopen(urllib.request.Request(server.url + path, data, sent), timeout=120) as response:
            return response.status, response.read()
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read()


@pytest.fixture(scope="session")
def browser():
    """A Selenium driver of Debian's headless Chromium (skipped where it is not installed, except
    under CI, where .ci/run installs it and its absence is a failure)."""
    if not (Path(CHROMIUM).exists() and Path(CHROMEDRIVER).exists()):
        if os.environ.get("CI"):
            pytest.fail("Chromium and ChromeDriver must be installed (apt-get install chromium chromium-driver)")
        pytest.skip("Debian's chromium and chromium-driver are not installed")
    profile = tempfile.mkdtemp(prefix="scenegrep-chromium-")
    driver = chromium_driver(profile)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def chromium_driver(profile: str):
    """A Selenium driver of Debian's Chromium, headless, with a fresh profile folder and no
    background network traffic (the flags the machine notes ask for)."""
    os.environ.setdefault("SE_OFFLINE", "true")
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "SEVERE"})
    return webdriver.Chrome(options=options, service=Service(CHROMEDRIVER))


def screenshot(driver, name: str) -> Path:
    """Save the browser's screen as test-artifacts/NAME.png."""
    ARTIFACTS.mkdir(exist_ok=True)
    path = ARTIFACTS / f"{name}.png"
    driver.save_screenshot(str(path))
    return path
