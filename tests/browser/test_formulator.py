"""The page as a formulator works in it (docs/serve.md §The page): readings as the instrument displays them
beside the command line's own values, recipes saved and loaded (a file, this browser, a draft kept over a
reload), a pinned reference beside another recipe, a sweep and a fit of the clear-coat roughness of a paint
that had none, every model switch giving readings, pigments and flakes added in the editor. Each test
compares what the page shows with what `glossmeter` itself computes, so that a wrong number fails it."""
import json
import math
import os
import re
import subprocess
import time
import urllib.request

from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select, WebDriverWait

from conftest import ROOT, binary
from test_page import WAIT, choose_fixture, cli_readings, console_errors, page_readings, wait_current

# The display steps docs/serve.md §The page states (and the page's STEP table).
STEP = {"GU": 0.1, "HU": 0.1, "HU(log)": 0.1, "DOI": 0.1, "°": 0.1, "": 0.01}


def displayed(v, unit):
    """A value rounded as the page says an instrument displays it (half away from zero is not needed: the
    page rounds half up, as Math.round)."""
    step = STEP.get(unit, 0.01)
    d = round(-math.log10(step))
    s = f"{math.floor(v / step + 0.5) * step:.{d}f}"
    return f"{0:.{d}f}" if s == "-" + f"{0:.{d}f}" else s


def raw(d):
    return json.loads(d.find_element(By.ID, "raw").get_attribute("value"))


def geos(d):
    return [i.get_attribute("value") for i in d.find_elements(By.CSS_SELECTOR, "#geometries input:checked")]


def cli_doc(recipe, tmp_path, geometries, name="r.json"):
    f = tmp_path / name
    f.write_text(json.dumps(recipe))
    args = [binary(), "measure", "--format", "json", "--no-timing", str(f)]
    for g in geometries:
        args += ["-g", g]
    out = subprocess.run(args, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)["readings"]


def type_into(e, text):
    e.send_keys(Keys.CONTROL, "a")
    e.send_keys(Keys.DELETE)
    e.send_keys(text)


def field(d, ptr):
    return d.find_element(By.CSS_SELECTOR, f"#params [data-pointer='{ptr}']")


def assert_page_is_cli(d, tmp_path):
    """Every reading the page shows is measure's value for the recipe in the raw view, bit for bit."""
    cli = cli_readings(json.dumps(raw(d)), tmp_path, geos(d))
    page = page_readings(d)
    assert set(page) == set(cli)
    for k, v in cli.items():
        assert (page[k] == "" if v is None else float(page[k]) == v), (k, page[k], v)


def walk_assumed(v):
    if isinstance(v, dict):
        n = 1 if v.get("status") == "assumed" and isinstance(v.get("value"), (int, float)) else 0
        return n + sum(walk_assumed(x) for x in v.values())
    if isinstance(v, list):
        return sum(walk_assumed(x) for x in v)
    return 0


def test_readings_are_shown_as_the_instrument_displays_them(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "cerulean-blue-c")
    cli = cli_doc(raw(d), tmp_path, geos(d))
    rows = d.find_elements(By.CSS_SELECTOR, "#readings tbody tr")
    assert len(rows) == len(cli)
    seen = set()
    for r, c in zip(rows, cli):
        assert (r.get_attribute("data-geometry"), r.get_attribute("data-name")) == (c["geometry"], c["name"])
        assert r.find_element(By.CSS_SELECTOR, "td.value").text == displayed(c["value"], c["unit"]), c
        assert r.find_element(By.CSS_SELECTOR, "td.unit").text == c["unit"]
        spec = json.loads((ROOT / "standards" / f"{c['geometry']}.json").read_text()) if (ROOT / "standards" / f"{c['geometry']}.json").exists() else None
        if c["geometry"] not in seen and spec:
            # The instrument's name from the geometry file, and its assumed numbers counted independently.
            assert r.find_element(By.CSS_SELECTOR, "td.instrument").text == spec["title"]
            n = walk_assumed(spec)
            if n:
                summary = r.find_element(By.CSS_SELECTOR, "details.assumed summary").text
                assert summary.startswith(f"{n} assumed number"), (c["geometry"], summary, n)
            seen.add(c["geometry"])
        note = r.find_element(By.CSS_SELECTOR, "td.note").text
        assert note.startswith("exact to the digit shown") == (c["error_estimate"] < STEP[c["unit"]] / 20), (note, c)
    for td in d.find_elements(By.CSS_SELECTOR, "#readings td.value, #readings td.note"):
        assert "±" not in td.text and not re.search(r"\de-\d", td.text), ("no ± beside a reading, no bare computing error", td.text)
    assert console_errors(d) == []


