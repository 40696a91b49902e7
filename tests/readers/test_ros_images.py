"""vision_msgs/Detection2DArray bags written from STREM streams give back their image boxes, and
SpREs return on them what they return on the streams."""

from __future__ import annotations

import json

import pytest

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.readers.ros.options import BagOptions
from scenegrep.readers.ros.reader import read_trace

from scenegrep.writers.ros_bag import write_detections2d

STREAMS = ["channels.json", "seq_b.json"]


@pytest.fixture(scope="module", params=STREAMS)
def stream(request, tmp_path_factory):
    from tests.conftest import SHARED

    source = SHARED / "conformance" / "strem" / "data" / request.param
    if not source.exists():
        pytest.skip(f"{source} is absent")
    trace = readers.read_trace(source)
    path = tmp_path_factory.mktemp("images") / "detections.mcap"
    write_detections2d(trace, path)
    return source, trace, path


def _contents(layer) -> tuple[list, list]:
    """A layer's samples (frame, channel) and boxes (frame, channel, class, score, centre, size,
    rotation; 1e-6 rounded), sorted: what the layer holds, whatever its row order."""
    samples, boxes = layer.samples, layer.boxes
    channel = [samples.channels[c] for c in samples.channel]
    sample_rows = sorted((int(f), c) for f, c in zip(samples.frame, channel))
    box_rows = sorted(
        (int(samples.frame[s]), channel[s], boxes.classes[k], *(round(float(v), 6) for v in values))
        for s, k, *values in zip(
            boxes.sample, boxes.category, boxes.score, boxes.cx, boxes.cy, boxes.w, boxes.h, boxes.rotation
        )
    )
    return sample_rows, box_rows


def test_image_boxes_come_back_per_channel(stream):
    _, trace, path = stream
    bag = read_trace(path, BagOptions(rate=10.0))
    assert bag.n_frames == trace.n_frames and bag.n_objects == 0
    assert _contents(bag.images) == _contents(trace.images)
    assert len(bag.images.boxes) == len(trace.images.boxes) > 0
    assert (bag.images.samples.image_width == 0).all()  # the message states no image size


@pytest.mark.parametrize(
    "query", ["[[:car:]]", "[[:car:]]*", "[[:pedestrian:] & [:car:]]+", "[[:car:]][[:car:]]", "[[:pedestrian:]]+"]
)
@pytest.mark.parametrize("channel", [[], ["--channel", "cam::front"]])
def test_spre_returns_on_the_bag_what_it_returns_on_the_stream(stream, query, channel, capsys):
    source, _, path = stream

    def spans(data: list[str]) -> list[tuple]:
        code = main(["spre", query, *data, *channel, "--json"])
        out = capsys.readouterr().out
        assert code in (0, 1), out
        return sorted((r["status"], r["start_frame"], r["end_frame"]) for r in map(json.loads, out.splitlines()))

    from_bag = spans([str(path), "--rate", "10"])
    assert from_bag == spans([str(source)])
    if query == "[[:car:]]":
        assert any(status == "match" for status, *_ in from_bag)
