"""One palette for the PNG, the GIF and the HTML page; multi-camera image views (a panel per
channel in the pictures, a channel switch in the page)."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest
from matplotlib.colors import to_hex
from PIL import Image

from scenegrep import readers
from scenegrep.model.taxonomy import kind_of
from scenegrep.view.data import QueryInfo, build_view, image_channels
from scenegrep.view.page import view_page
from scenegrep.view.payload import payload
from scenegrep.view.plot import Figure, picture
from scenegrep.view.style import KIND_COLOURS
from tests.conftest import REPO
from tests.spre.test_semantics import image_trace

SAMPLE = REPO / "examples" / "sample" / "s2_unprotected_left_turn-000.parquet"
"""A sample trace whose two objects go through four behaviour label sets."""

CAR, PED, CONE = ("car", 10, 10, 20, 14), ("pedestrian", 50, 50, 6, 20), ("traffic_cone", 80, 20, 4, 4)
LINKED = ("car", 30, 70, 10, 10, None, "b1")
"""A box of class car linked to object b1, a bus: the object's kind decides its colour."""
CAMERA_FRAMES = [
    [[CAR, PED, LINKED], [PED], []],
    [[CAR], [], [CONE, PED]],
    [[PED, CONE], [CAR, PED], [CONE, CAR]],
]
"""Three frames of three channels (front, back, side): each a list of boxes per channel."""
CHANNELS = ("front", "back", "side")


@pytest.fixture(scope="module")
def labelled():
    """The sample trace with a five-frame match of its two objects, and that match's figure."""
    trace = readers.read_trace(SAMPLE)
    ids = trace.objects.id.tolist()
    index = trace.frame_index.tolist()
    row = {"status": "match", "match": 0, "start_frame": index[60], "end_frame": index[64]}
    view = build_view(trace, rows=[{**row, "correspondence": {"ego": ids[0], "other": ids[1]}}])
    figure = Figure(view, view.matches[0])
    yield view, figure
    figure.close()


@pytest.fixture(scope="module")
def cameras():
    trace = image_trace(CAMERA_FRAMES, channels=CHANNELS, objects={"b1": "bus"})
    return build_view(trace)


def html_behaviour_colours(view) -> dict[str, str]:
    states = payload(view)["states"]
    return {name or "(none)": c for name, c in zip(states["label_names"], states["label_colours"], strict=True)}


def png_behaviour_colours(figure) -> dict[str, str]:
    legend = figure.timeline.get_legend()
    return {
        text.get_text(): to_hex(handle.get_facecolor())
        for text, handle in zip(legend.get_texts(), legend.legend_handles, strict=True)
    }


def test_behaviour_sets_have_the_same_colour_in_the_png_and_the_page(labelled):
    view, figure = labelled
    sets, _ = view.trace.behaviours.distinct_sets()
    html, png = html_behaviour_colours(view), png_behaviour_colours(figure)
    assert len(sets) == 4 and png == html and sorted(png) == sorted(sets)
    assert len(set(png.values())) == len(png), "two behaviour sets share a colour"
    bars = {to_hex(c.get_facecolor()[0]) for c in figure.timeline.collections}
    assert bars == set(png.values())


def test_behaviour_sets_have_the_same_colour_in_the_gif(labelled):
    view, figure = labelled
    gif = Image.open(io.BytesIO(picture(view, "gif", view.matches[0])))
    pixels = np.asarray(gif.convert("RGB")).reshape(-1, 3).astype(int)
    for name, colour in png_behaviour_colours(figure).items():
        rgb = np.array([int(colour[k : k + 2], 16) for k in (1, 3, 5)])
        assert np.abs(pixels - rgb).max(axis=1).min() <= 8, f"{name}: {colour} is not in the GIF"


def html_box_colours(doc: dict, channel: str) -> list[str]:
    """The colour the page's script gives every box of a channel (view.js drawObjects)."""
    table = next(t for t in doc["boxes"] if t["channel"] == channel)
    kinds = doc["objects"]["colour"]
    return [kinds[o] if o >= 0 else table["class_colours"][c] for o, c in zip(table["object"], table["class"])]