def test_a_decimal_comma_is_a_decimal_point(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "solid-white")
    type_into(field(d, "/clear_coat/index"), "1,52")
    WebDriverWait(d, WAIT).until(lambda d: raw(d)["clear_coat"]["index"] == 1.52)
    wait_current(d)
    assert_page_is_cli(d, tmp_path)
    # Two separators are refused, not guessed, and leave the recipe as it was.
    d.execute_script("arguments[0].value = '1,5.2'; arguments[0].dispatchEvent(new Event('input'))", field(d, "/clear_coat/index"))
    time.sleep(0.5)
    assert "bad" in field(d, "/clear_coat/index").get_attribute("class")
    assert raw(d)["clear_coat"]["index"] == 1.52
    assert console_errors(d) == []


def test_save_and_load_a_recipe_file_and_in_the_browser(browser, tmp_path):
    d = browser
    d.execute_cdp_cmd("Browser.setDownloadBehavior", {"behavior": "allow", "downloadPath": str(tmp_path)})
    wait_current(d)
    choose_fixture(d, "solid-white")
    type_into(field(d, "/clear_coat/index"), "1,61")
    WebDriverWait(d, WAIT).until(lambda d: raw(d)["clear_coat"]["index"] == 1.61)
    assert d.find_element(By.TAG_NAME, "body").get_attribute("data-unsaved") == "true"
    edited = raw(d)
    # A file: the download is the recipe in the raw view.
    d.find_element(By.ID, "save-file").click()
    WebDriverWait(d, WAIT).until(lambda d: [p for p in tmp_path.glob("*.json") if not p.name.endswith(".crdownload")])
    saved = next(tmp_path.glob("*.json"))
    assert json.loads(saved.read_text()) == edited
    assert d.find_element(By.TAG_NAME, "body").get_attribute("data-unsaved") == "false"
    # This browser: saved under its name, loaded back after another recipe.
    d.find_element(By.ID, "save-browser").click()
    name = edited["name"]
    assert name in [o.get_attribute("value") for o in d.find_elements(By.CSS_SELECTOR, "#saved-list option")]
    choose_fixture(d, "black-glass")
    assert raw(d)["model"] != "paint"
    Select(d.find_element(By.ID, "saved-list")).select_by_value(name)
    WebDriverWait(d, WAIT).until(lambda d: raw(d) == edited)
    wait_current(d)
    assert_page_is_cli(d, tmp_path)
    # Open a file: another index, read back with its readings.
    other = dict(edited, clear_coat=dict(edited["clear_coat"], index=1.45), name="opened from a file")
    f = tmp_path / "other.json"
    f.write_text(json.dumps(other))
    d.find_element(By.ID, "open-file").send_keys(str(f))
    WebDriverWait(d, WAIT).until(lambda d: raw(d) == other)
    wait_current(d)
    assert_page_is_cli(d, tmp_path)
    assert console_errors(d) == []


