"""End to end in headless Chromium: reports, views and the dataset server, as a person uses them."""

from __future__ import annotations

import json
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from scenegrep.view.report import write_report
from scenegrep.view.sources import ResultsSource
from tests.view.conftest import screenshot

pytestmark = [pytest.mark.slow, pytest.mark.browser, pytest.mark.real_data]


def wait_for(driver, script: str, timeout: float = 20.0):
    """The value of a JavaScript expression once it is truthy (fails the test after ``timeout`` s)."""
    from selenium.webdriver.support.ui import WebDriverWait

    return WebDriverWait(driver, timeout).until(lambda d: d.execute_script(f"return {script}"))


def open_view_from_report(browser, report: Path, k: int) -> dict:
    """Open the report, click its k-th match link; the link's data attributes."""
    from selenium.webdriver.common.by import By

    browser.get(report.as_uri())
    links = browser.find_elements(By.CSS_SELECTOR, "a.match-link")
    link = links[k]
    expected = {
        "trace": link.get_attribute("data-trace"),
        "match": int(link.get_attribute("data-match")),
        "window": [int(link.get_attribute("data-start")), int(link.get_attribute("data-end"))],
        "correspondence": json.loads(link.get_attribute("data-correspondence")),
    }
    link.click()
    wait_for(browser, "window.scenegrepView !== undefined")
    return expected


