"""Hypothesis strategies shared by the tests: random label traces."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st

from scenegrep.model import (
    BehaviourLabels,
    BoxTable,
    ImageLayer,
    LabelTrace,
    MapSource,
    ObjectTable,
    SampleTable,
    StateTable,
)

finite = st.floats(-1e4, 1e4, allow_nan=False, allow_infinity=False)


@st.composite
def label_traces(draw, max_frames: int = 8, max_objects: int = 4, images: bool = True) -> LabelTrace:
    """A random, valid trace: states, optional behaviours with confidences, optional image layer."""
    n_frames = draw(st.integers(0, max_frames))
    n_objects = draw(st.integers(0, max_objects))
    ids = [f"o{i}" for i in range(n_objects)]
    objects = ObjectTable.build(
        ids,
        [draw(st.sampled_from(["car", "pedestrian", "vehicle.truck"])) for _ in ids],
        [draw(st.dictionaries(st.sampled_from(["colour", "id2"]), st.text(max_size=3), max_size=2)) for _ in ids],
    )
    cells = [(f, o) for f in range(n_frames) for o in range(n_objects)]
    mask = draw(st.lists(st.booleans(), min_size=len(cells), max_size=len(cells)))
    present = [c for c, keep in zip(cells, mask) if keep]
    n = len(present)
    floats = lambda: np.array(draw(st.lists(finite, min_size=n, max_size=n)))  # noqa: E731
    lanes = ("L1", "L2")
    states = StateTable.build(
        [c[0] for c in present],
        [c[1] for c in present],
        floats(),
        floats(),
        floats(),
        z=floats(),
        length=np.abs(floats()),
        width=np.abs(floats()),
        height=np.full(n, np.nan),
        vx=floats(),
        vy=floats(),
        lane=draw(st.lists(st.integers(-1, 1), min_size=n, max_size=n)),
    )
    behaviours = None
    if draw(st.booleans()):
        names = st.sampled_from(["FollowLane", "LaneChange", "Stationary"])
        scored = draw(st.booleans())
        sets = [
            draw(st.dictionaries(names, st.floats(0, 1, width=32), max_size=3))
            if scored
            else draw(st.sets(names, max_size=3))
            for _ in range(n)
        ]
        behaviours = BehaviourLabels.from_sets(sets, ["Brake"])
    layer = draw(_image_layers(n_frames, n_objects)) if images and n_frames and draw(st.booleans()) else None
    times = np.round(np.arange(n_frames) * draw(st.sampled_from([0.1, 0.5])), 6)
    return LabelTrace.build(
        "t",
        np.arange(n_frames) * draw(st.integers(1, 3)),
        times,
        objects,
        states,
        lane_ids=lanes,
        behaviours=behaviours,
        images=layer,
        ego=draw(st.sampled_from([None, *ids])),
        attributes={"weather": "rain"},
        map_source=MapSource("m.json", "av2-map") if draw(st.booleans()) else None,
    )


@st.composite
def _image_layers(draw, n_frames: int, n_objects: int) -> ImageLayer:
    sample_frames = sorted(draw(st.lists(st.integers(0, n_frames - 1), max_size=6)))
    n_samples = len(sample_frames)
    samples = SampleTable(
        ("cam::front", "cam::back"),
        np.array(sample_frames, np.int32),
        np.array(draw(st.lists(st.integers(0, 1), min_size=n_samples, max_size=n_samples)), np.int32),
        np.array([f"{i}.png" for i in range(n_samples)], dtype=object),
        np.full(n_samples, 1920, np.int32),
        np.full(n_samples, 1080, np.int32),
    )
    box_samples = sorted(draw(st.lists(st.integers(0, n_samples - 1), max_size=8))) if n_samples else []
    k = len(box_samples)
    coords = lambda: np.array(draw(st.lists(st.floats(0, 2000), min_size=k, max_size=k)))  # noqa: E731
    oriented = np.array(draw(st.lists(st.booleans(), min_size=k, max_size=k)), dtype=bool)
    boxes = BoxTable(
        ("car", "ped"),
        np.array(box_samples, np.int32),
        np.array(draw(st.lists(st.integers(0, 1), min_size=k, max_size=k)), np.int32),
        np.array(draw(st.lists(st.floats(0, 1, width=32), min_size=k, max_size=k)), np.float32),
        coords(),
        coords(),
        coords(),
        coords(),
        np.where(oriented, coords() / 1000, 0.0),
        oriented,
        np.array(draw(st.lists(st.integers(-1, n_objects - 1), min_size=k, max_size=k)), np.int32),
    )
    return ImageLayer(samples, boxes)