def test_a_reload_warns_and_keeps_the_edits(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "solid-white")
    assert d.execute_script("const e = new Event('beforeunload', {cancelable: true}); window.dispatchEvent(e); return e.defaultPrevented") is False
    type_into(field(d, "/clear_coat/index"), "1.57")
    WebDriverWait(d, WAIT).until(lambda d: raw(d)["clear_coat"]["index"] == 1.57)
    edited = raw(d)
    # The page asks before leaving (the browser shows its dialog for a prevented beforeunload).
    assert d.execute_script("const e = new Event('beforeunload', {cancelable: true}); window.dispatchEvent(e); return e.defaultPrevented") is True
    d.execute_script("window.onbeforeunload = null")
    d.execute_script("location.reload()")
    try:
        WebDriverWait(d, 3).until(lambda d: d.switch_to.alert).accept()
    except Exception:
        pass
    WebDriverWait(d, WAIT).until(lambda d: "restored" in d.find_element(By.ID, "status").text or d.find_element(By.ID, "readings-state").text == "current")
    wait_current(d)
    assert raw(d) == edited, "the draft came back after the reload"
    assert d.find_element(By.TAG_NAME, "body").get_attribute("data-unsaved") == "true"
    assert_page_is_cli(d, tmp_path)


def test_pin_a_reference_and_compare_another_recipe(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "black-glass")
    ref = raw(d)
    d.find_element(By.ID, "pin").click()
    choose_fixture(d, "semigloss-white")
    cur = raw(d)
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#readings tbody td.ref"))
    g = geos(d)
    a = {(r["geometry"], r["name"]): r for r in cli_doc(cur, tmp_path, g, "cur.json")}
    b = {(r["geometry"], r["name"]): r for r in cli_doc(ref, tmp_path, g, "ref.json")}
    rows = d.find_elements(By.CSS_SELECTOR, "#readings tbody tr")
    assert len(rows) == len(a)
    for r in rows:
        k = (r.get_attribute("data-geometry"), r.get_attribute("data-name"))
        x, y = a[k]["value"], b[k]["value"]
        assert float(r.find_element(By.CSS_SELECTOR, "td.value").get_attribute("data-value")) == x
        assert float(r.find_element(By.CSS_SELECTOR, "td.ref").get_attribute("data-value")) == y
        shown = r.find_element(By.CSS_SELECTOR, "td.diff").text
        assert float(shown) == float(displayed(x - y, a[k]["unit"])), (k, shown, x - y)
    heads = [th.text for th in d.find_elements(By.CSS_SELECTOR, "#readings thead th")]
    assert "reference" in heads and "difference" in heads
    shots = os.environ.get("GLOSSMETER_SCREENSHOTS")
    if shots:
        d.save_screenshot(os.path.join(shots, "serve-pin.png"))
    d.find_element(By.ID, "unpin").click()
    assert not d.find_elements(By.CSS_SELECTOR, "#readings tbody td.ref")
    assert console_errors(d) == []


def test_pin_and_compare_colour(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "white-pearl-spectral")
    for box in d.find_elements(By.CSS_SELECTOR, "#geometries input:checked"):
        d.execute_script("arguments[0].checked = false", box)
    d.execute_script("const c = document.querySelector(\"#geometries input[value='d8-sci']\"); c.checked = true; c.dispatchEvent(new Event('change'))")
    wait_current(d)
    ref = raw(d)
    d.find_element(By.ID, "pin").click()
    choose_fixture(d, "blue-metallic-spectral")
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.ID, "delta-e"))

    def lab(recipe, name):
        rs = {r["name"]: r["value"] for r in cli_doc(recipe, tmp_path, ["d8-sci"], name)}
        return rs["L*"], rs["a*"], rs["b*"]

    x, y = lab(raw(d), "cur.json"), lab(ref, "ref.json")
    de = math.dist(x, y)
    text = d.find_element(By.ID, "delta-e").text
    assert text.startswith(f"ΔE*ab = {de:.2f}"), (text, de)
    assert len(d.find_elements(By.CSS_SELECTOR, "#colours .swatch")) == 2
    assert console_errors(d) == []


