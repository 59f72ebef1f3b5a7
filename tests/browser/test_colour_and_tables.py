"""Colour and table models on the page (docs/serve.md §The page): an RGB recipe through a colour geometry
shows its other readings and says in place why it has no colour (the library refuses it, as `measure` does);
sweep charts give colour axes of their own; switching to a table model fills `/file` with a table of the
server's data directory, or says in place what it needs. Every number is compared with `glossmeter`'s own."""
import json
import os
import subprocess

import pytest
from selenium import webdriver
from selenium.common.exceptions import StaleElementReferenceException
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select, WebDriverWait

from conftest import ROOT, binary
from test_formulator import cli_doc, raw
from test_page import WAIT, choose_fixture, console_errors, page_readings, wait_current


def tick_only(d, ids):
    """Untick every geometry, then tick `ids` (one change event at the end)."""
    d.execute_script(
        "for (const c of document.querySelectorAll('#geometries input')) c.checked = arguments[0].includes(c.value);"
        "document.querySelector('#geometries input').dispatchEvent(new Event('change'))",
        ids,
    )


def sweep_two_points(d, ptr, lo, hi):
    """Sweep `ptr` from `lo` to `hi` in two points on the Sweep tab, and wait until both are in (no error)."""
    d.find_element(By.ID, "tab-sweep").click()
    Select(d.find_element(By.ID, "sweep-path")).select_by_value(ptr)
    for i, v in [("sweep-lo", lo), ("sweep-hi", hi), ("sweep-n", "2")]:
        d.find_element(By.ID, i).clear()
        d.find_element(By.ID, i).send_keys(v)
    d.find_element(By.ID, "sweep-go").click()
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "sweep-count").text == "2 / 2 points" or d.find_element(By.ID, "sweep-error").text)
    assert d.find_element(By.ID, "sweep-error").text == ""


def test_an_rgb_recipe_says_in_place_why_it_has_no_colour(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "rgb-lambert")
    tick_only(d, ["astm-d523-60", "d8-sci"])
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#readings tr.refused"))
    wait_current(d)
    assert d.find_element(By.ID, "measure-error").text == ""
    # The gloss readings are measure's, bit for bit; d8-sci has a row saying why there is no colour.
    cli = {(r["geometry"], r["name"]): r["value"] for r in cli_doc(raw(d), tmp_path, ["astm-d523-60"])}
    shown = page_readings(d)
    assert shown.pop(("d8-sci", "")) == ""
    assert {k: float(v) for k, v in shown.items()} == cli
    row = d.find_element(By.CSS_SELECTOR, "#readings tr.refused")
    note = row.find_element(By.CSS_SELECTOR, "td.note").text
    assert note.startswith("no colour: colour readings need a spectral") and "wavelengths_nm" in note, note
    # The command line refuses the same recipe through d8-sci, for the same reason.
    f = tmp_path / "rgb.json"
    f.write_text(json.dumps(raw(d)))
    out = subprocess.run([binary(), "measure", str(f), "-g", "d8-sci"], capture_output=True, text=True)
    assert out.returncode == 2 and "colour readings need a spectral" in out.stderr, out.stderr
    advice = d.find_element(By.ID, "colour-refused").text
    assert "wavelengths_nm" in advice and "white-pearl-spectral" in advice, advice
    assert not d.find_elements(By.CSS_SELECTOR, "#colours .swatch")
    # A sweep leaves the refused geometry out and reads the rest.
    sweep_two_points(d, "/albedo/0", "0,2", "0,8")
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#sweep-charts svg.chart"))
    assert [c.get_attribute("data-unit") for c in d.find_elements(By.CSS_SELECTOR, "#sweep-charts svg.chart")] == ["GU"]
    # A spectral recipe through the same geometries gets its colour and no refusal.
    choose_fixture(d, "white-pearl-spectral")
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#colours .swatch"))
    assert not d.find_elements(By.CSS_SELECTOR, "#readings tr.refused") and not d.find_elements(By.ID, "colour-refused")
    assert console_errors(d) == []


