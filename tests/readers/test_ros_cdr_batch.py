"""A batch decoded run by run (:mod:`scenegrep.readers.ros.cdr_batch`: each chunk's messages copied
or walked as the chunk is read) against the generic walk over the whole batch: random
TrackedObjects of one to three layouts in small MCAP chunks, a stale cached layout or none, a
walk or none (so the parts are layout + walk, or layout + generic), columns that must grow, and at
times a truncated message (refused with the generic walk's position and reason); the segments of a
bag cut into runs anyhow are those of the whole batch at once; UUIDs numbered by their bytes in
order of first appearance; the most probable row of each item as numpy's argmax picks it."""

from __future__ import annotations

import io
import uuid

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.readers.ros.cdr import CdrError, Level, Payloads, decode
from scenegrep.readers.ros.cdr_batch import CdrBatch
from scenegrep.readers.ros.cdr_layout import layout
from scenegrep.readers.ros.cdr_walk import program
from scenegrep.readers.ros.chunks import mcap_runs
from scenegrep.readers.ros.decoders import _best, _uuid_text
from scenegrep.readers.ros.options import BagOptions
from scenegrep.readers.ros.segments import Decoder, segments

from .test_ros_cdr import _message, obj
from .test_ros_cdr_layout import BUILD, KEY, TOPIC, TYPES, WANTED, _mcap, _same_boxes

PROGRAM = program(TYPES, KEY, WANTED)


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.lists(obj, max_size=3), min_size=1, max_size=3),
    st.lists(st.tuples(st.integers(0, 2), st.integers(0, 10**6)), min_size=1, max_size=12),
    st.integers(300, 4000),
    st.sampled_from(["none", "stale", "first"]),
    st.booleans(),
    st.integers(1, 8),
    st.one_of(st.none(), st.tuples(st.integers(0, 11), st.integers(1, 60))),
)
def test_a_batch_added_run_by_run_decodes_as_the_generic_walk_of_it_all(
    pool, picks, chunk_size, cached, walk, capacity, truncate
):
    raw = [_message(pool[k % len(pool)], sec, "map") for k, sec in picks]
    if truncate is not None and truncate[0] < len(raw):
        raw[truncate[0]] = raw[truncate[0]][: max(4, len(raw[truncate[0]]) - truncate[1])]
    items = [(TOPIC, i, r) for i, r in enumerate(raw)]
    runs = [[m.data for m in run] for run in mcap_runs(io.BytesIO(_mcap(items, chunk_size=chunk_size)), 1 << 24, True)]
    layouts = {}
    if cached != "none":
        layouts["k"] = layout(TYPES, KEY, WANTED, _message(pool[-1 if cached == "stale" else 0], 0, "map")[4:])
    batch = CdrBatch(TYPES, KEY, WANTED, "k", capacity, layouts, PROGRAM if walk else None)
    for run in runs:
        batch.add(run)
    try:
        slow = BUILD(decode(TYPES, KEY, Payloads.of(raw), WANTED))
    except CdrError as exc:
        with pytest.raises(CdrError) as found:
            batch.levels()
        assert (found.value.message, found.value.reason) == (exc.message, exc.reason)
        return
    _same_boxes(BUILD(batch.levels()), slow)


@settings(max_examples=15, deadline=None)
@given(
    st.lists(st.lists(obj, max_size=2), min_size=1, max_size=2),
    st.lists(st.integers(0, 1), min_size=1, max_size=10),
    st.lists(st.integers(1, 9), min_size=1, max_size=5),
)
def test_the_segments_of_runs_are_those_of_the_whole_batch(pool, picks, cuts):
    from .test_ros_cdr_layout import _raw

    messages = [_raw(_message(pool[k % len(pool)], i, "map"), i) for i, k in enumerate(picks)]
    whole = segments(messages, BagOptions())
    decoder, at = Decoder(BagOptions(), 4), 0
    for cut in cuts * len(messages):
        decoder.add(messages[at : at + cut])
        at += cut
        if at >= len(messages):
            break
    parts = decoder.take()
    assert [s.topic for s in parts] == [s.topic for s in whole] == [TOPIC]
    np.testing.assert_array_equal(parts[0].log_times, whole[0].log_times)
    _same_boxes(parts[0].decoded, whole[0].decoded)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 5), max_size=300), st.integers(1, 4))
def test_uuid_codes_number_the_distinct_keys_in_order_of_first_appearance(picks, spread):
    keys = np.zeros((len(picks), 16), dtype=np.uint8)
    keys[:, 15 - spread] = picks  # keys differing in one byte, anywhere
    coded = _uuid_text(keys)
    first = {}
    for i, p in enumerate(picks):
        first.setdefault(p, i)
    assert coded.codes.tolist() == [list(first).index(p) for p in picks]
    assert coded.strings().tolist() == [str(uuid.UUID(bytes=bytes(k))) for k in keys]


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 12), st.lists(st.integers(0, 3), min_size=1, max_size=120))
def test_the_best_of_each_item_is_numpys_first_largest(per, values):
    items = max(len(values) // per, 1)
    v = np.resize(np.array(values, dtype=np.float32), items * per)
    level = Level(np.repeat(np.arange(items), per), np.tile(np.arange(per), items), {"p": v})
    expected = np.argmax(v.reshape(items, per), axis=1) + np.arange(items) * per
    assert _best(level, "p", items).tolist() == expected.tolist()
