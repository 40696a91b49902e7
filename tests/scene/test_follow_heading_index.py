"""The cuts for one heading (:func:`scenegrep.scene.follow_pieces.crossings` with ``only``) found
through the heading index (:mod:`scenegrep.scene.heading_index`) are exactly those of the R-tree
query followed by the heading test (the inverted walk's step before the index, written out here
as the reference): on random items against a brute-force pass over every (query, item) pair, and
as the preimages of random Town01 walk ends (the same starts, D intervals and headings)."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.scene import follow_pieces
from scenegrep.scene.follow_inverse import preimages
from scenegrep.scene.follow_pieces import ONLY_RAD, _equal_distances, _in_piece, _pieces_met, _segment_crossings, _wrap
from scenegrep.scene.heading_index import WINDOW_RAD, _wrapped, heading_index, near_heading
from tests.scene.test_follow import FIELD
from tests.scene.test_follow_start import town01_walks

ANGLES = st.sampled_from([0.0, 1e-7, -1e-7, np.pi / 2, np.pi, -np.pi, 2 * np.pi - 1e-9, 3.0, np.nan])


def boxes(draw, n: int, far: int = 40) -> np.ndarray:
    corner = np.array(draw(st.lists(st.tuples(*[st.integers(-far, far)] * 2), min_size=n, max_size=n)), float).reshape(
        n, 2
    )
    size = np.array(draw(st.lists(st.tuples(*[st.integers(0, 20)] * 2), min_size=n, max_size=n)), float).reshape(n, 2)
    return np.concatenate([corner, corner + size], axis=1)


@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.data(), st.integers(0, 12), st.integers(0, 8))
def test_near_heading_finds_every_item_near_in_heading_and_box_once(data, items, queries):
    """Brute force: every (query, item) whose boxes meet (closed) and, unless the item is found for
    every heading, one of whose headings lies within the window (WINDOW_RAD, or the inverted walk's
    narrower ONLY_RAD) of the query's, modulo 2π (headings at the wrap, NaN columns, touching boxes,
    queries beyond the items' extent)."""
    headings = np.array(data.draw(st.lists(st.tuples(ANGLES, ANGLES), min_size=items, max_size=items)), float)
    everywhere = np.array(data.draw(st.lists(st.booleans(), min_size=items, max_size=items)), bool)
    index = heading_index(headings.reshape(items, 2), boxes(data.draw, items), everywhere)
    asked = np.array(data.draw(st.lists(ANGLES.filter(lambda a: a == a), min_size=queries, max_size=queries)), float)
    where = boxes(data.draw, queries, far=80)
    window = data.draw(st.sampled_from([WINDOW_RAD, ONLY_RAD]))
    found = list(zip(*(a.tolist() for a in near_heading(index, asked, where, window))))
    expected = {
        (q, i)
        for q in range(queries)
        for i in range(items)
        if np.all(where[q, :2] <= index.bounds[i, 2:])
        and np.all(index.bounds[i, :2] <= where[q, 2:])
        and (everywhere[i] or np.any(np.abs(_wrap(headings.reshape(items, 2)[i] - asked[q])) <= window))
    }
    assert sorted(found) == sorted(expected)