def test_image_boxes_have_their_class_colour_in_the_png_and_the_page(cameras):
    figure = Figure(cameras, None)
    try:
        for f, frame in enumerate(CAMERA_FRAMES):
            figure.show_frame(f)
            doc = payload(cameras)
            for ax, collection in zip(figure.axes, figure.collections):
                channel = ax.get_title(loc="left").removeprefix("channel ")
                boxes = frame[CHANNELS.index(channel)]
                expected = [KIND_COLOURS["bus" if len(b) > 6 else kind_of(b[0])] for b in boxes]
                png = [to_hex(c) for c in collection.get_edgecolor()] if boxes else []
                shown = doc["boxes"][[t["channel"] for t in doc["boxes"]].index(channel)]
                in_frame = slice(shown["offsets"][f], shown["offsets"][f + 1])
                assert png == expected == html_box_colours(doc, channel)[in_frame], (f, channel)
    finally:
        figure.close()


def test_a_png_of_a_multi_camera_view_has_a_named_panel_per_channel_with_its_boxes(cameras):
    figure = Figure(cameras, None)
    try:
        assert [ax.get_title(loc="left") for ax in figure.axes] == [f"channel {c}" for c in image_channels(cameras)]
        for f, frame in enumerate(CAMERA_FRAMES):
            figure.show_frame(f)
            for ax, collection in zip(figure.axes, figure.collections):
                boxes = frame[CHANNELS.index(ax.get_title(loc="left").removeprefix("channel "))]
                centres = [path.vertices[:4].mean(axis=0).tolist() for path in collection.get_paths()]
                assert centres == [[float(b[1]), float(b[2])] for b in boxes]
    finally:
        figure.close()
    assert Image.open(io.BytesIO(picture(cameras, "png"))).size == (1000, 750)


def test_channels_are_ordered_asked_first_then_by_boxes():
    trace = image_trace(CAMERA_FRAMES, channels=CHANNELS, objects={"b1": "bus"})
    assert image_channels(build_view(trace)) == ("front", "side", "back")  # 6, 4 and 3 boxes
    asked = build_view(trace, query=QueryInfo("spre", "[[:car:]]", {"channels": ["back", "nowhere", "back"]}))
    assert image_channels(asked) == ("back", "front", "side")
    assert [t["channel"] for t in payload(asked)["boxes"]] == ["back", "front", "side"]
    one_empty = image_trace([[[CAR], []]], channels=("front", "back"))
    assert image_channels(build_view(one_empty)) == ("front", "back")  # a camera that saw nothing is drawn


@pytest.mark.slow
@pytest.mark.browser
def test_the_page_names_its_channel_switches_channels_and_uses_the_same_colours(browser, cameras, labelled, tmp_path):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import Select, WebDriverWait

    def open_page(view, name):
        page = tmp_path / name
        page.write_text(view_page(view))
        browser.get(page.as_uri())
        WebDriverWait(browser, 20).until(lambda d: d.execute_script("return window.scenegrepView !== undefined"))

    browser.get_log("browser")
    open_page(cameras, "cameras.html")
    doc = payload(cameras)
    choice = Select(browser.find_element(By.ID, "channel"))
    assert [o.text for o in choice.options] == list(image_channels(cameras))
    assert browser.execute_script("return scenegrepView.channel()") == choice.first_selected_option.text == "front"
    browser.execute_script("scenegrepView.setFrame(2)")
    for channel in ("back", "side", "front"):
        choice.select_by_visible_text(channel)
        assert browser.execute_script("return scenegrepView.channel()") == channel
        drawn = browser.execute_script("return scenegrepView.drawnColours()")
        table = next(t for t in doc["boxes"] if t["channel"] == channel)
        rows = range(table["offsets"][2], table["offsets"][3])
        assert drawn == [[r, html_box_colours(doc, channel)[r]] for r in rows]
    browser.execute_script("scenegrepView.setChannel('side')")
    assert choice.first_selected_option.text == "side"

    view, figure = labelled
    open_page(view, "labelled.html")
    swatches = browser.find_elements(By.CSS_SELECTOR, "#label-legend span")
    shown = {s.text: s.find_element(By.TAG_NAME, "i").value_of_css_property("background-color") for s in swatches}
    png = png_behaviour_colours(figure)
    as_css = {
        name: "rgba({}, {}, {}, 1)".format(*(int(c[k : k + 2], 16) for k in (1, 3, 5))) for name, c in png.items()
    }
    assert shown == as_css
    assert not browser.find_element(By.ID, "channel-choice").is_displayed()
    assert browser.get_log("browser") == []


def test_the_trace_renderers_have_no_colours_of_their_own():
    """Every colour of the page's script and of the pictures is :mod:`scenegrep.view.style`'s."""
    view = REPO / "src" / "scenegrep" / "view"
    for name in ("assets/view.js", "plot.py", "payload.py", "charts.py"):
        assert re.findall(r"#[0-9a-fA-F]{6}\b", (view / name).read_text()) == [], name
