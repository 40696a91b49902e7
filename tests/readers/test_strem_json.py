"""STREM JSON v0.2.0 streams: the conformance data, several documents, stdin streaming, errors."""

import io
import json
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.readers import strem_json
from scenegrep.readers.json_stream import DocumentSplitter


def data_file(conformance_dir: Path, name: str) -> Path:
    return conformance_dir / "strem" / "data" / name


def test_reads_frames_samples_and_boxes(conformance_dir):
    trace = strem_json.read_trace(data_file(conformance_dir, "seq_a.json"))
    doc = json.loads(data_file(conformance_dir, "seq_a.json").read_text())
    assert trace.frame_index.tolist() == [f["index"] for f in doc["frames"]]
    boxes = trace.images.boxes
    expected = [
        (a["class"], a["bbox"]["region"]["center"]["x"], a["bbox"]["region"]["dimensions"]["w"])
        for f in doc["frames"]
        for s in f["samples"]
        for a in s["annotations"]
    ]
    got = [(boxes.classes[c], x, w) for c, x, w in zip(boxes.category, boxes.cx, boxes.w)]
    assert got == expected
    assert (boxes.object == -1).all() and trace.n_objects == 0


def test_channels_and_oriented_boxes(conformance_dir):
    trace = strem_json.read_trace(data_file(conformance_dir, "channels.json"))
    samples = trace.images.samples
    assert set(samples.channels) == {"cam::front", "cam::back"}
    doc = json.loads(data_file(conformance_dir, "channels.json").read_text())
    per_frame = [sorted(s["channel"] for s in f["samples"]) for f in doc["frames"]]
    assert [
        sorted(samples.channels[c] for c, f in zip(samples.channel, samples.frame) if f == k)
        for k in range(trace.n_frames)
    ] == per_frame


def test_obb_rotation_read_and_aabb_rotation_ignored(tmp_path):
    def ann(kind, rotation):
        region = {"center": {"x": 1, "y": 2}, "dimensions": {"w": 3, "h": 4}, "rotation": rotation}
        return {"class": "car", "score": 0.5, "bbox": {"type": f"@stremf/bbox/{kind}", "region": region}}

    sample = {
        "type": "@stremf/sample/detection",
        "channel": "c",
        "image": {"path": "p", "dimensions": {"width": 10, "height": 10}},
        "annotations": [ann("aabb", 0.7), ann("obb", 0.3)],
    }
    path = tmp_path / "s.json"
    path.write_text(json.dumps({"version": "0.2.0", "frames": [{"index": 0, "samples": [sample]}]}))
    boxes = strem_json.read_trace(path).images.boxes
    assert boxes.oriented.tolist() == [False, True] and boxes.rotation.tolist() == [0.0, 0.3]


def test_several_documents_form_one_stream(conformance_dir):
    trace = strem_json.read_trace(data_file(conformance_dir, "multidoc.json"))
    assert trace.frame_index.tolist() == [0, 1, 2, 3, 4, 5]


def test_noncontiguous_indices_and_empty(conformance_dir):
    assert strem_json.read_trace(data_file(conformance_dir, "noncontig.json")).frame_index.tolist() == [10, 20, 30]
    assert strem_json.read_trace(data_file(conformance_dir, "fmt_empty_frames.json")).n_frames == 0
    assert strem_json.read_trace(data_file(conformance_dir, "fmt_extra_fields.json")).n_frames == 7


@pytest.mark.parametrize(
    "name, fragment",
    [
        ("fmt_missing_image.json", ":42:5: frames[1].samples[0]: missing field `image`"),
        (
            "fmt_bad_bbox_type.json",
            ":22:17: frames[0].samples[0].annotations[0].bbox.type: unknown variant `@stremf/bbox/3d`, "
            "expected `@stremf/bbox/aabb` or `@stremf/bbox/obb`",
        ),
        ("fmt_version_011.json", ":2:13: version: unsupported STREM version '0.1.1': expected 0.2.0"),
    ],
)
def test_format_errors_name_the_place(conformance_dir, name, fragment):
    with pytest.raises(UserError) as info:
        strem_json.read_trace(data_file(conformance_dir, name))
    assert info.value.one_line() == f"{data_file(conformance_dir, name)}{fragment}"


def test_truncated_and_wrong_types(conformance_dir, tmp_path):
    text = data_file(conformance_dir, "seq_a.json").read_bytes()
    cut = tmp_path / "cut.json"
    cut.write_bytes(text[: len(text) // 2])
    with pytest.raises(UserError, match=r"cut.json:\d+:\d+: frames\[3\].*unexpected end of input"):
        strem_json.read_trace(cut)
    bad = tmp_path / "bad.json"
    bad.write_text('{"version": "0.2.0", "frames": [{"index": 1.5, "samples": []}]}')
    with pytest.raises(UserError, match=r"bad.json:1:43: frames\[0\].index: expected an unsigned integer, found 1.5"):
        strem_json.read_trace(bad)
    with pytest.raises(UserError, match="no such file"):
        strem_json.read_trace(tmp_path / "absent.json")


def test_iter_documents_hands_each_document_on(conformance_dir):
    stream = io.BytesIO(data_file(conformance_dir, "multidoc.json").read_bytes())
    chunks = list(strem_json.iter_documents(stream, chunk_size=7))
    assert [c.frame_index.tolist() for c in chunks] == [[0, 1, 2], [3, 4, 5]]
    with pytest.raises(UserError, match="truncated"):
        list(strem_json.iter_documents(io.BytesIO(b'{"version": "0.2.0", "frames": [')))


json_values = st.recursive(
    st.none() | st.booleans() | st.integers() | st.text(alphabet='ab{}[]"\\ \n', max_size=5),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=3), inner, max_size=3),
    max_leaves=8,
)


@given(
    st.lists(st.dictionaries(st.text(alphabet='xy"\\{', max_size=3), json_values, max_size=3), min_size=1, max_size=4),
    st.lists(st.integers(1, 200), max_size=8),
    st.sampled_from(["", "\n", "  "]),
)
def test_document_splitter_against_json_module(documents, cuts, separator):
    text = separator.join(json.dumps(d) for d in documents).encode()
    splitter, found, start = DocumentSplitter(), [], 0
    for cut in sorted(set(cuts)) + [len(text)]:
        found += splitter.feed(text[start:cut])
        start = max(start, cut)
    assert [json.loads(d) for d in found] == documents and splitter.remainder() == b""
