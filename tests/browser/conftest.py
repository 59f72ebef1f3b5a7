"""Browser tests of `glossmeter serve` (docs/serve.md §Tests): headless Chromium driven by WebDriver
(Debian's `chromium` and `chromium-driver`, selenium from PyPI), against the binary in GLOSSMETER_BIN
(default: target/release/glossmeter), started on a free loopback port."""
import os
import pathlib
import subprocess

import pytest
from selenium import webdriver
from selenium.webdriver.chrome.service import Service

ROOT = pathlib.Path(__file__).resolve().parents[2]


def binary():
    return os.environ.get("GLOSSMETER_BIN", str(ROOT / "target" / "release" / "glossmeter"))


@pytest.fixture(scope="session")
def server():
    p = subprocess.Popen([binary(), "serve", "--port", "0"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = p.stdout.readline()
    assert "http://" in line, f"the server did not start: {line!r} {p.stderr.read() if p.poll() is not None else ''}"
    url = line.split()[2]
    yield url
    p.terminate()
    p.wait(timeout=10)


@pytest.fixture
def browser(server):
    o = webdriver.ChromeOptions()
    o.binary_location = os.environ.get("CHROMIUM", "/usr/bin/chromium")
    for a in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu", "--window-size=1280,800"]:
        o.add_argument(a)
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service(os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver")), options=o)
    # The viewport itself at 1280 x 800 (the window's size includes no chrome in headless mode, but be exact).
    d.execute_cdp_cmd("Emulation.setDeviceMetricsOverride", {"width": 1280, "height": 800, "deviceScaleFactor": 1, "mobile": False})
    d.get(server)
    yield d
    d.quit()