def test_a_sweep_and_a_fit_of_the_clear_coat_roughness_on_a_paint_that_had_none(browser, tmp_path):
    d = browser
    d.execute_cdp_cmd("Browser.setDownloadBehavior", {"behavior": "allow", "downloadPath": str(tmp_path)})
    wait_current(d)
    choose_fixture(d, "solid-white")
    recipe = raw(d)
    assert "roughness" not in recipe["clear_coat"]
    # The sweep offers the roughness although the recipe does not set it, over the registry's range 0..1.
    d.find_element(By.ID, "tab-sweep").click()
    Select(d.find_element(By.ID, "sweep-path")).select_by_value("/clear_coat/roughness")
    assert (d.find_element(By.ID, "sweep-lo").get_attribute("value"), d.find_element(By.ID, "sweep-hi").get_attribute("value")) == ("0", "1")
    type_into(d.find_element(By.ID, "sweep-hi"), "0,2")
    type_into(d.find_element(By.ID, "sweep-n"), "3")
    d.find_element(By.ID, "sweep-go").click()
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "sweep-count").text == "3 / 3 points" or d.find_element(By.ID, "sweep-error").text)
    assert d.find_element(By.ID, "sweep-error").text == ""
    f = tmp_path / "template.json"
    f.write_text(json.dumps(recipe))
    args = [binary(), "sweep", str(f), "--vary", "/clear_coat/roughness=0..0.2:3", "--format", "jsonl", "--no-timing"]
    for g in geos(d):
        args += ["-g", g]
    out = subprocess.run(args, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    cli = [json.loads(l) for l in out.stdout.splitlines() if l.strip()]
    units = {r["unit"] for r in cli[0]["readings"]}
    charts = d.find_elements(By.CSS_SELECTOR, "#sweep-charts svg.chart")
    assert sorted(c.get_attribute("data-unit") for c in charts) == sorted(units), "one chart per unit"
    for c in charts:
        n = len([r for r in cli[0]["readings"] if r["unit"] == c.get_attribute("data-unit")])
        assert len(c.find_elements(By.CSS_SELECTOR, "polyline.series")) == n
    shots = os.environ.get("GLOSSMETER_SCREENSHOTS")
    if shots:
        d.execute_script("document.getElementById('tabs').scrollIntoView()")
        d.save_screenshot(os.path.join(shots, "serve-sweep.png"))
    d.find_element(By.ID, "sweep-csv").click()
    WebDriverWait(d, WAIT).until(lambda d: (tmp_path / "sweep.csv").exists())
    lines = (tmp_path / "sweep.csv").read_text().splitlines()
    assert len(lines) == 4 and lines[0].startswith("/clear_coat/roughness,")
    for line, row in zip(lines[1:], cli):
        cells = line.split(",")
        assert float(cells[0]) == row["parameters"]["/clear_coat/roughness"]
        assert [float(x) for x in cells[1:-1:2]] == [r["value"] for r in row["readings"]]
    # The fit: bounds the registry's range, the target the 20° gloss the command line reads at roughness 0.05.
    truth = dict(recipe, clear_coat=dict(recipe["clear_coat"], roughness=0.05))
    target = {(r["geometry"], r["name"]): r["value"] for r in cli_doc(truth, tmp_path, ["astm-d523-20"], "truth.json")}[("astm-d523-20", "gloss")]
    d.find_element(By.ID, "tab-fit").click()
    box = d.find_element(By.CSS_SELECTOR, "#fit-free input[value='/clear_coat/roughness']")
    row = box.find_element(By.XPATH, "..")
    assert (row.find_element(By.CLASS_NAME, "lo").get_attribute("value"), row.find_element(By.CLASS_NAME, "hi").get_attribute("value")) == ("0", "1")
    box.click()
    type_into(d.find_element(By.ID, "fit-targets"), f"astm-d523-20/gloss={target:.6f}±0,01".replace(".", ",", 1))
    d.find_element(By.ID, "fit-go").click()
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "fit-verdict").text or d.find_element(By.ID, "fit-error").text)
    assert d.find_element(By.ID, "fit-error").text == ""
    assert d.find_element(By.ID, "fit-verdict").text.startswith("The fit is to be trusted"), d.find_element(By.ID, "fit-verdict").text
    got = float(d.find_element(By.CSS_SELECTOR, "#fit-params tr[data-pointer='/clear_coat/roughness'] td.value").get_attribute("data-value"))
    assert abs(got - 0.05) < 1e-3, got
    assert console_errors(d) == []