def test_colour_gets_its_own_axes_in_the_sweep(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "blue-metallic-spectral")
    tick_only(d, ["astm-d523-60", "astm-e2194-45"])
    wait_current(d)
    recipe = raw(d)
    ptr, lo, hi = "/clear_coat/roughness", "0.02", "0.1"
    sweep_two_points(d, ptr, lo, hi)
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#sweep-charts svg.chart"))
    f = tmp_path / "template.json"
    f.write_text(json.dumps(recipe))
    out = subprocess.run([binary(), "sweep", str(f), "--vary", f"{ptr}={lo}..{hi}:2", "--format", "jsonl", "--no-timing",
                          "-g", "astm-d523-60", "-g", "astm-e2194-45"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    first = json.loads(out.stdout.splitlines()[0])["readings"]

    def axis(r):
        if r["unit"] != "":
            return r["unit"]
        return "X, Y, Z" if r["name"] in ("X", "Y", "Z") else "L*, a*, b*, C*"

    want = {}
    for r in first:
        want.setdefault(axis(r), []).append(r["name"])
    assert set(want) == {"GU", "X, Y, Z", "L*, a*, b*, C*", "°"}, want
    charts = d.find_elements(By.CSS_SELECTOR, "#sweep-charts svg.chart")
    assert sorted(c.get_attribute("data-unit") for c in charts) == sorted(want), "one chart per axis"
    for c in charts:
        assert len(c.find_elements(By.CSS_SELECTOR, "polyline.series")) == len(want[c.get_attribute("data-unit")])
    assert console_errors(d) == []


@pytest.fixture(scope="module")
def tables_server():
    """A server whose data directory is the shipped tables, fixtures/materials/."""
    p = subprocess.Popen([binary(), "serve", "--port", "0", "--data-dir", str(ROOT / "fixtures" / "materials")],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = p.stdout.readline()
    assert "http://" in line, line
    yield line.split()[2]
    p.terminate()
    p.wait(timeout=10)


@pytest.fixture
def tables_browser(tables_server):
    o = webdriver.ChromeOptions()
    o.binary_location = os.environ.get("CHROMIUM", "/usr/bin/chromium")
    for a in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu", "--window-size=1280,800"]:
        o.add_argument(a)
    o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service(os.environ.get("CHROMEDRIVER", "/usr/bin/chromedriver")), options=o)
    d.get(tables_server)
    yield d
    d.quit()


def switch_model(d, model):
    Select(d.find_element(By.ID, "model")).select_by_value(model)
    WebDriverWait(d, WAIT).until(lambda d: raw(d)["model"] == model)
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "readings-state").text in ("current", "needs a value"))


def test_switching_to_a_table_model_fills_a_table_of_the_data_directory(tables_browser, tmp_path):
    d = tables_browser
    wait_current(d)
    # One model after the other: a table another model read is not kept for a model that reads another kind.
    for model, first in [("merl", "merl/lambert-tiny.binary"), ("inplane-csv", "inplane/beckmann.csv"),
                         ("e1392", "inplane/beckmann-e1392.txt")]:
        switch_model(d, model)
        wait_current(d)
        r = raw(d)
        assert r["file"] == first, r
        assert d.find_element(By.ID, "measure-error").text == ""
        geos = [i.get_attribute("value") for i in d.find_elements(By.CSS_SELECTOR, "#geometries input:checked")]
        # measure reads the same table by its path in the checkout.
        cli = cli_doc(dict(r, file=str(ROOT / "fixtures" / "materials" / first)), tmp_path, geos)
        shown = page_readings(d)
        assert len(shown) == len(cli) >= 6
        for c in cli:
            v = shown[(c["geometry"], c["name"])]
            assert (v == "" if c["value"] is None else float(v) == c["value"]), (model, c)
        options = [o.get_attribute("value") for o in d.find_elements(By.CSS_SELECTOR, "#params datalist option")]
        assert first in options, options
    assert console_errors(d) == []


