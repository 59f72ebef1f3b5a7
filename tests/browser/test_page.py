"""The page in a real browser: it loads without console errors, an edited parameter gives the reading
`glossmeter measure` gives (bit for bit), a shipped sheet gives its verdicts, the keyboard reaches every
tool, and the screenshots docs/serve.md shows are taken from it."""
import json
import os
import subprocess

from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select, WebDriverWait

from conftest import ROOT, binary

WAIT = 120


def wait_current(d):
    WebDriverWait(d, WAIT).until(
        lambda d: d.find_element(By.ID, "readings-state").text == "current"
        and "stale" not in d.find_element(By.ID, "readings").get_attribute("class")
    )


def console_errors(d):
    return [e for e in d.get_log("browser") if e["level"] == "SEVERE"]


def page_readings(d):
    rows = d.find_elements(By.CSS_SELECTOR, "#readings tbody tr")
    return {
        (r.get_attribute("data-geometry"), r.get_attribute("data-name")): r.find_element(By.CSS_SELECTOR, "td.value").get_attribute("data-value")
        for r in rows
    }


def cli_readings(recipe_text, tmp_path, geometries):
    f = tmp_path / "recipe.json"
    f.write_text(recipe_text)
    args = [binary(), "measure", "--format", "json", "--no-timing", str(f)]
    for g in geometries:
        args += ["-g", g]
    out = subprocess.run(args, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return {(r["geometry"], r["name"]): r["value"] for r in json.loads(out.stdout)["readings"]}


def choose_fixture(d, name):
    Select(d.find_element(By.ID, "fixture")).select_by_value(name)
    wait_current(d)


def test_the_page_loads_with_readings_and_no_console_errors(browser):
    wait_current(browser)
    assert len(page_readings(browser)) >= 6
    assert browser.find_elements(By.CSS_SELECTOR, "#params .field"), "the editor is built from the registry"
    assert console_errors(browser) == []


def test_an_edited_parameter_reads_what_measure_gives(browser, tmp_path):
    d = browser
    wait_current(d)
    choose_fixture(d, "semigloss-white")
    before = page_readings(d)
    # The first numeric field the editor shows set in this recipe.
    field = [f for f in d.find_elements(By.CSS_SELECTOR, "#params input.number") if f.get_attribute("value")][0]
    ptr = field.get_attribute("data-pointer")
    old = float(field.get_attribute("value"))
    new = round(old * 0.97, 6) if old != 0 else 0.1  # inside the range of every shipped field
    field.send_keys(Keys.CONTROL, "a")
    field.send_keys(str(new))
    WebDriverWait(d, WAIT).until(lambda d: json.loads(d.find_element(By.ID, "raw").get_attribute("value")) is not None)
    wait_current(d)
    raw = d.find_element(By.ID, "raw").get_attribute("value")
    sent = json.loads(raw)
    node = sent
    for t in ptr.split("/")[1:]:
        node = node[int(t) if isinstance(node, list) else t]
    assert node == new
    after = page_readings(d)
    assert after != before, f"editing {ptr} {old} -> {new} changed no reading"
    geos = [i.get_attribute("value") for i in d.find_elements(By.CSS_SELECTOR, "#geometries input:checked")]
    cli = cli_readings(raw, tmp_path, geos)
    assert set(after) == set(cli)
    for k, v in cli.items():
        shown = after[k]
        if v is None:
            assert shown == ""
        else:
            assert float(shown) == v, f"{k}: the page shows {shown}, measure gives {v!r}"
    assert console_errors(d) == []


def test_a_shipped_sheet_gives_its_verdicts(browser):
    d = browser
    wait_current(d)
    choose_fixture(d, "black-glass")
    d.find_element(By.ID, "tab-compare").click()
    sheet = ROOT / "fixtures" / "sheets" / "black-glass-check.csv"
    d.find_element(By.ID, "sheet").send_keys(str(sheet))
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#verdicts tbody tr"))
    verdicts = [td.text for td in d.find_elements(By.CSS_SELECTOR, "#verdicts td.verdict")]
    rows = [l for l in sheet.read_text().splitlines() if l and not l.startswith("#")][1:]
    assert len(verdicts) == len(rows)
    assert all(v == "ok" for v in verdicts), verdicts
    assert d.find_element(By.ID, "dl-csv").is_enabled()
    shots = os.environ.get("GLOSSMETER_SCREENSHOTS")
    if shots:
        d.execute_script("document.getElementById('tabs').scrollIntoView()")
        d.save_screenshot(os.path.join(shots, "serve-compare.png"))
    assert console_errors(d) == []


def test_the_keyboard_reaches_the_tools(browser):
    d = browser
    wait_current(d)
    body = d.find_element(By.TAG_NAME, "body")
    body.send_keys(Keys.TAB)
    assert d.switch_to.active_element.get_attribute("id") == "fixture"
    tab = d.find_element(By.ID, "tab-pictures")
    tab.send_keys(Keys.ARROW_RIGHT)
    assert d.switch_to.active_element.get_attribute("id") == "tab-sweep"
    assert d.find_element(By.ID, "panel-sweep").is_displayed()
    assert not d.find_element(By.ID, "panel-pictures").is_displayed()
    d.switch_to.active_element.send_keys(Keys.END)
    assert d.switch_to.active_element.get_attribute("id") == "tab-plan"
    assert console_errors(d) == []


def test_the_picture_and_the_screenshot(browser, tmp_path):
    d = browser
    wait_current(d)
    WebDriverWait(d, WAIT).until(lambda d: (d.find_element(By.ID, "picture").get_attribute("src") or "").startswith("blob:"))
    WebDriverWait(d, WAIT).until(lambda d: d.execute_script("const i = document.getElementById('picture'); return i.complete && i.naturalWidth > 0"))
    shots = os.environ.get("GLOSSMETER_SCREENSHOTS") or str(tmp_path)
    path = os.path.join(shots, "serve-page.png")
    d.execute_script("document.getElementById('result-pane').scrollTop = 220")
    assert d.save_screenshot(path)
    assert os.path.getsize(path) > 10_000
    assert console_errors(d) == []


def test_a_sweep_streams_its_points_and_draws_its_curve(browser):
    d = browser
    wait_current(d)
    choose_fixture(d, "black-glass")
    d.find_element(By.ID, "tab-sweep").click()
    Select(d.find_element(By.ID, "sweep-path")).select_by_value("/ior")
    n = d.find_element(By.ID, "sweep-n")
    n.clear()
    n.send_keys("3")
    d.find_element(By.ID, "sweep-go").click()
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "sweep-count").text == "3 / 3 points")
    assert len(d.find_elements(By.CSS_SELECTOR, "#sweep-rows tbody tr")) == 3
    WebDriverWait(d, WAIT).until(lambda d: d.find_elements(By.CSS_SELECTOR, "#sweep-charts svg.chart"))
    assert d.find_element(By.ID, "sweep-error").text == ""
    assert console_errors(d) == []


def test_a_fit_reaches_its_target(browser):
    d = browser
    wait_current(d)
    choose_fixture(d, "black-glass")
    d.find_element(By.ID, "tab-fit").click()
    box = d.find_element(By.CSS_SELECTOR, "#fit-free input[value='/ior']")
    box.click()
    row = box.find_element(By.XPATH, "..")
    for cls, v in (("lo", "1.3"), ("hi", "1.8")):
        e = row.find_element(By.CLASS_NAME, cls)
        e.clear()
        e.send_keys(v)
    t = d.find_element(By.ID, "fit-targets")
    t.clear()
    t.send_keys("astm-d523-60/gloss=90±0.1")
    d.find_element(By.ID, "fit-go").click()
    WebDriverWait(d, WAIT).until(lambda d: d.find_element(By.ID, "fit-verdict").text or d.find_element(By.ID, "fit-error").text)
    assert d.find_element(By.ID, "fit-error").text == ""
    assert d.find_element(By.ID, "fit-verdict").text.startswith("The fit is to be trusted"), d.find_element(By.ID, "fit-verdict").text
    assert console_errors(d) == []