def test_report_match_opens_its_view_and_scrubbing_moves_the_highlighted_objects(
    browser, real_dataset, scenario_run, tmp_path
):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys

    source = ResultsSource.of_run(real_dataset, scenario_run)
    report = tmp_path / "report.html"
    write_report(source, report)
    matches = scenario_run.matches.to_pylist()
    assert len(matches) == 12

    browser.get(report.as_uri())
    cards = {
        c.get_attribute("data-count"): c.find_element(By.TAG_NAME, "b").text
        for c in browser.find_elements(By.CSS_SELECTOR, ".card")
    }
    assert cards["matches"] == "12" and cards["matched"] == str(scenario_run.counts()["matched"])
    assert len(browser.find_elements(By.CSS_SELECTOR, "#chart-matches rect")) == 12

    expected = open_view_from_report(browser, report, 5)
    row = matches[5]
    assert expected["trace"] == row["trace_id"] and expected["window"] == [row["start_frame"], row["end_frame"]]
    assert browser.execute_script("return scenegrepView.window()") == expected["window"]
    mark = browser.find_element(By.ID, "window-mark")
    assert [int(mark.get_attribute("data-first")), int(mark.get_attribute("data-last"))] == expected["window"]
    legend = {
        li.get_attribute("data-name"): li.get_attribute("data-id")
        for li in browser.find_elements(By.CSS_SELECTOR, "#legend li[data-name]")
    }
    assert legend == expected["correspondence"]
    assert "window frame" in browser.find_element(By.ID, "explanation").text

    # The view opens on the window's first frame with the program's objects highlighted there.
    assert browser.execute_script("return scenegrepView.frame()") == expected["window"][0]
    highlighted = dict(browser.execute_script("return scenegrepView.highlighted()"))
    assert highlighted == expected["correspondence"]

    # Scrub: drag the slider's thumb to the far right, then step back with the keyboard.
    slider = browser.find_element(By.ID, "frame")
    from selenium.webdriver.common.action_chains import ActionChains

    ActionChains(browser).click_and_hold(slider).move_by_offset(slider.size["width"] // 2 - 1, 0).release().perform()
    last = int(browser.execute_script("return scenegrepView.frame()"))
    assert last > expected["window"][1]
    slider.send_keys(Keys.ARROW_LEFT * 3)
    assert browser.execute_script("return scenegrepView.frame()") == last - 3
    assert int(browser.find_element(By.TAG_NAME, "body").get_attribute("data-frame")) == last - 3 - 0
    assert re.match(rf"frame {last - 3} ", browser.find_element(By.ID, "frame-label").text)
    shown = dict(browser.execute_script("return scenegrepView.highlighted()"))
    assert shown.items() <= expected["correspondence"].items()
    screenshot(browser, "report-match-view")


def test_hovering_a_highlighted_object_shows_its_details(browser, real_dataset, scenario_run, tmp_path):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    report = tmp_path / "report.html"
    write_report(ResultsSource.of_run(real_dataset, scenario_run), report)
    expected = open_view_from_report(browser, report, 0)
    ego = expected["correspondence"]["ego"]
    x, y = browser.execute_script("return scenegrepView.screenOf(arguments[0])", ego)
    actions = ActionChains(browser)
    actions.w3c_actions.pointer_action.move_to_location(int(x), int(y))
    actions.perform()
    tooltip = browser.find_element(By.ID, "tooltip")
    wait_for(browser, "!document.getElementById('tooltip').hidden")
    assert f"id {ego}" in tooltip.text and "ego (program object)" in tooltip.text
    assert "behaviours" in tooltip.text


def test_spre_view_marks_the_named_class_on_real_nuscenes(browser, real_dataset, spre_run, tmp_path):
    from selenium.webdriver.common.by import By

    report = tmp_path / "report.html"
    write_report(ResultsSource.of_run(real_dataset, spre_run), report)
    links = [k for k, row in enumerate(spre_run.matches.to_pylist()) if row["name"] == "scene-0061"]
    expected = open_view_from_report(browser, report, links[0])
    first, last = expected["window"]
    assert browser.execute_script("return scenegrepView.window()") == [first, last]
    kinds = browser.execute_script(
        "const d = JSON.parse(document.getElementById('scenegrep-data').textContent);"
        "return scenegrepView.marked().map(r => d.objects.kind[d.states.object[r]]);"
    )
    assert kinds and set(kinds) == {"pedestrian"}
    assert browser.find_element(By.ID, "query").text == "spre: [[:pedestrian:]]+"
    screenshot(browser, "spre-nuscenes-view")


def test_every_view_of_real_av2_nuscenes_and_sample_matches_draws_without_errors(
    browser, real_dataset, spre_run, tmp_path
):
    report = tmp_path / "report.html"
    write_report(ResultsSource.of_run(real_dataset, spre_run), report)
    browser.get_log("browser")
    rows = spre_run.matches.to_pylist()
    names = {row["name"] for row in rows}
    assert {"7fab2350-7eaf-3b7e-a39d-6937a4c1bede", "scene-0061", "s3_pass_pedestrian-000"} <= names
    for k, row in enumerate(rows):
        expected = open_view_from_report(browser, report, k)
        wait_for(browser, "document.body.dataset.frame !== undefined")
        assert browser.execute_script("return scenegrepView.window()") == expected["window"], row["name"]
        assert browser.execute_script("return scenegrepView.frame()") == row["start_frame"]
        browser.execute_script("scenegrepView.setFrame(1e9)")  # the last frame draws too
        assert browser.get_log("browser") == [], row["name"]


def test_serve_runs_a_typed_query_and_opens_a_match(browser, real_dataset):
    from selenium.webdriver.common.by import By

    server = subprocess.Popen(
        [sys.executable, "-m", "scenegrep", "serve", str(real_dataset), "--port", "0", "-j", "2"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        line = server.stdout.readline()
        url = re.search(r"http://127\.0\.0\.1:\d+/", line).group(0)
        browser.get(url)
        wait_for(browser, "document.querySelectorAll('#traces tbody tr').length > 0")
        assert len(browser.find_elements(By.CSS_SELECTOR, "#traces tbody tr")) == 62
        text = browser.find_element(By.ID, "text")
        text.send_keys("[[:bicycle:]")
        browser.find_element(By.ID, "run").click()
        wait_for(browser, "!document.getElementById('error').hidden")
        assert "expected ']'" in browser.find_element(By.ID, "error").text
        text.send_keys("]")
        browser.find_element(By.ID, "run").click()
        wait_for(browser, "document.querySelectorAll('a.match-link').length > 0", timeout=60)
        link = browser.find_elements(By.CSS_SELECTOR, "a.match-link")[0]
        window = [int(link.get_attribute("data-start")), int(link.get_attribute("data-end"))]
        link.click()
        wait_for(browser, "window.scenegrepView !== undefined")
        assert browser.execute_script("return scenegrepView.window()") == window
        screenshot(browser, "serve-match-view")
    finally:
        server.send_signal(signal.SIGINT)
        server.wait(timeout=20)
    assert server.returncode == 0


def test_image_space_view_draws_boxes_and_marks_the_named_class(browser, tmp_path):
    from scenegrep.view.data import QueryInfo, build_view
    from scenegrep.view.page import view_page
    from tests.spre.test_semantics import image_trace

    car, ped = ("car", 10, 10, 4, 4), ("ped", 50, 50, 4, 4)
    trace = image_trace([[[car]], [[car, ped]], [[ped]], [[car]]])
    rows = [{"status": "match", "match": 0, "start_frame": 1, "end_frame": 2, "correspondence": "{}"}]
    page = tmp_path / "image.html"
    page.write_text(view_page(build_view(trace, None, rows, QueryInfo("spre", "[[:ped:]]+"))))
    browser.get(page.as_uri())
    wait_for(browser, "window.scenegrepView !== undefined")
    assert browser.execute_script("return scenegrepView.window()") == [1, 2]
    browser.execute_script("scenegrepView.setFrame(1)")
    assert len(browser.execute_script("return scenegrepView.marked()")) == 1
    browser.execute_script("scenegrepView.setFrame(3)")
    assert browser.execute_script("return scenegrepView.marked()") == []
    time.sleep(0.1)
    screenshot(browser, "image-space-view")
