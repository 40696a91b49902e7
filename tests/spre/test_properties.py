"""Property tests: the engine against brute-force references (tests/spre/reference.py) on random
queries and random streams, offline and online, in both syntaxes' semantics."""

import json
from unittest.mock import patch

from hypothesis import assume, given, settings
from hypothesis import strategies as st

from scenegrep.readers.strem_json import decode
from scenegrep.spre import SearchOptions, compile_query, search
from scenegrep.spre import evaluate
from scenegrep.spre.search import CompiledQuery
from tests.spre import reference as ref

CLASSES = ("car", "ped", "bus")
LETTERS = ["[:car:]", "[:ped:]", "![:bus:]", "[:car:] & [:ped:]"]


def truth_of(letter: str, classes: set[str]) -> bool:
    return {
        "[:car:]": "car" in classes,
        "[:ped:]": "ped" in classes,
        "![:bus:]": "bus" not in classes,
        "[:car:] & [:ped:]": {"car", "ped"} <= classes,
    }[letter]


queries = st.recursive(
    st.one_of(st.builds(lambda k: ("letter", k), st.integers(0, len(LETTERS) - 1)), st.just(("any",))),
    lambda inner: st.one_of(
        st.builds(lambda a, b: ("cat", a, b), inner, inner),
        st.builds(lambda a, b: ("alt", a, b), inner, inner),
        st.builds(
            lambda q, low, extra: ("rep", q, low, None if extra is None else low + extra),
            inner,
            st.integers(0, 2),
            st.one_of(st.none(), st.integers(0, 2)),
        ),
    ),
    max_leaves=5,
)
streams = st.lists(st.sets(st.sampled_from(CLASSES)), max_size=9)


def stream_document(frames: list[set[str]]) -> bytes:
    """One 4 x 4 box per class present in each frame."""
    return boxes_document([[ref.Box(c, 10.0 * k, 10.0, 4.0, 4.0) for k, c in enumerate(sorted(f))] for f in frames])


@settings(max_examples=300)
@given(queries, streams, st.booleans())
def test_regex_layer_matches_brute_force(query, frames, online):
    truth = [[truth_of(letter, f) for letter in LETTERS] for f in frames]
    trace = decode(stream_document(frames), "<test>", "t")
    found = [
        (m.start, m.end)
        for m in search(compile_query(ref.query_text(query, LETTERS)), trace, SearchOptions(), online=online)
    ]
    expected = ref.online(query, truth) if online else ref.offline(query, truth)
    assert found == expected


# ---------------------------------------------------------------------- formulas over random boxes
coords = st.floats(0, 40, allow_nan=False).map(lambda v: round(v, 1))
boxes = st.builds(
    ref.Box,
    st.sampled_from(CLASSES),
    coords,
    coords,
    st.floats(0, 20).map(lambda v: round(v, 1)),
    st.floats(0, 20).map(lambda v: round(v, 1)),
)
terms = st.recursive(
    st.one_of(
        st.sampled_from(CLASSES).map(lambda c: ("class", c)), st.sampled_from(["u", "v"]).map(lambda v: ("var", v))
    ),
    lambda inner: st.builds(lambda kind, a, b: (kind, a, b), st.sampled_from(["inter", "union"]), inner, inner),
    max_leaves=3,
)
metrics = st.recursive(
    st.one_of(
        st.floats(-5, 50).map(lambda v: ("num", round(v, 1))),
        st.builds(lambda name, t: ("fn", name, t), st.sampled_from(["x", "y", "area", "dist"]), terms),
        st.builds(lambda a, b: ("fn", "dist", a, b), terms, terms),
    ),
    lambda inner: st.builds(lambda kind, a, b: (kind, a, b), st.sampled_from(["add", "sub", "mul"]), inner, inner),
    max_leaves=3,
)
bodies = st.recursive(
    st.one_of(
        st.sampled_from(CLASSES).map(lambda c: ("class", c)),
        terms.map(lambda t: ("ne", t)),
        st.builds(lambda op, a, b: ("cmp", op, a, b), st.sampled_from(["<", ">", "<=", ">="]), metrics, metrics),
    ),
    lambda inner: st.one_of(
        st.builds(lambda f: ("not", f), inner),
        st.builds(lambda kind, a, b: (kind, a, b), st.sampled_from(["and", "or"]), inner, inner),
    ),
    max_leaves=3,
)
formulas = st.builds(
    lambda kind, u, v, body: (kind, ((("u", u),) + ((("v", v),) if v else ())), body),
    st.sampled_from(["E", "A"]),
    st.sampled_from(CLASSES),
    st.one_of(st.none(), st.sampled_from(CLASSES)),
    bodies,
)


def boxes_document(frames: list[list[ref.Box]]) -> bytes:
    def box(b: ref.Box) -> dict:
        region = {"center": {"x": b.cx, "y": b.cy}, "dimensions": {"w": b.w, "h": b.h}}
        return {"class": b.category, "score": 1.0, "bbox": {"type": "@stremf/bbox/aabb", "region": region}}

    return json.dumps(
        {
            "version": "0.2.0",
            "frames": [
                {
                    "index": i,
                    "samples": [
                        {
                            "type": "@stremf/sample/detection",
                            "channel": "c",
                            "image": {"path": "p", "dimensions": {"width": 100, "height": 100}},
                            "annotations": [box(b) for b in f],
                        }
                    ],
                }
                for i, f in enumerate(frames)
            ],
        }
    ).encode()


def _variables(node) -> set[str]:
    if isinstance(node, tuple) and node[:1] == ("var",):
        return {node[1]}
    return (
        set().union(*(_variables(child) for child in node if isinstance(child, tuple)))
        if isinstance(node, tuple)
        else set()
    )


@settings(max_examples=400)
@given(formulas, st.lists(st.lists(boxes, max_size=4), min_size=1, max_size=4), st.booleans())
def test_formulas_match_reference(formula, frames, strem):
    """Each frame satisfies the formula exactly when the reference says so, in scenegrep's
    point-set semantics and in STREM's list-of-boxes semantics (same syntax tree)."""
    assume(_variables(formula[2]) <= {v for v, _ in formula[1]})
    query = compile_query(f"[{ref.formula_text(formula)}]")
    if strem:
        query = CompiledQuery(query.text, query.tree, compat=True)
    trace = decode(boxes_document(frames), "<test>", "t")
    found = {m.start for m in search(query, trace, SearchOptions(), online=True)}
    expected = {i for i, f in enumerate(frames) if ref.holds(formula, f, {}, strem)}
    assert found == expected, query.text


@settings(max_examples=150)
@given(formulas, st.lists(st.lists(boxes, max_size=4), min_size=1, max_size=6), st.integers(1, 40))
def test_chunked_evaluation_equals_whole(formula, frames, cells):
    """Evaluating a quantified formula in chunks of a few samples (a tiny chunk budget) finds
    exactly the frames that one whole evaluation finds."""
    assume(_variables(formula[2]) <= {v for v, _ in formula[1]})
    query = compile_query(f"[{ref.formula_text(formula)}]")
    trace = decode(boxes_document(frames), "<test>", "t")
    whole = [m.start for m in search(query, trace, SearchOptions(), online=True)]
    with patch.object(evaluate, "CHUNK_CELLS", cells):
        chunked = [m.start for m in search(query, trace, SearchOptions(), online=True)]
    assert chunked == whole, query.text
