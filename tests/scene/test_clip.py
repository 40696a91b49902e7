"""Lines cut by their domains part by part (:func:`scenegrep.scene.clip.clipped`) give exactly the
geometries of ``shapely.intersection`` with the whole domains: random lines (some of no length,
some across several parts) against multi-part polygons and lines, single boxes, and a mix of
domains per line."""

from __future__ import annotations

import gc

import numpy as np
import shapely

from scenegrep.scene import clip
from scenegrep.scene.clip import clipped

SQUARES = shapely.union_all([shapely.box(x, y, x + 7.0, y + 5.0) for x in (0.0, 12.0, 30.0) for y in (0.0, 9.0, 20.0)])
CURBS = shapely.MultiLineString([[(0, 0), (10, 3), (20, 1)], [(0, 8), (25, 9)], [(5, 15), (5, 30), (18, 30)]])
BOX = shapely.box(3.0, 2.0, 14.0, 11.0)


def random_lines(seed: int, n: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    start = rng.uniform(-5.0, 40.0, (n, 2))
    end = start + rng.normal(0.0, 6.0, (n, 2))
    end[: n // 10] = start[: n // 10]
    return shapely.linestrings(np.stack([start, end], axis=1))


def same(found: np.ndarray, expected: np.ndarray) -> np.ndarray:
    both_empty = shapely.is_empty(found) & shapely.is_empty(expected)
    return both_empty | shapely.equals_exact(found, expected, 0.0)


def test_a_multi_part_domain_cuts_each_line_as_the_whole_does():
    lines = random_lines(1, 3000)
    for domain in (SQUARES, CURBS):
        found = clipped(lines, domain)
        expected = shapely.intersection(lines, domain)
        assert same(found, expected).all()
        hit = ~shapely.is_empty(expected)
        assert np.array_equal(shapely.get_type_id(found[hit]), shapely.get_type_id(expected[hit]))


def test_each_line_is_cut_by_its_own_domain():
    lines = random_lines(2, 900)
    domains = np.array([SQUARES, CURBS, BOX] * 300, dtype=object)
    assert same(clipped(lines, domains), shapely.intersection(lines, domains)).all()


def test_a_domains_parts_are_dropped_with_it():
    domain = shapely.union_all([shapely.box(0, 0, 1, 1), shapely.box(3, 0, 4, 1)])
    clipped(random_lines(3, 10), domain)
    assert id(domain) in clip._PARTS
    key = id(domain)
    del domain
    gc.collect()
    assert key not in clip._PARTS