def reference_crossings(lw, px, py, qx, qy, only=None):
    """The cuts as the inverted walk found them before the heading index: every line and pair whose
    box meets the swept segment's (R-tree), then those with the heading tried."""
    index = np.flatnonzero(np.hypot(qx - px, qy - py) > follow_pieces.DEGENERATE_M)
    p = np.stack([px, py], 1)[index]
    r = np.stack([qx, qy], 1)[index] - p
    only = np.asarray(only)[index]
    segments = shapely.linestrings(np.stack([p, p + r], axis=1))
    walk, line = lw.tree.query(segments)
    side = lw.heading_items.heading[line]  # the lines' headings either side, as the linework filed them
    mine = np.isnan(side[:, 0]) | np.any(np.abs(_wrap(side - only[walk][:, None])) <= ONLY_RAD, axis=1)
    walk, line = walk[mine], line[mine]
    hit, t = _segment_crossings(p[walk], r[walk], lw.start[line], lw.end[line] - lw.start[line])
    pair_walk, pair = lw.pair_tree.query(segments)
    heading = lw.polylines.heading[lw.pairs[pair]]
    mine = np.any(np.abs(_wrap(heading - only[pair_walk][:, None])) <= ONLY_RAD, axis=1)
    pair_walk, pair = pair_walk[mine], pair[mine]
    tie_t, tie = _equal_distances(lw, p[pair_walk], r[pair_walk], pair) if len(pair) else (np.zeros(0), pair)
    found_walk = np.concatenate([walk[hit], pair_walk[tie]])
    found_t = np.concatenate([t, tie_t])
    inside = (found_t > 0) & (found_t < 1)
    return index[found_walk[inside]], found_t[inside]


def rows(pre) -> list[tuple]:
    first = np.nan_to_num(pre.first, nan=9.0)
    return sorted(zip(*(a.tolist() for a in (pre.row, pre.lo, pre.hi, pre.steps, pre.ax, pre.ay, first))))


@pytest.mark.real_data
def test_town01_preimages_equal_those_of_the_r_tree_step(monkeypatch):
    """The preimages of 150 Town01 walk ends (random starts near the roads, D forwards and backwards,
    the first heading checked and not) equal, row for row, those with the reference's cuts."""
    geometry, x, y, _, ex, ey, lo, hi = town01_walks(15, 3000, 150)
    new = [rows(preimages(geometry, FIELD, ex, ey, lo, hi, check)) for check in (True, False)]
    monkeypatch.setattr(follow_pieces, "crossings", reference_crossings)
    old = [rows(preimages(geometry, FIELD, ex, ey, lo, hi, check)) for check in (True, False)]
    assert new == old
    assert len(new[0]) >= len(x)


def test_the_heading_wrap_is_np_mod_bit_for_bit():
    """The lookup's wrap divides only the angles outside (0, 2π): it must give np.mod's every bit
    (signed zeros, the ends of the range, NaN and infinities included)."""
    rng = np.random.default_rng(5)
    edges = [0.0, -0.0, 2 * np.pi, np.nextafter(2 * np.pi, 0), -1e-300, 1e-300, np.pi, 4 * np.pi, -2 * np.pi]
    angle = np.concatenate([rng.uniform(-20, 20, 20000), rng.uniform(0, 2 * np.pi, 20000), edges, [np.inf, np.nan]])
    with np.errstate(invalid="ignore"):
        expected, found = np.mod(angle, 2 * np.pi), _wrapped(angle.copy())
    assert np.array_equal(np.isnan(found), np.isnan(expected))
    same = ~np.isnan(expected)
    assert np.array_equal(found[same].view(np.int64), expected[same].view(np.int64))


@settings(max_examples=200, deadline=None)
@given(
    st.floats(-1e3, 1e3, allow_subnormal=False),
    st.floats(-1e3, 1e3, allow_subnormal=False),
    st.floats(0, 1, exclude_min=True, exclude_max=True),
)
def test_the_pieces_a_foot_may_reach_cover_every_root_kept(s0, s1, t):
    """A pair of distance pieces is solved only where both feet may reach them
    (:func:`~scenegrep.scene.follow_pieces._pieces_met`): every piece in which the foot s0 + s1 t
    lies for a t in (0, 1), as :func:`~scenegrep.scene.follow_pieces._in_piece` tests it, is met
    (feet near the pieces' ends included)."""
    foot = np.array([[s0, s1], [-1e-9 - s1 * t, s1], [1 + 1e-9 - s1 * t, s1]])
    met = _pieces_met(foot)
    for piece in range(3):
        inside = _in_piece(foot, np.full(3, piece), np.full(3, t))
        assert not np.any(inside & ~met[:, piece])