def test_switching_model_fills_the_models_required_fields(browser):
    d = browser
    wait_current(d)
    models = {json.loads(p.read_text())["model"] for p in (ROOT / "fixtures" / "recipes").glob("*.json")}
    for m in ["smooth-dielectric", "conductor", "lambert", "microfacet", "phong", "blinn-phong", "ward", "cook-torrance-lobes", "paint"]:
        assert m in models
        Select(d.find_element(By.ID, "fixture")).select_by_value("black-glass" if m != "smooth-dielectric" else "grey-lambert")
        try:
            d.switch_to.alert.accept()  # the model switch left edits not saved: the page asks first
        except Exception:
            pass
        wait_current(d)
        Select(d.find_element(By.ID, "model")).select_by_value(m)
        WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "readings-state").text in ("current", "no readings"))
        wait_current(d) if d.find_element(By.ID, "readings-state").text != "no readings" else None
        assert d.find_element(By.ID, "measure-error").text == "", (m, d.find_element(By.ID, "measure-error").text)
        assert raw(d)["model"] == m
        assert len(page_readings(d)) >= 6
    assert console_errors(d) == []


def test_pigments_and_flakes_are_added_in_the_editor(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "semigloss-white")
    n = len(raw(d)["pigmented_layer"]["pigments"])
    d.find_element(By.ID, "add-pigmented_layer_pigments").click()
    WebDriverWait(d, WAIT).until(lambda d: len(raw(d)["pigmented_layer"]["pigments"]) == n + 1)
    assert "metallic_flakes" not in raw(d)
    d.find_element(By.ID, "add-metallic_flakes").click()
    WebDriverWait(d, WAIT).until(lambda d: "metallic_flakes" in raw(d))
    # The new pigment's concentration is a field of the editor like the first one's.
    type_into(field(d, f"/pigmented_layer/pigments/{n}/concentration"), "0,05")
    WebDriverWait(d, WAIT).until(lambda d: raw(d)["pigmented_layer"]["pigments"][n]["concentration"] == 0.05)
    wait_current(d)
    assert d.find_element(By.ID, "measure-error").text == ""
    assert_page_is_cli(d, tmp_path)
    assert console_errors(d) == []


def test_a_nested_optional_block_is_added_and_removed(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "solid-white")
    assert "scatter" not in raw(d)["clear_coat"]
    d.find_element(By.ID, "add-clear_coat_scatter").click()
    WebDriverWait(d, WAIT).until(lambda d: "scatter" in raw(d)["clear_coat"])
    # Its numbers are fields of the editor now, and the readings are measure's.
    assert field(d, "/clear_coat/scatter/rms_roughness_nm").get_attribute("value")
    wait_current(d)
    assert d.find_element(By.ID, "measure-error").text == ""
    assert_page_is_cli(d, tmp_path)
    d.find_element(By.ID, "remove-clear_coat_scatter").click()
    WebDriverWait(d, WAIT).until(lambda d: "scatter" not in raw(d)["clear_coat"])
    assert console_errors(d) == []


def test_an_element_of_a_numeric_array_is_swept_over_the_arrays_range(browser, server):
    """`/albedo/0` takes the range of the registry's `/albedo` entry (0..1), not an open guess around the value."""
    d = browser
    wait_current(d)
    choose_fixture(d, "rgb-lambert")
    d.find_element(By.ID, "tab-sweep").click()
    Select(d.find_element(By.ID, "sweep-path")).select_by_value("/albedo/0")
    lo, hi = (d.find_element(By.ID, k).get_attribute("value") for k in ("sweep-lo", "sweep-hi"))
    with urllib.request.urlopen(server.rstrip("/") + "/api/registry") as r:
        reg = json.load(r)
    albedo = next(p for p in reg["parameters"] if p["pointer"] == "/albedo" and "lambert" in p["models"])
    assert (float(lo), float(hi)) == (albedo["range"]["lo"], albedo["range"]["hi"]) == (0, 1), (lo, hi)
    assert console_errors(d) == []