def test_a_table_model_without_a_data_directory_says_what_it_needs(browser):
    d = browser
    wait_current(d)
    switch_model(d, "merl")
    assert d.find_element(By.ID, "readings-state").text == "needs a value"
    assert "file" not in raw(d)
    assert d.find_element(By.ID, "measure-error").text == ""
    text = d.find_element(By.CSS_SELECTOR, "#readings tr.missing").text
    assert "file" in text and ".binary" in text and "--data-dir" in text, text
    placeholder = d.find_element(By.CSS_SELECTOR, "#params [data-pointer='/file']").get_attribute("placeholder")
    assert ".binary" in placeholder and "--data-dir" in placeholder, placeholder
    assert console_errors(d) == []


def test_colour_is_read_under_the_chosen_illuminant_and_observer(browser, tmp_path):
    """The page's illuminant and observer reach every colour request: the readings are `measure --illuminant A
    --observer 2`'s, the pinned reference is read again under them (a difference is never across two
    conditions), a sweep is `sweep --illuminant A --observer 2`'s, and the choice is kept on reload."""
    d = browser
    wait_current(d)
    choose_fixture(d, "white-pearl-spectral")
    geometry = "astm-e2194-15"
    tick_only(d, [geometry])
    wait_current(d)
    recipe = raw(d)
    f = tmp_path / "pearl.json"
    f.write_text(json.dumps(recipe))

    def cli(args):
        out = subprocess.run([binary(), *args], capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        return out.stdout

    def measured(colour):
        doc = json.loads(cli(["measure", "--format", "json", "--no-timing", str(f), "-g", geometry, *colour]))
        return {(r["geometry"], r["name"]): r["value"] for r in doc["readings"]}

    # The default is D65 / 10°, and reads as measure without flags.
    assert Select(d.find_element(By.ID, "illuminant")).first_selected_option.get_attribute("value") == "D65"
    assert Select(d.find_element(By.ID, "observer")).first_selected_option.get_attribute("value") == "10"
    assert {k: float(v) for k, v in page_readings(d).items()} == measured([])
    d.find_element(By.ID, "pin").click()
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "pin-state").text)
    # A / 2°: the readings are measure's under them, and differ from D65 / 10°.
    Select(d.find_element(By.ID, "illuminant")).select_by_value("A")
    Select(d.find_element(By.ID, "observer")).select_by_value("2")
    want = measured(["--illuminant", "A", "--observer", "2"])
    assert want != measured([])
    # The table is redrawn while it is read: a row replaced under the reader is read again.
    settled = WebDriverWait(d, WAIT, ignored_exceptions=(StaleElementReferenceException,))
    settled.until(lambda d: {k: float(v) for k, v in page_readings(d).items()} == want)
    wait_current(d)
    # The pinned reference (the same recipe) is read again under A / 2°: no difference remains, and both
    # swatches say the conditions.
    settled.until(lambda d: "ΔE*ab = 0.00" in d.find_element(By.ID, "colours").text
                  and [c.text.count("A / 2°") for c in d.find_elements(By.CSS_SELECTOR, "#colours figcaption")] == [1, 1])
    # A sweep under the same conditions is the command line's, reading for reading.
    ptr, lo, hi = "/pearlescent_flakes/tio2_thickness_nm", "60", "80"
    sweep_two_points(d, ptr, lo, hi)
    served = [json.loads(line)["readings"] for line in d.execute_script("return state.sweepText").splitlines() if line.strip()]
    lines = cli(["sweep", str(f), "--vary", f"{ptr}={lo}..{hi}:2", "--format", "jsonl", "--no-timing", "-g", geometry,
                 "--illuminant", "A", "--observer", "2"]).splitlines()
    assert served == [json.loads(line)["readings"] for line in lines]
    head = d.execute_script("return sweepCsv()").splitlines()[0]
    assert "astm-e2194-15/b* (A / 2°)" in head and "astm-e2194-15/h (°, A / 2°)" in head, head
    # The choice is this browser's: kept on reload.
    d.execute_script("window.onbeforeunload = null; location.reload()")
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#illuminant option"))
    assert Select(d.find_element(By.ID, "illuminant")).first_selected_option.get_attribute("value") == "A"
    assert Select(d.find_element(By.ID, "observer")).first_selected_option.get_attribute("value") == "2"
    assert console_errors(d) == []
